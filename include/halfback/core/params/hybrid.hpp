// hybrid: (‖h̄‖, φh, ‖k‖, φk), after Stark 2005 (docs/math.md §2.4).
#pragma once

#include <array>
#include <limits>
#include <string_view>

#include "halfback/core/params/charts.hpp"
#include "halfback/core/params/common.hpp"
#include "halfback/core/params/planar.hpp"

namespace halfback {

struct Hybrid {
  static constexpr std::string_view name = "hybrid";
  // hz² below this is at the rounding level of 1 − ‖h̄‖² − ‖k‖²: both directions graze.
  template <class S>
  static constexpr S kNoisyHz2 = S(16) * std::numeric_limits<S>::epsilon();
  static constexpr std::string_view summary = "(‖h̄‖, φh, ‖k‖, φk), Stark 2005, Barla et al. 2015";
  static constexpr std::array<Axis, 4> axes{sine_axis("hbar", "‖h\u0304‖").tilting_half_vector(),
                                            azimuth_axis("phi_h", "φ_h"), sine_axis("k", "‖k‖"),
                                            azimuth_axis("phi_k", "φ_k")};
  static constexpr std::array<Axis, 3> iso_axes{
      sine_axis("hbar", "‖h\u0304‖").tilting_half_vector(), sine_axis("k", "‖k‖"),
      azimuth_axis("dphi", "φ_k − φ_h")};
  using SamplerChart = ProjectedHalfChart;

  template <class T>
  static Tuple4<T> forward(const DirPair<T>& p) {
    const auto v = detail::planar_hk(p);
    return {detail::magnitude(v.hx * v.hx + v.hy * v.hy), LaneOps<T>::azimuth(v.hy, v.hx),
            detail::magnitude(v.kx * v.kx + v.ky * v.ky + v.kz * v.kz),
            LaneOps<T>::azimuth(v.ky, v.kx)};
  }

  // The pieces of the inverse that the Jacobian shares: hz² = 1 - ‖h̄‖² - ‖k‖², and
  // c = ‖h̄‖ cos(φk - φh), the component of h̄ along k̄'s azimuth.
  template <class T>
  struct Geometry {
    T hx, hy, ck, sk, hz2, hz, c;
  };
  template <class T>
  static Geometry<T> geometry(const Tuple4<T>& q) {
    using L = LaneOps<T>;
    T sh, ch, sk, ck;
    L::sincos(q[1], sh, ch);
    L::sincos(q[3], sk, ck);
    Geometry<T> g;
    g.hx = q[0] * ch;
    g.hy = q[0] * sh;
    g.ck = ck;
    g.sk = sk;
    g.hz2 = T(1) - q[0] * q[0] - q[2] * q[2];
    g.hz = L::sqrt(L::max(g.hz2, T(0)));
    g.c = g.hx * ck + g.hy * sk;
    return g;
  }

