// Shared helpers for the core tests: random direction pairs, edge cases, comparisons.
#pragma once

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "halfback/core/param.hpp"
#include "halfback/core/space.hpp"

namespace halfback::test {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTwoPiD = 2 * std::numbers::pi;

inline Vec3<double> direction(double z, double phi) {
  const double s = std::sqrt(std::max(0.0, (1 - z) * (1 + z)));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

template <class T, class U>
inline DirPair<T> cast_pair(const DirPair<U>& p) {
  return {{T(p.wi.x), T(p.wi.y), T(p.wi.z)}, {T(p.wo.x), T(p.wo.y), T(p.wo.z)}};
}

// Random pairs: a quarter uniform in solid angle, the rest concentrated towards grazing for one
// or both directions, and towards the retro (ωi = ωo) and mirror configurations.
inline std::vector<DirPair<double>> random_pairs(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<DirPair<double>> pairs;
  pairs.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    double zi = u(rng), zo = u(rng);
    const double pi = kTwoPiD * u(rng);
    double po = kTwoPiD * u(rng);
    switch (i % 6) {
      case 1:
        zi = std::pow(u(rng), 8);
        break;
      case 2:
        zo = std::pow(u(rng), 8);
        break;
      case 3:
        zi = std::pow(u(rng), 8);
        zo = std::pow(u(rng), 8);
        break;
      case 4:
        po = pi + std::pow(u(rng), 6) - 0.5 * std::pow(u(rng), 6);
        break;  // near retro
      case 5:
        po = pi + kPi + 1e-3 * (u(rng) - 0.5) * std::pow(u(rng), 4);
        break;  // near mirror
      default:
        break;
    }
    pairs.push_back({direction(zi, pi), direction(zo, po)});
  }
  return pairs;
}

// The targeted edge cases of the issue: normal incidence, grazing (z = 0 and 1e-9), ωi = ωo,
// mirror (θh = 0), both grazing and opposite (h = 0), azimuths near 0 and 2π.
inline std::vector<DirPair<double>> edge_pairs() {
  std::vector<DirPair<double>> e;
  const Vec3<double> n{0, 0, 1};
  const double tiny_phis[] = {0.0,    1e-15, 1e-300,    kTwoPiD - 1e-15,
                              -1e-15, kPi,   0.5 * kPi, 1.5 * kPi};
  for (double phi : tiny_phis) {
    const auto a = direction(0.6, phi), g = direction(0.0, phi), g9 = direction(1e-9, phi);
    const auto b = direction(0.3, phi + 2.0);
    e.push_back({n, n});
    e.push_back({n, a});
    e.push_back({a, n});
    e.push_back({a, a});                      // retro
    e.push_back({a, {-a.x, -a.y, a.z}});      // mirror: θh = 0
    e.push_back({g, {-g.x, -g.y, g.z}});      // both grazing, opposite: h = 0
    e.push_back({g9, {-g9.x, -g9.y, g9.z}});  // θh = 0, nearly h = 0
    e.push_back({g, a});
    e.push_back({a, g});
    e.push_back({g9, b});
    e.push_back({b, g9});
    e.push_back({g, g});
    e.push_back({g, direction(0.0, phi + 0.5 * kPi)});  // both grazing, orthogonal
    e.push_back({g9, direction(1e-9, phi + 2.5)});
    e.push_back({n, g});
    e.push_back({g, n});
  }
  return e;
}

inline double max_abs_diff(const DirPair<double>& a, const DirPair<double>& b) {
  const double d[6] = {a.wi.x - b.wi.x, a.wi.y - b.wi.y, a.wi.z - b.wi.z,
                       a.wo.x - b.wo.x, a.wo.y - b.wo.y, a.wo.z - b.wo.z};
  double m = 0;
  for (double v : d) m = std::isnan(v) ? INFINITY : std::max(m, std::abs(v));
  return m;
}

// Distance between two angles on the circle.
inline double angle_diff(double a, double b) {
  const double d = std::fmod(std::abs(a - b), kTwoPiD);
  return std::min(d, kTwoPiD - d);
}

inline DirPair<double> rotate_pair(const DirPair<double>& p, double alpha) {
  const double c = std::cos(alpha), s = std::sin(alpha);
  auto r = [&](const Vec3<double>& v) {
    return Vec3<double>{c * v.x - s * v.y, s * v.x + c * v.y, v.z};
  };
  return {r(p.wi), r(p.wo)};
}

// Every parameterization's full and isotropic forms, and a form's name for test messages.
inline std::vector<Form> parameterization_forms() {
  std::vector<Form> forms;
  for (Space s : kKernelSpaces) {
    forms.push_back({s, false});
    forms.push_back({s, true});
  }
  return forms;
}

inline std::string form_name(Form f) {
  return std::string(name_of(f.space)) + (f.isotropic ? "_iso" : "");
}

}  // namespace halfback::test
