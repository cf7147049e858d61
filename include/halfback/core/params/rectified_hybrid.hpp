// rectified-hybrid: (u, φh, ‖k‖, φk) with ‖h̄‖ = u m(‖k‖, φk − φh), m the largest valid ‖h̄‖ given
// the others: hybrid's iso-surfaces, with a valid domain that is the whole box, so that no cell of
// a regular grid is cut by the boundary (docs/math-more-parameterizations.md §5).
#pragma once

#include <array>
#include <numbers>
#include <string_view>

#include "halfback/core/params/charts.hpp"
#include "halfback/core/params/common.hpp"
#include "halfback/core/params/hybrid.hpp"

namespace halfback {

struct RectifiedHybrid {
  static constexpr std::string_view name = "rectified-hybrid";
  static constexpr std::string_view summary =
      "(u, φh, ‖k‖, φk), ‖h̄‖ = u · its largest valid value: hybrid on a box domain";
  static constexpr Axis kU{"u", "u", AxisKind::length, 0, 1, 0.1, AngleEncoding::none, true};
  static constexpr std::array<Axis, 4> axes{kU, azimuth_axis("phi_h", "φ_h"), sine_axis("k", "‖k‖"),
                                            azimuth_axis("phi_k", "φ_k")};
  static constexpr std::array<Axis, 3> iso_axes{kU, sine_axis("k", "‖k‖"),
                                                azimuth_axis("dphi", "φ_k − φ_h")};
  using SamplerChart = ProjectedHalfChart;

  // The largest valid ‖h̄‖ for ‖k‖ = K at relative azimuth Δφ with cos Δφ = c: the smaller root a
  // of hybrid's margin S a² − (2b − C d) a + b² (a = ‖h̄‖², b = 1 − K², d = 1 − 2K², C = c²,
  // S = 1 − C), in the form without cancellation, m² = 2b² / (2b − Cd + |c| √(4K²b + Cd²)).
  template <class T>
  static T largest_hbar(T K, T c) {
    using L = LaneOps<T>;
    const T root2(std::numbers::sqrt2_v<ScalarOf<T>>);
    const T b = (T(1) - K) * (T(1) + K), d = (T(1) - root2 * K) * (T(1) + root2 * K);
    const T C = c * c;
    const T den =
        T(2) * b - C * d + L::abs(c) * L::sqrt(L::max(T(4) * K * K * b + C * d * d, T(0)));
    const auto open = b > T(0);
    return L::select(open, L::sqrt(T(2) * b * b / L::select(open, den, T(1))), T(0));
  }

  template <class T>
  static Tuple4<T> forward(const DirPair<T>& p) {
    const Tuple4<T> h = Hybrid::forward(p);
    return {rectify(h[0], h[2], h[3] - h[1]), h[1], h[2], h[3]};
  }

  template <class T>
  static Solved<T> inverse_raw(const Tuple4<T>& q) {
    using L = LaneOps<T>;
    Solved<T> r = Hybrid::inverse_raw(hybrid_of(q));
    r.in_domain = L::mask_and(r.in_domain, detail::in_range(q[0], T(0), T(1)));
    return r;
  }

  // The map u ↦ ‖h̄‖ = u m at fixed (φh, ‖k‖, φk) is triangular: J = m J_hybrid(u m, ...).
  template <class T>
  static T jacobian(const Tuple4<T>& q) {
    const Tuple4<T> h = hybrid_of(q);
    return m_of(q) * Hybrid::jacobian(h);
  }

  template <class T>
  static Tuple3<T> forward_iso(const DirPair<T>& p) {
    const Tuple3<T> h = Hybrid::forward_iso(p);
    return {rectify(h[0], h[1], h[2]), h[1], h[2]};
  }
  template <class T>
  static Tuple4<T> lift_iso(const Tuple3<T>& q) {
    return {q[0], T(0), q[1], q[2]};
  }
  template <class T>
  static Solved<T> inverse_iso_raw(const Tuple3<T>& q) {
    return inverse_raw(lift_iso(q));
  }
  // cos² Δφ, and so m, is kept by both maps.
  template <class T>
  static Tuple4<T> reciprocal(const Tuple4<T>& q) {
    return Hybrid::reciprocal(q);
  }
  template <class T>
  static Tuple3<T> reciprocal_iso(const Tuple3<T>& q) {
    return Hybrid::reciprocal_iso(q);
  }
  template <class T>
  static Tuple4<T> mirror(const Tuple4<T>& q) {
    return Hybrid::mirror(q);
  }
  template <class T>
  static Tuple3<T> mirror_iso(const Tuple3<T>& q) {
    return Hybrid::mirror_iso(q);
  }

 private:
  template <class T>
  static T m_of(const Tuple4<T>& q) {
    T s, c;
    LaneOps<T>::sincos(q[3] - q[1], s, c);
    return largest_hbar(q[2], c);
  }
  template <class T>
  static Tuple4<T> hybrid_of(const Tuple4<T>& q) {
    return {q[0] * m_of(q), q[1], q[2], q[3]};
  }
  // u = ‖h̄‖ / m, clamped to 1 against rounding; 0 where m = 0 (h = 0).
  template <class T>
  static T rectify(T hbar, T K, T dphi) {
    using L = LaneOps<T>;
    T s, c;
    L::sincos(dphi, s, c);
    const T m = largest_hbar(K, c);
    const auto zero = m <= T(0);
    return L::select(zero, T(0), L::min(hbar / L::select(zero, T(1), m), T(1)));
  }
};

}  // namespace halfback
