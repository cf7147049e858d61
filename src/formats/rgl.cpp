// RGL material evaluation (docs/formats.md, "RGL"). Notation: a 2D table of W columns (x, the
// fastest index) and H rows (y) spans the unit square; the value at a point is the bilinear
// interpolation of the grid values. Tables that depend on the incidence (θi, φi) are interpolated
// linearly between the slices at the incidence grid values (clamped at the ends).
#include "halfback/formats/rgl.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "binary_io.hpp"
#include "halfback/core/batch.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/core/spectrum.hpp"
#include "halfback/util/format_error.hpp"

namespace halfback {

// The VNDF warp's storage (Warp, below), shared with the evaluation's block kernel (eval_rows).
namespace rgl_kernel {
struct Node {
  float f;  // density grid value, as the file stores it
  float c;  // C(j, i) = ∫_0^i f(s, j) ds (trapezoids, rounded to float)
};
struct Row {
  double m;  // M(j) = ∫_0^j R(t) dt / total: normalized, M(h-1) = 1
  double r;  // R(j) = C(j, w-1), not normalized
};
struct EvalRows;
}  // namespace rgl_kernel

// The block loops compiled for AVX-512, AVX2 and the baseline, chosen at load time by the CPU
// (GCC's target_clones, as merl_kernel.cpp).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(__SANITIZE_ADDRESS__)
#define HALFBACK_RGL_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define HALFBACK_RGL_CLONES
#endif

namespace {

using io_detail::load_le;

// Rows per block of eval_batch, sample_batch and pdf_batch: the columns, angles and lookups of a
// block stay in L1 while its table reads are in flight.
constexpr std::size_t kBlock = 64;

constexpr double kPi = std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Clamp to [0, 1], NaN to 0 (std::clamp would pass NaN through to an index computation).
double unit(double x) {
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

double theta_to_u(double theta) {
  return std::sqrt(theta * (2 / kPi));
}
double phi_to_u(double phi) {
  return (phi + kPi) * (0.5 / kPi);
}

// floor(u) for |u| < 1e9 without a libm call (SSE2 has no rounding instruction), in a form that
// loops vectorize; 0 for NaN and larger values (the conversion to int would be undefined), which
// the azimuths of finite directions never reach, and u - 0 keeps a NaN.
double floor_small(double u) {
  const double c = std::abs(u) < 1e9 ? u : 0.0;
  const double t = static_cast<double>(static_cast<int>(c));
  return t > c ? t - 1 : t;
}

// The half vector's azimuth on the unit square of the VNDF and NDF tables, in [0, 1]: relative to
// ωi's for isotropic data. Azimuths in (-π, π], so |u| < 2.
double azimuth_u(double phi_m, double phi_i, bool isotropic) {
  const double u = phi_to_u(isotropic ? phi_m - phi_i : phi_m);
  return u - floor_small(u);
}

class Validator {
 public:
  Validator(const TensorFile& tf, std::string file) : tf_(tf), file_(std::move(file)) {}

  const TensorField& field(std::string_view name, TensorDtype dtype, std::size_t ndim) const {
    const TensorField* f = tf_.find(name);
    if (!f) fail(name, "missing (required by the RGL material format)");
    if (f->dtype != dtype)
      fail(name, "has dtype " + std::string(name_of(f->dtype)) + ", expected " +
                     std::string(name_of(dtype)));
    if (f->shape.size() != ndim)
      fail(name, "has " + std::to_string(f->shape.size()) + " dimensions, expected " +
                     std::to_string(ndim));
    return *f;
  }

  std::vector<double> floats(const TensorField& f) const {
    std::vector<double> v(static_cast<std::size_t>(f.count()));
    for (std::size_t i = 0; i < v.size(); ++i) {
      const float x = load_le<float>(f.bytes.data() + 4 * i);
      if (!std::isfinite(x))
        fail(f.name, fmt::format("value {} is {}", i, std::isnan(x) ? "NaN" : "infinite"));
      v[i] = x;
    }
    return v;
  }

  void require_positive(const TensorField& f, const std::vector<double>& v) const {
    for (std::size_t i = 0; i < v.size(); ++i)
      if (!(v[i] > 0)) fail(f.name, fmt::format("value {} is {:g}, must be positive", i, v[i]));
  }

  // A density measured with noise: negative values within kRglNoiseFraction of the field's largest
  // value are set to 0 (the reference loader uses them as they are); larger ones are refused.
  // Returns how many were set to 0.
  std::size_t clamp_noise(const TensorField& f, std::vector<double>& v) const {
    double largest = 0;
    for (double x : v) largest = std::max(largest, x);
    const double floor = -kRglNoiseFraction * largest;
    std::size_t clamped = 0;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (v[i] >= 0) continue;
      if (v[i] < floor)
        fail(f.name, fmt::format("value {} is {:g}, below the noise tolerance {:g} ({:g} times the "
                                 "field's largest value {:g}): not a density",
                                 i, v[i], floor, -kRglNoiseFraction, largest));
      v[i] = 0;
      ++clamped;
    }
    return clamped;
  }

  void require_dim(const TensorField& f, std::size_t axis, std::uint64_t expected,
                   const std::string& why) const {
    if (f.shape[axis] != expected)
      fail(f.name,
           fmt::format("dimension {} is {}, expected {} ({})", axis, f.shape[axis], expected, why));
  }

  void require_at_least(const TensorField& f, std::size_t axis, std::uint64_t min) const {
    if (f.shape[axis] < min)
      fail(f.name, "dimension " + std::to_string(axis) + " is " + std::to_string(f.shape[axis]) +
                       ", must be at least " + std::to_string(min));
  }

  [[noreturn]] void fail(std::string_view field, const std::string& problem) const {
    throw FormatError(file_, "field '" + std::string(field) + "'", problem);
  }

 private:
  const TensorFile& tf_;
  std::string file_;
};

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

// A 2D distribution with the density bilinear in its grid values (a table per slice), sampled by
// inverting its marginal CDF in y and its conditional CDF in x (docs/formats.md). The density and
// the conditional CDF of a grid point are side by side (one 8-byte node of two floats: the file's
// float32 value and its running sum, not normalized, so that the tables of a 128 × 128 file take
// 1 MB rather than 2 and stay in a core's L2 cache), and so are the marginal CDF and the total of
// a row: the inverse warp at a point reads one or two cache lines per slice. A slice's
// normalization 1/total is applied to the blend's weights (Blend::scaled).
struct Warp {
  using Node = rgl_kernel::Node;
  using Row = rgl_kernel::Row;
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
  bool build(const std::vector<double>& data, std::size_t slices) {
    node.resize(data.size());
    row.resize(slices * h);
    inv_total.resize(slices);
    std::vector<double> c(w * h), m(h);
    for (std::size_t s = 0; s < slices; ++s) {
      const double* in = data.data() + s * w * h;
      for (std::size_t j = 0; j < h; ++j) {
        c[j * w] = 0;
        for (std::size_t i = 0; i + 1 < w; ++i)
          c[j * w + i + 1] = c[j * w + i] + 0.5 * (in[j * w + i] + in[j * w + i + 1]);
      }
      // The sums as stored (float), and the marginal from the stored row totals: the inverse and
      // forward warps then read one consistent set of values.
      for (std::size_t k = 0; k < w * h; ++k) c[k] = double(float(c[k]));
      m[0] = 0;
      for (std::size_t j = 0; j + 1 < h; ++j)
        m[j + 1] = m[j] + 0.5 * (c[j * w + w - 1] + c[(j + 1) * w + w - 1]);
      const double total = m[h - 1];
      if (!(total > 0) || !std::isfinite(total)) return false;
      for (std::size_t k = 0; k < w * h; ++k) node[s * w * h + k] = {float(in[k]), float(c[k])};
      for (std::size_t j = 0; j < h; ++j) row[s * h + j] = {m[j] / total, c[j * w + w - 1]};
      inv_total[s] = 1 / total;
    }
    build_guides(slices);
    return true;
  }

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

