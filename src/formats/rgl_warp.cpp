// The 2D warp of RGL materials (rgl_warp.hpp): the construction of its CDFs and guide tables,
// and its block loops (densities_at, draw_columns), compiled for AVX-512, AVX2 and the baseline
// and run as simd_isa() says (isa_versions.hpp). This file is compiled without contraction
// (src/formats/CMakeLists.txt), so every lane of every version rounds as the one-row path does.
#include "rgl_warp.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "formats/isa_versions.hpp"

namespace halfback::rgl_detail {

// The running sums of one slice's values `in` (C, rounded to float as stored) and the marginal
// over its rows (M, not normalized) from those stored sums, so that the inverse and forward warps
// read one consistent set of values; then the slice's nodes, rows and 1/total. False when the
// slice integrates to 0 (or beyond the float range).
bool Warp::build_slice(const double* in, std::size_t s, std::vector<double>& c,
                       std::vector<double>& m) {
  for (std::size_t j = 0; j < h; ++j) {
    c[j * w] = 0;
    for (std::size_t i = 0; i + 1 < w; ++i)
      c[j * w + i + 1] = c[j * w + i] + 0.5 * (in[j * w + i] + in[j * w + i + 1]);
  }
  for (std::size_t k = 0; k < w * h; ++k) c[k] = double(float(c[k]));
  m[0] = 0;
  for (std::size_t j = 0; j + 1 < h; ++j)
    m[j + 1] = m[j] + 0.5 * (c[j * w + w - 1] + c[(j + 1) * w + w - 1]);
  const double total = m[h - 1];
  if (!(total > 0) || !std::isfinite(total)) return false;
  for (std::size_t k = 0; k < w * h; ++k) node[s * w * h + k] = {float(in[k]), float(c[k])};
  for (std::size_t j = 0; j < h; ++j) row[s * h + j] = {m[j] / total, c[j * w + w - 1]};
  inv_total[s] = 1 / total;
  return true;
}

bool Warp::build(const std::vector<double>& data, std::size_t slices) {
  node.resize(data.size());
  row.resize(slices * h);
  inv_total.resize(slices);
  std::vector<double> c(w * h), m(h);  // one slice's C and M, reused
  for (std::size_t s = 0; s < slices; ++s)
    if (!build_slice(data.data() + s * w * h, s, c, m)) return false;
  build_guides(slices);
  return true;
}

void Warp::build_guides(std::size_t slices) {
  guided = w - 1 <= UINT16_MAX && h - 1 <= UINT16_MAX;
  if (!guided) return;
  row_guide.resize(slices * h);
  col_guide.resize(slices * h * w);
  for (std::size_t s = 0; s < slices; ++s) {
    build_row_guide(s);
    for (std::size_t j = 0; j < h; ++j) build_column_guide(s, j);
  }
}

// Bucket k of slice s's marginal: the last row j with M(j) < k/h.
void Warp::build_row_guide(std::size_t s) {
  const Row* r = &row[s * h];
  for (std::size_t k = 0, j = 0; k < h; ++k) {
    j = step_from(j, h - 2, double(k) / double(h), [&](std::size_t q) { return r[q].m; });
    row_guide[s * h + k] = std::uint16_t(j);
  }
}

// Bucket k of row j of slice s: the last column i with C(j, i) < (k/w) R(j).
void Warp::build_column_guide(std::size_t s, std::size_t j) {
  const Node* a = &node[(s * h + j) * w];
  const double total = row[s * h + j].r;
  for (std::size_t k = 0, i = 0; k < w; ++k) {
    i = step_from(i, w - 2, double(k) / double(w) * total, [&](std::size_t q) { return a[q].c; });
    col_guide[(s * h + j) * w + k] = std::uint16_t(i);
  }
}

namespace {

// Warp::density(Blend<N>, cell) of m rows in cells (i, j) at (tx, ty) of the unit square, the
// slices of row q slices(q): the grid values copied into columns (many rows' loads in flight),
// then blended in vector lanes, operation for operation as density() (the same values bit for
// bit).
template <int N, class SlicesOf>
[[gnu::always_inline]] inline void densities_in_cells(const Warp& wp, std::size_t m,
                                                      SlicesOf slices, const std::size_t* i,
                                                      const std::size_t* j, const double* tx,
                                                      const double* ty, double* out) {
  const std::size_t w = wp.w, h = wp.h;
  alignas(64) double f[N][4][kBlock], scaled[N][kBlock];
  for (std::size_t q = 0; q < m; ++q) {
    const Slices& s = slices(q);
    const std::size_t k = j[q] * w + i[q];
    for (int n = 0; n < N; ++n) {
      const Warp::Node* a = wp.node.data() + s.index[n] * h * w + k;
      f[n][0][q] = a[0].f, f[n][1][q] = a[w].f, f[n][2][q] = a[1].f, f[n][3][q] = a[w + 1].f;
      scaled[n][q] = s.weight[n] * wp.inv_total[s.index[n]];
    }
  }
  const double sx = double(w - 1), sy = double(h - 1);
  for (std::size_t q = 0; q < m; ++q) {
    double f00 = 0, f10 = 0, f01 = 0, f11 = 0;
    for (int n = 0; n < N; ++n) {
      f00 += scaled[n][q] * f[n][0][q];
      f10 += scaled[n][q] * f[n][1][q];
      f01 += scaled[n][q] * f[n][2][q];
      f11 += scaled[n][q] * f[n][3][q];
    }
    const double c0 = (1 - ty[q]) * f00 + ty[q] * f10;
    const double c1 = (1 - ty[q]) * f01 + ty[q] * f11;
    out[q] = ((1 - tx[q]) * c0 + tx[q] * c1) * sx * sy;
  }
}

// densities_at() for rows of N slices: the cells as cell_of() finds them, in vector lanes, then
// densities_in_cells().
template <int N>
[[gnu::always_inline]] inline void densities_at_n(const Warp& wp, const Slices* s, const double* x,
                                                  const double* y, std::size_t m, double* out) {
  Cells c;
  cells_of(x, y, m, wp.w, wp.h, c);
  std::size_t i[kBlock], j[kBlock];
  for (std::size_t q = 0; q < m; ++q) i[q] = std::size_t(c.i[q]), j[q] = std::size_t(c.j[q]);
  densities_in_cells<N>(
      wp, m, [&](std::size_t q) -> const Slices& { return s[q]; }, i, j, c.tx, c.ty, out);
}

[[gnu::always_inline]] inline void densities_at_body(const Warp& wp, const Slices* s,
                                                     const double* x, const double* y,
                                                     std::size_t m, double* out) {
  if (m == 0) return;
  switch (s[0].count) {  // the same for every row (Impl::slices())
    case 1:
      return densities_at_n<1>(wp, s, x, y, m, out);
    case 2:
      return densities_at_n<2>(wp, s, x, y, m, out);
    default:
      return densities_at_n<4>(wp, s, x, y, m, out);
  }
}

}  // namespace

HALFBACK_ISA_VERSIONS(densities_at,
                      (const Warp& wp, const Slices* s, const double* x, const double* y,
                       std::size_t m, double* out),
                      (wp, s, x, y, m, out))

namespace {

// Warp::draw_column() of a block's rows (sample_block), in passes across the rows: the column
// bounds and row values (loads), the row's position ty (a square root and a division, in vector
// lanes), the column search and its values (loads), the column's position, then the blend's
// density at the cell (loads, then vector lanes). Each row's chain of dependent loads, square roots
// and divisions is cut at the passes, so the rows' steps overlap. The arithmetic is draw_column()'s
// operation for operation (the solves as selects), the same points and densities bit for bit.
// Rows `apart` are skipped; rows of no positive weight, and warps without guides, go through
// draw_column().
class ColumnDraws {
 public:
  ColumnDraws(const Warp& wp, const Slices* s, const Warp::Drawing* d) : wp_(wp), s_(s), d_(d) {}

