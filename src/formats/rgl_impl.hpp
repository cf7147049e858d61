// RglBrdf's data (private header of src/formats): the material's tables as rgl_read.cpp builds
// them from a tensor file, and the one-row evaluation they share with the block paths
// (rgl.cpp, rgl_batch.cpp). Compiled with rgl_tables.hpp's floating-point flags wherever it is
// included.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "halfback/formats/rgl.hpp"
#include "rgl_tables.hpp"
#include "rgl_warp.hpp"

namespace halfback {

namespace rgl_kernel {
struct EvalRows;
}  // namespace rgl_kernel

namespace rgl_detail {

// The coordinates of the VNDF, NDF and sigma tables: u = √(2θ/π) for a polar angle, (φ + π)/2π for
// an azimuth in (-π, π].
inline double theta_to_u(double theta) {
  return std::sqrt(theta * (2 / kPi));
}
inline double phi_to_u(double phi) {
  return (phi + kPi) * (0.5 / kPi);
}
// The polar angle of u (the inverse of theta_to_u).
inline double u_to_theta(double u) {
  return u * u * (kPi / 2);
}

// dωm = sin θm dθm dφm = 2π² u sin θm du dv, and dω = 4 |ω·m| dωm (reflection about m): the
// solid angle of a reflected direction per unit area of the unit square at um.
inline double reflection_jacobian(RglWarpPoint um, double theta_m, double cos_gm) {
  return 2 * kPi * kPi * um.x * std::sin(theta_m) * 4 * std::abs(cos_gm);
}

// floor(u) for |u| < 1e9 without a libm call (SSE2 has no rounding instruction), in a form that
// loops vectorize; 0 for NaN and larger values (the conversion to int would be undefined), which
// the azimuths of finite directions never reach, and u - 0 keeps a NaN.
inline double floor_small(double u) {
  const double c = std::abs(u) < 1e9 ? u : 0.0;
  const double t = static_cast<double>(static_cast<int>(c));
  return t > c ? t - 1 : t;
}

// The half vector's azimuth on the unit square of the VNDF and NDF tables, in [0, 1]: relative to
// ωi's for isotropic data. Azimuths in (-π, π], so |u| < 2.
inline double azimuth_u(double phi_m, double phi_i, bool isotropic) {
  const double u = phi_to_u(isotropic ? phi_m - phi_i : phi_m);
  return u - floor_small(u);
}

// Whether an axis flips for a coordinate v of the given direction: v >= +0 (the reference
// loader's mulsign_neg).
inline bool negative_sign(double v) {
  return !std::signbit(v);
}

// The data's symmetry (a rotation by π, or reflections across both axes) that moves the given
// direction into the covered range of φ: which axes to flip.
struct Flips {
  bool x = false, y = false;
  Vec3<double> apply(Vec3<double> v) const {
    if (x) v.x = -v.x;
    if (y) v.y = -v.y;
    return v;
  }
};

inline Flips flips_for(int reduction, const Vec3<double>& given) {
  if (reduction < 2) return {};
  const double sy = given.y, sx = reduction == 4 ? given.x : sy;
  return {negative_sign(sx), negative_sign(sy)};
}

}  // namespace rgl_detail

struct RglBrdf::Impl {
  std::string description;
  std::vector<float> theta_i_raw, phi_i_raw;
  rgl_detail::IncidenceAxis phi, theta;  // incidence grids; slices are ordered [φi][θi]
  bool isotropic = true;
  bool jacobian = true;
  int reduction = 1;             // anisotropic data covering 2π / reduction of φi, by symmetry
  rgl_detail::Table ndf, sigma;  // no incidence dependence
  rgl_detail::Warp vndf;
  rgl_detail::RgbTable rgb;  // slices [φi][θi]
  std::size_t n_slices = 1;
  std::size_t noise_clamped = 0;  // tiny negative ndf, vndf and luminance values set to 0
  std::size_t rgb_negative = 0;   // negative (out-of-gamut) RGB values
  std::size_t wavelengths = 0;    // the spectral variant: its wavelengths, integrated to RGB

  bool lanes = false;  // the tables' sides fit the block kernel's 32-bit cell indices

  // Slices::count of every incidence (slices() blends 2 values of each axis of several values).
  int slice_count() const { return (phi.stride ? 2 : 1) * (theta.stride ? 2 : 1); }

  // Impl::value() of the packed rows of a block, over cos θo (eval_block): the block kernel.
  void eval_rows(rgl_kernel::EvalRows& rows, bool clamp_negative) const;

  rgl_detail::Slices slices(double phi_i, double theta_i) const {
    rgl_detail::Slices s;
    slices(phi_i, theta_i, s);
    return s;
  }
  // The same in place (a block's array: no copy of the struct, whose piecewise stores a copy's
  // wide loads would wait for).
  void slices(double phi_i, double theta_i, rgl_detail::Slices& s) const {
    std::size_t ip, it;
    double tp, tt;
    phi.locate(phi_i, ip, tp);
    theta.locate(theta_i, it, tt);
    s.count = 0;
    for (int a = 0; a < 2; ++a) {
      const double wa = a ? tp : 1 - tp;
      if (a && phi.stride == 0) break;
      for (int b = 0; b < 2; ++b) {
        const double wb = b ? tt : 1 - tt;
        if (b && theta.stride == 0) break;
        const std::size_t slice = (ip + a) * phi.stride + (it + b) * theta.stride;
        s.index[s.count] = slice;
        s.weight[s.count] = wa * wb;
        ++s.count;
      }
    }
  }

  // fr·cos θo at incidence slices s, with um the half vector on the unit square of the VNDF and NDF
  // tables and uwi ωi on that of the sigma table: the RGB tables at the sample that the inverse
  // VNDF warp gives um, times the NDF over 4 sigma when the file asks for that Jacobian; negative
  // values clamped to 0 on request.
  Rgb value(const rgl_detail::Slices& s, RglWarpPoint um, RglWarpPoint uwi,
            bool clamp_negative) const {
    return shade(s, vndf.inverse(s, um), um, uwi, clamp_negative);
  }
  // value() from the inverse warp's sample: the RGB tables there, the Jacobian.
  Rgb shade(const rgl_detail::Slices& s, RglWarpPoint sample, RglWarpPoint um, RglWarpPoint uwi,
            bool clamp_negative) const {
    switch (s.count) {
      case 1:
        return shade<1>(s, sample, um, uwi, clamp_negative);
      case 2:
        return shade<2>(s, sample, um, uwi, clamp_negative);
      default:
        return shade<4>(s, sample, um, uwi, clamp_negative);
    }
  }
  template <int N>
  Rgb shade(const rgl_detail::Slices& s, RglWarpPoint sample, RglWarpPoint um, RglWarpPoint uwi,
            bool clamp_negative) const {
    double scale = 1;
    if (jacobian) scale = ndf.eval(um.x, um.y) / (4 * sigma.eval(uwi.x, uwi.y));
    const std::array<double, 3> rgb_at = rgb.eval<N>(s, sample.x, sample.y);
    double c[3];
    for (std::size_t ch = 0; ch < 3; ++ch) {
      c[ch] = rgb_at[ch] * scale;
      if (clamp_negative) c[ch] = std::max(c[ch], 0.0);
    }
    return {c[0], c[1], c[2]};
  }
};

}  // namespace halfback
