// halfway-disk: (θi, φi, ρ, ψ), after Edwards et al. 2006: ωi, and the half vector scaled onto the
// horizontal plane through ωi's tip, as the point u = ρ (cos ψ, sin ψ) of the unit disk centred
// under ωi: u = (zi ω̄o − zo ω̄i) / (zi + zo). The valid domain is the whole box. Not symmetric in
// the two directions: the reciprocal pair has the disk point −u
// (docs/math-more-parameterizations.md §3).
#pragma once

#include <array>
#include <numbers>
#include <string_view>

#include "halfback/core/params/charts.hpp"
#include "halfback/core/params/common.hpp"
#include "halfback/core/params/planar.hpp"
#include "halfback/core/params/spherical.hpp"

namespace halfback {

struct HalfwayDisk {
  // Compared by `halfback study` when asked (--params): each parameterization adds about a fifth
  // to the full study's time (docs/study.md, "Results").
  static constexpr bool studied_by_default = false;
  static constexpr std::string_view name = "halfway-disk";
  static constexpr std::string_view summary =
      "(θi, φi, ρ, ψ): ωi and the half vector on the unit disk under it (Edwards et al. 2006)";
  static constexpr Axis kRho{"rho", "ρ", AxisKind::length, 0, 1, 0.1, AngleEncoding::none, true};
  static constexpr std::array<Axis, 4> axes{elevation_axis("theta_i", "θ_i"),
                                            azimuth_axis("phi_i", "φ_i"), kRho,
                                            azimuth_axis("psi", "ψ")};
  static constexpr std::array<Axis, 3> iso_axes{elevation_axis("theta_i", "θ_i"), kRho,
                                                azimuth_axis("dpsi", "ψ − φ_i")};
  using SamplerChart = SphericalChart;

  template <class T>
  static Tuple4<T> forward(const DirPair<T>& p) {
    using L = LaneOps<T>;
    const T zi = p.wi.z, zo = p.wo.z;
    const auto grazing = zi <= T(0);  // the limit for zo > 0: u = −ω̄i
    const T inv = T(1) / L::select(grazing, T(1), zi + zo);
    const T ux = L::select(grazing, -p.wi.x, (zi * p.wo.x - zo * p.wi.x) * inv);
    const T uy = L::select(grazing, -p.wi.y, (zi * p.wo.y - zo * p.wi.y) * inv);
    return {detail::elevation(p.wi.x, p.wi.y, zi), L::azimuth(p.wi.y, p.wi.x),
            detail::magnitude(ux * ux + uy * uy), L::azimuth(uy, ux)};
  }

  // With P̄ = ω̄i + u, |P|² = |P̄|² + zi² and g = ωi·P: ω̄o = 2g P̄/|P|² − ω̄i and, exactly,
  // zo = zi (1 − ρ²)/|P|².
  template <class T>
  static Solved<T> inverse_raw(const Tuple4<T>& q) {
    using L = LaneOps<T>;
    using S = ScalarOf<T>;
    T st, ct, sp, cp, sy, cy;
    L::sincos(q[0], st, ct);
    L::sincos(q[1], sp, cp);
    L::sincos(q[3], sy, cy);
    const Vec3<T> wi{st * cp, st * sp, ct};
    const T px = wi.x + q[2] * cy, py = wi.y + q[2] * sy;
    const T p2 = px * px + py * py + ct * ct, g = wi.x * px + wi.y * py + ct * ct;
    const T k = T(2) * g / p2;
    Solved<T> r;
    r.pair = {wi, {k * px - wi.x, k * py - wi.y, ct * (T(1) - q[2] * q[2]) / p2}};
    const T half_pi(kHalfPi<S>);
    r.in_domain = L::mask_and(
        L::mask_and(detail::in_range(q[0], T(0), half_pi), detail::in_range(q[2], T(0), T(1))),
        L::mask_and(L::mask_and(detail::is_azimuth(q[1]), detail::is_azimuth(q[3])), p2 > T(0)));
    return r;
  }

  // dωo = 4 (ωi·ĥ) dĥ, and dĥ = ĥz³ du / zi² (the central projection onto z = zi):
  // J = 4 ρ sin θi cos θi (1 + a) / (1 + 2a + ρ²)², a = ω̄i·u = ρ sin θi cos(ψ − φi).
  template <class T>
  static T jacobian(const Tuple4<T>& q) {
    T st, ct, sd, cd;
    LaneOps<T>::sincos(q[0], st, ct);
    LaneOps<T>::sincos(q[3] - q[1], sd, cd);
    const T a = q[2] * st * cd, den = T(1) + T(2) * a + q[2] * q[2];
    return LaneOps<T>::abs(T(4) * q[2] * st * ct * (T(1) + a) / (den * den));
  }

  // Isotropic: (θi, ρ, ψ − φi), 0 when ωi is vertical or u = 0.
  template <class T>
  static Tuple3<T> forward_iso(const DirPair<T>& p) {
    using L = LaneOps<T>;
    const Tuple4<T> q = forward(p);
    const auto none = L::mask_or(q[0] == T(0), q[2] == T(0));
    return {q[0], q[2], L::select(none, T(0), detail::wrap_two_pi(q[3] - q[1]))};
  }
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

  // The reciprocal pair has the disk point −u about ωo: its coordinates come from the pair.
  template <class T>
  static Tuple4<T> reciprocal(const Tuple4<T>& q) {
    const Solved<T> s = halfback::inverse<HalfwayDisk>(q);
    return forward(DirPair<T>{s.pair.wo, s.pair.wi});
  }
  template <class T>
  static Tuple3<T> reciprocal_iso(const Tuple3<T>& q) {
    const Solved<T> s = halfback::inverse_iso<HalfwayDisk>(q);
    return forward_iso(DirPair<T>{s.pair.wo, s.pair.wi});
  }
  // Across the vertical plane of h̄, whose azimuth is that of ω̄i + u (the xz-plane when 0).
  template <class T>
  static Tuple4<T> mirror(const Tuple4<T>& q) {
    using L = LaneOps<T>;
    T st, ct, sp, cp, sy, cy;
    L::sincos(q[0], st, ct);
    L::sincos(q[1], sp, cp);
    L::sincos(q[3], sy, cy);
    const T phi_h = L::azimuth(st * sp + q[2] * sy, st * cp + q[2] * cy);
    return {q[0], L::select(q[0] == T(0), T(0), detail::wrap_two_pi(T(2) * phi_h - q[1])), q[2],
            L::select(q[2] == T(0), T(0), detail::wrap_two_pi(T(2) * phi_h - q[3]))};
  }
  template <class T>
  static Tuple3<T> mirror_iso(const Tuple3<T>& q) {
    return {q[0], q[1], detail::wrap_two_pi(-q[2])};
  }
};

}  // namespace halfback
