// BRDF importance sampling for the renderer, through the one sampling interface (Brdf::sample and
// Brdf::pdf): a BRDF's own sampler when it has one (analytic models, RGL's VNDF warp), else a
// tabulation of ρ cos θi in a parameterization of ωi given ωo, sampled with piecewise-constant
// distributions (docs/render.md, "Sampling tabulated BRDFs"). The samplers here are BRDFs that
// wrap another: ρ is the wrapped one's, only sample() and pdf() change.
//
// Directions are in the local frame (n = +z); ωo is the view direction, ωi the sampled light
// direction; pdfs are per unit solid angle. All samplers are immutable and thread-safe.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/core/space.hpp"
#include "halfback/render/distribution.hpp"

namespace halfback::render {

namespace detail {  // src/render/chart_cells.hpp
struct MixtureSampling;
struct CellMixture;
}  // namespace detail

struct TabulationOptions {
  // The parameterization whose sampler chart (params/charts.hpp: the 2D chart of ωi, for a fixed
  // ωo, of its first two coordinates) the tabulated sampler's cells live in. halfdiff's
  // half-vector chart: the lowest variance per byte of table on every material measured
  // (docs/render.md, "Comparing samplers").
  Space param = space_of<HalfDiff>;
  // The radial coordinate (θi, θh or ‖h̄‖) as r = r_max s², s uniform over the cells: cells are
  // finer near the lobe's peak (the normal for spherical, the mirror direction for the others).
  bool warp = true;
  int radial = 64, azimuthal = 128;                    // cells of one slice
  int theta_slices = 32;                               // slices in θo (isotropic BRDFs)
  int aniso_theta_slices = 16, aniso_phi_slices = 16;  // anisotropic BRDFs: slices in θo × φo,
                                                       // each of radial/2 × azimuthal/2 cells
  int supersample = 2;      // ρ cos θi |J| per cell: mean over supersample² points
  double defensive = 0.05;  // probability of a cosine-weighted sample instead (never 0 where ρ ≠ 0)
  int threads = 0;          // for building the tables; 0: all cores
  // Seconds the build may take (0: no limit), checked between slices: past it the constructor
  // throws TimeBudgetExceeded (a render's --time-budget includes its sampler set-up).
  double time_budget = 0;
};

// A bounded piece of work (a render, the build of its sampler) that ran out of its time budget
// before it had a usable result.
class TimeBudgetExceeded : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
std::string format_seconds(double seconds);  // "0.2 s", "1e+09 s" (%g)

// A BRDF that samples another's ρ through the sampling methods of a third: the base for the
// samplers below (eval, name, symmetries and facts are the wrapped BRDF's). The wrapped BRDF must
// outlive the wrapper.
class SamplingWrapper : public Brdf {
 public:
  explicit SamplingWrapper(const Brdf& brdf) : brdf_(brdf) {}
  std::string name() const override { return brdf_.name(); }
  std::string description() const override { return brdf_.description(); }
  bool isotropic() const override { return brdf_.isotropic(); }
  bool reciprocal() const override { return brdf_.reciprocal(); }
  Rgb eval(const DirPair<double>& pair) const override { return brdf_.eval(pair); }
  void eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const override {
    brdf_.eval_batch(pairs, out);
  }
  std::vector<Fact> facts() const override { return brdf_.facts(); }

 protected:
  const Brdf& brdf_;
};

// `brdf` as the renderer samples it: itself when it has importance sampling of its own (unless
// `force_tabulated`), else a TabulatedSampler around it. The BRDF must outlive the result.
std::shared_ptr<const Brdf> with_importance_sampling(const Brdf& brdf,
                                                     const TabulationOptions& options = {},
                                                     bool force_tabulated = false);

// `brdf` sampled from the cosine-weighted hemisphere (for comparisons).
std::shared_ptr<const Brdf> with_cosine_sampling(const Brdf& brdf);

class TabulatedSampler final : public SamplingWrapper {
 public:
  TabulatedSampler(const Brdf& brdf, const TabulationOptions& options = {});
  BrdfSample sample(const Vec3<double>& wo, double u1, double u2) const override;
  double pdf(const Vec3<double>& wo, const Vec3<double>& wi) const override;
  bool has_importance_sampling() const override { return true; }
  std::string describe_sampling() const override;

  // Table size and build time, for reports.
  std::size_t cells() const;
  double build_seconds() const { return build_seconds_; }

 private:
  detail::MixtureSampling sampling() const;  // the slices as a mixture (chart_cells.hpp)
  detail::CellMixture blended(const Vec3<double>& wo) const;  // the slices' weights at ωo

  TabulationOptions options_;
  SamplerChart chart_;  // options_.param's, looked up once: sample() and pdf() are per path vertex
  bool isotropic_;
  int n_theta_, n_phi_, n_radial_, n_azimuthal_;
  std::vector<Distribution2D> slices_;  // [theta][phi]
  double build_seconds_ = 0;
};

}  // namespace halfback::render
