// What the tabulated samplers share (brdf_sampler.cpp, factored_sampler.cpp): the cells of a
// parameterization's sampler chart for a fixed ωo, ρ cos θi tabulated over them, the views (ωo)
// of the slices and the blend of slices at a given ωo, and the canonical pose of an isotropic
// BRDF. Internal to the render layer.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/core/space.hpp"

namespace halfback::render::detail {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kOneMinusEpsilon = 0x1.fffffffffffffp-1;

inline double azimuth(double y, double x) {
  const double p = std::atan2(y, x);
  return p < 0 ? p + 2 * kPi : p;
}

inline Vec3<double> rotate_z(const Vec3<double>& v, double c, double s) {
  return {c * v.x - s * v.y, s * v.x + c * v.y, v.z};
}

// The cell coordinates (s, t) ∈ [0, 1]² of ωi for a fixed ωo, and back: the polar chart of the
// parameterization (params/charts.hpp), r = r_max s² when warped, φ = 2π t.
struct ParamMap {
  const SamplerChart& chart;
  bool warp;

  double r_max() const { return chart.r_max; }
  double radius(double s) const { return r_max() * (warp ? s * s : s); }
  double radius_derivative(double s) const { return r_max() * (warp ? 2 * s : 1.0); }
  double s_of(double r) const {
    const double x = std::clamp(r / r_max(), 0.0, 1.0);
    return warp ? std::sqrt(x) : x;
  }

  // ωi and |dωi / (ds dt)|; false when (s, t) maps to no direction in the upper hemisphere.
  bool forward(const Vec3<double>& wo, double s, double t, Vec3<double>& wi, double& jac) const {
    const double r = radius(s), dr = radius_derivative(s);
    const double phi = 2 * kPi * t;
    if (!chart.to_direction(wo, r, dr, phi, wi, jac)) return false;
    return wi.z > 0 && jac > 0 && std::isfinite(jac);
  }

  // (s, t) of ωi and |dωi / (ds dt)| there; false outside the chart.
  bool inverse(const Vec3<double>& wo, const Vec3<double>& wi, double& s, double& t,
               double& jac) const {
    double r = 0, phi = 0;
    if (!chart.from_direction(wo, wi, r, phi, jac)) return false;
    phi = std::fmod(phi, 2 * kPi);
    if (phi < 0) phi += 2 * kPi;
    s = s_of(r);
    t = phi / (2 * kPi);
    jac *= radius_derivative(s) * 2 * kPi;
    return r <= r_max() && jac > 0 && std::isfinite(jac);
  }
};

// The grid of slices: views at the midpoints of n_theta steps of θo over [0, π/2] and, for an
// anisotropic BRDF, n_phi steps of φo over [0, 2π); slice index = theta × n_phi + phi.
struct SliceGrid {
  int n_theta = 1, n_phi = 1;

  int count() const { return n_theta * n_phi; }
  Vec3<double> view(int index) const;
  // Up to four slices around ωo (canonical for an isotropic BRDF) and their bilinear weights.
  struct Blend {
    int index[4];
    double weight[4];
    int count;
  };
  Blend blend(const Vec3<double>& wo) const;
};

// Picks an index in [0, count) with probability weight / Σ weights and rescales u (in [0, 1))
// to a fresh number in [0, 1) within the pick; −1 when every weight is ≤ 0.
inline int pick_weighted(const double* weight, int count, double& u) {
  double total = 0;
  for (int i = 0; i < count; ++i) total += std::max(weight[i], 0.0);
  if (!(total > 0)) return -1;
  const double target = u * total;
  double acc = 0;
  int last = -1;
  for (int i = 0; i < count; ++i) {
    if (!(weight[i] > 0)) continue;
    last = i;
    if (target < acc + weight[i]) {
      u = std::min((target - acc) / weight[i], kOneMinusEpsilon);
      return i;
    }
    acc += weight[i];
  }
  u = kOneMinusEpsilon;  // rounding put target at the total
  return last;
}

// ρ cos θi |J| (luminance) of each of the radial × azimuthal cells of the chart at `wo`
// (row-major, radial first), summed over supersample² points of the cell: proportional to the
// cell's integral. Points outside the hemisphere, non-finite and negative values count 0.
std::vector<double> tabulate_cells(const Brdf& brdf, const ParamMap& map, const Vec3<double>& wo,
                                   int radial, int azimuthal, int supersample);

// An isotropic BRDF is tabulated at ωo in the xz half-plane (φo = 0): ωo there, and the rotation
// (c, s) about z that takes it back.
struct CanonicalPose {
  Vec3<double> wo;
  double c = 1, s = 0;
};
inline CanonicalPose canonical_pose(const Vec3<double>& wo, bool isotropic) {
  if (!isotropic) return {wo, 1, 0};
  const double r = std::sqrt(wo.x * wo.x + wo.y * wo.y);
  if (!(r > 0)) return {{0, 0, wo.z}, 1, 0};
  return {{r, 0, wo.z}, wo.x / r, wo.y / r};
}

}  // namespace halfback::render::detail
