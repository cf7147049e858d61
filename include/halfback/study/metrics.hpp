// The quantitative comparison of the parameterizations (docs/study.md): metrics of how
// well a BRDF is represented in each parameterization, all computed under one measure on the
// space of direction pairs, so that the parameterizations are compared on the same footing.
//
// The BRDF is sampled under the measure dμ = cos θi cos θo dωi dωo, in an error space, by
// acquire/samples.hpp.
#pragma once

#include <vector>

#include "halfback/acquire/samples.hpp"

namespace halfback::study {

// Azimuthal dependence: the relative error of replacing the BRDF by its μ-weighted average over
// the relative azimuth φ of the parameterization, ρ̄(a, b) = ∫ρ dμ(φ | a, b):
//   E = ( ∫ (ρ − ρ̄)² dμ / ∫ ρ² dμ )^½.
// 0 when the BRDF depends on (a, b) only; how "2D" the BRDF is in this parameterization.
double azimuthal_error(const acquire::IsoSamples& s);

// Separability, relative errors of the best rank-r approximations (r = each of `ranks`) in the
// μ-weighted L² norm, E_r = min ( Σ w (M − U Vᵀ)² / Σ w M² )^½ over U, V of r columns (weighted
// alternating least squares from the SVD of √w ∘ M; cells outside the domain have w = 0):
//   of the 2D projection ρ̄(a, b) (weights ∫dμ over φ), a matrix over a × b;
//   of the 3D table unfolded along its azimuth, a matrix over (a, b) × φ.
// A table of rank r on the domain has E_r = 0 whatever the domain's shape.
std::vector<double> separability_2d(const acquire::IsoSamples& s, const std::vector<int>& ranks);
std::vector<double> separability_unfolded(const acquire::IsoSamples& s,
                                          const std::vector<int>& ranks);

// Azimuthal dependence in 4D: the error of replacing ρ by its μ-weighted mean over the second
// azimuth φb (φd, φk or φo) at fixed (a, φa, b), Stark's reduction applied to anisotropic data.
double azimuthal_error(const acquire::FullSamples& s);
// Separability in 4D: the best rank-r approximations of the table unfolded as (a, φa) × (b, φb),
// e.g. a function of the half vector times a function of the difference vector in halfdiff.
std::vector<double> separability_4d(const acquire::FullSamples& s, const std::vector<int>& ranks);

}  // namespace halfback::study
