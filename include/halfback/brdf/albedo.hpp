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

// How ωo is drawn: `cosine` alone, or `mis`: each of the n × n strata draws one cosine-weighted ωo
// and one from the BRDF's own sampler (by reciprocity, Brdf::sample with the roles of the
// directions swapped), combined by the balance heuristic (docs/render.md, "Directional albedo").
// `automatic`: mis for a reciprocal BRDF that has importance sampling of its own, else cosine.
enum class AlbedoSampling { automatic, cosine, mis };

// Jittered-stratified sampling on an n×n grid of the unit square (Malley's method for the cosine
// samples), so the cosine estimator is π · mean ρ. Deterministic for a given seed. The samples are
// drawn and evaluated a block at a time: memory does not grow with n. Missing values (ρ NaN or
// infinite in a channel: measured data without a measurement there) are left out: the mean is
// over the measured directions only, and `measured` says how much that is (docs/formats.md,
// "Missing and negative measurements"). The standard error is that of the mean of the n² stratum
// estimates treated as independent (an upper bound for stratified sampling). Throws
// std::invalid_argument when wi is not a finite unit vector (NaN would give zeros), n < 1 or
// n > kMaxAlbedoSide.
inline constexpr int kMaxAlbedoSide = 1 << 16;
AlbedoEstimate directional_albedo(const Brdf& brdf, const Vec3<double>& wi, int n = 256,
                                  std::uint64_t seed = 1,
                                  AlbedoSampling sampling = AlbedoSampling::automatic);

}  // namespace halfback
