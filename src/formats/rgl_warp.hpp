// The 2D warp of RGL materials (private header of src/formats): Dupuy & Jakob's piecewise-bilinear
// distribution on the unit square, one per incidence slice (the VNDF and luminance tables of the
// files), its marginal and conditional CDFs, their inversion (forward), the inverse map, the
// density, and the draws of a blend of slices (docs/formats.md, "Inverse warp", "Sampling").
// Compiled with rgl_tables.hpp's floating-point flags wherever it is included.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "halfback/formats/rgl.hpp"
#include "rgl_tables.hpp"

namespace halfback::rgl_detail {

// A 2D distribution with the density bilinear in its grid values (a table per slice), sampled by
// inverting its marginal CDF in y and its conditional CDF in x (docs/formats.md). The density and
// the conditional CDF of a grid point are side by side (one 8-byte node of two floats: the file's
// float32 value and its running sum, not normalized, so that the tables of a 128 × 128 file take
// 1 MB rather than 2 and stay in a core's L2 cache), and so are the marginal CDF and the total of
// a row: the inverse warp at a point reads one or two cache lines per slice. A slice's
// normalization 1/total is applied to the blend's weights (Blend::scaled).
struct Warp {
  struct Node {
    float f;  // density grid value, as the file stores it
    float c;  // C(j, i) = ∫_0^i f(s, j) ds (trapezoids, rounded to float)
  };
  struct Row {
    double m;  // M(j) = ∫_0^j R(t) dt / total: normalized, M(h-1) = 1
    double r;  // R(j) = C(j, w-1), not normalized
  };
  std::size_t w = 0, h = 0;
  std::vector<Node> node;         // h·w per slice
  std::vector<Row> row;           // h per slice
  std::vector<double> inv_total;  // 1 / ∫∫ f per slice
  // Guide tables (Chen and Asau 1974) of each slice's own CDFs: bucket k of the marginal's h
  // buckets holds the last row j with M(j) < k/h, bucket k of a row's w buckets the last column i
  // with C(j, i) < (k/w) R(j). They bound forward()'s searches of the blended CDFs (below).
  std::vector<std::uint16_t> row_guide;  // h per slice
  std::vector<std::uint16_t> col_guide;  // h·w per slice
  bool guided = false;                   // w and h fit the guides' 16 bits

  // Builds the CDFs of slice values `data`; returns false when a slice integrates to 0.
  bool build(const std::vector<double>& data, std::size_t slices);
  bool build_slice(const double* in, std::size_t s, std::vector<double>& c, std::vector<double>& m);

  // The last k in [0, last] with value(k) < x (0 when there is none) for a non-decreasing value,
  // starting from a guide's bucket and stepping.
  template <class Value>
  static std::size_t step_from(std::size_t k, std::size_t last, double x, Value value) {
    // Mostly the answer is among k .. k + 3: counted without branches (the values are
    // non-decreasing, so those below x are a prefix) and checked; else, the steps.
    if (k + 4 <= last) {
      const std::size_t i = k + std::size_t(value(k + 1) < x) + std::size_t(value(k + 2) < x) +
                            std::size_t(value(k + 3) < x);
      if (((k == 0) | (value(k) < x)) && !(value(i + 1) < x)) return i;
    }
    while (k + 1 <= last && value(k + 1) < x) ++k;
    while (k > 0 && !(value(k) < x)) --k;
    return k;
  }

  // The guide tables of every slice (row_guide, col_guide), when w and h fit their 16 bits.
  void build_guides(std::size_t slices);
  void build_row_guide(std::size_t s);
  void build_column_guide(std::size_t s, std::size_t j);

  // Bucket of u in [0, 1] among n.
  static std::size_t bucket(double u, std::size_t n) {
    return std::min(static_cast<std::size_t>(u * double(n)), n - 1);
  }

  // The last k in [0, last] with f(k) < x (0 when none), f non-decreasing: binary search in [lo,
  // hi], where the slices' own answers put it, then a check of the answer's neighbours; should the
  // bounds miss it by rounding, a search of everything. Returns what a search of [0, last] returns.
  template <class F>
  static std::size_t last_below(F f, double x, std::size_t lo, std::size_t hi, std::size_t last) {
    auto search = [&](std::size_t a, std::size_t b) {
      while (a < b) {
        const std::size_t mid = (a + b + 1) / 2;
        if (f(mid) < x)
          a = mid;
        else
          b = mid - 1;
      }
      return a;
    };
    // A bound range of up to 3 values (the common case) is counted without branches.
    const std::size_t k = hi - lo <= 2
                              ? lo + std::size_t((lo + 1 <= hi) & (f(std::min(lo + 1, hi)) < x)) +
                                    std::size_t((lo + 2 <= hi) & (f(std::min(lo + 2, hi)) < x))
                              : search(lo, hi);
    if ((k == 0 || f(k) < x) && (k == last || !(f(k + 1) < x))) return k;
    return search(0, last);
  }

