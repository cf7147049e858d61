// halfdiff: (θh, φh, θd, φd), Rusinkiewicz 1998 (docs/math.md §2.2).
#pragma once

#include <array>
#include <limits>
#include <numbers>
#include <string_view>

#include "halfback/core/params/charts.hpp"
#include "halfback/core/params/common.hpp"

namespace halfback {

// --------------------------------------------------------------------------------------------
// halfdiff: (θh, φh, θd, φd), Rusinkiewicz 1998. ĥ = (ωi+ωo)/|ωi+ωo| (ĥ = n when h = 0),
// d = rot_b(-θh) rot_n(-φh) ωi.
// --------------------------------------------------------------------------------------------
struct HalfDiff {
  static constexpr std::string_view name = "halfdiff";
  static constexpr std::string_view summary = "(θh, φh, θd, φd), Rusinkiewicz 1998";
  static constexpr std::array<Axis, 4> axes{
      elevation_axis("theta_h", "θ_h").tilting_half_vector(), azimuth_axis("phi_h", "φ_h"),
      elevation_axis("theta_d", "θ_d"), azimuth_axis("phi_d", "φ_d")};
  static constexpr std::array<Axis, 3> iso_axes{
      elevation_axis("theta_h", "θ_h").tilting_half_vector(), elevation_axis("theta_d", "θ_d"),
      azimuth_axis("phi_d", "φ_d")};
  using SamplerChart = HalfVectorChart;

  // θd and φd depend only on the direction of d = R_y(-θh) R_z(-φh) ωi, which is computed
  // symmetrically in ωi and ωo: R h = (0, 0, ‖h‖) exactly, so d = (R k)_xy + ‖h‖ n. Rotating ωi
  // alone would make the inverse reflect ωi about ĥ, and amplify the inputs' unit-norm rounding
  // (‖ωi‖ ≠ ‖ωo‖ by an ulp) by 1/‖h‖ near h = 0; with the symmetric form the inverse reproduces
  // the pair up to one common scale (docs/math.md §2.2). A positive multiple D of d is computed:
  // D = 2 rxy len d = 8‖h̄‖ ‖h‖ d needs no division (frame()). Where that multiple would underflow,
  // near a vertical ĥ or near h = 0, the rows take scaled_frame() instead, which rescales by powers
  // of 2.
  template <class T>
  static Tuple4<T> forward(const DirPair<T>& p) {
    const Sums<T> s = sums(p);
    // (rxy len)² small somewhere (h̄ = 0 included): those lanes take the scaled frame.
    const auto scaled = needs_scaled_frame(s);
    if (any_lanes(scaled)) [[unlikely]]
      return finish(select_frame(scaled, scaled_frame(s), frame(s)));
    return finish(frame(s));
  }

  template <class T>
  static Solved<T> inverse_raw(const Tuple4<T>& q) {
    using L = LaneOps<T>;
    using S = ScalarOf<T>;
    T sh, ch, sp, cp, sd, cd, sq, cq;
    L::sincos(q[0], sh, ch);
    L::sincos(q[1], sp, cp);
    L::sincos(q[2], sd, cd);
    L::sincos(q[3], sq, cq);
    const T dx = sd * cq, dy = sd * sq, dz = cd;
    // ωi = R_z(φh) R_y(θh) d and ωo = R_z(φh) R_y(θh) (-dx, -dy, dz)
    const T ai = ch * dx + sh * dz, ao = sh * dz - ch * dx;
    Solved<T> r;
    r.pair.wi = {cp * ai - sp * dy, sp * ai + cp * dy, ch * dz - sh * dx};
    r.pair.wo = {cp * ao + sp * dy, sp * ao - cp * dy, ch * dz + sh * dx};
    // The elevations inherit the inputs' unit-norm rounding amplified by 1/‖h‖ = 1/cos θd.
    const T half_pi(kHalfPi<S>), tol = detail::conditioned_tolerance(cd);
    r.in_domain =
        L::mask_and(L::mask_and(L::mask_and(detail::in_range(q[0], T(0), half_pi),
                                            detail::in_range(q[2], T(0), half_pi)),
                                L::mask_and(detail::is_azimuth(q[1]), detail::is_azimuth(q[3]))),
                    L::mask_and(r.pair.wi.z >= -tol, r.pair.wo.z >= -tol));
    return r;
  }

