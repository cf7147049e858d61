// LaneOps for xsimd packs: lets the generic kernels of param.hpp run on SIMD batches.
//
// Private to the library (xsimd stays out of the public headers). Included only by the
// per-instruction-set translation units batch_kernels_<isa>.cpp, each compiled with its own -m
// flags; see batch_kernels.hpp.
//
// The mapping follows the scalar LaneOps<float/double> (std math) wherever the two could differ:
//   - atan2: our own, with one division (xsimd's takes four in double); (±0, ±0) and (±∞, ±∞)
//     get the IEEE values of std::atan2 (±0 or ±π, ±π/4 or ±3π/4).
//   - min/max: SSE/AVX min/max return the second operand when either is NaN; std::fmin/fmax
//     return the other, non-NaN, operand. Ties (including ±0) return the second operand in both.
//   - sincos: our own, for |x| <= 20π (every angle of a valid row); lanes beyond get an
//     unspecified value, which the kernels mask. Branch-free, so a row's result never depends on
//     its neighbours in the vector (xsimd's chooses its reduction by testing all lanes at once).
//   - Never use operator!= of xsimd 8.1 for NaN tests: it is unordered on SSE2 (NaN != x is true,
//     as in IEEE) but ordered (_CMP_NEQ_OQ, false) on AVX and AVX-512. param.hpp does not use it.
// Accuracy (measured, tests/batch_test.cpp and docs/performance.md): atan2 (ours) within 2.4 ulp
// of the exact value, sin/cos (ours) within 1.6 ulp, sqrt is exact.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <numbers>
#include <type_traits>

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

// The constants of LaneOps::atan2 below: π and π/4 as a rounded value and its remainder; π/4 split
// again for azimuth, its high part short enough (50 bits in double, 21 in float) that k times it
// is exact for k <= 8; and the polynomial g(z) ≈ (atan(√z)/√z - 1)/z on [0, tan²(π/8)], highest
// degree first: Chebyshev least-squares fits (mpmath, 50 digits; 11 terms for double, 5 for float),
// whose error on atan(r) is below 6e-18 and 3e-9 relative, under the types' rounding.
template <class S>
struct Atan2Constants;
template <>
struct Atan2Constants<double> {
  static constexpr double tan_pi_8 = 0.41421356237309503, huge = 0x1p1000, tiny = 0x1p-1000;
  static constexpr double grow = 0x1p600;
  static constexpr double pi_hi = 0x1.921fb54442d18p1, pi_lo = 0x1.1a62633145c07p-53;
  static constexpr double quarter_pi_hi = pi_hi / 4, quarter_pi_lo = pi_lo / 4;
  static constexpr double eighth_turn_hi = quarter_pi_hi, eighth_turn_lo = quarter_pi_lo;
  static constexpr std::array<double, 11> g = {
      -0x1.39b571eaf17abp-6, 0x1.412ff8ed2a9c8p-5, -0x1.a0880440d55f1p-5, 0x1.dfe2ebe99b2b4p-5,
      -0x1.10fa460dd6e79p-4, 0x1.3b125f7f3f520p-4, -0x1.745d0b01be884p-4, 0x1.c71c71844817bp-4,
      -0x1.2492492434992p-3, 0x1.999999999932ep-3, -0x1.5555555555555p-2};
};
template <>
struct Atan2Constants<float> {
  static constexpr float tan_pi_8 = 0.41421356f, huge = 0x1p100f, tiny = 0x1p-120f;
  static constexpr float grow = 0x1p60f;
  static constexpr float pi_hi = 0x1.921fb6p1f, pi_lo = -0x1.777a5cp-24f;
  static constexpr float quarter_pi_hi = pi_hi / 4, quarter_pi_lo = pi_lo / 4;
  static constexpr float eighth_turn_hi = 0x1.921fbp-1f, eighth_turn_lo = 0x1.5110b4p-23f;
  static constexpr std::array<float, 5> g = {-0x1.08197cp-4f, 0x1.b802fp-4f, -0x1.241f98p-3f,
                                             0x1.99972cp-3f, -0x1.555554p-2f};
};