  void run(const bool* apart, std::size_t n, Warp::Drawn* out) {
    m_ = 0;
    for (std::size_t k = 0; k < n; ++k) {
      if (apart[k]) continue;
      if (d_[k].blend || !wp_.guided)
        out[k] = wp_.draw_column(s_[k], d_[k]);
      else
        at_[m_++] = k;
    }
    if (m_ == 0) return;
    bounds();
    rows();
    columns();
    cells();
    switch (s_[at_[0]].count) {  // the same for every row (Impl::slices())
      case 1:
        densities<1>();
        break;
      case 2:
        densities<2>();
        break;
      default:
        densities<4>();
    }
    for (std::size_t q = 0; q < m_; ++q) out[at_[q]] = {{x_[q], y_[q]}, density_[q]};
  }

 private:
  // Warp::solve_linear_density() as selects, so that its loops vectorize.
  static double solve(double a, double b, double area) {
    const double x = a * a + 2 * (b - a) * area;
    const double den = a + std::sqrt(x < 0.0 ? 0.0 : x);  // std::max(x, 0.0)
    const double t = unit(2 * area / den);
    return ((area > 0) & (den > 0)) ? t : 0.0;
  }

  // The guided column bounds (Warp::column_bounds) and R, M of the drawn slice's rows j, j + 1.
  void bounds() {
    for (std::size_t q = 0; q < m_; ++q) {
      const Warp::Drawing& d = d_[at_[q]];
      const Warp::Blend<1> b(wp_, d.slice);
      wp_.column_bounds(b, d.j, d.u.x, lo_[q], hi_[q]);
      r0_[q] = b.R(d.j), r1_[q] = b.R(d.j + 1);
      area_[q] = d.u.y - b.M(d.j);
      ux_[q] = d.u.x;
    }
  }
  // The row's position ty, and the target of the column search.
  void rows() {
    for (std::size_t q = 0; q < m_; ++q) {
      const double r0 = r0_[q], r1 = r1_[q];
      const double ty = solve(r0, r1, area_[q]);
      ty_[q] = ty;
      target_[q] = ux_[q] * ((1 - ty) * r0 + ty * r1);
    }
  }
  // The column (Warp::forward_column's search), C there, F at its ends.
  void columns() {
    const std::size_t w = wp_.w;
    for (std::size_t q = 0; q < m_; ++q) {
      const Warp::Drawing& d = d_[at_[q]];
      const Warp::Blend<1> b(wp_, d.slice);
      const double ty = ty_[q];
      const std::size_t row0 = d.j * w, row1 = row0 + w;
      auto ct = [&](std::size_t i) { return (1 - ty) * b.C(row0 + i) + ty * b.C(row1 + i); };
      const std::size_t i = Warp::last_below(ct, target_[q], lo_[q], hi_[q], w - 2);
      i_[q] = i;
      cell_x_[q] = double(i), cell_y_[q] = double(d.j);
      below_[q] = ct(i);
      f_[0][q] = b.F(row0 + i), f_[1][q] = b.F(row1 + i);
      f_[2][q] = b.F(row0 + i + 1), f_[3][q] = b.F(row1 + i + 1);
    }
  }
  // The column's position tx, and the point.
  void cells() {
    const double sx = double(wp_.w - 1), sy = double(wp_.h - 1);
    for (std::size_t q = 0; q < m_; ++q) {
      const double ty = ty_[q];
      const double c0 = (1 - ty) * f_[0][q] + ty * f_[1][q];
      const double c1 = (1 - ty) * f_[2][q] + ty * f_[3][q];
      const double tx = solve(c0, c1, target_[q] - below_[q]);
      tx_[q] = tx;
      x_[q] = (cell_x_[q] + tx) / sx;
      y_[q] = (cell_y_[q] + ty) / sy;
    }
  }
  // Warp::density(Blend<N>, cell) of the rows' slices.
  template <int N>
  void densities() {
    for (std::size_t q = 0; q < m_; ++q) j_[q] = d_[at_[q]].j;
    densities_in_cells<N>(
        wp_, m_, [&](std::size_t q) -> const Slices& { return s_[at_[q]]; }, i_, j_, tx_, ty_,
        density_);
  }

