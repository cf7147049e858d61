// What the tests of the tabulated and factored samplers share.
#pragma once

#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include "halfback/models/analytic.hpp"

namespace halfback::render::test_support {

// Hides a model's own sampler, as for measured data.
class Opaque final : public Brdf {
 public:
  explicit Opaque(BrdfPtr b) : b_(std::move(b)) {}
  std::string name() const override { return "opaque:" + b_->name(); }
  std::string description() const override { return b_->description(); }
  bool isotropic() const override { return b_->isotropic(); }
  bool reciprocal() const override { return b_->reciprocal(); }
  Rgb eval(const DirPair<double>& p) const override { return b_->eval(p); }

 private:
  BrdfPtr b_;
};

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
