// ortho: (‖h̄‖, φh, ‖k̄‖, φk), Neumann 1999, Löw 2012 (docs/math.md §2.3).
#pragma once

#include <array>
#include <string_view>

#include "halfback/core/params/charts.hpp"
#include "halfback/core/params/common.hpp"
#include "halfback/core/params/planar.hpp"

namespace halfback {

struct Ortho {
  static constexpr std::string_view name = "ortho";
  static constexpr std::string_view summary = "(‖h̄‖, φh, ‖k̄‖, φk), Neumann 1999, Löw 2012";
  static constexpr std::array<Axis, 4> axes{
      sine_axis("hbar", "‖h\u0304‖").tilting_half_vector(), azimuth_axis("phi_h", "φ_h"),
      sine_axis("kbar", "‖k\u0304‖"), azimuth_axis("phi_k", "φ_k")};
  static constexpr std::array<Axis, 3> iso_axes{
      sine_axis("hbar", "‖h\u0304‖").tilting_half_vector(), sine_axis("kbar", "‖k\u0304‖"),
      azimuth_axis("dphi", "φ_k − φ_h")};
  using SamplerChart = ProjectedHalfChart;

  template <class T>
  static Tuple4<T> forward(const DirPair<T>& p) {
    const auto v = detail::planar_hk(p);
    return {detail::magnitude(v.hx * v.hx + v.hy * v.hy), LaneOps<T>::azimuth(v.hy, v.hx),
            detail::magnitude(v.kx * v.kx + v.ky * v.ky), LaneOps<T>::azimuth(v.ky, v.kx)};
  }

  template <class T>
  static Solved<T> inverse_raw(const Tuple4<T>& q) {
    using L = LaneOps<T>;
    using S = ScalarOf<T>;
    T sh, ch, sk, ck;
    L::sincos(q[1], sh, ch);
    L::sincos(q[3], sk, ck);
    const T hx = q[0] * ch, hy = q[0] * sh, kx = q[2] * ck, ky = q[2] * sk;
    const T xi = hx + kx, yi = hy + ky, xo = hx - kx, yo = hy - ky;
    const T zi2 = T(1) - (xi * xi + yi * yi), zo2 = T(1) - (xo * xo + yo * yo);
    Solved<T> r;
    r.pair.wi = {xi, yi, L::sqrt(L::max(zi2, T(0)))};
    r.pair.wo = {xo, yo, L::sqrt(L::max(zo2, T(0)))};
    const T tol(kDomainTolerance<S>);
    r.in_domain = L::mask_and(
        L::mask_and(
            L::mask_and(detail::in_range(q[0], T(0), T(1)), detail::in_range(q[2], T(0), T(1))),
            L::mask_and(detail::is_azimuth(q[1]), detail::is_azimuth(q[3]))),
        L::mask_and(zi2 >= -tol, zo2 >= -tol));
    return r;
  }

  // dωi dωo = 4 ‖h̄‖ ‖k̄‖ / (zi zo) d‖h̄‖ dφh d‖k̄‖ dφk (docs/math.md); infinite at grazing.
  template <class T>
  static T jacobian(const Tuple4<T>& q) {
    const Solved<T> s = inverse_raw(q);
    return T(4) * q[0] * q[2] / (s.pair.wi.z * s.pair.wo.z);
  }

  template <class T>
  static Tuple3<T> forward_iso(const DirPair<T>& p) {
    const Tuple4<T> q = forward(p);
    return {q[0], q[2], detail::relative_azimuth(q[0], q[2], q[1], q[3])};
  }
  template <class T>
  static Tuple4<T> lift_iso(const Tuple3<T>& q) {
    return {q[0], T(0), q[1], q[2]};
  }
  template <class T>
  static Solved<T> inverse_iso_raw(const Tuple3<T>& q) {
    return inverse_raw(lift_iso(q));
  }
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