// The constants of LaneOps::sincos below: 2/π, the shifter that rounds x 2/π to an integer k in
// the low bits of its mantissa, π/2 in three parts (the first two short enough, 45 bits in
// double and 18 and 16 in float, that k times them, |k| <= 41, is exact also where fma is two
// operations: SSE2), the bit positions that move k's two low bits to the sign and to the
// exponent, and the polynomials
// S(z) ≈ (sin(r) - r)/(r z) and Y(z) ≈ (1 - cos(r))/z on z = r² <= (π/4)², highest degree first:
// Chebyshev least-squares fits (mpmath, 50 digits; 6 and 7 terms for double, 4 and 4 for float),
// relative errors below 2e-16 and 3e-8 on S, 3e-18 and 3e-9 on Y, under the types' rounding.
template <class S>
struct SincosConstants;
template <>
struct SincosConstants<double> {
  using Int = std::int64_t;
  static constexpr double two_over_pi = 0x1.45f306dc9c883p-1, shifter = 0x1.8p52;
  static constexpr double pio2_1 = 0x1.921fb54442d00p0, pio2_2 = 0x1.8469898cc5180p-48,
                          pio2_3 = -0x1.fc8f8cbb5bf6cp-97;
  static constexpr int sign_shift = 62, exponent_shift = 52;
  static constexpr Int one_bits = 0x3ff0000000000000;
  static constexpr std::array<double, 6> s = {0x1.5e0a1f55525f5p-33, -0x1.ae6007fd13afdp-26,
                                              0x1.71de379346184p-19, -0x1.a01a019e80c94p-13,
                                              0x1.1111111110ba4p-7,  -0x1.5555555555555p-3};
  static constexpr std::array<double, 7> y = {0x1.8ff8292cf1c76p-37,
                                              -0x1.1eea7c0e8ca3dp-29,
                                              0x1.27e4f8e057a91p-22,
                                              -0x1.a01a019ddbb17p-16,
                                              0x1.6c16c16c15d46p-10,
                                              -0x1.5555555555551p-5,
                                              0x1.0p-1};
};
template <>
struct SincosConstants<float> {
  using Int = std::int32_t;
  static constexpr float two_over_pi = 0x1.45f306p-1f, shifter = 0x1.8p23f;
  static constexpr float pio2_1 = 0x1.921f80p0f, pio2_2 = 0x1.aa2200p-19f, pio2_3 = 0x1.68c234p-39f;
  static constexpr int sign_shift = 30, exponent_shift = 23;
  static constexpr Int one_bits = 0x3f800000;
  static constexpr std::array<float, 4> s = {0x1.6dbc22p-19f, -0x1.a013a0p-13f, 0x1.11110ep-7f,
                                             -0x1.555556p-3f};
  static constexpr std::array<float, 4> y = {-0x1.9a6ab8p-16f, 0x1.6c0df8p-10f, -0x1.55554cp-5f,
                                             0x1.0p-1f};
};

template <class S, class A>
struct LaneOps<xsimd::batch<S, A>> {
  using T = xsimd::batch<S, A>;
  using Scalar = S;
  using Mask = xsimd::batch_bool<S, A>;

  static T select(const Mask& c, const T& a, const T& b) { return xsimd::select(c, a, b); }

  // a * b + c, one rounding where the instruction set has it. xsimd 8.1 has no fma kernel for
  // avx512f: its fallback a * b + c is two instructions and two roundings (the kernel files are
  // compiled with -ffp-contract=off), which doubled the length of atan2's polynomial.
  static T fma(const T& a, const T& b, const T& c) {
#if defined(__AVX512F__)
    if constexpr (std::is_same_v<A, xsimd::avx512f>) {
      if constexpr (std::is_same_v<S, float>)
        return _mm512_fmadd_ps(a, b, c);
      else
        return _mm512_fmadd_pd(a, b, c);
    }
#endif
    return xsimd::fma(a, b, c);
  }
  static T sqrt(const T& x) {
    return xsimd::sqrt(x);
  }
  static T abs(const T& x) {
    return xsimd::abs(x);
  }
  static T floor(const T& x) {
    return xsimd::floor(x);
  }

