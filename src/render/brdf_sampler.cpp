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

MixtureSampling TabulatedSampler::sampling() const {
  return {{chart_, options_.warp}, n_radial_,  n_azimuthal_,
          options_.defensive,      isotropic_, slices_};
}

BrdfSample TabulatedSampler::sample(const Vec3<double>& wo, double u1, double u2) const {
  return sampling().sample(wo, u1, u2, [this](const Vec3<double>& w) { return blended(w); });
}

double TabulatedSampler::pdf(const Vec3<double>& wo, const Vec3<double>& wi) const {
  return sampling().pdf(wo, wi, [this](const Vec3<double>& w) { return blended(w); });
}

// The slices around ωo (canonical) and their blend weights.
CellMixture TabulatedSampler::blended(const Vec3<double>& wo) const {
  const SliceGrid::Blend b = SliceGrid{n_theta_, n_phi_}.blend(wo);
  CellMixture m;
  m.count = b.count;
  for (int i = 0; i < b.count; ++i) {
    m.table[std::size_t(i)] = b.index[i];
    m.weight[std::size_t(i)] = b.weight[i];
  }
  return m;
}

}  // namespace halfback::render
