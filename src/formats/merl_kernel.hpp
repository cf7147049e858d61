// The MERL lookups' index arithmetic and trilinear blend, shared by MerlBrdf::eval (one row) and
// eval_batch (blocks of rows, compiled in merl_kernel.cpp for AVX-512, AVX2 and the baseline,
// vectorized across rows, and run as simd_isa() says). One definition of each formula, so that a
// row gets the same bins, cells and blended values on both paths for the same coordinates
// (docs/performance.md, "Measured lookups"). Branch-free: every condition is a select, which the
// compiler turns into masks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>

#include "halfback/core/rgb.hpp"
#include "halfback/formats/merl.hpp"

namespace halfback::merl_kernel {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Rows per block of eval_batch: the coordinates, bins and cells of a block stay in L1/L2 while
// its table reads are in flight.
inline constexpr std::size_t kBlock = 256;

// The reference reader's bin indices, operation for operation (the same roundings: a division by
// the same constants, the same order). NaN and negative angles give bin 0.
inline int theta_h_index(double theta_h) {
  const double x = theta_h > 0.0 ? theta_h : 0.0;
  const double deg = (x / (kPi / 2.0)) * merl::kThetaH;
  const double t = __builtin_sqrt(deg * merl::kThetaH);
  return static_cast<int>(t < merl::kThetaH - 1 ? t : double(merl::kThetaH - 1));
}

inline int theta_d_index(double theta_d) {
  const double t = theta_d / (kPi * 0.5) * merl::kThetaD;
  return static_cast<int>(t > 0.0 ? (t < merl::kThetaD - 1 ? t : double(merl::kThetaD - 1)) : 0.0);
}

// φd in (-π, π] (the reference's atan2 range) or [0, 2π) (the core's azimuths): the reference's
// reciprocity fold maps both to [0, π]; φd = π itself is kept, as the reference does.
inline int phi_d_index(double phi_d) {
  const double p = phi_d < 0.0 ? phi_d + kPi : (phi_d > kPi ? phi_d - kPi : phi_d);
  const double t = p / kPi * (2 * merl::kPhiD) / 2;
  return static_cast<int>(t > 0.0 ? (t < merl::kPhiD - 1 ? t : double(merl::kPhiD - 1)) : 0.0);
}

inline std::uint32_t nearest_bin(double theta_h, double theta_d, double phi_d) {
  return static_cast<std::uint32_t>(
      merl::bin(theta_h_index(theta_h), theta_d_index(theta_d), phi_d_index(phi_d)));
}

// The cell of a trilinear lookup: its lowest bin, the step in φd to the next bin (1, or 1 − 180
// across the wrap φd = π ≡ 0), and the position (θh, θd, φd) in the cell, each in [0, 1]. The other
// bins are base + a·(90·180) + b·180 + c·phi_step for a, b, c in {0, 1}.
struct Cell {
  std::uint32_t base;
  std::int32_t phi_step;
  double t[3];
};

inline constexpr std::uint32_t kThetaHStep = std::uint32_t(merl::kThetaD) * merl::kPhiD;
inline constexpr std::uint32_t kThetaDStep = merl::kPhiD;

// A cell's lower bin and the weight of the upper one along one axis.
struct Axis {
  int i;
  double t;
};

// A clamped axis (θh, θd) of n bins in continuous bin coordinates u (bin k covers [k, k+1), its
// centre at k + ½): the lower centre i in [0, n−2] and the weight t of the upper one. Constant over
// the half bins at both ends: below the first centre t = 0 at i = 0, above the last t = 1 at
// i = n−2. NaN gives i = 0, t = 0.
inline Axis clamped_axis(double u, int n) {
  const double x = u - 0.5;
  const double c = x > 0 ? (x < n - 1 ? x : double(n - 1)) : 0.0;
  const int k = static_cast<int>(c);
  const int i = k < n - 2 ? k : n - 2;
  return {i, c - i};
}

inline Axis theta_h_axis(double theta_h) {
  const double x = theta_h > 0 ? theta_h : 0.0;  // NaN too
  return clamped_axis(__builtin_sqrt(x / (kPi / 2) * (merl::kThetaH * merl::kThetaH)),
                      merl::kThetaH);
}

inline Axis theta_d_axis(double theta_d) {
  return clamped_axis(theta_d / (kPi / 2) * merl::kThetaD, merl::kThetaD);
}

// The periodic axis (φd, period π = 180 bins; φd in (-π, π] or [0, 2π)): the lower centre in
// [0, 179] (179: the cell across the wrap, its upper bin 0).
inline Axis phi_d_axis(double phi_d) {
  const double p0 = phi_d < 0 ? phi_d + kPi : phi_d;
  const double pd = p0 >= kPi ? p0 - kPi : p0;
  const double x0 = pd / kPi * merl::kPhiD - 0.5;
  const double x = ((x0 >= -1) & (x0 < merl::kPhiD)) ? x0 : 0.0;  // only for non-finite input
  const int k = static_cast<int>(x);
  const int i = k - (double(k) > x ? 1 : 0);  // floor, without a libm call
  // i + 180 when i = -1 (a select here keeps GCC 12 from vectorizing the loops that use this).
  return {i + merl::kPhiD * static_cast<int>(static_cast<unsigned>(i) >> 31), x - i};
}

// The cell's lowest bin and φd step from the three axes' lower centres.
inline std::uint32_t cell_base(int ih, int id, int ip) {
  return (std::uint32_t(ih) * merl::kThetaD + std::uint32_t(id)) * merl::kPhiD + std::uint32_t(ip);
}
inline std::int32_t phi_step(int ip) {
  return ip + 1 == merl::kPhiD ? 1 - merl::kPhiD : 1;
}

inline Cell cell_of(double theta_h, double theta_d, double phi_d) {
  const Axis h = theta_h_axis(theta_h), d = theta_d_axis(theta_d), p = phi_d_axis(phi_d);
  return {cell_base(h.i, d.i, p.i), phi_step(p.i), {h.t, d.t, p.t}};
}

// A cell's 8 corner slots, copied in the order (θh, θd, φd).
struct Corners {
  merl::BinValues slot[8];
};

inline void load_corners(const merl::BinValues* table, const Cell& c, Corners& out) {
  const merl::BinValues* p = table + c.base;
  const merl::BinValues* q = p + c.phi_step;
  out.slot[0] = p[0];
  out.slot[1] = q[0];
  out.slot[2] = p[kThetaDStep];
  out.slot[3] = q[kThetaDStep];
  out.slot[4] = p[kThetaHStep];
  out.slot[5] = q[kThetaHStep];
  out.slot[6] = p[kThetaHStep + kThetaDStep];
  out.slot[7] = q[kThetaHStep + kThetaDStep];
}

// The blend of a cell's 8 corners: per channel, the weighted mean of the measured corners (an
// unmeasured corner, negative, is skipped and the others' weights renormalized); NaN for a channel
// with no measured corner. The weights are products in the order (θh, θd, φd). x(k, ch) is the
// value of corner k (in the order θh, θd, φd) in channel ch; channels [0, C) are summed (C = 4
// takes the pad along, so that the compiler packs a slot into one vector), the first 3 returned.
// Written on scalars, for the one-row path and for the block loop that runs it across rows.
template <int C, class X>
inline void blend_channels(const X& x, double t0, double t1, double t2, double (&rgb)[3]) {
  double sum[C] = {}, wsum[C] = {};
  // Unrolled before vectorization: GCC 12 vectorizes the loop over rows around it only then.
#pragma GCC unroll 2
  for (int a = 0; a < 2; ++a) {
    const double wa = a ? t0 : 1 - t0;
#pragma GCC unroll 2
    for (int b = 0; b < 2; ++b) {
      const double wb = wa * (b ? t1 : 1 - t1);
#pragma GCC unroll 2
      for (int k = 0; k < 2; ++k) {
        const double w = wb * (k ? t2 : 1 - t2);
#pragma GCC unroll 4
        for (int ch = 0; ch < C; ++ch) {
          const double v = x(4 * a + 2 * b + k, ch);
          sum[ch] += v >= 0 ? w * v : 0.0;  // an unmeasured corner is skipped
          wsum[ch] += v >= 0 ? w : 0.0;
        }
      }
    }
  }
#pragma GCC unroll 3
  for (int ch = 0; ch < 3; ++ch)
    rgb[ch] = wsum[ch] > 0 ? sum[ch] / wsum[ch] * merl::kScale[ch] : kNaN;
}

inline Rgb blend(const merl::BinValues* table, const Cell& c) {
  Corners v;
  load_corners(table, c, v);
  double rgb[3];
  blend_channels<4>([&](int k, int ch) { return v.slot[k].rgb[ch]; }, c.t[0], c.t[1], c.t[2], rgb);
  return {rgb[0], rgb[1], rgb[2]};
}

// The stored value of a bin times the scale, NaN for an unmeasured (negative) value.
inline Rgb bin_rgb(const merl::BinValues& v) {
  return {v.rgb[0] < 0 ? kNaN : v.rgb[0] * merl::kScale[0],
          v.rgb[1] < 0 ? kNaN : v.rgb[1] * merl::kScale[1],
          v.rgb[2] < 0 ? kNaN : v.rgb[2] * merl::kScale[2]};
}

// A block's cells as columns.
struct Cells {
  alignas(64) std::uint32_t base[kBlock];
  alignas(64) std::int32_t phi_step[kBlock];
  alignas(64) double t[3][kBlock];
  Cell operator[](std::size_t i) const {
    return {base[i], phi_step[i], {t[0][i], t[1][i], t[2][i]}};
  }
};

// Vectorized across rows (merl_kernel.cpp): the bins of m ≤ kBlock rows from their (θh, θd, φd)
// columns, kept = 0 rows (left to eval()) set to `apart`; the cells of m rows; the blends of rows
// [begin, end) of a block's cells.
void nearest_bins(const double* theta_h, const double* theta_d, const double* phi_d,
                  const std::uint8_t* apart, std::size_t m, std::uint32_t apart_bin,
                  std::uint32_t* bin);
void cells(const double* theta_h, const double* theta_d, const double* phi_d, std::size_t m,
           Cells& out);
void blend_rows(const merl::BinValues* table, const Cells& cells, std::size_t begin,
                std::size_t end, Rgb* out);

// Whether each of m row-major pairs (6 doubles a row) is left to eval(): rejected by the
// conversion (valid = 0), below the horizon, or with ωi + ωo along the normal.
void rows_apart(const double* rows, const std::uint8_t* valid, std::size_t m, std::uint8_t* apart);

// blend_rows and rows_apart run the AVX-512 kernels when avx512_kernels() (simd_isa() is avx512:
// core/simd.hpp), else the portable loops (vectorized by the compiler, in the version simd_isa()
// names: isa_versions.hpp): the same bits either way. Both are public for the tests; the *_avx512
// ones only where avx512_kernels() (they fall back to the portable loops where the build has no x86
// kernels).
bool avx512_kernels();
void blend_rows_portable(const merl::BinValues* table, const Cells& cells, std::size_t begin,
                         std::size_t end, Rgb* out);
void blend_rows_avx512(const merl::BinValues* table, const Cells& cells, std::size_t begin,
                       std::size_t end, Rgb* out);
void rows_apart_portable(const double* rows, const std::uint8_t* valid, std::size_t m,
                         std::uint8_t* apart);
void rows_apart_avx512(const double* rows, const std::uint8_t* valid, std::size_t m,
                       std::uint8_t* apart);

}  // namespace halfback::merl_kernel
