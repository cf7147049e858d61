// What the tests of the tabulated and factored samplers share.
#pragma once

#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include "halfback/models/analytic.hpp"
#include "support/test_brdfs.hpp"

namespace halfback::render::test_support {

using test::Opaque;  // a model's own sampler hidden, as for measured data

inline Vec3<double> dir(double theta_deg, double phi_deg) {
  const double t = theta_deg * std::numbers::pi / 180, p = phi_deg * std::numbers::pi / 180;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

// GGX with a coloured Schlick Fresnel.
inline BrdfPtr ggx(double ax, double ay) {
  models::MicrofacetParams p;
  p.alpha_x = ax;
  p.alpha_y = ay;
  p.fresnel.kind = models::Fresnel::Kind::schlick;
  p.fresnel.f0 = {0.9, 0.8, 0.6};
  return std::make_shared<models::Microfacet>(p);
}

// The three views the samplers are tested at: normal, oblique, near grazing.
inline const Vec3<double> kViews[] = {dir(0, 0), dir(40, 30), dir(75, 250)};

}  // namespace halfback::render::test_support
