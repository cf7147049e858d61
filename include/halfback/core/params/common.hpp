// What every parameterization of a pair of directions (ωi, ωo) is made of: the vector and tuple
// types, the description of a coordinate (Axis), the lane helpers the maps share, and the checked
// operations (inverse, valid, ...) that apply a map's domain mask.
//
// Conventions (docs/math.md): frame n = +z, t = +x, b = +y; ωi is the incoming (light) and ωo the
// outgoing (view) direction, unit vectors with z >= 0; h = (ωi+ωo)/2 and k = (ωi-ωo)/2 are not
// normalized; h̄, k̄ are their projections on the tangent plane; every azimuth is in [0, 2π), and the
// azimuth of a zero-length vector is 0.
//
// A parameterization P is a stateless struct of static templates over a lane type T (float,
// double or a SIMD pack, see lane_math.hpp), and of constants that describe it; the concept
// `Parameterization` (core/parameterization.hpp) states the whole contract:
//   forward(pair)          -> Tuple4     the 4D coordinates
//   inverse_raw(q)         -> Solved     the pair, unclamped, and the domain mask
//   jacobian(q)            -> T          J with dωi dωo = J dq
//   forward_iso(pair)      -> Tuple3     coordinates of the pair's canonical pose (see below)
//   lift_iso(q3)           -> Tuple4     the 4D coordinates of the canonical pose
//   inverse_iso_raw(q3)    -> Solved     the canonical pose, unclamped, and the domain mask
//   reciprocal(q), mirror(q), reciprocal_iso(q3), mirror_iso(q3)
// Callers normally use the free functions at the end of this file (inverse(), inverse_iso(),
// valid(), ...), which apply the domain mask: an invalid tuple yields NaN directions, and a valid
// one never yields a direction below the horizon.
//
// Canonical pose of a pair (isotropic forms): the pair rotated about n so that φh = 0; when h̄ = 0,
// so that the azimuth of ωi is 0.
#pragma once

#include <array>
#include <limits>
#include <numbers>
#include <string_view>

#include "halfback/core/lane_math.hpp"