  // The slices of a blend as pointers to their nodes and rows, with the count N (1, 2 or 4, as
  // Impl::slices() gives) a constant: the loops unroll and the index arithmetic is done once.
  // Each sum adds the slices in the order of s.index, as a loop over s.count would.
  template <int N>
  struct Blend {
    const Node* node[N];  // the slice's h·w nodes
    const Row* row[N];    // its h rows
    const std::uint16_t* row_guide[N];
    const std::uint16_t* col_guide[N];
    double weight[N];  // of the normalized M
    double scaled[N];  // weight / total: of F, C and R, stored without normalization
    Blend(const Warp& wp, const Slices& s) {
      for (int n = 0; n < N; ++n) {
        const std::size_t first_row = s.index[n] * wp.h;
        node[n] = wp.node.data() + first_row * wp.w;
        row[n] = wp.row.data() + first_row;
        row_guide[n] = wp.guided ? wp.row_guide.data() + first_row : nullptr;
        col_guide[n] = wp.guided ? wp.col_guide.data() + first_row * wp.w : nullptr;
        weight[n] = s.weight[n];
        scaled[n] = s.weight[n] * wp.inv_total[s.index[n]];
      }
    }
    // One slice of weight 1.
    Blend(const Warp& wp, std::size_t slice) requires(N == 1)
        : Blend(wp, Slices{{slice, 0, 0, 0}, {1, 0, 0, 0}, 1}) {}
    // F and C at node k = j·w + i, M and R at row j, blended.
    double F(std::size_t k) const {
      double r = 0;
      for (int n = 0; n < N; ++n) r += scaled[n] * double(node[n][k].f);
      return r;
    }
    double C(std::size_t k) const {
      double r = 0;
      for (int n = 0; n < N; ++n) r += scaled[n] * double(node[n][k].c);
      return r;
    }
    double M(std::size_t j) const {
      double r = 0;
      for (int n = 0; n < N; ++n) r += weight[n] * row[n][j].m;
      return r;
    }
    double R(std::size_t j) const {
      double r = 0;
      for (int n = 0; n < N; ++n) r += scaled[n] * row[n][j].r;
      return r;
    }
  };

  // Calls f(Blend<N>) for the count of s.
  template <class Fn>
  decltype(auto) with_blend(const Slices& s, Fn f) const {
    switch (s.count) {
      case 1:
        return f(Blend<1>(*this, s));
      case 2:
        return f(Blend<2>(*this, s));
      default:
        return f(Blend<4>(*this, s));
    }
  }

  // Density on the unit square at p (the blended, normalized grid values, bilinear).
  double density(const Slices& s, RglWarpPoint p) const {
    return with_blend(s, [&](const auto& b) { return density(b, p); });
  }
  template <int N>
  double density(const Blend<N>& b, RglWarpPoint p) const {
    return density(b, cell_of(p.x, p.y, w, h));
  }
  // The same in cell g.
  template <int N>
  double density(const Blend<N>& b, const Cell& g) const {
    const std::size_t k = g.j * w + g.i;
    const double c0 = (1 - g.ty) * b.F(k) + g.ty * b.F(k + w);
    const double c1 = (1 - g.ty) * b.F(k + 1) + g.ty * b.F(k + w + 1);
    return ((1 - g.tx) * c0 + g.tx * c1) * double(w - 1) * double(h - 1);
  }

  // Point p of the unit square -> sample (the CDFs at p): the inverse of the warp. The grid
  // values around p's cell (F at its corners, C at its left ones, R and M of its rows) are blended
  // over the slices in one pass, each sum in the order of F(), C(), R() and M().
  RglWarpPoint inverse(const Slices& s, RglWarpPoint p) const {
    return with_blend(s, [&](const auto& b) { return inverse(b, p); });
  }
  template <int N>
  RglWarpPoint inverse(const Blend<N>& b, RglWarpPoint p) const {
    const Cell g = cell_of(p.x, p.y, w, h);
    const std::size_t k = g.j * w + g.i;
    double f00 = 0, f01 = 0, f10 = 0, f11 = 0, c00 = 0, c10 = 0, r0 = 0, r1 = 0, m0 = 0;
    for (int n = 0; n < N; ++n) {
      const double wn = b.scaled[n];
      const Node* a = b.node[n] + k;
      const Row* r = b.row[n] + g.j;
      f00 += wn * double(a[0].f);
      f01 += wn * double(a[1].f);
      f10 += wn * double(a[w].f);
      f11 += wn * double(a[w + 1].f);
      c00 += wn * double(a[0].c);
      c10 += wn * double(a[w].c);
      m0 += b.weight[n] * r[0].m;
      r0 += wn * r[0].r;
      r1 += wn * r[1].r;
    }
    const double sx = g.tx, ty = g.ty;
    const double c0 = (1 - ty) * f00 + ty * f10;
    const double c1 = (1 - ty) * f01 + ty * f11;
    const double below = (1 - ty) * c00 + ty * c10;
    const double num = below + sx * c0 + 0.5 * sx * sx * (c1 - c0);
    const double row_total = (1 - ty) * r0 + ty * r1;
    RglWarpPoint u;
    u.x = row_total > 0 ? unit(num / row_total) : unit(p.x);
    u.y = unit(m0 + ty * r0 + 0.5 * ty * ty * (r1 - r0));
    return u;
  }

