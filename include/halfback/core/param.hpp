// The four parameterizations of a pair of directions (ωi, ωo), as generic kernels.
//
// Conventions (docs/math.md): frame n = +z, t = +x, b = +y; ωi is the incoming (light) and ωo the
// outgoing (view) direction, unit vectors with z >= 0; h = (ωi+ωo)/2 and k = (ωi-ωo)/2 are not
// normalized; h̄, k̄ are their projections on the tangent plane; every azimuth is in [0, 2π), and the
// azimuth of a zero-length vector is 0.
//
// Each parameterization P is a stateless struct of static templates over a lane type T (float,
// double or a SIMD pack, see lane_math.hpp):
//   forward(pair)          -> Tuple4     the 4D coordinates
//   inverse_raw(q)         -> Solved     the pair, unclamped, and the domain mask
//   jacobian(q)            -> T          J with dωi dωo = J dq
//   forward_iso(pair)      -> Tuple3     coordinates of the pair's canonical pose (see below)
//   lift_iso(q3)           -> Tuple4     the 4D coordinates of the canonical pose
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

// --------------------------------------------------------------------------------------------
// spherical: (θi, φi, θo, φo)
// --------------------------------------------------------------------------------------------
struct Spherical {
  static constexpr std::string_view name = "spherical";
  static constexpr std::array<std::string_view, 4> columns{"theta_i", "phi_i", "theta_o", "phi_o"};
  static constexpr std::array<std::string_view, 3> iso_columns{"theta_i", "theta_o", "dphi"};

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
    using L = LaneOps<T>;
    Solved<T> r = inverse_raw(lift_iso(q));
    // Rotate by -φh so that h̄ lies on +x (nothing to do when h̄ = 0: ωi is already at azimuth 0).
    // The pose is discontinuous at h̄ = 0, so an h̄ at the rounding level of its two terms (an
    // exact mirror configuration, Δφ = π) counts as zero rather than picking a random rotation.
    const T hx = r.pair.wi.x + r.pair.wo.x, hy = r.pair.wi.y + r.pair.wo.y;
    const T len = L::sqrt(hx * hx + hy * hy);
    const T scale = L::abs(r.pair.wi.x) + L::abs(r.pair.wo.x) + L::abs(r.pair.wo.y);
    const auto zero = len <= T(8 * std::numeric_limits<ScalarOf<T>>::epsilon()) * scale;
    const T c = L::select(zero, T(1), hx / len), s = L::select(zero, T(0), -hy / len);
    r.pair.wi = detail::rotate_z(r.pair.wi, c, s);
    r.pair.wo = detail::rotate_z(r.pair.wo, c, s);
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

// --------------------------------------------------------------------------------------------
// halfdiff: (θh, φh, θd, φd), Rusinkiewicz 1998. ĥ = (ωi+ωo)/|ωi+ωo| (ĥ = n when h = 0),
// d = rot_b(-θh) rot_n(-φh) ωi.
// --------------------------------------------------------------------------------------------
struct HalfDiff {
  static constexpr std::string_view name = "halfdiff";
  static constexpr std::array<std::string_view, 4> columns{"theta_h", "phi_h", "theta_d", "phi_d"};
  static constexpr std::array<std::string_view, 3> iso_columns{"theta_h", "theta_d", "phi_d"};

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

// --------------------------------------------------------------------------------------------
// ortho: (‖h̄‖, φh, ‖k̄‖, φk), Neumann 1999 / Löw 2012. ωi = (h̄+k̄, √(1-|h̄+k̄|²)),
// ωo = (h̄-k̄, √(1-|h̄-k̄|²)).
// hybrid: (‖h̄‖, φh, ‖k‖, φk), after Stark 2005. k = ‖k‖ (sin θk cos φk, sin θk sin φk, cos θk)
// with θk ∈ [0, π] fixed by h·k = 0: θk = atan2(hz, -‖h̄‖ cos(φk-φh)).
// The two share their planar half, so they share the code below.
// --------------------------------------------------------------------------------------------
namespace detail {

template <class T>
struct PlanarHK {
  T hx, hy, kx, ky, kz;
};

template <class T>
inline PlanarHK<T> planar_hk(const DirPair<T>& p) {
  const T half(0.5);
  return {half * (p.wi.x + p.wo.x), half * (p.wi.y + p.wo.y), half * (p.wi.x - p.wo.x),
          half * (p.wi.y - p.wo.y), half * (p.wi.z - p.wo.z)};
}

// ‖v‖ from ‖v‖², clamped into [0, 1], the range of ‖h̄‖, ‖k̄‖ and ‖k‖ for unit directions: for
// ωi = ωo on the horizon, ‖h̄‖ rounds to 1 + 2e-16 and would fall outside the valid domain.
template <class T>
inline T magnitude(T squared) {
  const T m = LaneOps<T>::sqrt(squared);
  return LaneOps<T>::select(m > T(1), T(1), m);  // NaN stays NaN
}

// Δφ = φk - φh of the canonical pose: 0 when either planar vector is zero.
template <class T>
inline T relative_azimuth(T hbar, T kbar, T phi_h, T phi_k) {
  using L = LaneOps<T>;
  return L::select(L::mask_or(hbar == T(0), kbar == T(0)), T(0), wrap_two_pi(phi_k - phi_h));
}

template <class T>
inline T flip_azimuth(T magnitude, T phi) {  // φ + π, keeping 0 for a zero vector
  return LaneOps<T>::select(magnitude == T(0), T(0),
                            wrap_two_pi(phi + T(std::numbers::pi_v<ScalarOf<T>>)));
}

template <class T>
inline Tuple4<T> mirror_second_azimuth(const Tuple4<T>& q) {  // φk -> 2φh - φk
  return {q[0], q[1], q[2],
          LaneOps<T>::select(q[2] == T(0), T(0), wrap_two_pi(T(2) * q[1] - q[3]))};
}

template <class T>
inline Tuple3<T> reciprocal_planar_iso(const Tuple3<T>& q) {
  using L = LaneOps<T>;
  const auto keep = L::mask_or(q[0] == T(0), q[1] == T(0));
  return {q[0], q[1], L::select(keep, T(0), flip_azimuth(T(1), q[2]))};
}

}  // namespace detail

struct Ortho {
  static constexpr std::string_view name = "ortho";
  static constexpr std::array<std::string_view, 4> columns{"hbar", "phi_h", "kbar", "phi_k"};
  static constexpr std::array<std::string_view, 3> iso_columns{"hbar", "kbar", "dphi"};

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

struct Hybrid {
  static constexpr std::string_view name = "hybrid";
  // hz² below this is at the rounding level of 1 − ‖h̄‖² − ‖k‖²: both directions graze.
  template <class S>
  static constexpr S kNoisyHz2 = S(16) * std::numeric_limits<S>::epsilon();
  static constexpr std::array<std::string_view, 4> columns{"hbar", "phi_h", "k", "phi_k"};
  static constexpr std::array<std::string_view, 3> iso_columns{"hbar", "k", "dphi"};

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

// The pair with coordinates q; NaN directions when q is outside the valid domain.
template <class P, class T>
inline Solved<T> inverse(const Tuple4<T>& q) {
  Solved<T> s = P::inverse_raw(q);
  detail::finish_inverse(s);
  return s;
}

// The canonical pose with isotropic coordinates q (NaN when invalid).
template <class P, class T>
inline Solved<T> inverse_iso(const Tuple3<T>& q) {
  Solved<T> s = P::inverse_iso_raw(q);
  detail::finish_inverse(s);
  return s;
}

template <class P, class T>
inline MaskOf<T> valid(const Tuple4<T>& q) {
  return P::inverse_raw(q).in_domain;
}

template <class P, class T>
inline MaskOf<T> valid_iso(const Tuple3<T>& q) {
  return P::inverse_iso_raw(q).in_domain;
}

// The measure of the isotropic coordinates: ∫ over the rotation about n of dωi dωo = J3 dq3.
template <class P, class T>
inline T jacobian_iso(const Tuple3<T>& q) {
  return T(kTwoPi<ScalarOf<T>>) * P::jacobian(P::lift_iso(q));
}

}  // namespace halfback
