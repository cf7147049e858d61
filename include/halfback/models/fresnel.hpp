// Fresnel reflectance for unpolarized light: Schlick's approximation, exact dielectric, exact
// conductor (complex index of refraction). Per RGB channel.
#pragma once

#include "halfback/brdf/brdf.hpp"

namespace halfback::models {

// Reflectance at cos θ (θ: angle between the incident direction and the facet normal).
double fresnel_schlick(double f0, double cos_theta);
double fresnel_dielectric(double eta, double cos_theta);  // eta = n_inside / n_outside > 0
double fresnel_conductor(double eta, double k, double cos_theta);

struct Fresnel {
  enum class Kind { none, schlick, dielectric, conductor };
  Kind kind = Kind::schlick;
  Rgb f0{0.04, 0.04, 0.04};  // schlick
  Rgb eta{1.5, 1.5, 1.5};    // dielectric and conductor
  Rgb k{0, 0, 0};            // conductor

  Rgb eval(double cos_theta) const;
  std::string describe() const;
};

}  // namespace halfback::models
