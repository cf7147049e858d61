// How well a sampler importance-samples a BRDF (docs/render.md, "Comparing samplers"):
// the variance of the one-sample estimator of the directional albedo, f = ρ(ωi, ωo) cos θi /
// p(ωi | ωo) with ωi drawn by the sampler, over a set of ωo covering the hemisphere, grazing
// included, and the time per sample; efficiency = 1 / (variance × time per sample), reported
// relative to cosine sampling of the same BRDF.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/render/brdf_sampler.hpp"

namespace halfback::render {

struct SamplingMetricOptions {
  // θo at the midpoints of `theta_count` equal steps of cos θo over (cos 89°, 1]: equal measure
  // of the projected hemisphere; the last one near grazing. Anisotropic BRDFs: also φo at
  // `phi_count` equal steps of [0, 2π) (isotropic ones: φo = 0).
  int theta_count = 8, phi_count = 4;
  std::size_t samples = 4096;  // per ωo
  std::uint64_t seed = 1;
};

// The estimator at one ωo, in luminance (Rgb::luminance).
struct OutgoingEstimate {
  Vec3<double> wo{};
  double mean = 0;            // the albedo's estimate
  double variance = 0;        // of one sample of f
  double variance_error = 0;  // the standard error of `variance` (from the 4th moment)
};

struct SamplingMeasure {
  std::vector<OutgoingEstimate> per_wo;
  // The mean over ωo of variance / mean² (the squared coefficient of variation: every ωo weighs
  // the same whatever its albedo), and its standard error.
  double relative_variance = 0, relative_variance_error = 0;
  double seconds_per_sample = 0;  // sampling, evaluating ρ and the pdf: the thread's CPU time
};

// Measures `sampler` (its sample() and pdf()) on ρ of `brdf`. Deterministic numbers for a seed
// (the time aside). A sample of pdf 0 contributes f = 0.
SamplingMeasure measure_sampling(const Brdf& brdf, const Brdf& sampler,
                                 const SamplingMetricOptions& options = {});

// Efficiency of `a` relative to `b`: (relative variance × time) of b over that of a; > 1 when a
// is better. 0 when a's variance is infinite; a variance below 1e-20 (exact sampling up to
// rounding) counts as 1e-20.
double relative_efficiency(const SamplingMeasure& a, const SamplingMeasure& b);

// Tabulation options whose tables take about `bytes` of memory (the cells of an isotropic
// sampler: slices × radial × azimuthal, in the proportions 1 : 2 : 4, at 20 bytes a cell), in
// `param`'s chart.
TabulationOptions tabulation_for_memory(Space param, std::size_t bytes);

}  // namespace halfback::render
