// Nielsen, Jensen & Ramamoorthi 2015, "On Optimal, Minimal BRDF Sampling for Reflectance
// Acquisition" (docs/acquisition.md, "Nielsen et al.'s minimal sampling"): a BRDF
// measured in a few configurations and reconstructed as the combination of the principal
// components of a database of BRDFs that fits the measurements best.
//
//   mapping   each channel of each member is one observation; at a configuration x,
//             g(x) = ln(ρ c + ε), c = clamp(cos θi cos θo, 0.01, 1), ε = 0.001. (Their release
//             divides ρ c + ε by the database's median there: a term that is the same for every
//             observation at x, which the centring below removes and the unmapping adds back, so
//             the reconstruction does not depend on it: left out.)
//   basis     the principal components of the centred observations X (observations × candidate
//             configurations, MERL's bins at a resolution) scaled by their singular values, their
//             ScaledEigenvectors: with X = U S Vᵀ, Z = V S = Xᵀ U. Computed from the
//             observations' Gram matrix X Xᵀ = U S² Uᵀ, so that component j at a configuration x
//             is Σ_o U_oj X_o(x): a combination of the observations, defined at any x.
//   directions  their FewToMany's adding stage: the configuration of largest variance first,
//             then, one at a time, the one of `candidates_per_step` random candidates that makes
//             the condition number of the measured rows of Z (the first p components for p
//             measurements) smallest. (Their second stage, a local descent of each direction in
//             MERL's bin indices after every addition, is not done: docs/acquisition.md.)
//   reconstruction  per channel, the coefficients of the first min(n, K) components from the n
//             measured values by Tikhonov-regularized least squares (weight η), then unmapped:
//             ρ = max((e^g − ε) / c, 0).
//
// Because each component is a combination of the observations, a reconstruction is an affine
// combination of the database's mapped members: ĝ_c(x) = Σ_o w_co g_o(x), Σ_o w_co = 1.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "halfback/brdf/brdf.hpp"

namespace halfback::acquire {

inline constexpr double kNielsenEpsilon = 0.001, kNielsenMinCosines = 0.01;
// g = ln(ρ c + ε) (ρ < 0 taken as 0) and its inverse, clamped at 0.
double nielsen_map(double rho, const DirPair<double>& pair);
double nielsen_unmap(double g, const DirPair<double>& pair);

struct NielsenOptions {
  // The candidate configurations: the centres of MERL's bins at this resolution (θh spaced as
  // MERL's square root, θd, φd ∈ [0, π)), at φh = 0, both directions within max_theta_deg.
  int theta_h = 45, theta_d = 45, phi_d = 45;
  double max_theta_deg = 90;
  double eta = 40;                        // Tikhonov weight (their release's example)
  std::size_t candidates_per_step = 500;  // their FewToMany's addEvals
  std::uint64_t seed = 1;
  // Throws std::invalid_argument naming a bad option.
  void validate() const;
};

// The database: every member's three mapped channels at the candidate configurations, their
// Gram matrix, and optionally their values at fixed pairs (the study's test pairs) so that
// combinations there are read rather than evaluated.
class NielsenDatabase {
 public:
  // Throws std::invalid_argument for fewer than two members, an anisotropic one, or a value that
  // is not finite (naming the member).
  NielsenDatabase(std::vector<std::shared_ptr<const Brdf>> members, NielsenOptions options,
                  std::vector<DirPair<double>> cached_pairs = {});

  std::size_t members() const { return members_.size(); }
  std::size_t observations() const { return 3 * members_.size(); }  // o = 3 member + channel
  const Brdf& member(std::size_t m) const { return *members_[m]; }
  const NielsenOptions& options() const { return options_; }
  std::span<const DirPair<double>> configurations() const { return configurations_; }
  // The observations' mapped values at a candidate configuration.
  std::span<const double> mapped_at(std::size_t configuration) const;
  // Σ over configurations of g_a g_b.
  double gram(std::size_t a, std::size_t b) const { return gram_[a * observations() + b]; }

  // The members whose mapped values at every configuration are those of `brdf` (to 1e-4), in
  // order: the members to leave out when `brdf` is studied (every copy of it, whatever its name);
  // empty when none is.
  std::vector<std::size_t> members_like(const Brdf& brdf) const;

  // out[i][c] = Σ_o weights[c][o] g_o(pairs[i]) (weights: one per observation and channel).
  void combine(const std::array<std::vector<double>, 3>& weights,
               std::span<const DirPair<double>> pairs, std::span<std::array<double, 3>> out) const;