  // The bounds of the blended row search: each slice's own last row with M(j) < u.y (a blend of
  // non-decreasing CDFs with weights summing to 1 crosses u.y between its slices' crossings).
  template <int N>
  void row_bounds(const Blend<N>& b, double uy, std::size_t& lo, std::size_t& hi) const {
    lo = h - 2;
    hi = 0;
    const std::size_t k = bucket(uy, h);
    for (int n = 0; n < N; ++n) {
      if (!(b.weight[n] > 0)) continue;
      const Row* r = b.row[n];
      const std::size_t j =
          step_from(b.row_guide[n][k], h - 2, uy, [&](std::size_t q) { return r[q].m; });
      lo = std::min(lo, j);
      hi = std::max(hi, j);
    }
    if (lo > hi) lo = 0, hi = h - 2;
  }

  // The same for the columns of rows j and j + 1 blended with weights 1 - ty and ty: each row's
  // and slice's own last column with C(j, i) < u.x R(j). Both rows whatever ty (a row of weight
  // 0 only widens the bounds), so that these loads need not wait for ty's square root.
  template <int N>
  void column_bounds(const Blend<N>& b, std::size_t j, double ux, std::size_t& lo,
                     std::size_t& hi) const {
    lo = w - 2;
    hi = 0;
    const std::size_t k = bucket(ux, w);
    for (int n = 0; n < N; ++n)
      for (std::size_t d = 0; d < 2; ++d) {
        if (!(b.weight[n] > 0)) continue;
        const Node* a = b.node[n] + (j + d) * w;
        const double x = ux * b.row[n][j + d].r;
        const std::size_t i = step_from(b.col_guide[n][(j + d) * w + k], w - 2, x,
                                        [&](std::size_t q) { return a[q].c; });
        lo = std::min(lo, i);
        hi = std::max(hi, i);
      }
    if (lo > hi) lo = 0, hi = w - 2;
  }

  // Sample -> point: inverts the marginal CDF in y, then the conditional CDF in x. The searches
  // find what binary searches of [0, h-2] and [0, w-2] find, within the slices' guided bounds.
  // `use_guides` false: plain binary searches (the reference the tests compare with).
  RglWarpPoint forward(const Slices& s, RglWarpPoint u, bool use_guides = true) const {
    return with_blend(s, [&](const auto& b) { return forward(b, u, use_guides); });
  }
  template <int N>
  RglWarpPoint forward(const Blend<N>& b, RglWarpPoint u, bool use_guides = true) const {
    const Cell c = forward_cell(b, u, use_guides);
    return {(double(c.i) + c.tx) / double(w - 1), (double(c.j) + c.ty) / double(h - 1)};
  }
  // The same as a cell and the position in it.
  template <int N>
  Cell forward_cell(const Blend<N>& b, RglWarpPoint u, bool use_guides) const {
    const bool guides = guided && use_guides;
    u.x = unit(u.x);
    u.y = unit(u.y);
    return forward_column(b, u, forward_row(b, u.y, guides), guides);
  }
  // Its row: the last j in [0, h-2] with M(j) < u.y.
  template <int N>
  std::size_t forward_row(const Blend<N>& b, double uy, bool guides) const {
    std::size_t lo = 0, hi = h - 2;
    if (guides) row_bounds(b, uy, lo, hi);
    return last_below([&](std::size_t q) { return b.M(q); }, uy, lo, hi, h - 2);
  }
  // The rest, in row j (u in the unit square).
  template <int N>
  Cell forward_column(const Blend<N>& b, RglWarpPoint u, std::size_t j, bool guides) const {
    std::size_t col_lo = 0, col_hi = w - 2;
    if (guides) column_bounds(b, j, u.x, col_lo, col_hi);
    const double r0 = b.R(j), r1 = b.R(j + 1);
    const double ty = solve_linear_density(r0, r1, u.y - b.M(j));
    // Column: the last i in [0, w-2] with C_ty(i) < u.x · R(ty).
    const double target = u.x * ((1 - ty) * r0 + ty * r1);
    const std::size_t row0 = j * w, row1 = row0 + w;
    auto ct = [&](std::size_t i) { return (1 - ty) * b.C(row0 + i) + ty * b.C(row1 + i); };
    const std::size_t i = last_below(ct, target, col_lo, col_hi, w - 2);
    const double c0 = (1 - ty) * b.F(row0 + i) + ty * b.F(row1 + i);
    const double c1 = (1 - ty) * b.F(row0 + i + 1) + ty * b.F(row1 + i + 1);
    return {i, j, solve_linear_density(c0, c1, target - ct(i)), ty};
  }

