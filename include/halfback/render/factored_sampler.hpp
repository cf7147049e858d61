// A factored importance sampler in the manner of Lawrence, Rusinkiewicz & Ramamoorthi 2004
// ("Efficient BRDF Importance Sampling Using a Factored Representation"; docs/render.md,
// "The factored sampler"): ρ cos θi, tabulated in a parameterization's sampler chart at a set of
// views ωo, is approximated by a few terms shared by every view,
//
//   p(ωi | ωo) ∝ Σ_j w_j(ωo) h_j(ωi),
//
// with non-negative view weights w_j and 2D tables h_j over the chart's cells (non-negative
// matrix factorization of the views' distributions, Lee & Seung's updates for the generalized
// Kullback–Leibler divergence). Where the tabulated sampler stores one table per view, this one
// stores `terms` tables: at equal memory its cells are finer, its dependence on ωo coarser.
// Sampling picks a term by its weight at ωo (interpolated between views as the tabulated
// sampler's slices are) and a cell of its table. Immutable and thread-safe once built.
#pragma once

#include <cstddef>
#include <vector>

#include "halfback/render/brdf_sampler.hpp"

namespace halfback::render {

struct FactorOptions {
  Space param = space_of<HalfDiff>;  // whose sampler chart the tables live in
  bool warp = true;                  // r = r_max s² (TabulationOptions::warp)
  int terms = 4;                     // J, 1 to FactoredSampler::kMaxTerms
  int radial = 64, azimuthal = 128;  // cells of each term's table
  // Views the factorization is fitted to: θo steps (isotropic BRDFs), θo × φo (anisotropic).
  int theta_views = 16;
  int aniso_theta_views = 8, aniso_phi_views = 8;
  int supersample = 1;      // points per cell and axis in the views' tabulation
  int iterations = 200;     // of the multiplicative updates
  double defensive = 0.05;  // probability of a cosine-weighted sample
  int threads = 0;          // for the build; 0: all cores
};

class FactoredSampler final : public SamplingWrapper {
 public:
  static constexpr int kMaxTerms = 16;
  // Throws std::invalid_argument for options out of range (terms outside [1, kMaxTerms]; cells,
  // views, iterations < 1; defensive outside [0, 1)).
  FactoredSampler(const Brdf& brdf, const FactorOptions& options = {});
  BrdfSample sample(const Vec3<double>& wo, double u1, double u2) const override;
  double pdf(const Vec3<double>& wo, const Vec3<double>& wi) const override;
  bool has_importance_sampling() const override { return true; }
  std::string describe_sampling() const override;

  // Bytes of the tables (20 a cell, as the tabulated sampler's) and of the views' weights.
  std::size_t bytes() const;
  // How well the factorization fits: the mean over views of the total-variation distance (half
  // the L1 norm of the difference) between a view's tabulated distribution and the factored one,
  // in [0, 1]; 0 when exact.
  double approximation_error() const { return approximation_error_; }
  double build_seconds() const { return build_seconds_; }

 private:
  detail::MixtureSampling sampling() const;  // the terms as a mixture (chart_cells.hpp)
  // The terms' weights at ωo (canonical pose), blended between the views.
  detail::CellMixture term_weights(const Vec3<double>& wo) const;

  FactorOptions options_;
  SamplerChart chart_;
  bool isotropic_;
  int n_theta_, n_phi_, n_terms_;
  std::vector<double> weights_;  // [view][term]: a term's share of the view's distribution
  std::vector<Distribution2D> tables_;
  double approximation_error_ = 0, build_seconds_ = 0;
};

// Factorization options whose tables and weights take about `bytes` (`terms` tables of
// radial × 2·radial cells at 20 bytes a cell, and the views' weights at 8 bytes each).
FactorOptions factoring_for_memory(Space param, std::size_t bytes, int terms = 4);

}  // namespace halfback::render
