// Directional albedo a(ωi) = ∫ ρ(ωi, ωo) cos θo dωo, by stratified Monte-Carlo.
#pragma once

#include <cstdint>

#include "halfback/brdf/brdf.hpp"

namespace halfback {

struct AlbedoEstimate {
  Rgb mean;
  Rgb standard_error;
};

// Cosine-weighted, jittered-stratified sampling of ωo on an n×n grid of the unit square
// (Malley's method), so the estimator is π · mean ρ. Deterministic for a given seed. Throws
// std::invalid_argument when wi is not a finite unit vector (NaN would give zeros) or n < 1.
AlbedoEstimate directional_albedo(const Brdf& brdf, const Vec3<double>& wi, int n = 256,
                                  std::uint64_t seed = 1);

}  // namespace halfback