  // A point drawn from the blend's density, and its density (density(s, point) up to rounding):
  // a slice n chosen with probability s.weight[n], then that slice's own CDFs inverted. The
  // blend's density is the mixture Σ w_n p_n (the bilinear interpolant is linear in the grid
  // values), so this samples what forward() samples, by another map of u: one slice's searches
  // instead of the blend's (docs/formats.md, "Sampling"). u.x chooses the slice and is rescaled
  // to its share.
  struct Drawn {
    RglWarpPoint point;
    double density;
  };
  Drawn draw(const Slices& s, RglWarpPoint u) const {
    Drawing d;
    draw_row(s, u, d);
    return draw_column(s, d);
  }

  // draw() in steps, so that a block's column searches find the lines that the steps before ask
  // for: the slice and the row (the column guides of rows j and j + 1 prefetched), the nodes at
  // the guides prefetched (prefetch_nodes), then the rest.
  struct Drawing {
    std::size_t slice = 0;  // the drawn one
    RglWarpPoint u;
    std::size_t j = 0;
    bool blend = false;  // no slice of positive weight: forward() of the blend
  };
  // Into d in place (a block's array: its copy would wait on the piecewise stores).
  void draw_row(const Slices& s, RglWarpPoint u, Drawing& d) const {
    const double x = unit(u.x);
    int pick = -1;
    double below = 0, share = 1, sum = 0;
    for (int n = 0; n < s.count; ++n) {
      if (!(s.weight[n] > 0)) continue;
      pick = n, below = sum, share = s.weight[n];
      sum += s.weight[n];
      if (x < sum) break;  // the last slice of positive weight also takes x >= Σ w (rounding)
    }
    d.blend = pick < 0;  // no positive weight (a NaN incidence)
    if (d.blend) {
      d.u = u;
      return;
    }
    d.slice = s.index[pick];
    d.u = {unit((x - below) / share), unit(u.y)};
    d.j = forward_row(Blend<1>(*this, d.slice), d.u.y, guided);
    if (guided) {
      const std::uint16_t* g = &col_guide[(d.slice * h + d.j) * w + bucket(d.u.x, w)];
      __builtin_prefetch(g);
      __builtin_prefetch(g + w);
    }
  }
  void prefetch_nodes(const Drawing& d) const {
    if (d.blend || !guided) return;
    const std::size_t first = (d.slice * h + d.j) * w, k = bucket(d.u.x, w);
    __builtin_prefetch(&node[first + col_guide[first + k]]);
    __builtin_prefetch(&node[first + w + col_guide[first + w + k]]);
  }
  Drawn draw_column(const Slices& s, const Drawing& d) const {
    if (d.blend) {
      const RglWarpPoint p = forward(s, d.u);
      return {p, density(s, p)};
    }
    const Cell c = forward_column(Blend<1>(*this, d.slice), d.u, d.j, guided);
    return {{(double(c.i) + c.tx) / double(w - 1), (double(c.j) + c.ty) / double(h - 1)},
            with_blend(s, [&](const auto& b) { return density(b, c); })};
  }

  // t in [0, 1] with ∫_0^t ((1-τ) a + τ b) dτ = a t + (b - a) t²/2 = area, in the form that stays
  // accurate when b ≈ a.
  static double solve_linear_density(double a, double b, double area) {
    if (!(area > 0)) return 0;
    const double disc = std::max(a * a + 2 * (b - a) * area, 0.0);
    const double den = a + std::sqrt(disc);
    if (!(den > 0)) return 0;
    return unit(2 * area / den);
  }
};

// Warp::density() of m rows at points (x, y), the slices of row q s[q], all with as many slices
// (Impl::slices()): the same values as density() bit for bit, in vector lanes (pdf_block).
void densities_at(const Warp& wp, const Slices* s, const double* x, const double* y, std::size_t m,
                  double* out);

// Warp::draw_column() of the n rows of a block that are not `apart`, in passes across the rows:
// the same points and densities as draw_column() bit for bit (sample_block).
void draw_columns(const Warp& wp, const Slices* s, const Warp::Drawing* d, const bool* apart,
                  std::size_t n, Warp::Drawn* out);

}  // namespace halfback::rgl_detail