  void build_guides(std::size_t slices) {
    guided = w - 1 <= UINT16_MAX && h - 1 <= UINT16_MAX;
    if (!guided) return;
    row_guide.resize(slices * h);
    col_guide.resize(slices * h * w);
    for (std::size_t s = 0; s < slices; ++s) {
      const Row* r = &row[s * h];
      for (std::size_t k = 0, j = 0; k < h; ++k) {
        j = step_from(j, h - 2, double(k) / double(h), [&](std::size_t q) { return r[q].m; });
        row_guide[s * h + k] = std::uint16_t(j);
      }
      for (std::size_t j = 0; j < h; ++j) {
        const Node* a = &node[(s * h + j) * w];
        for (std::size_t k = 0, i = 0; k < w; ++k) {
          i = step_from(i, w - 2, double(k) / double(w) * r[j].r,
                        [&](std::size_t q) { return a[q].c; });
          col_guide[(s * h + j) * w + k] = std::uint16_t(i);
        }
      }
    }
  }

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

// Warp::density() of m rows at points (x, y) (pdf_block): the cells as cell_of() finds them, in
// vector lanes, then densities_in_cells(). Every row has as many slices (Impl::slices()).
template <int N>
[[gnu::always_inline]] inline void densities_at(const Warp& wp, const Slices* s, const double* x,
                                                const double* y, std::size_t m, double* out) {
  Cells c;
  cells_of(x, y, m, wp.w, wp.h, c);
  std::size_t i[kBlock], j[kBlock];
  for (std::size_t q = 0; q < m; ++q) i[q] = std::size_t(c.i[q]), j[q] = std::size_t(c.j[q]);
  densities_in_cells<N>(
      wp, m, [&](std::size_t q) -> const Slices& { return s[q]; }, i, j, c.tx, c.ty, out);
}
HALFBACK_RGL_CLONES void densities_at(const Warp& wp, const Slices* s, const double* x,
                                      const double* y, std::size_t m, double* out) {
  if (m == 0) return;
  switch (s[0].count) {  // the same for every row (Impl::slices())
    case 1:
      return densities_at<1>(wp, s, x, y, m, out);
    case 2:
      return densities_at<2>(wp, s, x, y, m, out);
    default:
      return densities_at<4>(wp, s, x, y, m, out);
  }
}

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
    return (area > 0) & (den > 0) ? t : 0.0;
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

HALFBACK_RGL_CLONES void draw_columns(const Warp& wp, const Slices* s, const Warp::Drawing* d,
                                      const bool* apart, std::size_t n, Warp::Drawn* out) {
  ColumnDraws(wp, s, d).run(apart, n, out);
}

bool negative_sign(double v) {
  return !std::signbit(v);
}  // mulsign_neg: flip when v >= +0

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

Flips flips_for(int reduction, const Vec3<double>& given) {
  if (reduction < 2) return {};
  const double sy = given.y, sx = reduction == 4 ? given.x : sy;
  return {negative_sign(sx), negative_sign(sy)};
}

}  // namespace

struct RglBrdf::Impl {
  std::string description;
  std::vector<float> theta_i_raw, phi_i_raw;
  IncidenceAxis phi, theta;  // incidence grids; slices are ordered [φi][θi]
  bool isotropic = true;
  bool jacobian = true;
  int reduction = 1;  // anisotropic data covering 2π / reduction of φi, by symmetry
  Table ndf, sigma;   // no incidence dependence
  Warp vndf;
  RgbTable rgb;  // slices [φi][θi]
  std::size_t n_slices = 1;
  std::size_t noise_clamped = 0;  // tiny negative ndf, vndf and luminance values set to 0
  std::size_t rgb_negative = 0;   // negative (out-of-gamut) RGB values
  std::size_t wavelengths = 0;    // the spectral variant: its wavelengths, integrated to RGB

  bool lanes = false;  // the tables' sides fit the block kernel's 32-bit cell indices

  // Impl::value() of the packed rows of a block, over cos θo (eval_block): the block kernel.
  void eval_rows(rgl_kernel::EvalRows& rows, bool clamp_negative) const;

