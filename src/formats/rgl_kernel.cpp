// The evaluation's block kernel of RGL materials (rgl_kernel.hpp). Compiled for AVX-512, AVX2 and
// the baseline and run as simd_isa() says (isa_versions.hpp); this file is compiled without
// contraction (src/formats/CMakeLists.txt), so every lane of every version rounds as the one-row
// path does: the values are those of Impl::value() bit for bit.
#include "rgl_kernel.hpp"

#include <cmath>

#include "formats/isa_versions.hpp"

namespace halfback::rgl_kernel {

using rgl_detail::Cells;
using rgl_detail::cells_of;
using rgl_detail::RgbTable;
using rgl_detail::unit;
using Node = Warp::Node;
using Row = Warp::Row;

namespace {

// Table::eval() of n points: the corners copied into columns, then blended.
[[gnu::always_inline]] inline void table_eval(const double* v, std::size_t w, std::size_t h,
                                              const double* x, const double* y, std::size_t n,
                                              double* out) {
  Cells c;
  cells_of(x, y, n, w, h, c);
  alignas(64) double p[4][kRows];
  for (std::size_t k = 0; k < n; ++k) {
    const double* a = v + std::size_t(c.j[k]) * w + std::size_t(c.i[k]);
    p[0][k] = a[0], p[1][k] = a[1], p[2][k] = a[w], p[3][k] = a[w + 1];
  }
  for (std::size_t k = 0; k < n; ++k) {
    const double tx = c.tx[k], ty = c.ty[k];
    const double top = (1 - tx) * p[0][k] + tx * p[1][k];
    const double bottom = (1 - tx) * p[2][k] + tx * p[3][k];
    out[k] = 0.0 + ((1 - ty) * top + ty * bottom);
  }
}

// Warp::inverse() of the rows' um: the point on the unit square of the RGB tables.
template <int N>
[[gnu::always_inline]] inline void inverse_warp(const EvalTables& t, const EvalRows& r, double* sx,
                                                double* sy) {
  const std::size_t n = r.n, w = t.vw, h = t.vh;
  Cells c;
  cells_of(r.um_x, r.um_y, n, w, h, c);
  // Per slice: F at the cell's corners, C at its left ones (as double), M, R of its rows, 1/total.
  alignas(64) double v[N][10][kRows];
  for (std::size_t k = 0; k < n; ++k)
    for (int s = 0; s < N; ++s) {
      const std::size_t first = r.slice[s][k] * h + std::size_t(c.j[k]);
      const Node* a = t.node + first * w + std::size_t(c.i[k]);
      const Row* q = t.row + first;
      v[s][0][k] = a[0].f, v[s][1][k] = a[1].f, v[s][2][k] = a[w].f, v[s][3][k] = a[w + 1].f;
      v[s][4][k] = a[0].c, v[s][5][k] = a[w].c;
      v[s][6][k] = q[0].m, v[s][7][k] = q[0].r, v[s][8][k] = q[1].r;
      v[s][9][k] = t.inv_total[r.slice[s][k]];
    }
  for (std::size_t k = 0; k < n; ++k) {
    double f00 = 0, f01 = 0, f10 = 0, f11 = 0, c00 = 0, c10 = 0, r0 = 0, r1 = 0, m0 = 0;
    for (int s = 0; s < N; ++s) {
      const double wn = r.weight[s][k] * v[s][9][k];
      f00 += wn * v[s][0][k];
      f01 += wn * v[s][1][k];
      f10 += wn * v[s][2][k];
      f11 += wn * v[s][3][k];
      c00 += wn * v[s][4][k];
      c10 += wn * v[s][5][k];
      m0 += r.weight[s][k] * v[s][6][k];
      r0 += wn * v[s][7][k];
      r1 += wn * v[s][8][k];
    }
    const double tx = c.tx[k], ty = c.ty[k];
    const double c0 = (1 - ty) * f00 + ty * f10;
    const double c1 = (1 - ty) * f01 + ty * f11;
    const double below = (1 - ty) * c00 + ty * c10;
    const double num = below + tx * c0 + 0.5 * tx * tx * (c1 - c0);
    const double row_total = (1 - ty) * r0 + ty * r1;
    // Both sides, then a select (a branch stops the loop's vectorization).
    const double x = unit(num / row_total), x_empty = unit(r.um_x[k]);
    sx[k] = row_total > 0 ? x : x_empty;
    sy[k] = unit(m0 + ty * r0 + 0.5 * ty * ty * (r1 - r0));
  }
}

// Impl::shade() and over_cosine() of the rows, sample (sx, sy) on the RGB tables.
template <int N>
[[gnu::always_inline]] inline void shade(const EvalTables& t, EvalRows& r, const double* sx,
                                         const double* sy) {
  const std::size_t n = r.n, w = t.rw, h = t.rh;
  constexpr std::size_t kSlot = RgbTable::kSlot;
  Cells c;
  cells_of(sx, sy, n, w, h, c);
  alignas(64) double v[N][4][3][kRows];  // the corners (i, j), (i+1, j), (i, j+1), (i+1, j+1)
  for (std::size_t k = 0; k < n; ++k)
    for (int s = 0; s < N; ++s) {
      const double* p =
          t.rgb + ((r.slice[s][k] * h + std::size_t(c.j[k])) * w + std::size_t(c.i[k])) * kSlot;
      const double* q = p + w * kSlot;
      for (std::size_t ch = 0; ch < 3; ++ch) {
        v[s][0][ch][k] = p[ch], v[s][1][ch][k] = p[kSlot + ch];
        v[s][2][ch][k] = q[ch], v[s][3][ch][k] = q[kSlot + ch];
      }
    }
  alignas(64) double scale[kRows], fr[3][kRows];
  if (t.jacobian) {
    alignas(64) double ndf[kRows], sigma[kRows];
    table_eval(t.ndf, t.nw, t.nh, r.um_x, r.um_y, n, ndf);
    table_eval(t.sigma, t.sw, t.sh, r.uwi_x, r.uwi_y, n, sigma);
    for (std::size_t k = 0; k < n; ++k) scale[k] = ndf[k] / (4 * sigma[k]);
  } else {
    for (std::size_t k = 0; k < n; ++k) scale[k] = 1;
  }
  const bool clamp = t.clamp_negative;
  for (std::size_t k = 0; k < n; ++k) {
    const double tx = c.tx[k], ty = c.ty[k];
    const double x = r.wo[0][k], y = r.wo[1][k], z = r.wo[2][k];
    const double inverse_cos_o = std::sqrt(x * x + y * y + z * z) / z;
    for (std::size_t ch = 0; ch < 3; ++ch) {
      double sum = 0;
      for (int s = 0; s < N; ++s) {
        const double top = (1 - tx) * v[s][0][ch][k] + tx * v[s][1][ch][k];
        const double bottom = (1 - tx) * v[s][2][ch][k] + tx * v[s][3][ch][k];
        sum += r.weight[s][k] * ((1 - ty) * top + ty * bottom);
      }
      const double value = sum * scale[k];
      // std::max(value, 0.0) on request, as a select.
      fr[ch][k] = ((clamp & (value < 0.0)) ? 0.0 : value) * inverse_cos_o;
    }
  }
  for (std::size_t ch = 0; ch < 3; ++ch)
    for (std::size_t k = 0; k < n; ++k) r.fr[ch][k] = fr[ch][k];
}

template <int N>
[[gnu::always_inline]] inline void eval_rows_n(const EvalTables& t, EvalRows& r) {
  alignas(64) double sx[kRows], sy[kRows];
  inverse_warp<N>(t, r, sx, sy);
  shade<N>(t, r, sx, sy);
}

[[gnu::always_inline]] inline void eval_rows_1_body(const EvalTables& t, EvalRows& r) {
  eval_rows_n<1>(t, r);
}
[[gnu::always_inline]] inline void eval_rows_2_body(const EvalTables& t, EvalRows& r) {
  eval_rows_n<2>(t, r);
}
[[gnu::always_inline]] inline void eval_rows_4_body(const EvalTables& t, EvalRows& r) {
  eval_rows_n<4>(t, r);
}

}  // namespace

// One function per slice count (1, 2 or 4: Impl::slices()).
HALFBACK_ISA_VERSIONS(eval_rows_1, (const EvalTables& t, EvalRows& r), (t, r))
HALFBACK_ISA_VERSIONS(eval_rows_2, (const EvalTables& t, EvalRows& r), (t, r))
HALFBACK_ISA_VERSIONS(eval_rows_4, (const EvalTables& t, EvalRows& r), (t, r))

void eval_rows(const EvalTables& t, EvalRows& r, int slice_count) {
  switch (slice_count) {
    case 1:
      return eval_rows_1(t, r);
    case 2:
      return eval_rows_2(t, r);
    default:
      return eval_rows_4(t, r);
  }
}

}  // namespace halfback::rgl_kernel
