// stereographic: (s(ωi), s(ωo)) with s(ω) = ω_xy / (1 + z), the stereographic projections of the
// two directions from −n (ALTA's STEREOGRAPHIC, which stores them in the order ωo, ωi), and
// stereo-halfdiff: (s(ĥ), s(d)), halfdiff's two unit vectors in the same projection
// (docs/math-more-parameterizations.md §2). |s| = tan(θ/2); dω = 4 ds / (1 + |s|²)².
#pragma once

#include <array>
#include <numbers>
#include <string_view>

#include "halfback/core/params/charts.hpp"
#include "halfback/core/params/common.hpp"
#include "halfback/core/params/halfdiff.hpp"
#include "halfback/core/params/spherical.hpp"

namespace halfback {

namespace detail {

// The projection s(ω) of a direction of the upper hemisphere, and back (exact for z >= 0).
template <class T>
inline std::array<T, 2> stereo_of(const Vec3<T>& w) {
  const T inv = T(1) / (T(1) + w.z);
  return {w.x * inv, w.y * inv};
}
template <class T>
inline Vec3<T> direction_of_stereo(T x, T y) {
  const T r2 = x * x + y * y, inv = T(1) / (T(1) + r2);
  return {T(2) * x * inv, T(2) * y * inv, (T(1) - r2) * inv};
}
// tan(θ/2) from θ ∈ [0, π/2], and θ from it, clamped to π/2 (t = 1 + rounding is a valid radius:
// in_disk below decides).
template <class T>
inline T half_tan(T theta) {
  T s, c;
  LaneOps<T>::sincos(theta, s, c);
  return s / (T(1) + c);
}
template <class T>
inline T from_half_tan(T t) {
  return LaneOps<T>::min(T(2) * LaneOps<T>::atan2_nonneg(t, T(1)), T(kHalfPi<ScalarOf<T>>));
}
// A radius of the projection inside the unit disk, within the domain tolerance; false for NaN.
template <class T>
inline MaskOf<T> in_disk(T r) {
  return LaneOps<T>::mask_and(r >= T(0), r <= T(1) + T(kDomainTolerance<ScalarOf<T>>));
}
// dω / ds² of the projection at radius² r2.
template <class T>
inline T stereo_density(T r2) {
  const T d = T(1) + r2;
  return T(4) / (d * d);
}

// A Cartesian coordinate of a projected direction, in [−1, 1], and the radius tan(θ/2).
constexpr Axis planar_axis(std::string_view column, std::string_view label) {
  return {column, label, AxisKind::length, -1, 1, 0.1};
}
constexpr Axis stereo_radius_axis(std::string_view column, std::string_view label) {
  return {column, label, AxisKind::length, 0, 1, 0.1};
}

// The 4D Cartesian tuple (ρa, 0, ρb cos Δφ, ρb sin Δφ) of isotropic polar coordinates
// (ρa, ρb, Δφ): the first vector on +x.
template <class T>
inline Tuple4<T> polar_lift(const Tuple3<T>& q) {
  T s, c;
  LaneOps<T>::sincos(q[2], s, c);
  return {q[0], T(0), q[1] * c, q[1] * s};
}

}  // namespace detail

struct Stereographic {
  // Compared by `halfback study` when asked (--params): each parameterization adds about a fifth
  // to the full study's time (docs/study.md, "Results").
  static constexpr bool studied_by_default = false;
  static constexpr std::string_view name = "stereographic";
  static constexpr std::string_view summary =
      "(s(ωi), s(ωo)), s(ω) = ω_xy/(1 + z): stereographic projections of the two directions "
      "(ALTA's STEREOGRAPHIC, ωi first)";
  static constexpr std::array<Axis, 4> axes{
      detail::planar_axis("si_x", "s_{i,x}"), detail::planar_axis("si_y", "s_{i,y}"),
      detail::planar_axis("so_x", "s_{o,x}"), detail::planar_axis("so_y", "s_{o,y}")};
  static constexpr std::array<Axis, 3> iso_axes{detail::stereo_radius_axis("rho_i", "|s_i|"),
                                                detail::stereo_radius_axis("rho_o", "|s_o|"),
                                                azimuth_axis("dphi", "φ_o − φ_i")};
  using SamplerChart = SphericalChart;

  template <class T>
  static Tuple4<T> forward(const DirPair<T>& p) {
    const auto si = detail::stereo_of(p.wi), so = detail::stereo_of(p.wo);
    return {si[0], si[1], so[0], so[1]};
  }

