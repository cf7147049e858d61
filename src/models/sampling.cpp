// Importance sampling of the analytic models (Brdf::sample and Brdf::pdf). The formulas
// and their sources are in docs/render.md.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "halfback/models/analytic.hpp"
#include "sampling_detail.hpp"

namespace halfback::models {

namespace {

constexpr double kPi = std::numbers::pi;

double dot(const Vec3<double>& a, const Vec3<double>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

Vec3<double> normalize(const Vec3<double>& v) {
  const double l = std::sqrt(dot(v, v));
  return {v.x / l, v.y / l, v.z / l};
}

// Mirror of wo about the unit normal m.
Vec3<double> reflect(const Vec3<double>& wo, const Vec3<double>& m) {
  const double c = 2 * dot(wo, m);
  return {c * m.x - wo.x, c * m.y - wo.y, c * m.z - wo.z};
}

BrdfSample finish(const Brdf& s, const Vec3<double>& wo, const Vec3<double>& wi) {
  if (!(wi.z > 0)) return {};
  return {wi, s.pdf(wo, wi)};
}

}  // namespace

// --- mixture weights --------------------------------------------------------------------------

namespace detail {

void MixtureWeightsDeleter::operator()(MixtureWeights* p) const {
  delete p;
}

MixtureWeights::MixtureWeights(
    std::size_t lobes, const std::function<double(std::size_t, const Vec3<double>&)>& albedo)
    : lobes_(lobes), table_(std::size_t(kNodes) * lobes) {
  for (int k = 0; k < kNodes; ++k) {
    const double c = (k + 0.5) / kNodes, s = std::sqrt(1 - c * c);
    // At φo = π/4, between the two roughness axes of an anisotropic lobe.
    const Vec3<double> wo{s * std::sqrt(0.5), s * std::sqrt(0.5), c};
    double sum = 0;
    for (std::size_t j = 0; j < lobes; ++j) {
      const double a = std::max(0.0, albedo(j, wo));
      table_[std::size_t(k) * lobes + j] = std::isfinite(a) ? a : 0;
      sum += table_[std::size_t(k) * lobes + j];
    }
    for (std::size_t j = 0; j < lobes; ++j) {
      double& w = table_[std::size_t(k) * lobes + j];
      w = sum > 0 ? w / sum : 1.0 / double(lobes);
    }
  }
}

void MixtureWeights::weights(double cos_o, std::span<double> out) const {
  const double x = std::clamp(cos_o * kNodes - 0.5, 0.0, double(kNodes - 1));
  const int k0 = std::min(int(x), kNodes - 2);
  const double t = std::clamp(x - k0, 0.0, 1.0);
  for (std::size_t j = 0; j < lobes_; ++j)
    out[j] = (1 - t) * table_[std::size_t(k0) * lobes_ + j] +
             t * table_[std::size_t(k0 + 1) * lobes_ + j];
}

double MixtureWeights::albedo(const Brdf& brdf, const Brdf& sampler, const Vec3<double>& wo) {
  double sum = 0;
  for (int i = 0; i < kStrata; ++i)
    for (int j = 0; j < kStrata; ++j) {
      const BrdfSample s = sampler.sample(wo, (i + 0.5) / kStrata, (j + 0.5) / kStrata);
      if (s.pdf > 0) sum += brdf.eval({s.wi, wo}).luminance() * s.wi.z / s.pdf;
    }
  return sum / (kStrata * kStrata);
}

}  // namespace detail

// --- Lambert and sheen: the cosine ------------------------------------------------------------

BrdfSample Lambert::sample(const Vec3<double>& wo, double u1, double u2) const {
  return Brdf::sample(wo, u1, u2);
}
double Lambert::pdf(const Vec3<double>& wo, const Vec3<double>& wi) const {
  return Brdf::pdf(wo, wi);
}

BrdfSample Sheen::sample(const Vec3<double>& wo, double u1, double u2) const {
  return Brdf::sample(wo, u1, u2);
}
double Sheen::pdf(const Vec3<double>& wo, const Vec3<double>& wi) const {
  return Brdf::pdf(wo, wi);
}

// --- Microfacet ---------------------------------------------------------------------------------
// GGX: the distribution of visible normals D_ωo(m) = G1(ωo) max(0, ωo·m) D(m) / cos θo, sampled
// exactly (Heitz 2018, "Sampling the GGX Distribution of Visible Normals"); ωi = reflect(ωo, m),
// pdf(ωi) = D_ωo(m) / (4 ωo·m) = G1(ωo) D(m) / (4 cos θo).
// Beckmann: m with density D(m) cos θm (a Gaussian in slope space), pdf(ωi) = D(m) cos θm /
// (4 ωo·m).

BrdfSample Microfacet::sample(const Vec3<double>& wo, double u1, double u2) const {
  if (!(wo.z > 0)) return {};
  if (params_.distribution == MicrofacetParams::Distribution::ggx) return sample_ggx(wo, u1, u2);
  const double ax = params_.alpha_x, ay = params_.alpha_y;
  const double r = std::sqrt(-std::log1p(-u1)), phi = 2 * kPi * u2;
  const Vec3<double> m = normalize({-ax * r * std::cos(phi), -ay * r * std::sin(phi), 1});
  if (!(dot(wo, m) > 0)) return {};
  const Vec3<double> wi = reflect(wo, m);
  if (!(wi.z > 0)) return {};
  return {wi, distribution(m) * m.z / (4 * dot(wo, m))};
}

namespace {

// One GGX visible-normal sample, with selects rather than early returns; a sample that fails (ωo or
// ωi below the horizon, ωo·m ≤ 0) comes back as BrdfSample{}. The stretched view s = (αx ωo_x, αy
// ωo_y, ωo_z), of length L, gives both the hemisphere configuration's view ŝ and 1 + Λ(ωo) = (1 +
// L/cos θo)/2; the normal drawn there, n, stretches back to m = t/‖t‖ with t = (αx n_x, αy n_y,
// n_z), where D(m) = (‖t‖²/‖n‖²)² / (π αx αy). The pdf D(m)/((1 + Λ(ωo)) 4 cos θo) is then D(m) /
// (2 (cos θo + L)) (docs/models.md).
struct GgxShape {
  double ax, ay, inv_pi_axay;
};
[[gnu::always_inline]] inline BrdfSample ggx_visible_normal_sample(const GgxShape& g,
                                                                   const Vec3<double>& wo,
                                                                   double u1, double u2) {
  const double sx = g.ax * wo.x, sy = g.ay * wo.y, len2 = sx * sx + sy * sy;
  const double l = std::sqrt(len2 + wo.z * wo.z), inv_l = 1 / l;
  const double vx = sx * inv_l, vy = sy * inv_l, vz = wo.z * inv_l;
  const bool tilted = len2 > 0;
  const double inv_t = 1 / std::sqrt(tilted ? len2 : 1.0);
  const double t1x = tilted ? -sy * inv_t : 1.0, t1y = tilted ? sx * inv_t : 0.0;
  const double t2x = -vz * t1y, t2y = vz * t1x, t2z = vx * t1y - vy * t1x;  // ŝ × t1
  // A point on the projected hemisphere: a disk, half of it squashed by the view's slope.
  double sin_phi, cos_phi;
  detail::sincos_turns(u2, sin_phi, cos_phi);
  const double r = std::sqrt(u1), p1 = r * cos_phi, s = 0.5 * (1 + vz);
  const double p2 = (1 - s) * std::sqrt(std::max(0.0, 1 - p1 * p1)) + s * (r * sin_phi);
  const double pz = std::sqrt(std::max(0.0, 1 - p1 * p1 - p2 * p2));
  const double nx = p1 * t1x + p2 * t2x + pz * vx, ny = p1 * t1y + p2 * t2y + pz * vy;
  const double nz = std::max(1e-300, p2 * t2z + pz * vz);
  const double tx = g.ax * nx, ty = g.ay * ny, tt = tx * tx + ty * ty + nz * nz;
  const double inv_len = 1 / std::sqrt(tt);
  const double mx = tx * inv_len, my = ty * inv_len, mz = nz * inv_len;
  const double cos_om = wo.x * mx + wo.y * my + wo.z * mz;
  const double wix = 2 * cos_om * mx - wo.x, wiy = 2 * cos_om * my - wo.y;
  const double wiz = 2 * cos_om * mz - wo.z;
  const double ratio = tt / (nx * nx + ny * ny + nz * nz);
  const double pdf = ratio * ratio * g.inv_pi_axay / (2 * (wo.z + l));
  const bool ok = (wo.z > 0) & (cos_om > 0) & (wiz > 0);  // no branches
  return {{ok ? wix : 0.0, ok ? wiy : 0.0, ok ? wiz : 0.0}, ok ? pdf : 0.0};
}

// The batch: no virtual call per sample, and the samples in SIMD lanes: the directions are copied
// into columns (structure of arrays) so that the loop of the branch-free sample vectorizes (the
// layer is compiled with -fno-trapping-math, which lets the compiler evaluate both sides of a
// select), then copied back. The lanes' arithmetic is IEEE per element, so the numbers are
// sample()'s bit for bit.
void ggx_visible_normal_batch(const GgxShape g, const Vec3<double>* wo, const double* u1,
                              const double* u2, BrdfSample* out, std::size_t n) {
  constexpr std::size_t kLanes = 16;
  for (std::size_t first = 0; first < n; first += kLanes) {
    const std::size_t m = std::min(kLanes, n - first);
    double x[kLanes], y[kLanes], z[kLanes], a[kLanes], b[kLanes];
    double ox[kLanes], oy[kLanes], oz[kLanes], op[kLanes];
    for (std::size_t i = 0; i < m; ++i) {
      x[i] = wo[first + i].x, y[i] = wo[first + i].y, z[i] = wo[first + i].z;
      a[i] = u1[first + i], b[i] = u2[first + i];
    }
    for (std::size_t i = 0; i < m; ++i) {
      const BrdfSample s = ggx_visible_normal_sample(g, {x[i], y[i], z[i]}, a[i], b[i]);
      ox[i] = s.wi.x, oy[i] = s.wi.y, oz[i] = s.wi.z, op[i] = s.pdf;
    }
    for (std::size_t i = 0; i < m; ++i) out[first + i] = {{ox[i], oy[i], oz[i]}, op[i]};
  }
}

}  // namespace

BrdfSample Microfacet::sample_ggx(const Vec3<double>& wo, double u1, double u2) const {
  return ggx_visible_normal_sample({params_.alpha_x, params_.alpha_y, inv_pi_axay_}, wo, u1, u2);
}

void Microfacet::sample_batch(std::span<const Vec3<double>> wo, std::span<const double> u1,
                              std::span<const double> u2, std::span<BrdfSample> out) const {
  if (params_.distribution != MicrofacetParams::Distribution::ggx || wo.size() != out.size() ||
      u1.size() != out.size() || u2.size() != out.size()) {
    Brdf::sample_batch(wo, u1, u2, out);  // one at a time, and the size check
    return;
  }
  ggx_visible_normal_batch({params_.alpha_x, params_.alpha_y, inv_pi_axay_}, wo.data(), u1.data(),
                           u2.data(), out.data(), out.size());
}

// GGX: with h = ωi + ωo, D(ĥ) = ‖h‖⁴ / (π αx αy Q²), Q = h_x²/αx² + h_y²/αy² + h_z² (no
// normalization; docs/models.md).
double Microfacet::pdf(const Vec3<double>& wo, const Vec3<double>& wi) const {
  if (!(wo.z > 0 && wi.z > 0)) return 0;
  if (params_.distribution == MicrofacetParams::Distribution::ggx) {
    const double hx = wi.x + wo.x, hy = wi.y + wo.y, hz = wi.z + wo.z;
    const double h2 = hx * hx + hy * hy + hz * hz;
    const double q = hx * hx * inv_ax2_ + hy * hy * inv_ay2_ + hz * hz;
    const double ax = params_.alpha_x, ay = params_.alpha_y;
    const double l = std::sqrt(ax * ax * wo.x * wo.x + ay * ay * wo.y * wo.y + wo.z * wo.z);
    return h2 * h2 * inv_pi_axay_ / (2 * q * q * (wo.z + l));
  }
  const Vec3<double> m = normalize({wi.x + wo.x, wi.y + wo.y, wi.z + wo.z});
  return distribution(m) * m.z / (4 * dot(wo, m));
}

void Microfacet::pdf_batch(std::span<const DirPair<double>> pairs, std::span<double> out) const {
  if (out.size() != pairs.size()) {
    Brdf::pdf_batch(pairs, out);  // the size check
    return;
  }
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = Microfacet::pdf(pairs[i].wo, pairs[i].wi);
}

// --- ABC
// ------------------------------------------------------------------------------------------ The
// specular lobe is S(f), f = ‖ωi_xy + ωo_xy‖: in the plane of projected directions it is a radial
// function around the projected mirror direction −ωo_xy. It is sampled there with density q(x) ∝ (1
// + B f²)^(−a), a = (C+1)/2, truncated to f ≤ 2 (the largest possible f); a point outside the unit
// disk is no sample. dA = cos θi dωi, so pdf(ωi) = q(ωi_xy) cos θi. kd is sampled by the cosine;
// the two are mixed with weights from their albedos at θo.

namespace {

// ∫_0^f r (1 + B r²)^(−a) dr, and the inverse of its normalized form.
struct AbcRadial {
  double b, e;  // e = 1 − a
  double integral(double f) const {
    if (b <= 0) return 0.5 * f * f;
    const double l = std::log1p(b * f * f);
    if (std::abs(e) < 1e-9) return l / (2 * b);
    return std::expm1(e * l) / (2 * b * e);
  }
  double invert(double u) const {  // f with integral(f) = u · integral(2)
    if (b <= 0) return 2 * std::sqrt(u);
    const double l2 = std::log1p(4 * b);
    double f2;
    if (std::abs(e) < 1e-9) {
      f2 = std::expm1(u * l2) / b;
    } else {
      f2 = std::expm1(std::log1p(u * std::expm1(e * l2)) / e) / b;
    }
    return std::sqrt(std::max(0.0, f2));
  }
};

}  // namespace

const detail::MixtureWeights& Abc::mixture() const {
  std::call_once(mixture_once_, [this] {
    const double kd = params_.kd.luminance();
    const AbcRadial radial{params_.b, 1 - 0.5 * (params_.c + 1)};
    mixture_.reset(new detail::MixtureWeights(2, [&](std::size_t lobe, const Vec3<double>& wo) {
      if (lobe == 1) return kd;
      // The specular albedo, sampled with the specular lobe's own density.
      double sum = 0;
      const int n = detail::MixtureWeights::kStrata;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const double f = radial.invert((i + 0.5) / n), phi = 2 * kPi * (j + 0.5) / n;
          const double x = f * std::cos(phi) - wo.x, y = f * std::sin(phi) - wo.y;
          const double r2 = x * x + y * y;
          if (r2 >= 1) continue;
          const Vec3<double> wi{x, y, std::sqrt(1 - r2)};
          const double q = std::pow(1 + params_.b * f * f, -0.5 * (params_.c + 1)) /
                           (2 * kPi * radial.integral(2));
          const double spec = eval({wi, wo}).luminance() - kd / kPi;
          sum += std::max(0.0, spec) * wi.z / (q * wi.z);
        }
      return sum / (n * n);
    }));
  });
  return *mixture_;
}

BrdfSample Abc::sample(const Vec3<double>& wo, double u1, double u2) const {
  if (!(wo.z > 0)) return {};
  std::array<double, 2> w;
  mixture().weights(wo.z, w);
  if (detail::pick_lobe(w, u1) == 1) return finish(*this, wo, sample_cosine_hemisphere(u1, u2));
  const AbcRadial radial{params_.b, 1 - 0.5 * (params_.c + 1)};
  const double f = radial.invert(u1), phi = 2 * kPi * u2;
  const double x = f * std::cos(phi) - wo.x, y = f * std::sin(phi) - wo.y;
  const double r2 = x * x + y * y;
  if (!(r2 < 1)) return {};
  return finish(*this, wo, {x, y, std::sqrt(1 - r2)});
}

double Abc::pdf(const Vec3<double>& wo, const Vec3<double>& wi) const {
  if (!(wo.z > 0 && wi.z > 0)) return 0;
  std::array<double, 2> w;
  mixture().weights(wo.z, w);
  const AbcRadial radial{params_.b, 1 - 0.5 * (params_.c + 1)};
  const double fx = wi.x + wo.x, fy = wi.y + wo.y, f2 = fx * fx + fy * fy;
  const double q =
      std::pow(1 + params_.b * f2, -0.5 * (params_.c + 1)) / (2 * kPi * radial.integral(2));
  return w[0] * q * wi.z + w[1] * cosine_hemisphere_pdf(wi);
}

// --- Sum: a mixture of the terms' samplers --------------------------------------------------

const detail::MixtureWeights& Sum::mixture() const {
  std::call_once(mixture_once_, [this] {
    mixture_.reset(
        new detail::MixtureWeights(terms_.size(), [this](std::size_t j, const Vec3<double>& wo) {
          return detail::MixtureWeights::albedo(*terms_[j], *terms_[j], wo);
        }));
  });
  return *mixture_;
}

BrdfSample Sum::sample(const Vec3<double>& wo, double u1, double u2) const {
  if (!(wo.z > 0)) return {};
  std::vector<double> w(terms_.size());
  mixture().weights(wo.z, w);
  const std::size_t j = detail::pick_lobe(w, u1);
  const BrdfSample s = terms_[j]->sample(wo, u1, u2);
  if (!(s.pdf > 0)) return {};
  return finish(*this, wo, s.wi);
}

double Sum::pdf(const Vec3<double>& wo, const Vec3<double>& wi) const {
  if (!(wo.z > 0 && wi.z > 0)) return 0;
  std::vector<double> w(terms_.size());
  mixture().weights(wo.z, w);
  double p = 0;
  for (std::size_t j = 0; j < terms_.size(); ++j)
    if (w[j] > 0) p += w[j] * terms_[j]->pdf(wo, wi);
  return p;
}

}  // namespace halfback::models