  // dωi dωo = 4 cos θd sin θd sin θh dθh dφh dθd dφd (docs/math.md)
  template <class T>
  static T jacobian(const Tuple4<T>& q) {
    T sh, ch, sd, cd;
    LaneOps<T>::sincos(q[0], sh, ch);
    LaneOps<T>::sincos(q[2], sd, cd);
    return LaneOps<T>::abs(T(4) * cd * sd * sh);
  }

  template <class T>
  static Tuple3<T> forward_iso(const DirPair<T>& p) {
    using L = LaneOps<T>;
    const Tuple4<T> q = forward(p);
    const auto flat = L::mask_and(p.wi.x + p.wo.x == T(0), p.wi.y + p.wo.y == T(0));  // h̄ = 0
    return {q[0], q[2], L::select(flat, T(0), q[3])};
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
    using L = LaneOps<T>;
    return {q[0], q[1], q[2], L::select(q[2] == T(0), T(0), detail::wrap_two_pi(q[3] + T(kPi)))};
  }
  template <class T>
  static Tuple3<T> reciprocal_iso(const Tuple3<T>& q) {
    using L = LaneOps<T>;
    const auto keep = L::mask_or(q[0] == T(0), q[1] == T(0));
    return {q[0], q[1], L::select(keep, T(0), detail::wrap_two_pi(q[2] + T(kPi)))};
  }
  template <class T>
  static Tuple4<T> mirror(const Tuple4<T>& q) {
    return {q[0], q[1], q[2], detail::wrap_two_pi(-q[3])};
  }
  template <class T>
  static Tuple3<T> mirror_iso(const Tuple3<T>& q) {
    return {q[0], q[1], detail::wrap_two_pi(-q[2])};
  }

 private:
  static constexpr double kPi = std::numbers::pi;

  template <class T>
  struct Sums {
    T sx, sy, sz;  // s = ωi + ωo = 2h
    T tx, ty, tz;  // ωi - ωo = 2k
    T rxy2, len2;  // ‖(sx, sy)‖², ‖s‖²
  };
  template <class T>
  static Sums<T> sums(const DirPair<T>& p) {
    const T sx = p.wi.x + p.wo.x, sy = p.wi.y + p.wo.y, sz = p.wi.z + p.wo.z;
    const T rxy2 = sx * sx + sy * sy;
    return {sx, sy, sz, p.wi.x - p.wo.x, p.wi.y - p.wo.y, p.wi.z - p.wo.z, rxy2, rxy2 + sz * sz};
  }

  // θh before its clamp, φh, (st, ct) = a positive multiple of (sin θh, cos θh), and D a positive
  // multiple of d.
  template <class T>
  struct Frame {
    T theta_h, phi_h, st, ct;
    Vec3<T> D;
    T dxy;  // ‖(D.x, D.y)‖, formed by the frames so that its square root overlaps ĥ's atan2
  };
  template <class T>
  static Frame<T> select_frame(const MaskOf<T>& m, const Frame<T>& a, const Frame<T>& b) {
    using L = LaneOps<T>;
    return {L::select(m, a.theta_h, b.theta_h),
            L::select(m, a.phi_h, b.phi_h),
            L::select(m, a.st, b.st),
            L::select(m, a.ct, b.ct),
            {L::select(m, a.D.x, b.D.x), L::select(m, a.D.y, b.D.y), L::select(m, a.D.z, b.D.z)},
            L::select(m, a.dxy, b.dxy)};
  }

  // D = 2 rxy len d with rxy = ‖(sx, sy)‖ = 2‖h̄‖, len = ‖s‖ = 2‖h‖ and t = ωi - ωo = 2k
  // (docs/math.md §2.2): (A, B) = rxy R_z(-φh) t_xy = (s_xy · t_xy, s_xy × t_xy), and R_y(-θh)
  // is (sz, rxy)/len, so
  //   D = (sz A - rxy² tz, len B, rxy len²).
  // No division, and len's square root is off the chain to Dx. Accurate (its squares normal)
  // unless needs_scaled_frame: that takes the rows where rxy len is tiny, and h̄ = 0 (here D = 0).
  template <class T>
  static Frame<T> frame(const Sums<T>& s) {
    using L = LaneOps<T>;
    const T rxy = L::sqrt(s.rxy2), len = L::sqrt(s.len2);
    const T A = s.sx * s.tx + s.sy * s.ty, B = s.sx * s.ty - s.sy * s.tx;
    const Vec3<T> D{s.sz * A - s.rxy2 * s.tz, len * B, s.len2 * rxy};
    const T dxy = L::sqrt(D.x * D.x + D.y * D.y);
    // D and ‖D_xy‖ before the angles of ĥ: GCC keeps this order, so the sums are dead during the
    // atan2 (fewer cycles by register pressure) and the square root overlaps them; same bits.
    const T theta_h = L::atan2_nonneg(rxy, s.sz);
    const T phi_h = L::azimuth(s.sy, s.sx);
    return {theta_h, phi_h, rxy, s.sz, D, dxy};
  }

