// Row-wise decode (form -> direction pair) and encode (direction pair -> form) on lane types.
// Shared by convert_one(), the batch engine's kernels and the reference implementation.
#pragma once

#include <cmath>
#include <limits>
#include <type_traits>

#include "halfback/core/param.hpp"
#include "halfback/core/space.hpp"

namespace halfback::detail {

// Validity of a user-given pair, in the precision of T (see check_pair()).
template <class T>
inline MaskOf<T> pair_is_valid(const DirPair<T>& p) {
  using L = LaneOps<T>;
  using S = ScalarOf<T>;
  const T unit_tol(static_cast<S>(kUnitTolerance)), horizon_tol(kDomainTolerance<S>);
  auto unit = [&](const Vec3<T>& w) {
    return L::abs(dot(w, w) - T(1)) <= unit_tol;  // false for NaN and ±inf
  };
  return L::mask_and(L::mask_and(unit(p.wi), unit(p.wo)),
                     L::mask_and(p.wi.z >= -horizon_tol, p.wo.z >= -horizon_tol));
}

// Whether w is kept as it is by onto_unit_hemisphere below: ‖ω‖² within 4ε of 1 and z >= 0;
// false for NaN. (‖ω‖² is pair_is_valid's expression, so the kernels compute it once.)
template <class T>
inline MaskOf<T> on_unit_hemisphere(const Vec3<T>& w) {
  using L = LaneOps<T>;
  using S = ScalarOf<T>;
  const T unit_tol(S(4) * std::numeric_limits<S>::epsilon());
  return L::mask_and(L::abs(dot(w, w) - T(1)) <= unit_tol, w.z >= T(0));
}

// An accepted direction onto the unit upper hemisphere: a z below the horizon (within the
// tolerance) onto it, then unit length. The tolerances let through directions off unit length by
// up to 1e-6, whose coordinates would leave their range (‖h̄‖ = 1.0000004) and not convert back.
// A direction already unit to rounding (‖ω‖² within 4ε of 1, z >= 0) is kept bit for bit:
// dividing it by its norm would only round it again. That is almost every direction, so the
// square root and the division (slow in SIMD lanes, double above all) are skipped when every lane
// keeps its own: the same bits either way.
template <class T>
inline Vec3<T> onto_unit_hemisphere(const Vec3<T>& w) {
  using L = LaneOps<T>;
  const auto keep = on_unit_hemisphere(w);
  if (all_lanes(keep)) [[likely]]
    return w;
  const T z = L::max(w.z, T(0));
  const T inv = T(1) / L::sqrt(w.x * w.x + w.y * w.y + z * z);
  return {L::select(keep, w.x, w.x * inv), L::select(keep, w.y, w.y * inv),
          L::select(keep, w.z, z * inv)};
}

// The accepted pair that the conversions use (see onto_unit_hemisphere).
template <class T>
inline DirPair<T> accepted_pair(const DirPair<T>& p) {
  return {onto_unit_hemisphere(p.wi), onto_unit_hemisphere(p.wo)};
}

// Decodes coordinates `in` (dimension(from) values) into a pair; the mask says whether valid.
// Invalid pairs are NaN.
template <class P, class T>
inline Solved<T> decode_param(bool isotropic, const T* in) {
  if (isotropic) return inverse_iso<P>(Tuple3<T>{in[0], in[1], in[2]});
  return inverse<P>(Tuple4<T>{in[0], in[1], in[2], in[3]});
}

template <class P, class T>
inline void encode_param(bool isotropic, const DirPair<T>& p, T* out) {
  if (isotropic) {
    const Tuple3<T> q = P::forward_iso(p);
    for (int i = 0; i < 3; ++i) out[i] = q[i];
  } else {
    const Tuple4<T> q = P::forward(p);
    for (int i = 0; i < 4; ++i) out[i] = q[i];
  }
}

template <class P, class T>
inline T jacobian_of(bool isotropic, const T* q) {
  if (isotropic) return jacobian_iso<P>(Tuple3<T>{q[0], q[1], q[2]});
  return P::jacobian(Tuple4<T>{q[0], q[1], q[2], q[3]});
}

inline constexpr int kMaxDim = 6;

// A parameterization outside KernelParams, through its descriptor (in double).
template <class T>
inline Solved<T> decode_registered(Form from, const T* in) {
  const ParamDescriptor& d = from.space.param();
  double q[4] = {double(in[0]), double(in[1]), double(in[2]), from.isotropic ? 0 : double(in[3])};
  wrap_azimuth_rows(d.axes(from.isotropic), q, 1);
  const Solved<double> s =
      from.isotropic ? d.inverse_iso({q[0], q[1], q[2]}) : d.inverse({q[0], q[1], q[2], q[3]});
  const auto& p = s.pair;
  return {{{T(p.wi.x), T(p.wi.y), T(p.wi.z)}, {T(p.wo.x), T(p.wo.y), T(p.wo.z)}}, s.in_domain};
}

template <class T>
inline void encode_registered(Form to, const DirPair<T>& p, T* out) {
  const ParamDescriptor& d = to.space.param();
  const DirPair<double> pd{{p.wi.x, p.wi.y, p.wi.z}, {p.wo.x, p.wo.y, p.wo.z}};
  if (to.isotropic) {
    const Tuple3<double> q = d.forward_iso(pd);
    for (int i = 0; i < 3; ++i) out[i] = T(q[i]);
  } else {
    const Tuple4<double> q = d.forward(pd);
    for (int i = 0; i < 4; ++i) out[i] = T(q[i]);
  }
}

template <class T>
inline T jacobian_registered(Form side, const T* q) {
  const ParamDescriptor& d = side.space.param();
  if (side.isotropic) return T(d.jacobian_iso({double(q[0]), double(q[1]), double(q[2])}));
  return T(d.jacobian({double(q[0]), double(q[1]), double(q[2]), double(q[3])}));
}

// One row, scalar T: the reference semantics of convert().
template <class T>
inline bool convert_row(Form from, Form to, const T* in, T* out, T* jacobian) {
  DirPair<T> pair;
  bool ok;
  if (from.space.is_dirs()) {
    pair = {{in[0], in[1], in[2]}, {in[3], in[4], in[5]}};
    ok = pair_is_valid(pair);
    pair = accepted_pair(pair);
  } else {
    const Solved<T> s =
        from.space.has_kernels()
            ? visit_kernel_param(
                  from.space.kernel_index(),
                  [&](auto p) { return decode_param<decltype(p)>(from.isotropic, in); })
            : decode_registered(from, in);
    pair = s.pair;
    ok = s.in_domain;
  }
  const int dim_out = static_cast<int>(dimension(to));
  if (!ok) {
    for (int i = 0; i < dim_out; ++i) out[i] = std::numeric_limits<T>::quiet_NaN();
    if (jacobian) *jacobian = std::numeric_limits<T>::quiet_NaN();
    return false;
  }
  if (to.space.is_dirs()) {
    const T v[6] = {pair.wi.x, pair.wi.y, pair.wi.z, pair.wo.x, pair.wo.y, pair.wo.z};
    for (int i = 0; i < 6; ++i) out[i] = v[i];
  } else {
    // A decoded pair too is unit only to rounding (accepted_pair keeps it when within 4ε).
    const DirPair<T> unit = accepted_pair(pair);
    if (to.space.has_kernels())
      visit_kernel_param(to.space.kernel_index(),
                         [&](auto p) { encode_param<decltype(p)>(to.isotropic, unit, out); });
    else
      encode_registered(to, unit, out);
  }
  if (jacobian) {
    const Form side = !to.space.is_dirs() ? to : from;
    const T* q = !to.space.is_dirs() ? out : in;
    if (side.space.is_dirs())
      *jacobian = T(1);
    else if (side.space.has_kernels())
      *jacobian = visit_kernel_param(side.space.kernel_index(), [&](auto p) {
        return jacobian_of<decltype(p)>(side.isotropic, q);
      });
    else
      *jacobian = jacobian_registered(side, q);
  }
  return true;
}

}  // namespace halfback::detail