 private:
  std::vector<std::shared_ptr<const Brdf>> members_;
  NielsenOptions options_;
  std::vector<DirPair<double>> configurations_;
  std::vector<double> mapped_;  // configurations × observations, row-major
  std::vector<double> gram_;    // observations × observations
  std::vector<DirPair<double>> cached_pairs_;
  // Cached pairs × observations, row-major; in single precision (only errors are computed there).
  std::vector<float> cached_;
};

// The principal components of a database's observations, some members left out (or none).
class NielsenBasis {
 public:
  NielsenBasis(std::shared_ptr<const NielsenDatabase> database, std::vector<std::size_t> left_out);

  std::size_t components() const { return singular_.size(); }  // K
  const std::vector<std::size_t>& left_out() const { return left_out_; }
  // The first p scaled components at a candidate configuration (out: p values).
  void scaled_row(std::size_t configuration, std::size_t p, std::span<double> out) const;
  // The first `count` directions (candidate configurations) of the greedy selection; the first
  // n of them are the selection for n. `conditions`, when given, receives the condition number
  // of the first n for each n, as the selection computed it (by a rank-one update). Throws
  // std::invalid_argument when count exceeds the candidates.
  std::vector<std::size_t> directions(std::size_t count,
                                      std::vector<double>* conditions = nullptr) const;
  // The condition number of the measured rows at these configurations (the first p = min(n, K)
  // components): what directions() makes small.
  double condition_number(std::span<const std::size_t> configurations) const;
  // The weights of the reconstruction (per channel, one per observation of the database, 0 for
  // the member left out) from values measured at candidate configurations; a value that is not
  // finite is not a measurement. Throws std::invalid_argument when the counts differ,
  // std::runtime_error when nothing finite is measured.
  std::array<std::vector<double>, 3> solve(std::span<const std::size_t> configurations,
                                           std::span<const Rgb> values, double eta) const;

  const NielsenDatabase& database() const { return *database_; }
  std::shared_ptr<const NielsenDatabase> database_ptr() const { return database_; }

 private:
  double kept_mean(std::size_t configuration) const;  // the kept observations' mean there

  std::shared_ptr<const NielsenDatabase> database_;
  std::vector<std::size_t> left_out_;  // sorted
  std::vector<std::size_t> kept_;      // the observations in the basis
  std::vector<double> u_;         // kept × K, column-major: component j = Σ u_oj (g_o − μ)
  std::vector<double> singular_;  // K singular values, descending
};

// A reconstruction: the combination of the database's members that solve() found.
class NielsenReconstruction final : public Brdf {
 public:
  NielsenReconstruction(std::shared_ptr<const NielsenDatabase> database,
                        std::array<std::vector<double>, 3> weights, std::string measured,
                        std::size_t measurements);
  std::string name() const override;
  std::string description() const override;
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return false; }  // as reciprocal as the members
  Rgb eval(const DirPair<double>& pair) const override;
  void eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const override;
  std::size_t measurements() const { return measurements_; }

 private:
  std::shared_ptr<const NielsenDatabase> database_;
  std::array<std::vector<double>, 3> weights_;
  std::string measured_;
  std::size_t measurements_ = 0;
};

// Nielsen et al.'s acquisition of `brdf` with each of `counts` measurements: the basis of the
// database without the member like `brdf` (leave-one-out), its directions, `brdf` evaluated
// there, the reconstructions (in the order of counts). Throws std::invalid_argument for an
// anisotropic BRDF or a count of 0 or more than the candidates.
struct NielsenAcquisition {
  std::vector<std::size_t> left_out;    // every member like `brdf`
  std::vector<std::size_t> directions;  // the largest count's
  // One per count that has a finite value of every channel among its measurements, in the order
  // of the counts (measurements() says which); the others are in `unmeasured`: a BRDF without a
  // value at its first directions (an ALTA file measured on part of the hemisphere) cannot be
  // reconstructed from them.
  std::vector<std::shared_ptr<const NielsenReconstruction>> reconstructions;
  std::vector<std::size_t> unmeasured;
};
NielsenAcquisition nielsen_acquisition(std::shared_ptr<const NielsenDatabase> database,
                                       const Brdf& brdf, std::span<const std::size_t> counts);

// The database's identity in a study's settings: the options, its members' names and values
// (their Gram matrix), hashed.
std::string nielsen_fingerprint(const NielsenDatabase& database);

}  // namespace halfback::acquire
