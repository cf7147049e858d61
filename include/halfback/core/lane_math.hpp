// Lane primitives used by the generic parameterization kernels.
//
// Every kernel in param.hpp is written once, as a template over a lane type T: a scalar (float,
// double) or a SIMD pack (xsimd::batch; its LaneOps specialization lives in
// src/core/batch_simd.hpp). Kernels reach math through LaneOps<T> only, so the single-pair API and
// the SIMD batch path run the same formulas. Kernels are branch-free: both sides of a select() are
// evaluated, and masks are combined with mask_and / mask_or.
#pragma once

#include <cmath>
#include <limits>
#include <numbers>
#include <type_traits>

namespace halfback {

template <class S>
inline constexpr S kTwoPi = S(2) * std::numbers::pi_v<S>;
template <class S>
inline constexpr S kHalfPi = std::numbers::pi_v<S> / S(2);

template <class T>
struct LaneOps;

template <class T>
requires std::is_floating_point_v<T>
struct LaneOps<T> {
  using Scalar = T;
  using Mask = bool;
  static T select(bool c, T a, T b) { return c ? a : b; }
  static T sqrt(T x) { return std::sqrt(x); }
  static T atan2(T y, T x) { return std::atan2(y, x); }
  // Narrower contracts that SIMD lanes exploit (batch_simd.hpp): finite |x|, |y| < 2^1000, not
  // both below 2^-1000 (float 2^-120) but for azimuth's zero vector; and in addition x, y >= 0
  // (atan2_nonneg). Other lanes get an unspecified value (for both tiny, an angle up to 0.02 off).
  static T atan2_nonneg(T y, T x) { return std::atan2(y, x); }
  // The azimuth of the planar vector (x, y) in [0, 2π); 0 for the zero vector; never -0. Where
  // both are below 2^-1000 (float 2^-120) the SIMD lanes' angle may be up to 0.02 off: such a
  // vector moves its direction by less than 1e-300 (1e-36) whatever its azimuth; HalfDiff's φh,
  // which sets the frame of d, is taken of scaled sums.
  static T azimuth(T y, T x) {
    // atan2 negated where y < 0 and then wrapped, 2π + (-|atan2|), is 2π - |atan2| (the same
    // rounding).
    const T a = std::abs(std::atan2(y, x));
    T phi = y < T(0) ? kTwoPi<T> - a : a;
    if (phi >= kTwoPi<T>) phi = T(0);  // -tiny + 2π may round up to 2π
    return x == T(0) && y == T(0) ? T(0) : phi;
  }
  static T abs(T x) { return std::abs(x); }
  static T floor(T x) { return std::floor(x); }
  static T min(T a, T b) { return std::fmin(a, b); }
  static T max(T a, T b) { return std::fmax(a, b); }
  static void sincos(T x, T& s, T& c) {
    s = std::sin(x);
    c = std::cos(x);
  }
  static bool mask_and(bool a, bool b) { return a && b; }
  static bool mask_or(bool a, bool b) { return a || b; }
  static bool mask_not(bool a) { return !a; }
  static bool select_mask(bool c, bool a, bool b) { return c ? a : b; }
};

// Whether a mask is true in every lane (all() for packs, found by argument lookup): for a branch
// around work that every lane can skip.
template <class M>
inline bool all_lanes(const M& m) {
  if constexpr (std::is_same_v<M, bool>)
    return m;
  else
    return all(m);
}

// Whether a mask is true in some lane: for a branch into work that only a few rows need.
template <class M>
inline bool any_lanes(const M& m) {
  if constexpr (std::is_same_v<M, bool>)
    return m;
  else
    return any(m);
}

template <class T>
using ScalarOf = typename LaneOps<T>::Scalar;
template <class T>
using MaskOf = typename LaneOps<T>::Mask;

// Tolerance of the domain predicates, in units of the parameter computations' rounding. A tuple
// whose reconstructed elevations are below the horizon by less than this is valid, and the
// inverse map clamps it onto the horizon (see docs/math.md, "Valid domain").
template <class S>
inline constexpr S kDomainTolerance = S(64) * std::numeric_limits<S>::epsilon();

// Newton's iteration, for compile-time constants only.
template <class S>
constexpr S constexpr_sqrt(S x) {
  S r = x > S(1) ? x : S(1);
  for (int i = 0; i < 200; ++i) r = S(0.5) * (r + x / r);
  return r;
}

template <class S>
inline constexpr S kSqrtDomainTolerance = constexpr_sqrt(kDomainTolerance<S>);

}  // namespace halfback
