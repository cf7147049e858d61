#include "halfback/render/brdf_sampler.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "halfback/core/parallel.hpp"

namespace halfback::render {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kOneMinusEpsilon = 0x1.fffffffffffffp-1;

double azimuth(double y, double x) {
  const double p = std::atan2(y, x);
  return p < 0 ? p + 2 * kPi : p;
}

// The cell coordinates (s, t) ∈ [0, 1]² of ωi for a fixed ωo, and back: the polar chart of the
// parameterization (params/charts.hpp), r = r_max s² when warped, φ = 2π t.
struct ParamMap {
  const SamplerChart& chart;
  bool warp;

  double r_max() const { return chart.r_max; }
  double radius(double s) const { return r_max() * (warp ? s * s : s); }
  double radius_derivative(double s) const { return r_max() * (warp ? 2 * s : 1.0); }
  double s_of(double r) const {
    const double x = std::clamp(r / r_max(), 0.0, 1.0);
    return warp ? std::sqrt(x) : x;
  }

  // ωi and |dωi / (ds dt)|; false when (s, t) maps to no direction in the upper hemisphere.
  bool forward(const Vec3<double>& wo, double s, double t, Vec3<double>& wi, double& jac) const {
    const double r = radius(s), dr = radius_derivative(s);
    const double phi = 2 * kPi * t;
    if (!chart.to_direction(wo, r, dr, phi, wi, jac)) return false;
    return wi.z > 0 && jac > 0 && std::isfinite(jac);
  }

  bool inverse(const Vec3<double>& wo, const Vec3<double>& wi, double& s, double& t,
               double& jac) const {
    double r = 0, phi = 0;
    if (!chart.from_direction(wo, wi, r, phi, jac)) return false;
    phi = std::fmod(phi, 2 * kPi);
    if (phi < 0) phi += 2 * kPi;
    s = s_of(r);
    t = phi / (2 * kPi);
    jac *= radius_derivative(s) * 2 * kPi;
    return r <= r_max() && jac > 0 && std::isfinite(jac);
  }
};

Vec3<double> rotate_z(const Vec3<double>& v, double c, double s) {
  return {c * v.x - s * v.y, s * v.x + c * v.y, v.z};
}

// The wrapped BRDF with Brdf's default sampling, the cosine-weighted hemisphere.
class CosineSampling final : public SamplingWrapper {
 public:
  using SamplingWrapper::SamplingWrapper;
};

}  // namespace

std::string format_seconds(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, "%g s", seconds);
  return text;
}

std::shared_ptr<const Brdf> with_importance_sampling(const Brdf& brdf,
                                                     const TabulationOptions& options,
                                                     bool force_tabulated) {
  if (!force_tabulated && brdf.has_importance_sampling())
    return std::shared_ptr<const Brdf>(&brdf, [](const Brdf*) {});  // not owned
  return std::make_shared<TabulatedSampler>(brdf, options);
}

std::shared_ptr<const Brdf> with_cosine_sampling(const Brdf& brdf) {
  return std::make_shared<CosineSampling>(brdf);
}

// --------------------------------------------------------------------------------------------

