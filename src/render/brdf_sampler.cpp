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

#include "chart_cells.hpp"
#include "halfback/core/parallel.hpp"

namespace halfback::render {

using namespace detail;

namespace {

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
  const SliceGrid grid{n_theta_, n_phi_};
  slices_.resize(std::size_t(grid.count()));
  auto build = [&](int index) {
    slices_[std::size_t(index)] = Distribution2D(
        std::size_t(n_radial_), std::size_t(n_azimuthal_),
        tabulate_cells(brdf, map, grid.view(index), n_radial_, n_azimuthal_, o.supersample));
  };

  const bool budgeted = o.time_budget > 0;
  auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  std::atomic<bool> out_of_time{false};
  parallel_for(
      std::size_t(grid.count()), 1,
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

BrdfSample TabulatedSampler::sample(const Vec3<double>& wo_in, double u1, double u2) const {
  if (!(wo_in.z > 0)) return {};
  const double eps = options_.defensive;
  if (u1 < eps) {
    const Vec3<double> wi = sample_cosine_hemisphere(u1 / eps, u2);
    if (!(wi.z > 0)) return {};
    return {wi, pdf(wo_in, wi)};
  }
  u1 = std::min((u1 - eps) / (1 - eps), kOneMinusEpsilon);
  const CanonicalPose pose = canonical_pose(wo_in, isotropic_);
  const SliceGrid::Blend b = SliceGrid{n_theta_, n_phi_}.blend(pose.wo);
  const int pick = pick_weighted(b.weight, b.count, u1);
  if (pick < 0) return {};
  const auto cell = slices_[std::size_t(b.index[pick])].sample(u1, u2);
  if (!(cell.probability > 0)) return {};
  const double s = (double(cell.row) + cell.remapped_row) / n_radial_;
  const double t = (double(cell.col) + cell.remapped_col) / n_azimuthal_;
  Vec3<double> wi{0, 0, 0};
  double jac = 0;
  if (!ParamMap{chart_, options_.warp}.forward(pose.wo, s, t, wi, jac)) return {};
  wi = rotate_z(wi, pose.c, pose.s);
  // pdf(ωo, ωi) from the cell and Jacobian at hand (pdf() would map ωi back to them).
  double p = 0;
  for (int i = 0; i < b.count; ++i)
    if (b.weight[i] > 0)
      p += b.weight[i] * slices_[std::size_t(b.index[i])].probability(cell.row, cell.col);
  const double table = p * double(n_radial_) * double(n_azimuthal_) / jac;
  return {wi, (1 - eps) * table + eps * cosine_hemisphere_pdf(wi)};
}

double TabulatedSampler::table_pdf(const Vec3<double>& wo, const Vec3<double>& wi) const {
  double s = 0, t = 0, jac = 0;
  if (!ParamMap{chart_, options_.warp}.inverse(wo, wi, s, t, jac)) return 0;
  const std::size_t row = std::min(std::size_t(s * n_radial_), std::size_t(n_radial_ - 1));
  const std::size_t col = std::min(std::size_t(t * n_azimuthal_), std::size_t(n_azimuthal_ - 1));
  const SliceGrid::Blend b = SliceGrid{n_theta_, n_phi_}.blend(wo);
  double p = 0;
  for (int i = 0; i < b.count; ++i)
    if (b.weight[i] > 0) p += b.weight[i] * slices_[std::size_t(b.index[i])].probability(row, col);
  return p * double(n_radial_) * double(n_azimuthal_) / jac;
}

double TabulatedSampler::pdf(const Vec3<double>& wo_in, const Vec3<double>& wi_in) const {
  if (!(wo_in.z > 0 && wi_in.z > 0)) return 0;
  const CanonicalPose pose = canonical_pose(wo_in, isotropic_);
  const Vec3<double> wi = rotate_z(wi_in, pose.c, -pose.s);
  const double eps = options_.defensive;
  return (1 - eps) * table_pdf(pose.wo, wi) + eps * cosine_hemisphere_pdf(wi_in);
}

}  // namespace halfback::render
