// Directional albedo a(ωi) = ∫ ρ(ωi, ωo) cos θo dωo, by stratified Monte-Carlo.
#pragma once

#include <cstdint>

#include "halfback/brdf/brdf.hpp"

namespace halfback {

struct AlbedoEstimate {
  Rgb mean;
  Rgb standard_error;
  // The cosine-weighted fraction of the hemisphere of ωo where ρ was measured: the fraction of the
  // samples whose ρ is finite in every channel. 1 for models; 0 gives a NaN mean.
  double measured = 1;
};

// Cosine-weighted, jittered-stratified sampling of ωo on an n×n grid of the unit square
// (Malley's method), so the estimator is π · mean ρ. Deterministic for a given seed. Missing
// values (ρ NaN or infinite in a channel: measured data without a measurement there) are left
// out: the mean is over the measured directions only, and `measured` says how much that is
// (docs/formats.md, "Missing and negative measurements"). Throws std::invalid_argument when wi is
// not a finite unit vector (NaN would give zeros) or n < 1.
AlbedoEstimate directional_albedo(const Brdf& brdf, const Vec3<double>& wi, int n = 256,
                                  std::uint64_t seed = 1);

}  // namespace halfback