  const Warp& wp_;
  const Slices* s_;
  const Warp::Drawing* d_;
  std::size_t m_ = 0;  // rows in the passes
  std::size_t at_[kBlock], lo_[kBlock], hi_[kBlock], i_[kBlock], j_[kBlock];
  alignas(64) double ux_[kBlock], r0_[kBlock], r1_[kBlock], area_[kBlock], ty_[kBlock];
  alignas(64) double target_[kBlock], below_[kBlock], f_[4][kBlock], tx_[kBlock];
  alignas(64) double cell_x_[kBlock], cell_y_[kBlock];  // i, j as doubles
  alignas(64) double x_[kBlock], y_[kBlock], density_[kBlock];
};

[[gnu::always_inline]] inline void draw_columns_body(const Warp& wp, const Slices* s,
                                                     const Warp::Drawing* d, const bool* apart,
                                                     std::size_t n, Warp::Drawn* out) {
  ColumnDraws(wp, s, d).run(apart, n, out);
}

}  // namespace

HALFBACK_ISA_VERSIONS(draw_columns,
                      (const Warp& wp, const Slices* s, const Warp::Drawing* d, const bool* apart,
                       std::size_t n, Warp::Drawn* out),
                      (wp, s, d, apart, n, out))

}  // namespace halfback::rgl_detail