  // The polynomial with coefficients c (highest degree first) at z. Up to 6 terms by Horner's
  // rule. For 7 and 8 (sincos) by Estrin's scheme: terms paired at each level (a + b z, then with
  // z², z⁴), so the chain of dependent fmas is log2(N) long instead of N - 1, which the inverse
  // kernels' latency feels. Beyond (atan2's 11 terms in double) by a second-order Horner rule,
  // even and odd terms as two chains in w = z²: N - 1 fmas and one product, two fewer than
  // Estrin's squares of z, which the forward kernels' throughput feels more than its longer chain
  // (docs/performance.md, "Conversions").
  template <std::size_t N>
  static T polynomial(const std::array<S, N>& c, const T& z) {
    if constexpr (N <= 6) {
      T g(c[0]);
      for (std::size_t i = 1; i < N; ++i) g = fma(g, z, T(c[i]));
      return g;
    } else if constexpr (N <= 8) {
      std::array<T, N> t;  // lowest degree first
      for (std::size_t k = 0; k < N; ++k) t[k] = T(c[N - 1 - k]);
      T x = z;
      for (std::size_t n = N; n > 1; n = (n + 1) / 2) {
        for (std::size_t j = 0; j < n / 2; ++j) t[j] = fma(t[2 * j + 1], x, t[2 * j]);
        if (n % 2 == 1) t[n / 2] = t[n - 1];
        if (n > 2) x = x * x;
      }
      return t[0];
    } else {
      constexpr std::size_t top_odd = N % 2;  // c[top_odd] is the odd term of highest degree
      const T w = z * z;
      T even(c[1 - top_odd]), odd(c[top_odd]);
      for (std::size_t i = 3 - top_odd; i < N; i += 2) even = fma(even, w, T(c[i]));
      for (std::size_t i = 2 + top_odd; i < N; i += 2) odd = fma(odd, w, T(c[i]));
      return fma(odd, z, even);
    }
  }

  // atan2 with one division (xsimd's takes four in double and three in float, the most costly
  // part of a forward conversion). With a = |y|, b = |x|, the angle in [0, π/2] is folded onto
  // r in [-tan(π/8), tan(π/8)]: r = a/b (offset 0), (a - b)/(a + b) (offset π/4) or -b/a (offset
  // π/2); atan(r) = r + r z g(z) with z = r² and g a polynomial fitted to (atan(r)/r - 1)/z
  // (docs/performance.md, "Conversions"); then π minus that for x < 0, and the sign of y. Zero
  // over zero and infinity over infinity get the IEEE values of std::atan2.
  static T atan2(const T& y, const T& x) {
    using C = Atan2Constants<S>;
    const T a = xsimd::abs(y), b = xsimd::abs(x);
    // Beyond 2^1000 a + b could overflow: scale both (exactly) by 1/4. Where both are tiny
    // (subnormal or nearly), scale them up: the octant tests' products by tan(π/8) would round on
    // the subnormal grid (atan2(2^-1074, 0) took the middle octant with r = 1, 0.018 rad off).
    const auto big = a > T(C::huge) || b > T(C::huge);
    const auto small = a < T(C::tiny) && b < T(C::tiny);
    const T scale = xsimd::select(big, T(S(0.25)), xsimd::select(small, T(C::grow), T(S(1))));
    const T angle = half_plane_angle(first_quadrant(a * scale, b * scale), x);
    const auto zero = (y == T(S(0))) && (x == T(S(0)));
    const auto both_inf = xsimd::isinf(y) && xsimd::isinf(x);
    const auto left = xsimd::copysign(T(S(1)), x) < T(S(0));
    constexpr S pi = std::numbers::pi_v<S>;
    const T special = xsimd::select(zero, xsimd::select(left, T(pi), T(S(0))),
                                    xsimd::select(left, T(S(0.75) * pi), T(S(0.25) * pi)));
    return xsimd::copysign(xsimd::select(zero || both_inf, special, angle), y);
  }

