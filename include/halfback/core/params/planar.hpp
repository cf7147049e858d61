// The planar half and difference vectors h̄, k̄ that ortho and hybrid share (docs/math.md §2.3-2.4).
#pragma once

#include <numbers>

#include "halfback/core/params/common.hpp"

namespace halfback {

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

}  // namespace halfback