TabulatedSampler::TabulatedSampler(const Brdf& brdf, const TabulationOptions& o)
    : SamplingWrapper(brdf),
      options_(o),
      chart_(o.param.param().sampler_chart()),
      isotropic_(brdf.isotropic()) {
  const auto start = std::chrono::steady_clock::now();
  if (o.radial < 2 || o.azimuthal < 2 || o.theta_slices < 1 || o.aniso_theta_slices < 1 ||
      o.aniso_phi_slices < 1 || o.supersample < 1 || !(o.defensive >= 0 && o.defensive < 1))
    throw std::invalid_argument("TabulatedSampler: invalid tabulation options");
  n_theta_ = isotropic_ ? o.theta_slices : o.aniso_theta_slices;
  n_phi_ = isotropic_ ? 1 : o.aniso_phi_slices;
  n_radial_ = isotropic_ ? o.radial : std::max(2, o.radial / 2);
  n_azimuthal_ = isotropic_ ? o.azimuthal : std::max(2, o.azimuthal / 2);
  const ParamMap map{chart_, o.warp};
  const int n_slices = n_theta_ * n_phi_, ss = o.supersample;
  slices_.resize(std::size_t(n_slices));

  auto build = [&](int index) {
    const int k = index / n_phi_, l = index % n_phi_;
    const double theta = (k + 0.5) / n_theta_ * kPi / 2;
    const double phi = isotropic_ ? 0.0 : (l + 0.5) / n_phi_ * 2 * kPi;
    const Vec3<double> wo{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                          std::cos(theta)};
    const std::size_t cells = std::size_t(n_radial_) * std::size_t(n_azimuthal_);
    std::vector<DirPair<double>> pairs;
    std::vector<double> factor;  // cos θi |J| of each valid point
    std::vector<std::size_t> cell_of;
    pairs.reserve(cells * std::size_t(ss * ss));
    for (int i = 0; i < n_radial_; ++i)
      for (int j = 0; j < n_azimuthal_; ++j)
        for (int a = 0; a < ss; ++a)
          for (int b = 0; b < ss; ++b) {
            const double s = (i + (a + 0.5) / ss) / n_radial_;
            const double t = (j + (b + 0.5) / ss) / n_azimuthal_;
            Vec3<double> wi{0, 0, 0};
            double jac = 0;
            if (!map.forward(wo, s, t, wi, jac)) continue;
            pairs.push_back({wi, wo});
            factor.push_back(wi.z * jac);
            cell_of.push_back(std::size_t(i) * std::size_t(n_azimuthal_) + std::size_t(j));
          }
    std::vector<Rgb> values(pairs.size());
    for (std::size_t p = 0; p < pairs.size(); ++p) values[p] = brdf.eval(pairs[p]);
    std::vector<double> weights(cells, 0.0);
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      const double v = values[p].luminance() * factor[p];
      if (std::isfinite(v) && v > 0) weights[cell_of[p]] += v;
    }
    slices_[std::size_t(index)] =
        Distribution2D(std::size_t(n_radial_), std::size_t(n_azimuthal_), weights);
  };

  const bool budgeted = o.time_budget > 0;
  auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  std::atomic<bool> out_of_time{false};
  parallel_for(
      std::size_t(n_slices), 1,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end && !out_of_time; ++i) {
          if (budgeted && seconds() > o.time_budget) {
            out_of_time = true;
            return;
          }
          build(int(i));
        }
      },
      o.threads);
  if (out_of_time)
    throw TimeBudgetExceeded("the time budget of " + format_seconds(o.time_budget) +
                             " ran out while tabulating the BRDF's sampler");
  build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::size_t TabulatedSampler::cells() const {
  return slices_.size() * std::size_t(n_radial_) * std::size_t(n_azimuthal_);
}

std::string TabulatedSampler::describe_sampling() const {
  return std::string("tabulated (") + std::string(name_of(options_.param)) +
         (options_.warp ? ", warped" : "") + ", " + std::to_string(n_theta_) +
         (isotropic_ ? "" : " x " + std::to_string(n_phi_)) + " slices of " +
         std::to_string(n_radial_) + " x " + std::to_string(n_azimuthal_) + " cells) of " +
         brdf_.name();
}

TabulatedSampler::Blend TabulatedSampler::blend(const Vec3<double>& wo) const {
  Blend b{};
  const double theta = std::atan2(std::sqrt(wo.x * wo.x + wo.y * wo.y), wo.z);
  const double x = theta / (kPi / 2) * n_theta_ - 0.5;
  int k0 = int(std::floor(x));
  double tk = x - k0;
  if (k0 < 0) {
    k0 = 0;
    tk = 0;
  } else if (k0 >= n_theta_ - 1) {
    k0 = n_theta_ - 1;
    tk = 0;
  }
  const int k1 = std::min(k0 + 1, n_theta_ - 1);
  if (n_phi_ == 1) {
    b.index[0] = k0;
    b.weight[0] = 1 - tk;
    b.index[1] = k1;
    b.weight[1] = tk;
    b.count = 2;
    return b;
  }
  const double y = azimuth(wo.y, wo.x) / (2 * kPi) * n_phi_ - 0.5;
  int l0 = int(std::floor(y));
  const double tl = y - l0;
  l0 = (l0 % n_phi_ + n_phi_) % n_phi_;
  const int l1 = (l0 + 1) % n_phi_;
  const int ks[2] = {k0, k1}, ls[2] = {l0, l1};
  const double wk[2] = {1 - tk, tk}, wl[2] = {1 - tl, tl};
  b.count = 4;
  for (int a = 0; a < 2; ++a)
    for (int c = 0; c < 2; ++c) {
      b.index[2 * a + c] = ks[a] * n_phi_ + ls[c];
      b.weight[2 * a + c] = wk[a] * wl[c];
    }
  return b;
}

