// The building blocks of BRDF importance sampling (Brdf::sample and Brdf::pdf, brdf.hpp):
// a drawn direction with its density, and the cosine-weighted hemisphere. Directions are in the
// local frame (n = +z); ωo is the given (view) direction and ωi the drawn (light) direction, the
// convention of every sampler in halfback.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "halfback/core/param.hpp"

namespace halfback {

struct BrdfSample {
  Vec3<double> wi{0, 0, 0};
  double pdf = 0;  // per unit solid angle; 0: no sample (ωi below the horizon or ωo invalid)
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