  template <class T>
  static Solved<T> inverse_raw(const Tuple4<T>& q) {
    using L = LaneOps<T>;
    const T tol(kDomainTolerance<ScalarOf<T>>);
    Solved<T> r;
    r.pair = {detail::direction_of_stereo(q[0], q[1]), detail::direction_of_stereo(q[2], q[3])};
    r.in_domain = L::mask_and(q[0] * q[0] + q[1] * q[1] <= T(1) + tol,
                              q[2] * q[2] + q[3] * q[3] <= T(1) + tol);  // false for NaN
    return r;
  }

  // dωi dωo = 16 / ((1 + |si|²)² (1 + |so|²)²) dq: smooth, in [1, 16].
  template <class T>
  static T jacobian(const Tuple4<T>& q) {
    return detail::stereo_density(q[0] * q[0] + q[1] * q[1]) *
           detail::stereo_density(q[2] * q[2] + q[3] * q[3]);
  }

  // Isotropic: (|si|, |so|, Δφ = φo − φi), spherical's form with tan(θ/2) for θ.
  template <class T>
  static Tuple3<T> forward_iso(const DirPair<T>& p) {
    const Tuple3<T> a = Spherical::forward_iso(p);
    return {detail::half_tan(a[0]), detail::half_tan(a[1]), a[2]};
  }
  template <class T>
  static Tuple4<T> lift_iso(const Tuple3<T>& q) {
    return detail::polar_lift(q);
  }
  template <class T>
  static Solved<T> inverse_iso_raw(const Tuple3<T>& q) {
    using L = LaneOps<T>;
    Solved<T> r = inverse_raw(lift_iso(q));
    r.in_domain = L::mask_and(r.in_domain, L::mask_and(q[0] >= T(0), q[1] >= T(0)));
    r.in_domain = L::mask_and(r.in_domain, detail::is_azimuth(q[2]));
    detail::rotate_to_canonical_pose(r);
    return r;
  }
  // The polar radii contribute |si| |so|.
  template <class T>
  static T jacobian_iso(const Tuple3<T>& q) {
    return T(kTwoPi<ScalarOf<T>>) * q[0] * q[1] * detail::stereo_density(q[0] * q[0]) *
           detail::stereo_density(q[1] * q[1]);
  }

  template <class T>
  static Tuple4<T> reciprocal(const Tuple4<T>& q) {
    return {q[2], q[3], q[0], q[1]};
  }
  template <class T>
  static Tuple3<T> reciprocal_iso(const Tuple3<T>& q) {
    return Spherical::reciprocal_iso(q);
  }
  // Across the vertical plane of h̄ (the xz-plane when h̄ = 0), with 2h̄ = ω̄i + ω̄o and
  // ω̄ = 2s/(1 + |s|²).
  template <class T>
  static Tuple4<T> mirror(const Tuple4<T>& q) {
    using L = LaneOps<T>;
    const T wi = T(1) / (T(1) + q[0] * q[0] + q[1] * q[1]);
    const T wo = T(1) / (T(1) + q[2] * q[2] + q[3] * q[3]);
    const T phi_h = L::azimuth(q[1] * wi + q[3] * wo, q[0] * wi + q[2] * wo);
    T s2, c2;
    L::sincos(T(2) * phi_h, s2, c2);
    return {c2 * q[0] + s2 * q[1], s2 * q[0] - c2 * q[1], c2 * q[2] + s2 * q[3],
            s2 * q[2] - c2 * q[3]};
  }
  template <class T>
  static Tuple3<T> mirror_iso(const Tuple3<T>& q) {
    return Spherical::mirror_iso(q);
  }
};

struct StereoHalfDiff {
  // Compared by `halfback study` when asked (--params): each parameterization adds about a fifth
  // to the full study's time (docs/study.md, "Results").
  static constexpr bool studied_by_default = false;
  static constexpr std::string_view name = "stereo-halfdiff";
  static constexpr std::string_view summary =
      "(s(ĥ), s(d)): halfdiff's half and difference vectors in stereographic projection";
  static constexpr std::array<Axis, 4> axes{
      detail::planar_axis("sh_x", "s_{h,x}"), detail::planar_axis("sh_y", "s_{h,y}"),
      detail::planar_axis("sd_x", "s_{d,x}"), detail::planar_axis("sd_y", "s_{d,y}")};
  // Isotropic: halfdiff's (θh, θd, φd) with tan(θ/2) radii.
  static constexpr std::array<Axis, 3> iso_axes{
      detail::stereo_radius_axis("rho_h", "|s_h|").tilting_half_vector(),
      detail::stereo_radius_axis("rho_d", "|s_d|"), azimuth_axis("phi_d", "φ_d")};
  using SamplerChart = HalfVectorChart;