namespace halfback {

template <class T>
struct Vec3 {
  T x, y, z;
};

template <class T>
struct DirPair {
  Vec3<T> wi, wo;
};

template <class T>
using Tuple4 = std::array<T, 4>;
template <class T>
using Tuple3 = std::array<T, 3>;

template <class T>
struct Solved {
  DirPair<T> pair;  // unclamped; meaningful only where `in_domain`
  MaskOf<T> in_domain;
};

namespace detail {

// Reduces an angle in (-2π, 4π) to [0, 2π). Both steps are exact (Sterbenz) or round into range.
template <class T>
inline T wrap_two_pi(T a) {
  using L = LaneOps<T>;
  using S = ScalarOf<T>;
  a = L::select(a < T(0), a + T(kTwoPi<S>), a);
  a = L::select(a >= T(kTwoPi<S>), a - T(kTwoPi<S>), a);
  return a + T(0);
}

template <class T>
inline MaskOf<T> in_range(T x, T lo, T hi) {
  return LaneOps<T>::mask_and(x >= lo, x <= hi);  // false for NaN
}

template <class T>
inline MaskOf<T> is_azimuth(T phi) {
  using S = ScalarOf<T>;
  return LaneOps<T>::mask_and(phi >= T(0), phi < T(kTwoPi<S>));
}

// Elevation angle of (x, y, z) from n, for z >= 0 and finite coordinates below 2^500 not all zero
// (others give an unspecified value): atan2 is accurate near 0 and π/2, where acos is not.
template <class T>
inline T elevation(T x, T y, T z) {
  return LaneOps<T>::atan2_nonneg(LaneOps<T>::sqrt(x * x + y * y), z);
}

// Margin, relative to the lengths involved, below which HalfDiff::forward's clamp of θh is
// evaluated: 64ε against the ~5ε that the rounding of its test and of two atan2 can account for.
template <class S>
inline constexpr S kClampMargin = S(64) * std::numeric_limits<S>::epsilon();

// Powers of two for HalfDiff's scaled frame. frame_min: the least (rxy len)² for which the unscaled
// D's squares are normal with a margin (its rounding near underflow then stays below ε/8 of |D|).
// A sum of squares below tiny_sq has its components multiplied by up, exactly: the smallest
// subnormal then squares to a normal number, and the largest scaled component is far from overflow.
template <class S>
struct TinyScale;
template <>
struct TinyScale<double> {
  static constexpr double frame_min = 0x1p-963, tiny_sq = 0x1p-900, up = 0x1p600;
};
template <>
struct TinyScale<float> {
  static constexpr float frame_min = 0x1p-96f, tiny_sq = 0x1p-100f, up = 0x1p99f;
};

// Tolerance on a reconstructed elevation whose rounding error grows like ε / cond: the domain
// predicates accept z >= -tol / max(cond, √tol) (docs/math.md, "Valid domain").
template <class T>
inline T conditioned_tolerance(T cond) {
  using S = ScalarOf<T>;
  const S tol = kDomainTolerance<S>;
  return T(tol) / LaneOps<T>::max(cond, T(kSqrtDomainTolerance<S>));
}

template <class T>
inline T dot(const Vec3<T>& a, const Vec3<T>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

template <class T>
inline Vec3<T> rotate_z(const Vec3<T>& v, T c, T s) {
  return {c * v.x - s * v.y, s * v.x + c * v.y, v.z};
}

}  // namespace detail

// One coordinate of a parameterization, as every tool names, scales and draws it.
enum class AxisKind {
  angle,    // radians in [lo, hi], shown in degrees
  azimuth,  // radians in [lo, hi), periodic
  length,   // a dimensionless length in [lo, hi]
};
// What a non-azimuthal coordinate is a function of, for the designs that re-space it as an angle
// (acquire/design.hpp): the angle itself, or its sine (‖h̄‖ ≈ sin θh, ‖k‖ = sin θd).
enum class AngleEncoding { none, angle, sine };
struct Axis {
  std::string_view column;  // CSV and NumPy name, e.g. "theta_h"
  std::string_view label;  // figure label, with the markup of figure/scene.hpp: "θ_h", "‖h\u0304‖"
  AxisKind kind = AxisKind::length;
  double lo = 0, hi = 1;
  double spacing = 0.1;  // the figures' isoline spacing, in the axis's units
  AngleEncoding encoding = AngleEncoding::none;
  bool half_vector_tilt = false;  // measures ĥ's tilt from n (θh, ‖h̄‖): the specular peak's axis
  constexpr std::string_view unit() const { return kind == AxisKind::length ? "" : "rad"; }
  constexpr bool is_angle() const { return kind != AxisKind::length; }
  constexpr Axis tilting_half_vector() const {
    Axis a = *this;
    a.half_vector_tilt = true;
    return a;
  }
};

// The common kinds of axis: an elevation in [0, π/2], an azimuth in [0, 2π), a length in [0, 1]
// that is the sine of an angle.
constexpr Axis elevation_axis(std::string_view column, std::string_view label) {
  return {column,
          label,
          AxisKind::angle,
          0,
          std::numbers::pi / 2,
          std::numbers::pi / 18,
          AngleEncoding::angle};
}
constexpr Axis azimuth_axis(std::string_view column, std::string_view label) {
  return {column, label, AxisKind::azimuth, 0, 2 * std::numbers::pi, std::numbers::pi / 18};
}
constexpr Axis sine_axis(std::string_view column, std::string_view label) {
  return {column, label, AxisKind::length, 0, 1, 0.1, AngleEncoding::sine};
}

namespace detail {

// Rotates a solved pair about n so that h̄ lies on +x: the canonical pose, for isotropic inverses
// that first place ωi at azimuth 0 (nothing to do when h̄ = 0: ωi is then already at azimuth 0).
// The pose is discontinuous at h̄ = 0, so an h̄ at the rounding level of its terms (an exact mirror
// configuration) counts as zero rather than picking a random rotation.
template <class T>
inline void rotate_to_canonical_pose(Solved<T>& r) {
  using L = LaneOps<T>;
  const T hx = r.pair.wi.x + r.pair.wo.x, hy = r.pair.wi.y + r.pair.wo.y;
  const T len = L::sqrt(hx * hx + hy * hy);
  const T scale = L::abs(r.pair.wi.x) + L::abs(r.pair.wo.x) + L::abs(r.pair.wo.y);
  const auto zero = len <= T(8 * std::numeric_limits<ScalarOf<T>>::epsilon()) * scale;
  const T c = L::select(zero, T(1), hx / len), s = L::select(zero, T(0), -hy / len);
  r.pair.wi = rotate_z(r.pair.wi, c, s);
  r.pair.wo = rotate_z(r.pair.wo, c, s);
}

}  // namespace detail

// --------------------------------------------------------------------------------------------
// Checked operations, common to all parameterizations.
// --------------------------------------------------------------------------------------------
namespace detail {
template <class T>
inline void finish_inverse(Solved<T>& s) {
  using L = LaneOps<T>;
  using S = ScalarOf<T>;
  const T nan(std::numeric_limits<S>::quiet_NaN());
  auto fix = [&](Vec3<T>& w) {
    w.x = L::select(s.in_domain, w.x, nan);
    w.y = L::select(s.in_domain, w.y, nan);
    w.z = L::select(s.in_domain, L::max(w.z, T(0)), nan);  // within tolerance: onto the horizon
  };
  fix(s.pair.wi);
  fix(s.pair.wo);
}
}  // namespace detail

namespace detail {

// An azimuth reduced to [0, 2π), its period being the double (or float) 2π: azimuths are
// periodic, so φd = -π/2 is 3π/2 (docs/math.md, "Valid domain"). Lanes already in range are
// returned as they are (bit for bit), the others through floor(a / 2π). NaN, infinities and
// |a| > kMaxAzimuth (where a float's turn is no longer resolved to a hundredth of a radian) give
// NaN: invalid.
inline constexpr double kMaxAzimuth = 65536;
template <class T>
inline T wrap_azimuth(T a) {
  using L = LaneOps<T>;
  using S = ScalarOf<T>;
  if (all_lanes(is_azimuth(a))) return a;
  const T turns = L::floor(a * T(S(1) / kTwoPi<S>));
  const T wrapped = wrap_two_pi(a - turns * T(kTwoPi<S>));  // a rounding off: into range
  const T bad(std::numeric_limits<S>::quiet_NaN());
  return L::select(is_azimuth(a), a, L::select(L::abs(a) <= T(S(kMaxAzimuth)), wrapped, bad));
}

// The azimuth coordinates (AxisKind::azimuth) of `axes` as a bit mask, at compile time: the
// kernels of every instruction set then refer to no axis table at run time (a table referred to
// would be a weak symbol shared across them: test halfback_isa_symbols).
template <std::size_t N>
constexpr unsigned azimuth_mask(const std::array<Axis, N>& axes) {
  unsigned mask = 0;
  for (std::size_t k = 0; k < N; ++k)
    if (axes[k].kind == AxisKind::azimuth) mask |= 1u << k;
  return mask;
}

// q with the coordinates of `Mask` (azimuth_mask) wrapped.
template <unsigned Mask, class T, std::size_t N>
inline std::array<T, N> with_azimuths_wrapped(std::array<T, N> q) {
  for (std::size_t k = 0; k < N; ++k)
    if ((Mask >> k) & 1u) q[k] = wrap_azimuth(q[k]);
  return q;
}

}  // namespace detail

// The pair with coordinates q; NaN directions when q is outside the valid domain.
template <class P, class T>
inline Solved<T> inverse(const Tuple4<T>& q) {
  Solved<T> s = P::inverse_raw(detail::with_azimuths_wrapped<detail::azimuth_mask(P::axes)>(q));
  detail::finish_inverse(s);
  return s;
}

// The canonical pose with isotropic coordinates q (NaN when invalid).
template <class P, class T>
inline Solved<T> inverse_iso(const Tuple3<T>& q) {
  Solved<T> s =
      P::inverse_iso_raw(detail::with_azimuths_wrapped<detail::azimuth_mask(P::iso_axes)>(q));
  detail::finish_inverse(s);
  return s;
}

template <class P, class T>
inline MaskOf<T> valid(const Tuple4<T>& q) {
  return P::inverse_raw(detail::with_azimuths_wrapped<detail::azimuth_mask(P::axes)>(q)).in_domain;
}

template <class P, class T>
inline MaskOf<T> valid_iso(const Tuple3<T>& q) {
  return P::inverse_iso_raw(detail::with_azimuths_wrapped<detail::azimuth_mask(P::iso_axes)>(q))
      .in_domain;
}

// The measure of the isotropic coordinates: ∫ over the rotation about n of dωi dωo = J3 dq3.
// The measure of the isotropic coordinates: ∫ over the rotation about n of dωi dωo = J3 dq3. A
// parameterization whose isotropic coordinates are not three of its 4D ones with the rotation
// dropped (a radius of Cartesian coordinates, say) gives its own P::jacobian_iso.
template <class P, class T>
inline T jacobian_iso(const Tuple3<T>& q) {
  if constexpr (requires { P::template jacobian_iso<T>(q); })
    return P::template jacobian_iso<T>(q);
  else
    return T(kTwoPi<ScalarOf<T>>) * P::jacobian(P::lift_iso(q));
}

}  // namespace halfback
