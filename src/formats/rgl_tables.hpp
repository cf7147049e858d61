// The grids of an RGL material (private header of src/formats): cells of the unit square, plain
// and RGB bilinear tables, and the incidence grids (θi, φi) whose slices the tables are blended
// over. Notation: a 2D table of W columns (x, the fastest index) and H rows (y) spans the unit
// square; the value at a point is the bilinear interpolation of the grid values. Tables that depend
// on the incidence are interpolated linearly between the slices at the incidence grid values
// (clamped at the ends). Shared by the warp (rgl_warp.hpp), the block kernel (rgl_kernel.hpp) and
// RglBrdf (rgl_impl.hpp); every file that includes it is compiled with the same floating-point
// flags (src/formats/CMakeLists.txt), so that its inline arithmetic rounds alike in all of them.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <vector>

namespace halfback::rgl_detail {

// Rows per block of eval_batch, sample_batch and pdf_batch: the columns, angles and lookups of a
// block stay in L1 while its table reads are in flight.
inline constexpr std::size_t kBlock = 64;

inline constexpr double kPi = std::numbers::pi;

// Clamp to [0, 1], NaN to 0 (std::clamp would pass NaN through to an index computation).
inline double unit(double x) {
  return x > 0 ? (x < 1 ? x : 1) : 0;
}

// cell_of() of n points (x, y) in columns, with 32-bit indices (a conversion the vector units
// have; the tables' sides fit, eval_block checks): the same cells.
struct Cells {
  alignas(64) std::int32_t i[kBlock], j[kBlock];
  alignas(64) double tx[kBlock], ty[kBlock];
};
[[gnu::always_inline]] inline void cells_of(const double* x, const double* y, std::size_t n,
                                            std::size_t w, std::size_t h, Cells& c) {
  const double sw = double(w - 1), sh = double(h - 1);
  const auto last_i = std::int32_t(w - 2), last_j = std::int32_t(h - 2);
  for (std::size_t k = 0; k < n; ++k) {
    const double u = unit(x[k]) * sw, v = unit(y[k]) * sh;
    const std::int32_t i = std::min(static_cast<std::int32_t>(u), last_i);
    const std::int32_t j = std::min(static_cast<std::int32_t>(v), last_j);
    c.i[k] = i, c.j[k] = j;
    c.tx[k] = u - double(i), c.ty[k] = v - double(j);
  }
}

// A grid over an incidence parameter (θi or φi): where a value falls, and its weights.
struct IncidenceAxis {
  std::vector<double> values;
  std::size_t stride = 0;  // in slices; 0 when the axis has a single value

  // Index of the lower grid value and the weight of the upper one, clamped at the ends.
  void locate(double x, std::size_t& index, double& t) const {
    const std::size_t n = values.size();
    if (n == 1) {
      index = 0;
      t = 0;
      return;
    }
    // The lower bound of x as a count of the (strictly increasing) values below it: a loop without
    // branches to mispredict, over grids of a few values (8 θi in the published files). NaN: 0.
    std::size_t k = 0;
    for (const double v : values) k += v < x ? 1 : 0;
    index = std::min(k == 0 ? 0 : k - 1, n - 2);
    const double lo = values[index], hi = values[index + 1];
    t = std::clamp((x - lo) / (hi - lo), 0.0, 1.0);
    if (std::isnan(t)) t = 0;
  }
};

// Up to 4 slices (2 incidence axes) and their weights.
struct Slices {
  std::size_t index[4];
  double weight[4];
  int count;
};

// A grid cell of the unit square: the lower corner (i, j) and the position (tx, ty) in the cell.
struct Cell {
  std::size_t i, j;
  double tx, ty;
};

[[gnu::always_inline]] inline Cell cell_of(double x, double y, std::size_t w, std::size_t h) {
  x = unit(x) * double(w - 1);
  y = unit(y) * double(h - 1);
  // Through a signed integer: x, y >= 0, and one instruction converts a double to it.
  const std::size_t i = std::min(static_cast<std::size_t>(static_cast<std::int64_t>(x)), w - 2);
  const std::size_t j = std::min(static_cast<std::size_t>(static_cast<std::int64_t>(y)), h - 2);
  return {i, j, x - double(i), y - double(j)};
}

// A plain bilinear table on the unit square.
struct Table {
  std::size_t w = 0, h = 0;
  std::vector<double> v;  // slices of h·w values

  // The value at (x, y) (0 + the bilinear sum: the sign of a zero as a sum over slices gives it).
  double eval(double x, double y) const {
    const Cell c = cell_of(x, y, w, h);
    const double* p = v.data() + c.j * w + c.i;
    const double top = (1 - c.tx) * p[0] + c.tx * p[1];
    const double bottom = (1 - c.tx) * p[w] + c.tx * p[w + 1];
    return 0.0 + ((1 - c.ty) * top + c.ty * bottom);
  }
};

// The RGB tables: a bilinear table per slice with the three channels of a grid point side by side
// in a 32-byte slot, so that the four corners of a cell are two or three cache lines instead of
// twelve (the file stores each channel as a table of its own).
struct RgbTable {
  static constexpr std::size_t kSlot = 4;  // r, g, b, unused
  std::size_t w = 0, h = 0;
  std::vector<double> v;  // slices of h·w slots

  // From the file's layout: slices of 3 channels of h·w values.
  void assign(const std::vector<double>& planar, std::size_t slices) {
    v.assign(slices * h * w * kSlot, 0.0);
    for (std::size_t s = 0; s < slices; ++s)
      for (std::size_t ch = 0; ch < 3; ++ch)
        for (std::size_t k = 0; k < h * w; ++k)
          v[(s * h * w + k) * kSlot + ch] = planar[(s * 3 + ch) * h * w + k];
  }

  const double* slot(std::size_t slice, std::size_t j, std::size_t i) const {
    return v.data() + ((slice * h + j) * w + i) * kSlot;
  }

  // The same arithmetic, channel by channel, as Table::eval on a channel's own table; N is
  // s.count.
  template <int N>
  std::array<double, 3> eval(const Slices& s, double x, double y) const {
    const Cell c = cell_of(x, y, w, h);
    std::array<double, 3> r{0, 0, 0};
    for (int k = 0; k < N; ++k) {
      const double* p = slot(s.index[k], c.j, c.i);
      const double* q = p + w * kSlot;  // the row above
      for (std::size_t ch = 0; ch < 3; ++ch) {
        const double top = (1 - c.tx) * p[ch] + c.tx * p[kSlot + ch];
        const double bottom = (1 - c.tx) * q[ch] + c.tx * q[kSlot + ch];
        r[ch] += s.weight[k] * ((1 - c.ty) * top + c.ty * bottom);
      }
    }
    return r;
  }
};

}  // namespace halfback::rgl_detail