  Slices slices(double phi_i, double theta_i) const {
    Slices s;
    slices(phi_i, theta_i, s);
    return s;
  }
  // The same in place (a block's array: no copy of the struct, whose piecewise stores a copy's
  // wide loads would wait for).
  void slices(double phi_i, double theta_i, Slices& s) const {
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
  Rgb value(const Slices& s, RglWarpPoint um, RglWarpPoint uwi, bool clamp_negative) const {
    return shade(s, vndf.inverse(s, um), um, uwi, clamp_negative);
  }
  // value() from the inverse warp's sample: the RGB tables there, the Jacobian.
  Rgb shade(const Slices& s, RglWarpPoint sample, RglWarpPoint um, RglWarpPoint uwi,
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
  Rgb shade(const Slices& s, RglWarpPoint sample, RglWarpPoint um, RglWarpPoint uwi,
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

namespace {

// The spectral variant's `spectra` [φi, θi, wavelengths, h, w] integrated to RGB tables
// (core/spectrum.hpp: the CIE 1931 observer under the illuminant the writer upsamples with), so
// that spectral files read like RGB ones. docs/formats.md, "Spectra".
Table spectra_as_rgb(const Validator& v, const TensorField& lum, std::size_t n_phi,
                     std::size_t n_theta, std::size_t& n_wavelengths) {
  const TensorField& wl = v.field("wavelengths", TensorDtype::float32, 1);
  v.require_at_least(wl, 0, 2);
  std::vector<double> lambda = v.floats(wl);
  for (std::size_t k = 0; k < lambda.size(); ++k)
    if (!(lambda[k] > 0) || (k > 0 && !(lambda[k] > lambda[k - 1])))
      v.fail("wavelengths", fmt::format("value {} is {:g} nm: wavelengths must be positive and "
                                        "strictly increasing",
                                        k, lambda[k]));
  const TensorField& f = v.field("spectra", TensorDtype::float32, 5);
  v.require_dim(f, 0, n_phi, "number of phi_i values");
  v.require_dim(f, 1, n_theta, "number of theta_i values");
  v.require_dim(f, 2, lambda.size(), "number of wavelengths");
  v.require_dim(f, 3, lum.shape[2], "the luminance grid's resolution");
  v.require_dim(f, 4, lum.shape[3], "the luminance grid's resolution");
  const spectral::SpectrumToRgb to_rgb(lambda);
  const std::vector<double> values = v.floats(f);
  Table t;
  t.h = static_cast<std::size_t>(f.shape[3]);
  t.w = static_cast<std::size_t>(f.shape[4]);
  const std::size_t n = t.h * t.w, nl = lambda.size();
  t.v.assign(n_phi * n_theta * 3 * n, 0.0);
  std::vector<double> spectrum(nl);
  for (std::size_t s = 0; s < n_phi * n_theta; ++s)
    for (std::size_t node = 0; node < n; ++node) {
      for (std::size_t k = 0; k < nl; ++k) spectrum[k] = values[(s * nl + k) * n + node];
      const Rgb c = to_rgb(spectrum);
      t.v[(s * 3 + 0) * n + node] = c.r;
      t.v[(s * 3 + 1) * n + node] = c.g;
      t.v[(s * 3 + 2) * n + node] = c.b;
    }
  n_wavelengths = nl;
  return t;
}

}  // namespace

RglBrdf::RglBrdf(const TensorFile& tf, std::string label, RglOptions options)
    : impl_(std::make_unique<Impl>()), label_(std::move(label)), options_(options) {
  Validator v(tf, tf.name.empty() ? label_ : tf.name);
  Impl& m = *impl_;

  const TensorField& desc = v.field("description", TensorDtype::uint8, 1);
  m.description.assign(reinterpret_cast<const char*>(desc.bytes.data()), desc.bytes.size());
  while (!m.description.empty() && m.description.back() == '\0') m.description.pop_back();

  if (const TensorField* ver = tf.find("version")) {
    if (ver->dtype != TensorDtype::uint32 || ver->shape.size() != 1 || ver->shape[0] != 2)
      v.fail("version", "expected 2 uint32 values");
  }

  auto incidence = [&](std::string_view name, double lo, double hi, std::vector<float>& raw,
                       IncidenceAxis& axis) {
    const TensorField& f = v.field(name, TensorDtype::float32, 1);
    v.require_at_least(f, 0, 1);
    axis.values = v.floats(f);
    raw.assign(axis.values.begin(), axis.values.end());
    for (std::size_t i = 0; i < axis.values.size(); ++i) {
      const double x = axis.values[i];
      if (x < lo || x > hi)
        v.fail(name, fmt::format("value {} is {:g} rad, outside [{:g}, {:g}]", i, x, lo, hi));
      if (i > 0 && !(x > axis.values[i - 1])) v.fail(name, "values are not strictly increasing");
    }
    return axis.values.size();
  };
  const double tol = 1e-5;
  const std::size_t n_theta = incidence("theta_i", -tol, kPi / 2 + tol, m.theta_i_raw, m.theta);
  const std::size_t n_phi = incidence("phi_i", -kPi - tol, kPi + tol, m.phi_i_raw, m.phi);
  m.theta.stride = n_theta > 1 ? 1 : 0;
  m.phi.stride = n_phi > 1 ? n_theta : 0;
  m.n_slices = n_theta * n_phi;
  // As in the reference loader: at most 2 φi values means isotropic data, whose tables are
  // indexed by the azimuth of the half vector relative to ωi. Anisotropic data may cover a fraction
  // 1/reduction of the azimuths, the rest following by symmetry.
  m.isotropic = n_phi <= 2;
  if (!m.isotropic) {
    const double span = m.phi.values.back() - m.phi.values.front();
    m.reduction = static_cast<int>(std::lround(2 * kPi / span));
    if (m.reduction != 1 && m.reduction != 2 && m.reduction != 4)
      v.fail("phi_i", fmt::format("covers {:g} rad: expected 2π, π or π/2 (full, half or quarter "
                                  "symmetry)",
                                  span));
  }

  auto table = [&](std::string_view name, Table& t) -> const TensorField& {
    const TensorField& f = v.field(name, TensorDtype::float32, 2);
    v.require_at_least(f, 0, 2);
    v.require_at_least(f, 1, 2);
    t.h = static_cast<std::size_t>(f.shape[0]);
    t.w = static_cast<std::size_t>(f.shape[1]);
    t.v = v.floats(f);
    return f;
  };
  m.noise_clamped += v.clamp_noise(table("ndf", m.ndf), m.ndf.v);
  v.require_positive(table("sigma", m.sigma), m.sigma.v);  // divides ρ

  {
    const TensorField& f = v.field("vndf", TensorDtype::float32, 4);
    v.require_dim(f, 0, n_phi, "number of phi_i values");
    v.require_dim(f, 1, n_theta, "number of theta_i values");
    v.require_at_least(f, 2, 2);
    v.require_at_least(f, 3, 2);
    m.vndf.h = static_cast<std::size_t>(f.shape[2]);
    m.vndf.w = static_cast<std::size_t>(f.shape[3]);
    std::vector<double> data = v.floats(f);
    m.noise_clamped += v.clamp_noise(f, data);
    if (!m.vndf.build(data, m.n_slices))
      v.fail("vndf", "a slice integrates to zero (or beyond the float range)");
  }

  const TensorField& lum = v.field("luminance", TensorDtype::float32, 4);
  v.require_dim(lum, 0, n_phi, "number of phi_i values");
  v.require_dim(lum, 1, n_theta, "number of theta_i values");
  v.require_at_least(lum, 2, 2);
  v.require_dim(lum, 3, lum.shape[2], "the sample grid is square");
  {
    std::vector<double> luminance = v.floats(lum);  // checked only: the evaluation does not use it
    m.noise_clamped += v.clamp_noise(lum, luminance);
  }

  std::vector<double> planar;  // slices of 3 channels of h·w; may be slightly negative (gamut)
  if (!tf.find("rgb") && tf.find("spectra")) {
    Table t = spectra_as_rgb(v, lum, n_phi, n_theta, m.wavelengths);
    m.rgb.h = t.h;
    m.rgb.w = t.w;
    planar = std::move(t.v);
  } else {
    const TensorField& f = v.field("rgb", TensorDtype::float32, 5);
    v.require_dim(f, 0, n_phi, "number of phi_i values");
    v.require_dim(f, 1, n_theta, "number of theta_i values");
    v.require_dim(f, 2, 3, "red, green, blue");
    v.require_dim(f, 3, lum.shape[2], "the luminance grid's resolution");
    v.require_dim(f, 4, lum.shape[3], "the luminance grid's resolution");
    m.rgb.h = static_cast<std::size_t>(f.shape[3]);
    m.rgb.w = static_cast<std::size_t>(f.shape[4]);
    planar = v.floats(f);  // see RglOptions for the negative values
  }
  m.rgb.assign(planar, m.n_slices);
  m.rgb_negative = static_cast<std::size_t>(
      std::count_if(planar.begin(), planar.end(), [](double x) { return x < 0; }));

  {
    const TensorField& f = v.field("jacobian", TensorDtype::uint8, 1);
    v.require_dim(f, 0, 1, "a single flag");
    const auto flag = static_cast<std::uint8_t>(f.bytes[0]);
    if (flag > 1) v.fail("jacobian", "is " + std::to_string(flag) + ", expected 0 or 1");
    m.jacobian = flag == 1;
  }
  constexpr std::size_t kSide = INT32_MAX;
  m.lanes = std::max({m.vndf.w, m.vndf.h, m.rgb.w, m.rgb.h, m.ndf.w, m.ndf.h, m.sigma.w,
                      m.sigma.h}) < kSide;
}

RglBrdf::~RglBrdf() = default;

std::string RglBrdf::name() const {
  return "rgl:" + label_;
}

std::string RglBrdf::description() const {
  return "RGL measured BRDF: " + impl_->description + " (" + std::to_string(impl_->n_slices) +
         " incidence slices, " + (impl_->isotropic ? "isotropic" : "anisotropic") + ")";
}

std::vector<Brdf::Fact> RglBrdf::facts() const {
  const Impl& m = *impl_;
  std::vector<Fact> f;
  f.push_back({"format", m.wavelengths == 0
                             ? std::string("RGL tensor_file (Dupuy & Jakob 2018), RGB variant")
                             : fmt::format("RGL tensor_file (Dupuy & Jakob 2018), spectral variant "
                                           "({} wavelengths, integrated to RGB)",
                                           m.wavelengths)});
  f.push_back({"material", m.description});
  f.push_back({"incidence grid",
               fmt::format("{} θi × {} φi{}", m.theta_i_raw.size(), m.phi_i_raw.size(),
                           m.reduction > 1 ? fmt::format(" (1/{} of the azimuths, the rest "
                                                         "by symmetry)",
                                                         m.reduction)
                                           : std::string())});
  f.push_back({"spectral slices",
               fmt::format("{} × {} samples per incidence, 3 channels", m.rgb.h, m.rgb.w)});
  f.push_back({"VNDF / NDF tables",
               fmt::format("{} × {} / {} × {}", m.vndf.h, m.vndf.w, m.ndf.h, m.ndf.w)});
  f.push_back({"symmetry", m.isotropic ? "isotropic" : "anisotropic"});
  f.push_back({"negative values",
               fmt::format("{} tiny negative density values (noise) set to 0; {} negative RGB "
                           "values (out of gamut) {}",
                           m.noise_clamped, m.rgb_negative,
                           options_.clamp_negative ? "clamped to 0 in ρ" : "kept in ρ")});
  return f;
}

bool RglBrdf::isotropic() const {
  return impl_->isotropic;
}
const std::string& RglBrdf::material_description() const {
  return impl_->description;
}
std::span<const float> RglBrdf::theta_i() const {
  return impl_->theta_i_raw;
}
std::span<const float> RglBrdf::phi_i() const {
  return impl_->phi_i_raw;
}

RglWarpPoint RglBrdf::vndf_inverse(RglWarpPoint p, double theta_i, double phi_i) const {
  return impl_->vndf.inverse(impl_->slices(phi_i, theta_i), p);
}

RglWarpPoint RglBrdf::vndf_forward(RglWarpPoint u, double theta_i, double phi_i) const {
  return impl_->vndf.forward(impl_->slices(phi_i, theta_i), u);
}

RglWarpPoint RglBrdf::vndf_forward_by_search(RglWarpPoint u, double theta_i, double phi_i) const {
  return impl_->vndf.forward(impl_->slices(phi_i, theta_i), u, false);
}

double RglBrdf::vndf_density(RglWarpPoint p, double theta_i, double phi_i) const {
  return impl_->vndf.density(impl_->slices(phi_i, theta_i), p);
}

namespace {

// dωm = sin θm dθm dφm = 2π² u sin θm du dv, and dω = 4 |ω·m| dωm (reflection about m).
double reflection_jacobian(RglWarpPoint um, double theta_m, double cos_gm) {
  return 2 * kPi * kPi * um.x * std::sin(theta_m) * 4 * std::abs(cos_gm);
}

}  // namespace

BrdfSample RglBrdf::sample(const Vec3<double>& wo, double u1, double u2) const {
  const Impl& m = *impl_;
  if (!(wo.z > 0)) return {};
  const Flips flips = flips_for(m.reduction, wo);
  const Vec3<double> g = flips.apply(wo);
  const double theta_g = std::atan2(std::hypot(g.x, g.y), g.z);
  const double phi_g = std::atan2(g.y, g.x);
  const Slices s = m.slices(phi_g, theta_g);
  const auto [um, pdf_u] = m.vndf.draw(s, {u1, u2});
  const double theta_m = um.x * um.x * (kPi / 2);
  const double phi_m = (2 * um.y - 1) * kPi + (m.isotropic ? phi_g : 0.0);
  const Vec3<double> n{std::sin(theta_m) * std::cos(phi_m), std::sin(theta_m) * std::sin(phi_m),
                       std::cos(theta_m)};
  const double dot = g.x * n.x + g.y * n.y + g.z * n.z;
  const Vec3<double> wi =
      flips.apply({2 * dot * n.x - g.x, 2 * dot * n.y - g.y, 2 * dot * n.z - g.z});
  const double jacobian = reflection_jacobian(um, theta_m, dot);
  return {wi, jacobian > 0 && wi.z > 0 ? pdf_u / jacobian : 0.0};
}

double RglBrdf::pdf(const Vec3<double>& wo, const Vec3<double>& wi) const {
  const Impl& m = *impl_;
  if (!(wo.z > 0) || !(wi.z > 0)) return 0;
  const Flips flips = flips_for(m.reduction, wo);
  const Vec3<double> g = flips.apply(wo), d = flips.apply(wi);
  // The microfacet normal that reflects g into d: their half vector.
  const Vec3<double> h{g.x + d.x, g.y + d.y, g.z + d.z};
  const double len = std::sqrt(h.x * h.x + h.y * h.y + h.z * h.z);
  if (!(len > 0)) return 0;
  const Vec3<double> n{h.x / len, h.y / len, h.z / len};
  const double theta_g = std::atan2(std::hypot(g.x, g.y), g.z);
  const double phi_g = std::atan2(g.y, g.x);
  const double theta_m = std::atan2(std::hypot(n.x, n.y), n.z);
  double v = (std::atan2(n.y, n.x) - (m.isotropic ? phi_g : 0.0) + kPi) / (2 * kPi);
  v -= std::floor(v);
  const RglWarpPoint um{std::sqrt(theta_m / (kPi / 2)), v};
  const double pdf_u = m.vndf.density(m.slices(phi_g, theta_g), um);
  const double jacobian = reflection_jacobian(um, theta_m, g.x * n.x + g.y * n.y + g.z * n.z);
  return jacobian > 0 && std::isfinite(pdf_u) ? pdf_u / jacobian : 0;
}

Rgb RglBrdf::eval_cosine(const DirPair<double>& pair) const {
  const Impl& m = *impl_;
  Vec3<double> wi = pair.wi, wo = pair.wo;
  const double v[6] = {wi.x, wi.y, wi.z, wo.x, wo.y, wo.z};
  for (double x : v)
    if (std::isnan(x)) return {kNaN, kNaN, kNaN};
  if (!(wi.z > 0) || !(wo.z > 0)) return {};
  const Flips flips = flips_for(m.reduction, wi);  // ωi into the range of φi the data covers
  wi = flips.apply(wi);
  wo = flips.apply(wo);
  const double hx = wi.x + wo.x, hy = wi.y + wo.y, hz = wi.z + wo.z;
  const double theta_i = std::atan2(std::hypot(wi.x, wi.y), wi.z);
  const double phi_i = std::atan2(wi.y, wi.x);
  const double theta_m = std::atan2(std::hypot(hx, hy), hz);
  const double phi_m = std::atan2(hy, hx);
  const RglWarpPoint um{theta_to_u(theta_m), azimuth_u(phi_m, phi_i, m.isotropic)};
  const RglWarpPoint uwi{theta_to_u(theta_i), phi_to_u(phi_i)};
  return m.value(m.slices(phi_i, theta_i), um, uwi, options_.clamp_negative);
}

namespace {

// fr from fr·cos θo, for a pair with both directions above the horizon.
Rgb over_cosine(Rgb r, const Vec3<double>& wo) {
  const double inverse_cos_o = std::sqrt(wo.x * wo.x + wo.y * wo.y + wo.z * wo.z) / wo.z;
  r.r *= inverse_cos_o;
  r.g *= inverse_cos_o;
  r.b *= inverse_cos_o;
  return r;
}

// Row k of a block's directions: `given`, the direction whose azimuth indexes the tables, and the
// unit half vector of the pair, both after the flips that bring `given` into the range the data
// covers. True when the row must go through the one-pair path: a direction at or below the
// horizon, `given` or the half vector along the normal (azimuth atan2(±0, ±0)).
template <std::size_t N>
bool put_direction_and_half_vector(int reduction, const Vec3<double>& given,
                                   const Vec3<double>& other, double (&dirs)[6][N], std::size_t k) {
  const Flips flips = flips_for(reduction, given);
  const Vec3<double> g = flips.apply(given), d = flips.apply(other);
  const double hx = g.x + d.x, hy = g.y + d.y, hz = g.z + d.z;
  const double inverse_len = 1 / std::sqrt(hx * hx + hy * hy + hz * hz);
  dirs[0][k] = g.x, dirs[1][k] = g.y, dirs[2][k] = g.z;
  dirs[3][k] = hx * inverse_len, dirs[4][k] = hy * inverse_len, dirs[5][k] = hz * inverse_len;
  return !(g.z > 0) || !(d.z > 0) || (g.x == 0 && g.y == 0) || (hx == 0 && hy == 0);
}

// How close (in units of the unit square) an azimuth coordinate may come to the seam 0 ≡ 1 of the
// tables before the row goes to eval(): there the table value jumps, and the batch's azimuth,
// a few ulps from eval()'s, could fall on the other side.
constexpr double kSeam = 1e-9;

bool near_seam(double u01) {
  return u01 < kSeam || u01 > 1 - kSeam;
}

// An azimuth of [0, 2π) (the batch engine's) in (-π, π] (atan2's).
double signed_azimuth(double phi) {
  return phi > kPi ? phi - 2 * kPi : phi;
}

// The spherical angles (θ, φ) of the two directions of each row (the columns of dirs), φ in
// [0, 2π) as the spherical form gives it, by the batch engine's SIMD conversion; valid[k] = 0
// where the row is not one it accepts (not unit, below the horizon).
void angles_of(double (&dirs)[6][kBlock], std::size_t n, double (&angle)[4][kBlock],
               std::uint8_t* valid) {
  const ConstColumn<double> in[6] = {{dirs[0], 1}, {dirs[1], 1}, {dirs[2], 1},
                                     {dirs[3], 1}, {dirs[4], 1}, {dirs[5], 1}};
  const Column<double> cols[4] = {{angle[0], 1}, {angle[1], 1}, {angle[2], 1}, {angle[3], 1}};
  convert<double>(Form{Space::dirs}, Form{space_of<Spherical>}, in, n,
                  ConvertOutput<double>{cols, {}, valid}, BatchOptions{1});
}

// A block of pairs as eval_block and pdf_block read it: per row, the direction that indexes the
// tables (ωi for eval, ωo for pdf) and the unit half vector (put_direction_and_half_vector), their
// spherical angles (angles_of), and whether the row goes through the one-pair path.
struct PairBlock {
  alignas(64) double dirs[6][kBlock];
  alignas(64) double angle[4][kBlock];
  alignas(64) std::uint8_t valid[kBlock];
  bool apart[kBlock];

  PairBlock(int reduction, std::span<const DirPair<double>> pairs, bool given_is_wi) {
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const DirPair<double>& p = pairs[k];
      apart[k] = given_is_wi ? put_direction_and_half_vector(reduction, p.wi, p.wo, dirs, k)
                             : put_direction_and_half_vector(reduction, p.wo, p.wi, dirs, k);
    }
    angles_of(dirs, pairs.size(), angle, valid);
  }
};

}  // namespace

// The evaluation's block kernel: Impl::value() and over_cosine() of a block's rows, step by step
// across the rows, each step a loop that the compiler vectorizes (the cells, the blends, the
// inverse warp's solve, the shading) or a loop of independent loads into columns (the tables'
// values at the cells, many rows' misses in flight), instead of each row's chain of dependent
// loads, divisions and square roots in turn. Compiled for AVX-512, AVX2 and the baseline, chosen
// at load time by the CPU (GCC's target_clones, as merl_kernel.cpp); rgl.cpp is compiled without
// contraction (src/formats/CMakeLists.txt), so every lane rounds as the one-row path does: the
// values are those of Impl::value() bit for bit.
namespace rgl_kernel {

inline constexpr std::size_t kRows = kBlock;

// The tables eval() reads (RglBrdf::Impl), as plain arrays.
struct EvalTables {
  const Node* node;  // the VNDF warp: slices of vh·vw nodes
  const Row* row;    // slices of vh rows
  const double* inv_total;
  std::size_t vw, vh;
  const double* rgb;  // slices of rh·rw slots of RgbTable::kSlot
  std::size_t rw, rh;
  const double* ndf;
  std::size_t nw, nh;
  const double* sigma;
  std::size_t sw, sh;
  bool jacobian, clamp_negative;
};

// The rows of a block that take the common path, packed: their table coordinates, slices and ωo
// in, fr out.
struct EvalRows {
  std::size_t n = 0;
  alignas(64) double um_x[kRows], um_y[kRows], uwi_x[kRows], uwi_y[kRows];
  alignas(64) double wo[3][kRows];
  alignas(64) std::size_t slice[4][kRows];
  alignas(64) double weight[4][kRows];
  alignas(64) double fr[3][kRows];
};

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
      fr[ch][k] = (clamp & (value < 0.0) ? 0.0 : value) * inverse_cos_o;
    }
  }
  for (std::size_t ch = 0; ch < 3; ++ch)
    for (std::size_t k = 0; k < n; ++k) r.fr[ch][k] = fr[ch][k];
}

template <int N>
[[gnu::always_inline]] inline void eval_rows(const EvalTables& t, EvalRows& r) {
  alignas(64) double sx[kRows], sy[kRows];
  inverse_warp<N>(t, r, sx, sy);
  shade<N>(t, r, sx, sy);
}

// One function per slice count (1, 2 or 4: Impl::slices()).
HALFBACK_RGL_CLONES void eval_rows_1(const EvalTables& t, EvalRows& r) {
  eval_rows<1>(t, r);
}
HALFBACK_RGL_CLONES void eval_rows_2(const EvalTables& t, EvalRows& r) {
  eval_rows<2>(t, r);
}
HALFBACK_RGL_CLONES void eval_rows_4(const EvalTables& t, EvalRows& r) {
  eval_rows<4>(t, r);
}

}  // namespace rgl_kernel

void RglBrdf::Impl::eval_rows(rgl_kernel::EvalRows& rows, bool clamp_negative) const {
  const rgl_kernel::EvalTables t{vndf.node.data(),
                                 vndf.row.data(),
                                 vndf.inv_total.data(),
                                 vndf.w,
                                 vndf.h,
                                 rgb.v.data(),
                                 rgb.w,
                                 rgb.h,
                                 ndf.v.data(),
                                 ndf.w,
                                 ndf.h,
                                 sigma.v.data(),
                                 sigma.w,
                                 sigma.h,
                                 jacobian,
                                 clamp_negative};
  switch ((phi.stride ? 2 : 1) * (theta.stride ? 2 : 1)) {  // Slices::count of every incidence
    case 1:
      return rgl_kernel::eval_rows_1(t, rows);
    case 2:
      return rgl_kernel::eval_rows_2(t, rows);
    default:
      return rgl_kernel::eval_rows_4(t, rows);
  }
}

Rgb RglBrdf::eval(const DirPair<double>& pair) const {
  const Rgb r = eval_cosine(pair);
  if (!(pair.wi.z > 0) || !(pair.wo.z > 0)) return r;  // 0, or NaN for NaN input
  // The reference loader returns fr·cos θo (a sampling-friendly quantity); fr is that over cos θo.
  return over_cosine(r, pair.wo);
}

// One block: the angles of every row by the batch engine's SIMD conversion (ωi and the unit half
// vector as a pair of directions, to spherical coordinates), the table coordinates of every row,
// then the values. Rows that eval() treats apart go through it: NaN, at or below the horizon, not
// unit (the conversion rejects them), ωi or the half vector along the normal (whose azimuth is
// atan2(±0, ±0)), an azimuth within kSeam of a seam.
void RglBrdf::eval_block(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const {
  const Impl& m = *impl_;
  const std::size_t n = pairs.size();
  PairBlock block(m.reduction, pairs, true);
  auto& [dirs, angle, valid, apart] = block;

  // The table coordinates of every row, in a loop without calls that the compiler vectorizes.
  alignas(64) double um_x[kBlock], um_y[kBlock], uwi_x[kBlock], uwi_y[kBlock];
  for (std::size_t k = 0; k < n; ++k) {
    const double phi_i = signed_azimuth(angle[1][k]), phi_m = signed_azimuth(angle[3][k]);
    angle[1][k] = phi_i;
    um_x[k] = theta_to_u(angle[2][k]);
    um_y[k] = azimuth_u(phi_m, phi_i, m.isotropic);
    uwi_x[k] = theta_to_u(angle[0][k]);
    uwi_y[k] = phi_to_u(phi_i);
  }
  // The common rows packed for the block kernel (rgl_kernel), the others through eval().
  rgl_kernel::EvalRows rows;
  std::size_t at[kBlock];  // the rows' places in the block
  for (std::size_t k = 0; k < n; ++k) {
    apart[k] = apart[k] || !valid[k] || near_seam(um_y[k]) || near_seam(uwi_y[k]) || !m.lanes;
    if (apart[k]) continue;
    const std::size_t r = rows.n++;
    at[r] = k;
    Slices s;
    m.slices(angle[1][k], angle[0][k], s);
    for (int c = 0; c < s.count; ++c)
      rows.slice[c][r] = s.index[c], rows.weight[c][r] = s.weight[c];
    rows.um_x[r] = um_x[k], rows.um_y[r] = um_y[k];
    rows.uwi_x[r] = uwi_x[k], rows.uwi_y[r] = uwi_y[k];
    rows.wo[0][r] = pairs[k].wo.x, rows.wo[1][r] = pairs[k].wo.y, rows.wo[2][r] = pairs[k].wo.z;
  }
  m.eval_rows(rows, options_.clamp_negative);
  for (std::size_t r = 0; r < rows.n; ++r)
    out[at[r]] = {rows.fr[0][r], rows.fr[1][r], rows.fr[2][r]};
  for (std::size_t k = 0; k < n; ++k)
    if (apart[k]) out[k] = eval(pairs[k]);
}

void RglBrdf::eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const {
  if (out.size() != pairs.size())
    throw std::invalid_argument("RglBrdf::eval_batch: " + std::to_string(pairs.size()) +
                                " pairs but " + std::to_string(out.size()) + " outputs");
  // Tasks of 16 blocks (tens of microseconds, well above the start-up of a thread).
  const std::size_t n = pairs.size(), blocks = (n + kBlock - 1) / kBlock;
  parallel_for(blocks, 16, [&](std::size_t begin, std::size_t end) {
    for (std::size_t b = begin; b < end; ++b) {
      const std::size_t first = b * kBlock, count = std::min(kBlock, n - first);
      eval_block(pairs.subspan(first, count), out.subspan(first, count));
    }
  });
}

namespace {

// An azimuth near ±π, where the SIMD azimuth and atan2's may fall on either side of the seam (the
// slices' weights jump there for data with several φi).
bool near_pi(double phi) {
  return std::abs(phi) > kPi - 1e-9;
}

}  // namespace

void RglBrdf::sample_batch(std::span<const Vec3<double>> wo, std::span<const double> u1,
                           std::span<const double> u2, std::span<BrdfSample> out) const {
  if (wo.size() != out.size() || u1.size() != out.size() || u2.size() != out.size()) {
    Brdf::sample_batch(wo, u1, u2, out);  // the size check
    return;
  }
  for (std::size_t first = 0; first < out.size(); first += kBlock) {
    const std::size_t n = std::min(kBlock, out.size() - first);
    sample_block(wo.subspan(first, n), u1.subspan(first, n), u2.subspan(first, n),
                 out.subspan(first, n));
  }
}

// One block of sample(): the angles of ωo (flipped into the data's range) by the SIMD conversion,
// the warps, then the normals' directions by the inverse conversion (spherical to directions).
// Rows that sample() treats apart go through it: ωo at or below the horizon or along the normal,
// not accepted by the conversion, an azimuth at the seam.
void RglBrdf::sample_block(std::span<const Vec3<double>> wo, std::span<const double> u1,
                           std::span<const double> u2, std::span<BrdfSample> out) const {
  const Impl& m = *impl_;
  const std::size_t n = wo.size();
  alignas(64) double dirs[6][kBlock];
  alignas(64) double angle[4][kBlock];
  alignas(64) std::uint8_t valid[kBlock];
  bool apart[kBlock];
  Flips flips[kBlock];
  // Two samples per row of the conversions, each way a pair of directions: sample k in half
  // k % 2 of row k / 2 (columns 3 (k % 2) .. +2 of the directions, 2 (k % 2) .. +1 of the
  // angles). A row's second half when n is odd, and the rows of samples that go apart, hold +z,
  // which every conversion accepts.
  const std::size_t rows = (n + 1) / 2;
  for (std::size_t k = 0; k < 2 * rows; ++k) {
    Vec3<double> g{0, 0, 1};
    if (k < n) {
      flips[k] = flips_for(m.reduction, wo[k]);
      const Vec3<double> d = flips[k].apply(wo[k]);
      apart[k] = !(d.z > 0) || (d.x == 0 && d.y == 0);
      if (!apart[k]) g = d;
    }
    dirs[3 * (k % 2)][k / 2] = g.x;
    dirs[3 * (k % 2) + 1][k / 2] = g.y;
    dirs[3 * (k % 2) + 2][k / 2] = g.z;
  }
  angles_of(dirs, rows, angle, valid);
  double theta_g[kBlock], phi_g[kBlock];
  for (std::size_t k = 0; k < n; ++k) {
    theta_g[k] = angle[2 * (k % 2)][k / 2];
    phi_g[k] = signed_azimuth(angle[2 * (k % 2) + 1][k / 2]);
    apart[k] = apart[k] || !valid[k / 2] || near_pi(phi_g[k]);
  }
  double pdf_u[kBlock] = {}, um_x[kBlock] = {};
  // The warp's draws in steps over the block (Warp::draw_row), each prefetching for the next.
  Slices slices[kBlock];
  Warp::Drawing drawing[kBlock];
  for (std::size_t k = 0; k < n; ++k) {
    if (apart[k]) continue;
    m.slices(phi_g[k], theta_g[k], slices[k]);
    m.vndf.draw_row(slices[k], {u1[k], u2[k]}, drawing[k]);
  }
  for (std::size_t k = 0; k < n; ++k)
    if (!apart[k]) m.vndf.prefetch_nodes(drawing[k]);
  Warp::Drawn drawn[kBlock];
  draw_columns(m.vndf, slices, drawing, apart, n, drawn);
  for (std::size_t k = 0; k < 2 * rows; ++k) {
    double theta_m = 0, phi_m = 0;  // any valid angles for the rows apart
    if (k < n && !apart[k]) {
      const auto [um, density] = drawn[k];
      pdf_u[k] = density;
      um_x[k] = um.x;
      // The normal's angles, φm in [0, 2π) as the inverse conversion takes it.
      const double phi = (2 * um.y - 1) * kPi + (m.isotropic ? phi_g[k] : 0.0);
      theta_m = um.x * um.x * (kPi / 2);
      phi_m = phi < 0 ? phi + 2 * kPi : phi >= 2 * kPi ? 0.0 : phi;
    }
    angle[2 * (k % 2)][k / 2] = theta_m;
    angle[2 * (k % 2) + 1][k / 2] = phi_m;
  }
  {
    const ConstColumn<double> in[4] = {{angle[0], 1}, {angle[1], 1}, {angle[2], 1}, {angle[3], 1}};
    const Column<double> cols[6] = {{dirs[0], 1}, {dirs[1], 1}, {dirs[2], 1},
                                    {dirs[3], 1}, {dirs[4], 1}, {dirs[5], 1}};
    convert<double>(Form{space_of<Spherical>}, Form{Space::dirs}, in, rows,
                    ConvertOutput<double>{cols, {}, valid}, BatchOptions{1});
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (apart[k] || !valid[k / 2]) {
      out[k] = sample(wo[k], u1[k], u2[k]);
      continue;
    }
    const Vec3<double> g = flips[k].apply(wo[k]);
    const std::size_t c = 3 * (k % 2), r = k / 2;
    const Vec3<double> nm{dirs[c][r], dirs[c + 1][r], dirs[c + 2][r]};
    const double dot = g.x * nm.x + g.y * nm.y + g.z * nm.z;
    const Vec3<double> wi =
        flips[k].apply({2 * dot * nm.x - g.x, 2 * dot * nm.y - g.y, 2 * dot * nm.z - g.z});
    // sin θm = ‖nm_xy‖; the Jacobian of reflection_jacobian().
    const double jacobian =
        2 * kPi * kPi * um_x[k] * std::sqrt(nm.x * nm.x + nm.y * nm.y) * 4 * std::abs(dot);
    out[k] = {wi, jacobian > 0 && wi.z > 0 ? pdf_u[k] / jacobian : 0.0};
  }
}

void RglBrdf::pdf_batch(std::span<const DirPair<double>> pairs, std::span<double> out) const {
  if (out.size() != pairs.size()) {
    Brdf::pdf_batch(pairs, out);  // the size check
    return;
  }
  for (std::size_t first = 0; first < out.size(); first += kBlock) {
    const std::size_t n = std::min(kBlock, out.size() - first);
    pdf_block(pairs.subspan(first, n), out.subspan(first, n));
  }
}

// One block of pdf(): the angles of ωo and of the half vector (both flipped into the data's
// range) by one SIMD conversion, then the density of the warp. Rows that pdf() treats apart go
// through it: a direction at or below the horizon, ωo or the half vector along the normal, not
// accepted by the conversion, an azimuth at a seam.
void RglBrdf::pdf_block(std::span<const DirPair<double>> pairs, std::span<double> out) const {
  const Impl& m = *impl_;
  const std::size_t n = pairs.size();
  const PairBlock block(m.reduction, pairs, false);
  const auto& [dirs, angle, valid, apart] = block;
  // The rows' points and Jacobians, then their densities in passes (densities_at).
  Slices slices[kBlock];
  std::size_t at[kBlock], rows = 0;
  alignas(64) double um_x[kBlock], um_y[kBlock], jacobian[kBlock], pdf_u[kBlock];
  for (std::size_t k = 0; k < n; ++k) {
    const double phi_g = signed_azimuth(angle[1][k]);
    const double phi_m = signed_azimuth(angle[3][k]);
    const double v = azimuth_u(phi_m, phi_g, m.isotropic);
    if (apart[k] || !valid[k] || near_pi(phi_g) || near_seam(v)) {
      out[k] = pdf(pairs[k].wo, pairs[k].wi);
      continue;
    }
    const std::size_t q = rows++;
    at[q] = k;
    const double theta_m = angle[2][k];
    um_x[q] = std::sqrt(theta_m / (kPi / 2)), um_y[q] = v;
    m.slices(phi_g, angle[0][k], slices[q]);
    const double sin_m = std::sqrt(dirs[3][k] * dirs[3][k] + dirs[4][k] * dirs[4][k]);
    const double cos_gm =
        dirs[0][k] * dirs[3][k] + dirs[1][k] * dirs[4][k] + dirs[2][k] * dirs[5][k];
    jacobian[q] = 2 * kPi * kPi * um_x[q] * sin_m * 4 * std::abs(cos_gm);
  }
  densities_at(m.vndf, slices, um_x, um_y, rows, pdf_u);
  for (std::size_t q = 0; q < rows; ++q)
    out[at[q]] = jacobian[q] > 0 && std::isfinite(pdf_u[q]) ? pdf_u[q] / jacobian[q] : 0;
}

std::shared_ptr<const RglBrdf> load_rgl(const std::filesystem::path& path, RglOptions options) {
  return std::make_shared<const RglBrdf>(read_tensor_file(path), path.stem().string(), options);
}

}  // namespace halfback