  // The azimuth of (x, y) in [0, 2π), 0 for the zero vector and never -0, for finite x, y below
  // 2^1000 in magnitude and, but for the zero vector, not both below `tiny` (2^-1000, float
  // 2^-120; other lanes get an unspecified value). The forward conversions' azimuths: their
  // invalid rows are masked afterwards, and a planar vector that tiny moves its direction by as
  // little. One octant reduction for the whole circle: θ, π - θ, π + θ or 2π - θ of the
  // first-quadrant angle θ = k π/4 + at is k' π/4 ± at for an integer k' <= 8 (docs/math.md §6,
  // "The SIMD azimuth"), so the reflections cost no rounding of their own and no select per half.
  static T azimuth(const T& y, const T& x) {
    using C = Atan2Constants<S>;
    const Octant o = first_quadrant<true>(xsimd::abs(y), xsimd::abs(x));
    // x = -0 counts as right: the same angle where y != 0 (π/2 or 3π/2), and 0 for (±0, ±0).
    const auto below = y < T(S(0)), left = x < T(S(0));
    // π - θ or 2π - θ, of θ = k π/4 + at: below xor left. (xsimd 8.1's ^ of masks is an or on
    // AVX-512, and its != of masks compares them as NaNs on SSE2.)
    const auto mirrored = (below & ~left) | (left & ~below);
    const T k =
        xsimd::select(below, T(S(4)), T(S(0))) + xsimd::select(mirrored, T(S(4)) - o.k, o.k);
    const T at = xsimd::select(mirrored, -o.at, o.at);
    const T phi = fma(k, T(C::eighth_turn_lo), at) + k * T(C::eighth_turn_hi);
    return xsimd::select(phi >= T(kTwoPi<S>), T(S(0)), phi);  // 2π - tiny may round up to 2π
  }

  // atan2 for y >= 0 and x >= 0 (either may be -0) under the same conditions as azimuth: the same
  // bits as atan2 there. Elevations, whose two arguments are a length and a z >= 0.
  static T atan2_nonneg(const T& y, const T& x) {
    using C = Atan2Constants<S>;
    const Octant o = first_quadrant(y, x);
    return o.k * T(C::quarter_pi_hi) + fma(o.k, T(C::quarter_pi_lo), o.at);
  }

  // The angle of (b, a) for a, b >= 0 as k π/4 + at: the octant k in {0, 1, 2} (as a lane value)
  // and atan of the reduced ratio, |at| <= π/8. k times the halves of a split π/4 is exact, so the
  // offset k π/4 costs no select per half. ZeroSafe: (0, 0) gives k = 0 and at = 0 instead of
  // NaN (the denominator is raised to the least normal number, which changes no other lane of
  // the narrow domain: there it is at least max(a, b) >= `tiny`).
  struct Octant {
    T at, k;
  };
  template <bool ZeroSafe = false>
  static Octant first_quadrant(const T& a, const T& b) {
    using C = Atan2Constants<S>;
    const auto low = a <= b * T(C::tan_pi_8);  // |y/x| <= tan(π/8)
    const auto high = a * T(C::tan_pi_8) > b;  // |x/y| < tan(π/8)
    const T num = xsimd::select(low, a, xsimd::select(high, -b, a - b));
    T den = xsimd::select(low, b, xsimd::select(high, a, a + b));
    if constexpr (ZeroSafe) den = xsimd::max(den, T(std::numeric_limits<S>::min()));
    const T r = num / den;
    const T z = r * r;
    // A local copy: the loop then reads no symbol that every instruction set's kernel file would
    // share (halfback_isa_symbols forbids weak symbols common to two of them).
    constexpr auto coefficients = C::g;
    const T g = polynomial(coefficients, z);
    return {fma(r * z, g, r), xsimd::select(low, T(S(0)), xsimd::select(high, T(S(2)), T(S(1))))};
  }

  // The first-quadrant angle o reflected to π minus it where x < 0 (or -0):
  // π - (off + at) = (π_hi - off_hi) + ((π_lo - off_lo) - at), off = k π/4 (both halves exact).
  static T half_plane_angle(const Octant& o, const T& x) {
    using C = Atan2Constants<S>;
    const T off_hi = o.k * T(C::quarter_pi_hi), off_lo = o.k * T(C::quarter_pi_lo);
    const auto left = xsimd::copysign(T(S(1)), x) < T(S(0));
    const T base = xsimd::select(left, T(C::pi_hi) - off_hi, off_hi);
    const T rest = xsimd::select(left, (T(C::pi_lo) - off_lo) - o.at, o.at + off_lo);
    return base + rest;
  }

