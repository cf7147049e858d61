// spherical: (θi, φi, θo, φo), the classical baseline (docs/math.md §2.1).
#pragma once

#include <array>
#include <limits>
#include <string_view>

#include "halfback/core/params/charts.hpp"
#include "halfback/core/params/common.hpp"

namespace halfback {

// --------------------------------------------------------------------------------------------
// spherical: (θi, φi, θo, φo)
// --------------------------------------------------------------------------------------------
struct Spherical {
  static constexpr std::string_view name = "spherical";
  static constexpr std::string_view summary = "(θi, φi, θo, φo), the classical baseline";
  static constexpr std::array<Axis, 4> axes{
      elevation_axis("theta_i", "θ_i"), azimuth_axis("phi_i", "φ_i"),
      elevation_axis("theta_o", "θ_o"), azimuth_axis("phi_o", "φ_o")};
  static constexpr std::array<Axis, 3> iso_axes{elevation_axis("theta_i", "θ_i"),
                                                elevation_axis("theta_o", "θ_o"),
                                                azimuth_axis("dphi", "φ_o − φ_i")};
  using SamplerChart = SphericalChart;

  template <class T>
  static Tuple4<T> forward(const DirPair<T>& p) {
    using detail::elevation;
    using L = LaneOps<T>;
    return {elevation(p.wi.x, p.wi.y, p.wi.z), L::azimuth(p.wi.y, p.wi.x),
            elevation(p.wo.x, p.wo.y, p.wo.z), L::azimuth(p.wo.y, p.wo.x)};
  }

  template <class T>
  static Solved<T> inverse_raw(const Tuple4<T>& q) {
    using L = LaneOps<T>;
    using S = ScalarOf<T>;
    T sti, cti, spi, cpi, sto, cto, spo, cpo;
    L::sincos(q[0], sti, cti);
    L::sincos(q[1], spi, cpi);
    L::sincos(q[2], sto, cto);
    L::sincos(q[3], spo, cpo);
    Solved<T> r;
    r.pair = {{sti * cpi, sti * spi, cti}, {sto * cpo, sto * spo, cto}};
    const T half_pi(kHalfPi<S>);
    r.in_domain = L::mask_and(
        L::mask_and(detail::in_range(q[0], T(0), half_pi), detail::in_range(q[2], T(0), half_pi)),
        L::mask_and(detail::is_azimuth(q[1]), detail::is_azimuth(q[3])));
    return r;
  }

  template <class T>
  static T jacobian(const Tuple4<T>& q) {
    T s0, c0, s2, c2;
    LaneOps<T>::sincos(q[0], s0, c0);
    LaneOps<T>::sincos(q[2], s2, c2);
    return LaneOps<T>::abs(s0 * s2);
  }

  template <class T>
  static Tuple3<T> forward_iso(const DirPair<T>& p) {
    using L = LaneOps<T>;
    const Tuple4<T> q = forward(p);
    const auto vertical_i = L::mask_and(p.wi.x == T(0), p.wi.y == T(0));
    const auto vertical_o = L::mask_and(p.wo.x == T(0), p.wo.y == T(0));
    const T dphi =
        L::select(L::mask_or(vertical_i, vertical_o), T(0), detail::wrap_two_pi(q[3] - q[1]));
    return {q[0], q[2], dphi};
  }

  // (θi, θo, Δφ) -> (θi, 0, θo, Δφ): not yet the canonical pose; inverse_iso_raw rotates it there.
  template <class T>
  static Tuple4<T> lift_iso(const Tuple3<T>& q) {
    return {q[0], T(0), q[1], q[2]};
  }

  template <class T>
  static Solved<T> inverse_iso_raw(const Tuple3<T>& q) {
    Solved<T> r = inverse_raw(lift_iso(q));
    detail::rotate_to_canonical_pose(r);
    return r;
  }

  template <class T>
  static Tuple4<T> reciprocal(const Tuple4<T>& q) {
    return {q[2], q[3], q[0], q[1]};
  }
  template <class T>
  static Tuple3<T> reciprocal_iso(const Tuple3<T>& q) {
    return {q[1], q[0], detail::wrap_two_pi(-q[2])};
  }

  // Mirror across the vertical plane at azimuth φh (the plane of h̄; the xz-plane when h̄ = 0).
  template <class T>
  static Tuple4<T> mirror(const Tuple4<T>& q) {
    using L = LaneOps<T>;
    T sti, cti, spi, cpi, sto, cto, spo, cpo;
    L::sincos(q[0], sti, cti);
    L::sincos(q[1], spi, cpi);
    L::sincos(q[2], sto, cto);
    L::sincos(q[3], spo, cpo);
    const T phi_h = L::azimuth(sti * spi + sto * spo, sti * cpi + sto * cpo);
    const T phi_i = L::select(q[0] == T(0), T(0), detail::wrap_two_pi(T(2) * phi_h - q[1]));
    const T phi_o = L::select(q[2] == T(0), T(0), detail::wrap_two_pi(T(2) * phi_h - q[3]));
    return {q[0], phi_i, q[2], phi_o};
  }
  template <class T>
  static Tuple3<T> mirror_iso(const Tuple3<T>& q) {
    return {q[0], q[1], detail::wrap_two_pi(-q[2])};
  }
};

}  // namespace halfback
