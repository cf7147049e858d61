// What the tabulated samplers share (brdf_sampler.cpp, factored_sampler.cpp): the cells of a
// parameterization's sampler chart for a fixed ωo, ρ cos θi tabulated over them, the views (ωo)
// of the slices and the blend of slices at a given ωo, and the canonical pose of an isotropic
// BRDF. Internal to the render layer.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <array>

#include "halfback/brdf/brdf.hpp"
#include "halfback/brdf/sampling.hpp"
#include "halfback/core/space.hpp"
#include "halfback/render/distribution.hpp"

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

// The weights of up to kMax of a sampler's tables at one ωo.
struct CellMixture {
  static constexpr int kMax = 16;
  int count = 0;
  std::array<int, kMax> table{};
  std::array<double, kMax> weight{};
};

// What the tabulated (slices) and factored (terms) samplers share: ωi drawn from a mixture of 2D
// distributions over the same radial × azimuthal cells of a chart, the weights a function of the
// canonical ωo (`mixture_at`), with a defensive cosine share. The pdf is
//   (1 − ε) Σ w_k P_k(cell) / Σ w_k · N_r N_a / |J(ωi)| + ε cos θi / π.
struct MixtureSampling {
  ParamMap map;
  int radial = 0, azimuthal = 0;
  double defensive = 0;
  bool isotropic = true;
  const std::vector<Distribution2D>& tables;

  template <class MixtureAt>
  BrdfSample sample(const Vec3<double>& wo_in, double u1, double u2, MixtureAt mixture_at) const {
    if (!(wo_in.z > 0)) return {};
    if (u1 < defensive) {
      const Vec3<double> wi = sample_cosine_hemisphere(u1 / defensive, u2);
      if (!(wi.z > 0)) return {};
      return {wi, pdf(wo_in, wi, mixture_at)};
    }
    u1 = std::min((u1 - defensive) / (1 - defensive), kOneMinusEpsilon);
    const CanonicalPose pose = canonical_pose(wo_in, isotropic);
    const CellMixture m = mixture_at(pose.wo);
    const int pick = pick_weighted(m.weight.data(), m.count, u1);
    if (pick < 0) return {};
    const auto cell = tables[std::size_t(m.table[std::size_t(pick)])].sample(u1, u2);
    if (!(cell.probability > 0)) return {};
    const double s = (double(cell.row) + cell.remapped_row) / radial;
    const double t = (double(cell.col) + cell.remapped_col) / azimuthal;
    Vec3<double> wi{0, 0, 0};
    double jac = 0;
    if (!map.forward(pose.wo, s, t, wi, jac)) return {};
    wi = rotate_z(wi, pose.c, pose.s);
    // The pdf from the cell and Jacobian at hand (pdf() would map ωi back to them).
    return {wi, (1 - defensive) * density(m, cell.row, cell.col, jac) +
                    defensive * cosine_hemisphere_pdf(wi)};
  }

  template <class MixtureAt>
  double pdf(const Vec3<double>& wo_in, const Vec3<double>& wi_in, MixtureAt mixture_at) const {
    if (!(wo_in.z > 0 && wi_in.z > 0)) return 0;
    const CanonicalPose pose = canonical_pose(wo_in, isotropic);
    const Vec3<double> wi = rotate_z(wi_in, pose.c, -pose.s);
    double table = 0, s = 0, t = 0, jac = 0;
    if (map.inverse(pose.wo, wi, s, t, jac)) {
      const auto row = std::min(std::size_t(s * radial), std::size_t(radial - 1));
      const auto col = std::min(std::size_t(t * azimuthal), std::size_t(azimuthal - 1));
      table = density(mixture_at(pose.wo), row, col, jac);
    }
    return (1 - defensive) * table + defensive * cosine_hemisphere_pdf(wi_in);
  }

 private:
  // The mixture's density per unit solid angle in a cell of Jacobian `jac`; 0 without weight.
  double density(const CellMixture& m, std::size_t row, std::size_t col, double jac) const {
    double p = 0, total = 0;
    for (int k = 0; k < m.count; ++k)
      if (m.weight[std::size_t(k)] > 0) {
        p += m.weight[std::size_t(k)] *
             tables[std::size_t(m.table[std::size_t(k)])].probability(row, col);
        total += m.weight[std::size_t(k)];
      }
    return total > 0 ? p / total * double(radial) * double(azimuthal) / jac : 0;
  }
};

}  // namespace halfback::render::detail