  static T min(const T& a, const T& b) {
    return xsimd::select(xsimd::isnan(b), a, xsimd::min(a, b));
  }
  static T max(const T& a, const T& b) {
    return xsimd::select(xsimd::isnan(b), a, xsimd::max(a, b));
  }

  // sin and cos of x for |x| <= 20π, which every angle of a valid row is (elevations, azimuths
  // and their differences); other lanes (out-of-domain rows, NaN) get an unspecified value, and
  // the kernels mask those rows. Our own rather than xsimd's: one reduction for both, the
  // quadrant from the bits of the rounded k rather than floor and four selects, and no branch on
  // the range of the whole vector (xsimd tests all lanes to choose its reduction, so a lane's
  // result could depend on its neighbours).
  // x = k π/2 + r with |r| <= π/4 (k = round(x 2/π)); sin and cos of r by polynomials, then
  // swapped where k is odd and negated in quadrants 2-3 (sin) and 1-2 (cos).
  static void sincos(const T& x, T& s, T& c) {
    using C = SincosConstants<S>;
    using I = xsimd::batch<typename C::Int, A>;
    const T t = fma(x, T(C::two_over_pi), T(C::shifter));  // k in the low bits of t's mantissa
    const T minus_k = T(C::shifter) - t;
    T r = fma(minus_k, T(C::pio2_1), x);  // exact: k pio2_1 and x lie on one grid
    r = fma(minus_k, T(C::pio2_2), r);
    r = fma(minus_k, T(C::pio2_3), r);
    const T z = r * r;
    constexpr auto sc = C::s;  // local copies, as in atan2
    constexpr auto yc = C::y;
    const T sin_r = fma(r * z, polynomial(sc, z), r);
    const T cos_r = fma(-z, polynomial(yc, z), T(S(1)));
    const I q = xsimd::bitwise_cast<I>(t);
    // k odd: 1.0 or 2.0 by k's low bit moved into the exponent, compared in the float domain
    // (xsimd 8 has no cast from an integer mask to a floating-point one).
    const auto odd =
        xsimd::bitwise_cast<T>(I(C::one_bits) + ((q & I(1)) << C::exponent_shift)) > T(S(1.5));
    const T sin_sign = xsimd::bitwise_cast<T>((q & I(2)) << C::sign_shift);
    const T cos_sign = xsimd::bitwise_cast<T>(((q + I(1)) & I(2)) << C::sign_shift);
    s = xsimd::select(odd, cos_r, sin_r) ^ sin_sign;
    c = xsimd::select(odd, sin_r, cos_r) ^ cos_sign;
  }

  static Mask mask_and(const Mask& a, const Mask& b) {
    return a && b;
  }
  static Mask mask_or(const Mask& a, const Mask& b) {
    return a || b;
  }
  static Mask mask_not(const Mask& a) {
    return !a;
  }
  static Mask select_mask(const Mask& c, const Mask& a, const Mask& b) {
    return (c && a) || (!c && b);
  }
};

// Two vectors as one lane type: every operation is issued on both halves, next to each other in
// the instruction stream. The forward kernels are chains of dependent divisions, square roots and
// polynomials (~700 instructions a vector for halfdiff double), longer than the out-of-order
// window, so one vector's latency stalls were not hidden by the next vector's work; with the two
// halves interleaved, each stall has an independent instruction beside it. Lanes are
// independent, so a row's result is bit for bit that of the single vector.
template <class B>
struct Twin {
  B lo, hi;
  Twin() = default;
  Twin(const B& l, const B& h) : lo(l), hi(h) {}
  template <class U>
  requires std::is_arithmetic_v<U>
  explicit(false) Twin(U s) : lo(B(static_cast<typename B::value_type>(s))), hi(lo) {}
  static constexpr std::size_t size = 2 * B::size;
  // What batch_kernels.hpp's Lanes calls on a vector type.
  template <class S>
  static Twin load_unaligned(const S* p) {
    return {B::load_unaligned(p), B::load_unaligned(p + B::size)};
  }
  template <class S>
  void store_unaligned(S* p) const {
    lo.store_unaligned(p);
    hi.store_unaligned(p + B::size);
  }
};

template <class M>
struct TwinMask {
  M lo, hi;
};

