#include "halfback/models/fresnel.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace halfback::models {

double fresnel_schlick(double f0, double cos_theta) {
  const double m = 1 - std::clamp(cos_theta, 0.0, 1.0);
  const double m2 = m * m;
  return f0 + (1 - f0) * m2 * m2 * m;
}

double fresnel_dielectric(double eta, double cos_theta) {
  const double c = std::clamp(cos_theta, 0.0, 1.0);
  const double s2 = 1 - c * c;
  const double ct2 = 1 - s2 / (eta * eta);  // Snell: sin θt = sin θ / η
  if (ct2 <= 0) return 1;                   // total internal reflection (η < 1)
  const double ct = std::sqrt(ct2);
  const double rs = (c - eta * ct) / (c + eta * ct);
  const double rp = (eta * c - ct) / (eta * c + ct);
  return 0.5 * (rs * rs + rp * rp);
}

// Unpolarized reflectance of a conductor with index η + i k. With a² + b² = |(η+ik)² − sin²θ|
// and a = Re √((η+ik)² − sin²θ), the s and p amplitudes' squared moduli reduce to real
// expressions (docs/models.md); this avoids complex arithmetic in the hot path.
double fresnel_conductor(double eta, double k, double cos_theta) {
  const double c = std::clamp(cos_theta, 0.0, 1.0);
  const double c2 = c * c, s2 = 1 - c2;
  const double t0 = eta * eta - k * k - s2;
  const double a2b2 = std::sqrt(t0 * t0 + 4 * eta * eta * k * k);
  const double a = std::sqrt(std::max(0.0, 0.5 * (a2b2 + t0)));
  const double t1 = a2b2 + c2, t2 = 2 * a * c;
  if (t1 + t2 <= 0) return 0;  // η = 1, k = 0 at grazing: no interface, the limit is 0
  const double rs = (t1 - t2) / (t1 + t2);
  const double t3 = c2 * a2b2 + s2 * s2, t4 = t2 * s2;
  const double rp = rs * (t3 - t4) / (t3 + t4);
  return 0.5 * (rs + rp);
}

Rgb Fresnel::eval(double cos_theta) const {
  switch (kind) {
    case Kind::none:
      return {1, 1, 1};
    case Kind::schlick:
      return {fresnel_schlick(f0.r, cos_theta), fresnel_schlick(f0.g, cos_theta),
              fresnel_schlick(f0.b, cos_theta)};
    case Kind::dielectric:
      return {fresnel_dielectric(eta.r, cos_theta), fresnel_dielectric(eta.g, cos_theta),
              fresnel_dielectric(eta.b, cos_theta)};
    case Kind::conductor:
      return {fresnel_conductor(eta.r, k.r, cos_theta), fresnel_conductor(eta.g, k.g, cos_theta),
              fresnel_conductor(eta.b, k.b, cos_theta)};
  }
  return {1, 1, 1};
}

std::string Fresnel::describe() const {
  auto rgb = [](const Rgb& v) {
    return std::to_string(v.r) + "/" + std::to_string(v.g) + "/" + std::to_string(v.b);
  };
  switch (kind) {
    case Kind::none:
      return "no Fresnel factor";
    case Kind::schlick:
      return "Schlick Fresnel, f0 = " + rgb(f0);
    case Kind::dielectric:
      return "dielectric Fresnel, eta = " + rgb(eta);
    case Kind::conductor:
      return "conductor Fresnel, eta = " + rgb(eta) + ", k = " + rgb(k);
  }
  return "";
}

}  // namespace halfback::models
