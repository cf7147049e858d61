// Importance sampling of BRDFs: the interface a BRDF with its own sampler implements, and the
// shared building blocks (cosine-weighted hemisphere). Directions are in the local frame
// (n = +z), ωo is the outgoing (view) direction, ωi the sampled incoming (light) direction.
//
// A sampler draws ωi from a density p(ωi | ωo) per unit solid angle that is meant to resemble
// ρ(ωi, ωo) cos θi. The density may put mass below the horizon (a microfacet reflection can leave
// the hemisphere): such a sample comes back with pdf 0 and contributes nothing, so pdf() integrates
// to at most 1 over the upper hemisphere, and exactly to the probability of a valid sample.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "halfback/brdf/brdf.hpp"

namespace halfback {

struct BrdfSample {
  Vec3<double> wi{0, 0, 0};
  double pdf = 0;  // per unit solid angle; 0: no sample (ωi below the horizon or ωo invalid)
};

class SamplableBrdf {
 public:
  virtual ~SamplableBrdf() = default;
  // ωi given ωo (unit, ωo.z > 0) from two numbers u1, u2 in [0, 1).
  virtual BrdfSample sample(const Vec3<double>& wo, double u1, double u2) const = 0;
  // The density of sample() at ωi, per unit solid angle; 0 for ωi or ωo below the horizon.
  virtual double pdf(const Vec3<double>& wo, const Vec3<double>& wi) const = 0;
};

// Cosine-weighted hemisphere (Malley: uniform on the disk, lifted), pdf = cos θ / π.
inline Vec3<double> sample_cosine_hemisphere(double u1, double u2) {
  const double r = std::sqrt(u1), phi = 2 * std::numbers::pi * u2;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1 - u1))};
}
inline double cosine_hemisphere_pdf(const Vec3<double>& w) {
  return w.z > 0 ? w.z / std::numbers::pi : 0;
}

}  // namespace halfback