template <class M>
inline TwinMask<M> operator&&(const TwinMask<M>& a, const TwinMask<M>& b) {
  return {a.lo && b.lo, a.hi && b.hi};
}
template <class M>
inline TwinMask<M> operator||(const TwinMask<M>& a, const TwinMask<M>& b) {
  return {a.lo || b.lo, a.hi || b.hi};
}
template <class M>
inline TwinMask<M> operator!(const TwinMask<M>& a) {
  return {!a.lo, !a.hi};
}
template <class M>
inline bool all(const TwinMask<M>& m) {
  return xsimd::all(m.lo) && xsimd::all(m.hi);
}
template <class M>
inline bool any(const TwinMask<M>& m) {
  return xsimd::any(m.lo) || xsimd::any(m.hi);
}

#define HALFBACK_TWIN_BINARY(op)                                   \
  template <class B>                                               \
  inline Twin<B> operator op(const Twin<B>& a, const Twin<B>& b) { \
    return {a.lo op b.lo, a.hi op b.hi};                           \
  }
HALFBACK_TWIN_BINARY(+)
HALFBACK_TWIN_BINARY(-)
HALFBACK_TWIN_BINARY(*)
HALFBACK_TWIN_BINARY(/)
#undef HALFBACK_TWIN_BINARY
#define HALFBACK_TWIN_COMPARE(op)                                                                \
  template <class B>                                                                             \
  inline TwinMask<typename B::batch_bool_type> operator op(const Twin<B>& a, const Twin<B>& b) { \
    return {a.lo op b.lo, a.hi op b.hi};                                                         \
  }
HALFBACK_TWIN_COMPARE(<)
HALFBACK_TWIN_COMPARE(<=)
HALFBACK_TWIN_COMPARE(>)
HALFBACK_TWIN_COMPARE(>=)
HALFBACK_TWIN_COMPARE(==)
#undef HALFBACK_TWIN_COMPARE
template <class B>
inline Twin<B> operator-(const Twin<B>& a) {
  return {-a.lo, -a.hi};
}

template <class B>
struct LaneOps<Twin<B>> {
  using T = Twin<B>;
  using O = LaneOps<B>;
  using Scalar = typename O::Scalar;
  using Mask = TwinMask<typename O::Mask>;

  static T select(const Mask& c, const T& a, const T& b) {
    return {O::select(c.lo, a.lo, b.lo), O::select(c.hi, a.hi, b.hi)};
  }
  static T fma(const T& a, const T& b, const T& c) {
    return {O::fma(a.lo, b.lo, c.lo), O::fma(a.hi, b.hi, c.hi)};
  }
  static T sqrt(const T& x) { return {O::sqrt(x.lo), O::sqrt(x.hi)}; }
  static T abs(const T& x) { return {O::abs(x.lo), O::abs(x.hi)}; }
  static T floor(const T& x) { return {O::floor(x.lo), O::floor(x.hi)}; }
  static T atan2(const T& y, const T& x) { return {O::atan2(y.lo, x.lo), O::atan2(y.hi, x.hi)}; }
  static T atan2_nonneg(const T& y, const T& x) {
    return {O::atan2_nonneg(y.lo, x.lo), O::atan2_nonneg(y.hi, x.hi)};
  }
  static T azimuth(const T& y, const T& x) {
    return {O::azimuth(y.lo, x.lo), O::azimuth(y.hi, x.hi)};
  }
  static T min(const T& a, const T& b) { return {O::min(a.lo, b.lo), O::min(a.hi, b.hi)}; }
  static T max(const T& a, const T& b) { return {O::max(a.lo, b.lo), O::max(a.hi, b.hi)}; }
  static void sincos(const T& x, T& s, T& c) {
    O::sincos(x.lo, s.lo, c.lo);
    O::sincos(x.hi, s.hi, c.hi);
  }
  static Mask mask_and(const Mask& a, const Mask& b) { return a && b; }
  static Mask mask_or(const Mask& a, const Mask& b) { return a || b; }
  static Mask mask_not(const Mask& a) { return !a; }
  static Mask select_mask(const Mask& c, const Mask& a, const Mask& b) {
    return (c && a) || (!c && b);
  }
};

}  // namespace halfback
