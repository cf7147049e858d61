// A sequential design of halfback's own (docs/acquisition.md, "The sequential design"):
// measure a pilot, estimate from its values alone where interpolation errs most, measure the rest
// of the budget there.
//
//   1. pilot   the parameterization's regular grid (own spacing) at a share of the budget;
//   2. demand  from the pilot's values only, per axis of the isotropic form, the demand of
//              interpolation error D(x) = ∫ w (∂²T/∂x²)² over the other axes (second differences
//              of the measured values in the error space, μ-weighted: design.hpp's axis_demand),
//              the error estimate of linear interpolation (h² T''/8 per cell);
//   3. main    the rest of the budget (the budget less the pilot's measurements) as a regular grid
//              whose cells follow the density ∝ D^(1/5) floored by a uniform share (the learned
//              design's rule, design.hpp, here learned from this material's pilot instead of
//              other BRDFs), reconstructed by GonioReconstruction in those warps.
// The pilot's measurements count in the budget; the reconstruction interpolates the main grid only
// (a tensor grid: the pilot's points are not on it). Isotropic form only.
#pragma once

#include <cstddef>
#include <memory>
#include <span>

#include "halfback/acquire/design.hpp"
#include "halfback/acquire/gonio.hpp"
#include "halfback/acquire/samples.hpp"

namespace halfback::acquire {

// The defaults were chosen on five BRDFs and a test function in halfdiff and hybrid
// (docs/acquisition.md, "The sequential design").
struct SequentialOptions {
  double pilot_share = 0.25;   // of the budget, in (0, 1)
  double uniform_share = 0.2;  // the floor of the main grid's density (learn_warps's), in [0, 1]
};

// The pilot's setup: `setup` (isotropic, design sequential) as its regular grid, own spacing, at
// the pilot's share of the budget (at least 1). Throws std::invalid_argument for a full (4D) form,
// another design or a share outside (0, 1).
GonioSetup sequential_pilot(const GonioSetup& setup, const SequentialOptions& options = {});

// The pilot's values as samples of the isotropic form on its cells (error space `es`, the
// measure's weights; cells without a finite measurement have weight 0): what axis_demand reads.
IsoSamples pilot_samples(const GonioPlan& pilot, std::span<const Rgb> values, ErrorSpace es);

// The main stage: the regular grid of the rest of the budget in the warps the pilot's demand
// asks for (spacing learned, from the pilot). `measured` is the pilot's count of measurements.
GonioSetup sequential_main(const GonioSetup& setup, const IsoSamples& pilot, std::size_t measured,
                           const SequentialOptions& options = {});
// The same from the values measured at the pilot's points (values[k] at pilot.points[k]; not
// finite: not measured), counted as the study counts them: by points.
GonioSetup sequential_main(const GonioSetup& setup, const GonioPlan& pilot,
                           std::span<const Rgb> values, ErrorSpace es,
                           const SequentialOptions& options = {});
// How many of the values are finite (measurements taken).
std::size_t finite_values(std::span<const Rgb> values);

// The study's virtual instrument through both stages: the main stage's reconstruction and the
// measurements of both.
struct SequentialAcquisition {
  std::unique_ptr<GonioReconstruction> reconstruction;
  std::size_t samples = 0;  // pilot and main
  LearnedWarps warps;       // the main stage's
};
SequentialAcquisition sequential_acquisition(const Brdf& truth, const GonioSetup& setup,
                                             ErrorSpace es, const SequentialOptions& options = {});

}  // namespace halfback::acquire