BrdfSample TabulatedSampler::sample(const Vec3<double>& wo_in, double u1, double u2) const {
  if (!(wo_in.z > 0)) return {};
  const double eps = options_.defensive;
  if (u1 < eps) {
    const Vec3<double> wi = sample_cosine_hemisphere(u1 / eps, u2);
    if (!(wi.z > 0)) return {};
    return {wi, pdf(wo_in, wi)};
  }
  u1 = std::min((u1 - eps) / (1 - eps), kOneMinusEpsilon);
  // Isotropic: work in the canonical pose, ωo in the xz half-plane.
  double c = 1, s = 0;
  Vec3<double> wo = wo_in;
  if (isotropic_) {
    const double r = std::sqrt(wo.x * wo.x + wo.y * wo.y);
    if (r > 0) {
      c = wo.x / r;
      s = wo.y / r;
    }
    wo = {r, 0, wo.z};
  }
  const Blend b = blend(wo);
  int pick = b.count - 1;
  double acc = 0;
  for (int i = 0; i < b.count; ++i) {
    if (b.weight[i] <= 0) continue;
    if (u1 < acc + b.weight[i]) {
      pick = i;
      u1 = std::min((u1 - acc) / b.weight[i], kOneMinusEpsilon);
      break;
    }
    acc += b.weight[i];
  }
  const auto cell = slices_[std::size_t(b.index[pick])].sample(u1, u2);
  if (!(cell.probability > 0)) return {};
  const double ss = (double(cell.row) + cell.remapped_row) / n_radial_;
  const double tt = (double(cell.col) + cell.remapped_col) / n_azimuthal_;
  Vec3<double> wi{0, 0, 0};
  double jac = 0;
  if (!ParamMap{chart_, options_.warp}.forward(wo, ss, tt, wi, jac)) return {};
  wi = rotate_z(wi, c, s);
  return {wi, pdf(wo_in, wi)};
}

double TabulatedSampler::table_pdf(const Vec3<double>& wo, const Vec3<double>& wi,
                                   const Blend& b) const {
  double s = 0, t = 0, jac = 0;
  if (!ParamMap{chart_, options_.warp}.inverse(wo, wi, s, t, jac)) return 0;
  const std::size_t row = std::min(std::size_t(s * n_radial_), std::size_t(n_radial_ - 1));
  const std::size_t col = std::min(std::size_t(t * n_azimuthal_), std::size_t(n_azimuthal_ - 1));
  double p = 0;
  for (int i = 0; i < b.count; ++i)
    if (b.weight[i] > 0) p += b.weight[i] * slices_[std::size_t(b.index[i])].probability(row, col);
  return p * double(n_radial_) * double(n_azimuthal_) / jac;
}

double TabulatedSampler::pdf(const Vec3<double>& wo_in, const Vec3<double>& wi_in) const {
  if (!(wo_in.z > 0 && wi_in.z > 0)) return 0;
  Vec3<double> wo = wo_in, wi = wi_in;
  if (isotropic_) {
    const double r = std::sqrt(wo.x * wo.x + wo.y * wo.y);
    if (r > 0) wi = rotate_z(wi, wo.x / r, -wo.y / r);
    wo = {r, 0, wo.z};
  }
  const double eps = options_.defensive;
  return (1 - eps) * table_pdf(wo, wi, blend(wo)) + eps * cosine_hemisphere_pdf(wi_in);
}

}  // namespace halfback::render