  // Rows where frame()'s D, of size rxy len, would have a subnormal square: ĥ within ~1e-145 rad
  // of n (h̄ = 0 included) or ‖ωi + ωo‖ below ~1e-145 in double (3e-15 in float).
  template <class T>
  static MaskOf<T> needs_scaled_frame(const Sums<T>& s) {
    return s.rxy2 * s.len2 < T(detail::TinyScale<ScalarOf<T>>::frame_min);
  }

  // The same angles with s_xy and s rescaled by powers of two (exact) so that their squares are
  // normal, and D = 2d, whose z component 2‖h‖ is formed without squaring. Rare rows only.
  // h = 0 exactly: ĥ := n, θh = 0 and D = (tx, ty, 0).
  template <class T>
  static Frame<T> scaled_frame(const Sums<T>& s) {
    using L = LaneOps<T>;
    using Scale = detail::TinyScale<ScalarOf<T>>;
    const T tiny(Scale::tiny_sq), one(1), up(Scale::up);
    const T pxy = L::select(s.rxy2 < tiny, up, one), p = L::select(s.len2 < tiny, up, one);
    const T xs = pxy * s.sx, ys = pxy * s.sy;
    const T rs = L::sqrt(xs * xs + ys * ys);                               // pxy rxy
    const auto flat = rs == T(0), null = L::mask_and(flat, s.sz == T(0));  // s = 0
    const T cx = L::select(flat, one, xs / rs), cy = L::select(flat, T(0), ys / rs);
    const T a = cx * s.tx + cy * s.ty, b = cx * s.ty - cy * s.tx;
    const T rxy = (p / pxy) * rs, sz = p * s.sz;  // p rxy, p sz: exact unless underflowing
    const T len = L::sqrt(rxy * rxy + sz * sz);   // p len
    const T norm = L::select(null, one, len);
    const Vec3<T> D{L::select(null, s.tx, (sz / norm) * a - (rxy / norm) * s.tz),
                    L::select(null, s.ty, b), L::select(null, T(0), len / p)};
    return {L::select(null, T(0), L::atan2_nonneg(rxy, sz)),
            L::azimuth(ys, xs),  // exact multiples of sy, sx, and not subnormal
            rxy,
            sz,
            D,
            L::sqrt(D.x * D.x + D.y * D.y)};
  }

  // φh, θd, φd from the frame, and θh clamped (below): the inverse's elevations are
  // Dz cos θh ∓ Dx sin θh, both >= 0 iff θh <= atan2(Dz, |Dx|). For inputs unit only to rounding,
  // h·k = (‖ωi‖² − ‖ωo‖²)/4 is not 0, and near h = 0 (a pair opposite each other at the horizon)
  // θh is then noise that breaks this by up to ε/‖h‖. A tilt of ĥ down to the bound rotates the
  // pair by no more than that error, and keeps the round trip of every accepted pair valid
  // (docs/math.md §6). Valid pairs are unchanged but for rounding. θh_raw > θh_max iff
  // sin(θh_max - θh_raw) ∝ Dz ct - |Dx| st < 0. Where that is clearly positive in every lane
  // (beyond the rounding of both sides and of both atan2, docs/math.md §6), the clamp cannot act
  // and its atan2 is skipped: the same result either way.
  template <class T>
  static Tuple4<T> finish(const Frame<T>& f) {
    using L = LaneOps<T>;
    using S = ScalarOf<T>;
    const Vec3<T>& D = f.D;
    const T adx = L::abs(D.x);
    const auto clear =
        D.z * f.ct - adx * f.st > T(detail::kClampMargin<S>) * (f.st + f.ct) * (D.z + adx);
    T theta_h = f.theta_h;
    if (!all_lanes(clear)) [[unlikely]] {
      const T theta_h_max = L::atan2_nonneg(D.z, adx);
      theta_h = L::select(theta_h > theta_h_max, theta_h_max, theta_h);
    }
    return {theta_h, f.phi_h, L::atan2_nonneg(f.dxy, D.z), L::azimuth(D.y, D.x)};
  }
};

}  // namespace halfback