  // Through halfdiff's angles: its forward map is the accurate one (near h = 0 included).
  template <class T>
  static Tuple4<T> forward(const DirPair<T>& p) {
    const Tuple4<T> a = HalfDiff::forward(p);
    return cartesian(a);
  }

  template <class T>
  static Solved<T> inverse_raw(const Tuple4<T>& q) {
    using L = LaneOps<T>;
    const T rh = L::sqrt(q[0] * q[0] + q[1] * q[1]), rd = L::sqrt(q[2] * q[2] + q[3] * q[3]);
    const Tuple4<T> a{detail::from_half_tan(rh), L::azimuth(q[1], q[0]), detail::from_half_tan(rd),
                      L::azimuth(q[3], q[2])};
    Solved<T> r = HalfDiff::inverse_raw(a);
    r.in_domain = L::mask_and(r.in_domain, L::mask_and(detail::in_disk(rh), detail::in_disk(rd)));
    return r;
  }

  // dωi dωo = 4 cos θd dĥ dd with dĥ, dd the projection's densities and
  // cos θd = (1 − |sd|²)/(1 + |sd|²): 64 (1 − |sd|²) / ((1 + |sh|²)² (1 + |sd|²)³).
  template <class T>
  static T jacobian(const Tuple4<T>& q) {
    const T rh2 = q[0] * q[0] + q[1] * q[1], rd2 = q[2] * q[2] + q[3] * q[3];
    const T dh = T(1) + rh2, dd = T(1) + rd2;
    return LaneOps<T>::abs(T(64) * (T(1) - rd2) / (dh * dh * dd * dd * dd));
  }

  template <class T>
  static Tuple3<T> forward_iso(const DirPair<T>& p) {
    const Tuple3<T> a = HalfDiff::forward_iso(p);
    return {detail::half_tan(a[0]), detail::half_tan(a[1]), a[2]};
  }
  template <class T>
  static Tuple4<T> lift_iso(const Tuple3<T>& q) {
    return detail::polar_lift(q);
  }
  template <class T>
  static Solved<T> inverse_iso_raw(const Tuple3<T>& q) {
    using L = LaneOps<T>;
    Solved<T> r = HalfDiff::inverse_iso_raw(
        Tuple3<T>{detail::from_half_tan(q[0]), detail::from_half_tan(q[1]), q[2]});
    r.in_domain =
        L::mask_and(r.in_domain, L::mask_and(detail::in_disk(q[0]), detail::in_disk(q[1])));
    return r;
  }
  // The polar radii contribute |sh| |sd|.
  template <class T>
  static T jacobian_iso(const Tuple3<T>& q) {
    return T(kTwoPi<ScalarOf<T>>) * q[0] * q[1] * jacobian(lift_iso(q));
  }

  template <class T>
  static Tuple4<T> reciprocal(const Tuple4<T>& q) {
    return cartesian(HalfDiff::reciprocal(angles(q)));
  }
  template <class T>
  static Tuple3<T> reciprocal_iso(const Tuple3<T>& q) {
    return HalfDiff::reciprocal_iso(q);  // the radii do not change
  }
  template <class T>
  static Tuple4<T> mirror(const Tuple4<T>& q) {
    return {q[0], q[1], q[2], -q[3] + T(0)};
  }
  template <class T>
  static Tuple3<T> mirror_iso(const Tuple3<T>& q) {
    return HalfDiff::mirror_iso(q);
  }

 private:
  template <class T>
  static Tuple4<T> cartesian(const Tuple4<T>& a) {
    T sh, ch, sd, cd;
    LaneOps<T>::sincos(a[1], sh, ch);
    LaneOps<T>::sincos(a[3], sd, cd);
    const T th = detail::half_tan(a[0]), td = detail::half_tan(a[2]);
    return {th * ch, th * sh, td * cd, td * sd};
  }
  template <class T>
  static Tuple4<T> angles(const Tuple4<T>& q) {
    using L = LaneOps<T>;
    return {detail::from_half_tan(L::sqrt(q[0] * q[0] + q[1] * q[1])), L::azimuth(q[1], q[0]),
            detail::from_half_tan(L::sqrt(q[2] * q[2] + q[3] * q[3])), L::azimuth(q[3], q[2])};
  }
};

}  // namespace halfback