  template <class T>
  static Solved<T> inverse_raw(const Tuple4<T>& q) {
    using L = LaneOps<T>;
    using S = ScalarOf<T>;
    const Geometry<T> g = geometry(q);
    // h·k = 0 gives (sin θk, cos θk) ∝ (hz, -c). When both vanish (both directions grazing and
    // h̄ ⟂ k̄, or h = 0) the only solution in the upper hemisphere is θk = π/2.
    const T d2 = g.hz * g.hz + g.c * g.c;
    const auto degenerate = d2 == T(0);
    const T inv_d = T(1) / L::sqrt(d2);
    const T sin_tk = L::select(degenerate, T(1), g.hz * inv_d);
    const T cos_tk = L::select(degenerate, T(0), -g.c * inv_d);
    // Both elevations hz ± kz are >= 0 iff |kz| <= hz. When hz is at rounding level (both
    // directions grazing) the raw kz can jump to the wrong branch (±‖k‖); clamping it, and
    // taking ‖k̄‖ from ‖k‖² = ‖k̄‖² + kz², keeps the error at the representation's own limit.
    // Outside that regime the clamp only moves kz by rounding, and ‖k‖ sin θk stays the
    // accurate ‖k̄‖ (√(‖k‖² − kz²) is not, when k is nearly vertical).
    const T kz_raw = q[2] * cos_tk;
    const T kz = L::max(-g.hz, L::min(kz_raw, g.hz));
    const auto noisy = g.hz2 < T(kNoisyHz2<S>);
    const T zi_raw = g.hz + kz_raw, zo_raw = g.hz - kz_raw;
    const T kbar = L::select(noisy, L::sqrt(L::max(q[2] * q[2] - kz * kz, T(0))), q[2] * sin_tk);
    const T kx = kbar * g.ck, ky = kbar * g.sk;
    Solved<T> r;
    r.pair.wi = {g.hx + kx, g.hy + ky, g.hz + kz};
    r.pair.wo = {g.hx - kx, g.hy - ky, g.hz - kz};
    // Domain: hz² >= 0, and both elevations >= 0 within their rounding error (~ε/hz). Where hz is
    // itself at rounding level the elevations are meaningless and the test is the polynomial
    // margin zi zo (hz² + c²) = hz² (hz² + c²) - ‖k‖² c², accurate to a few ulps (docs/math.md).
    const T margin = g.hz2 * (g.hz2 + g.c * g.c) - q[2] * q[2] * g.c * g.c;
    const T tol(kDomainTolerance<S>), ztol = detail::conditioned_tolerance(g.hz);
    const auto elevations_ok =
        L::select_mask(noisy, margin >= -tol, L::mask_and(zi_raw >= -ztol, zo_raw >= -ztol));
    r.in_domain = L::mask_and(
        L::mask_and(
            L::mask_and(detail::in_range(q[0], T(0), T(1)), detail::in_range(q[2], T(0), T(1))),
            L::mask_and(detail::is_azimuth(q[1]), detail::is_azimuth(q[3]))),
        L::mask_and(g.hz2 >= -tol, elevations_ok));
    return r;
  }

  // dωi dωo = 4 ‖h̄‖ ‖k‖ / (hz² + ‖h̄‖² cos²(φk-φh)) d‖h̄‖ dφh d‖k‖ dφk (docs/math.md): finite
  // unless both directions are grazing.
  template <class T>
  static T jacobian(const Tuple4<T>& q) {
    const Geometry<T> g = geometry(q);
    return T(4) * q[0] * q[2] / (g.hz * g.hz + g.c * g.c);
  }

  template <class T>
  static Tuple3<T> forward_iso(const DirPair<T>& p) {
    using L = LaneOps<T>;
    const auto v = detail::planar_hk(p);
    const Tuple4<T> q = forward(p);
    const T kbar = L::sqrt(v.kx * v.kx + v.ky * v.ky);
    return {q[0], q[2], detail::relative_azimuth(q[0], kbar, q[1], q[3])};
  }
  template <class T>
  static Tuple4<T> lift_iso(const Tuple3<T>& q) {
    return {q[0], T(0), q[1], q[2]};
  }
  template <class T>
  static Solved<T> inverse_iso_raw(const Tuple3<T>& q) {
    return inverse_raw(lift_iso(q));
  }
  // In the upper hemisphere k̄ = 0 implies k = 0, so ‖k‖ = 0 is the zero-vector case of φk.
  template <class T>
  static Tuple4<T> reciprocal(const Tuple4<T>& q) {
    return {q[0], q[1], q[2], detail::flip_azimuth(q[2], q[3])};
  }
  template <class T>
  static Tuple3<T> reciprocal_iso(const Tuple3<T>& q) {
    return detail::reciprocal_planar_iso(q);
  }
  template <class T>
  static Tuple4<T> mirror(const Tuple4<T>& q) {
    return detail::mirror_second_azimuth(q);
  }
  template <class T>
  static Tuple3<T> mirror_iso(const Tuple3<T>& q) {
    return {q[0], q[1], detail::wrap_two_pi(-q[2])};
  }
};

}  // namespace halfback
