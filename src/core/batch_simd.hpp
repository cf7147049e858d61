// LaneOps for xsimd packs: lets the generic kernels of param.hpp run on SIMD batches.
//
// Private to the library (xsimd stays out of the public headers). Included only by the
// per-instruction-set translation units batch_kernels_<isa>.cpp, each compiled with its own -m
// flags; see batch_kernels.hpp.
//
// The mapping follows the scalar LaneOps<float/double> (std math) wherever the two could differ:
//   - atan2: xsimd computes atan(|y/x|), which is NaN for (±0, ±0) and (±∞, ±∞); those lanes get
//     the IEEE values of std::atan2 (±0 or ±π, ±π/4 or ±3π/4).
//   - min/max: SSE/AVX min/max return the second operand when either is NaN; std::fmin/fmax
//     return the other, non-NaN, operand. Ties (including ±0) return the second operand in both.
//   - sincos: xsimd chooses its range reduction by testing all lanes at once, so one huge or NaN
//     lane would switch the other lanes to a different (slightly differently rounded) reduction.
//     Lanes beyond 20π are evaluated separately, so a row's result never depends on its
//     neighbours in the vector.
//   - Never use operator!= of xsimd 8.1 for NaN tests: it is unordered on SSE2 (NaN != x is true,
//     as in IEEE) but ordered (_CMP_NEQ_OQ, false) on AVX and AVX-512. param.hpp does not use it.
// Accuracy (measured, tests/batch_test.cpp and docs/performance.md): xsimd's atan2 is within
// 2.5 ulp of the exact value, sin/cos within 1.5 ulp, sqrt is exact.
#pragma once

#include <numbers>

// xsimd 8's large-argument reduction (__kernel_rem_pio2) trips GCC 12's -Wmaybe-uninitialized when
// it is inlined into our kernels (seen in the sanitizer build): a false positive in a
// third-party header, silenced for it alone.
// (GCC only: clang has no such warning and would warn about the unknown option.)
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <xsimd/xsimd.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include "halfback/core/lane_math.hpp"

namespace halfback {

template <class S, class A>
struct LaneOps<xsimd::batch<S, A>> {
  using T = xsimd::batch<S, A>;
  using Scalar = S;
  using Mask = xsimd::batch_bool<S, A>;

  static T select(const Mask& c, const T& a, const T& b) { return xsimd::select(c, a, b); }
  static T sqrt(const T& x) { return xsimd::sqrt(x); }
  static T abs(const T& x) { return xsimd::abs(x); }

  static T atan2(const T& y, const T& x) {
    const T r = xsimd::atan2(y, x);
    const auto zero = (y == T(S(0))) && (x == T(S(0)));
    const auto both_inf = xsimd::isinf(y) && xsimd::isinf(x);
    const auto x_negative = xsimd::copysign(T(S(1)), x) < T(S(0));  // true for -0
    constexpr S pi = std::numbers::pi_v<S>;
    const T special = xsimd::select(zero, xsimd::select(x_negative, T(pi), T(S(0))),
                                    xsimd::select(x_negative, T(S(0.75) * pi), T(S(0.25) * pi)));
    return xsimd::select(zero || both_inf, xsimd::copysign(special, y), r);
  }

  static T min(const T& a, const T& b) {
    return xsimd::select(xsimd::isnan(b), a, xsimd::min(a, b));
  }
  static T max(const T& a, const T& b) {
    return xsimd::select(xsimd::isnan(b), a, xsimd::max(a, b));
  }

  static void sincos(const T& x, T& s, T& c) {
    const T limit(S(20) * std::numbers::pi_v<S>);
    const auto large = !(xsimd::abs(x) <= limit);  // NaN included
    if (xsimd::any(large)) [[unlikely]] {
      sincos_with_large_lanes(x, large, s, c);
      return;
    }
    const auto r = xsimd::sincos(x);
    s = r.first;
    c = r.second;
  }

  // Out of line, so that the kernels inline only the common path.
  [[gnu::noinline]] static void sincos_with_large_lanes(const T& x, const Mask& large, T& s, T& c) {
    const auto small = xsimd::sincos(xsimd::select(large, T(S(0)), x));
    const auto big = xsimd::sincos(xsimd::select(large, x, T(S(0))));
    s = xsimd::select(large, big.first, small.first);
    c = xsimd::select(large, big.second, small.second);
  }

  static Mask mask_and(const Mask& a, const Mask& b) { return a && b; }
  static Mask mask_or(const Mask& a, const Mask& b) { return a || b; }
  static Mask mask_not(const Mask& a) { return !a; }
  static Mask select_mask(const Mask& c, const Mask& a, const Mask& b) {
    return (c && a) || (!c && b);
  }
};

}  // namespace halfback
