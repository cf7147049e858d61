// An independent, straightforward implementation of the MERL reference reader's lookup
// (Matusik et al.'s BRDFRead.cpp, as described in docs/formats.md): the half vector, θh = acos(hz),
// the difference vector by two Rodrigues rotations, θd = acos(dz), φd = atan2, then the published
// bin formulas. Used by the tests (to check halfback's indices) and by the benchmark (as the
// per-pair baseline). Not used by the library.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>

namespace halfback::merl_reference {

struct V3 {
  double x, y, z;
};

inline V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// Rotation of v about the unit axis by angle (Rodrigues' formula).
inline V3 rotate(const V3& v, const V3& axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const V3 k = cross(axis, v);
  const double d = (axis.x * v.x + axis.y * v.y + axis.z * v.z) * (1 - c);
  return {v.x * c + k.x * s + axis.x * d, v.y * c + k.y * s + axis.y * d,
          v.z * c + k.z * s + axis.z * d};
}

struct HalfDiffAngles {
  double theta_h, phi_h, theta_d, phi_d;
};

// The reference's (θh, φh, θd, φd) of the pair (in = light, out = view). acos arguments are clamped
// to [-1, 1] (the reference does not; it gets NaN when rounding pushes them out).
inline HalfDiffAngles half_diff(const V3& in, const V3& out) {
  V3 h{in.x + out.x, in.y + out.y, in.z + out.z};
  const double n = std::sqrt(h.x * h.x + h.y * h.y + h.z * h.z);
  h = {h.x / n, h.y / n, h.z / n};
  HalfDiffAngles a;
  a.theta_h = std::acos(std::clamp(h.z, -1.0, 1.0));
  a.phi_h = std::atan2(h.y, h.x);
  const V3 tmp = rotate(in, {0, 0, 1}, -a.phi_h);
  const V3 d = rotate(tmp, {0, 1, 0}, -a.theta_h);
  a.theta_d = std::acos(std::clamp(d.z, -1.0, 1.0));
  a.phi_d = std::atan2(d.y, d.x);
  return a;
}

constexpr double kPi = std::numbers::pi;

// Continuous bin coordinates (the values the bin formulas truncate), before clamping.
inline double theta_h_coordinate(double theta_h) {
  return std::sqrt(theta_h / (kPi / 2.0) * 90 * 90);
}
inline double theta_d_coordinate(double theta_d) {
  return theta_d / (kPi * 0.5) * 90;
}
inline double phi_d_coordinate(double phi_d) {
  if (phi_d < 0.0) phi_d += kPi;
  return phi_d / kPi * 360 / 2;
}

inline int theta_h_index(double theta_h) {
  if (theta_h <= 0.0) return 0;
  const int i = static_cast<int>(theta_h_coordinate(theta_h));
  return std::clamp(i, 0, 89);
}
inline int theta_d_index(double theta_d) {
  const int i = static_cast<int>(theta_d_coordinate(theta_d));
  return std::clamp(i, 0, 89);
}
inline int phi_d_index(double phi_d) {
  const int i = static_cast<int>(phi_d_coordinate(phi_d));
  return std::clamp(i, 0, 179);
}

// Index into one channel's block, and the three scaled values of a pair.
inline std::size_t index(const V3& in, const V3& out) {
  const HalfDiffAngles a = half_diff(in, out);
  return std::size_t(phi_d_index(a.phi_d)) + std::size_t(theta_d_index(a.theta_d)) * 180 +
         std::size_t(theta_h_index(a.theta_h)) * 180 * 90;
}

inline void lookup(const double* values, const V3& in, const V3& out, double& r, double& g,
                   double& b) {
  const std::size_t i = index(in, out);
  constexpr std::size_t n = std::size_t(90) * 90 * 180;
  r = values[i] * (1.0 / 1500.0);
  g = values[i + n] * (1.15 / 1500.0);
  b = values[i + 2 * n] * (1.66 / 1500.0);
}

}  // namespace halfback::merl_reference
