#include "halfback/brdf/resample.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "halfback/core/batch.hpp"
#include "halfback/core/parallel.hpp"

namespace halfback {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The axes of a kind (the parameterization's descriptor): those of the form, without the relative
// azimuth for a slice.
std::vector<Axis> grid_axes(Space space, GridKind kind) {
  const auto axes = space.param().axes(kind != GridKind::full);
  std::vector<Axis> v(axes.begin(), axes.end());
  if (kind == GridKind::slice) v.pop_back();  // the isotropic forms end with their azimuth
  return v;
}

}  // namespace

double wrap_azimuth_degrees(double degrees, std::string_view what) {
  if (!std::isfinite(degrees))
    throw std::invalid_argument(
        fmt::format("{}: '{}' is not a finite azimuth in degrees", what, degrees));
  double wrapped = std::fmod(degrees, 360.0);  // exact, in (−360, 360)
  if (wrapped < 0) wrapped += 360;
  return wrapped < 360 ? wrapped : 0.0;  // −1e-20 + 360 rounds to 360
}

double wrap_azimuth_radians(double radians) {
  if (!std::isfinite(radians)) return radians;  // validate() reports it
  double wrapped = std::fmod(radians, 2 * kPi);
  if (wrapped < 0) wrapped += 2 * kPi;
  return wrapped < 2 * kPi ? wrapped : 0.0;
}

std::string_view name_of(GridKind kind) {
  switch (kind) {
    case GridKind::full:
      return "full";
    case GridKind::isotropic:
      return "isotropic";
    case GridKind::slice:
      break;
  }
  return "slice";
}

std::string_view name_of(GridSampling sampling) {
  return sampling == GridSampling::centres ? "centres" : "nodes";
}

double GridAxis::position(std::size_t i, GridSampling sampling) const {
  if (sampling == GridSampling::centres) return lo + (double(i) + 0.5) * (hi - lo) / double(count);
  if (count == 1) return lo;
  // The last node is exactly hi (no rounding past the end of the range).
  return i + 1 == count ? hi : lo + double(i) * (hi - lo) / double(count - 1);
}

std::array<double, 4> GridSpec::point(std::size_t flat) const {
  std::array<double, 4> x{};
  for (std::size_t a = axes.size(); a-- > 0;) {
    x[a] = axes[a].position(flat % axes[a].count, sampling);
    flat /= axes[a].count;
  }
  if (kind == GridKind::slice) x[axes.size()] = wrap_azimuth_radians(slice_azimuth);
  return x;
}

GridAxis& GridSpec::axis(std::string_view name) {
  std::string names;
  for (GridAxis& a : axes) {
    if (a.name == name) return a;
    names += (names.empty() ? "" : ", ") + a.name;
  }
  throw std::invalid_argument(
      fmt::format("this grid has no axis '{}' (its axes: {})", name, names));
}

std::size_t GridSpec::points() const {
  std::size_t n = 1;
  for (const GridAxis& a : axes) n *= a.count;
  return n;
}

GridSpec default_grid(Space space, GridKind kind, std::vector<std::size_t> counts,
                      double slice_azimuth) {
  if (space == Space::dirs)
    throw std::invalid_argument("a grid needs a parameterization (" + parameterization_names() +
                                "), not dirs");
  const std::vector<Axis> axes = grid_axes(space, kind);
  if (counts.size() == 1) counts.assign(axes.size(), counts.front());
  if (counts.size() != axes.size())
    throw std::invalid_argument(fmt::format("a {} grid of {} has {} axes, got {} sample counts",
                                            name_of(kind), name_of(space), axes.size(),
                                            counts.size()));
  GridSpec g;
  g.space = space;
  g.kind = kind;
  g.slice_azimuth = wrap_azimuth_radians(slice_azimuth);
  for (std::size_t i = 0; i < axes.size(); ++i)
    g.axes.push_back({std::string(axes[i].column), axes[i].lo, axes[i].hi, counts[i]});
  validate(g);
  return g;
}

void validate(const GridSpec& g) {
  if (g.space == Space::dirs) throw std::invalid_argument("a grid needs a parameterization");
  const std::vector<Axis> axes = grid_axes(g.space, g.kind);
  std::vector<std::string_view> names;
  for (const Axis& a : axes) names.push_back(a.column);
  if (g.axes.size() != names.size())
    throw std::invalid_argument(fmt::format("a {} grid of {} has {} axes, not {}", name_of(g.kind),
                                            name_of(g.space), names.size(), g.axes.size()));
  if (g.kind == GridKind::slice && !std::isfinite(g.slice_azimuth))
    throw std::invalid_argument("the slice azimuth must be a finite number");
  double points = 1;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const GridAxis& a = g.axes[i];
    if (a.name != names[i])
      throw std::invalid_argument(fmt::format("axis {} of a {} {} grid is {}, not '{}'", i,
                                              name_of(g.kind), name_of(g.space), names[i], a.name));
    if (a.count == 0) throw std::invalid_argument(fmt::format("axis {}: no samples", a.name));
    if (!std::isfinite(a.lo) || !std::isfinite(a.hi) || !(a.lo <= a.hi))
      throw std::invalid_argument(fmt::format(
          "axis {}: the range [{}, {}] must be finite with lo <= hi", a.name, a.lo, a.hi));
    if (a.lo == a.hi && a.count != 1)
      throw std::invalid_argument(
          fmt::format("axis {}: an empty range [{}, {}] takes one sample", a.name, a.lo, a.hi));
    points *= double(a.count);
  }
  if (points > double(kMaxGridPoints))
    throw std::invalid_argument(fmt::format(
        "the grid has {:.3g} points, more than the maximum of 2^26 = {} (25 bytes a point in "
        "memory, 1.7 GB at the maximum)",
        points, kMaxGridPoints));
}

std::size_t ResampledTable::valid_count() const {
  return std::size_t(std::count(valid.begin(), valid.end(), std::uint8_t{1}));
}

void grid_pairs(const GridSpec& grid, std::size_t begin, std::span<DirPair<double>> pairs,
                std::span<std::uint8_t> valid, std::span<double> jacobian) {
  const std::size_t m = pairs.size();
  if (valid.size() != m || (!jacobian.empty() && jacobian.size() != m) || begin + m > grid.points())
    throw std::invalid_argument("grid_pairs: output sizes do not match the points asked for");
  const Form form = grid.form();
  const std::size_t dim = dimension(form);
  std::vector<std::vector<double>> coords(dim, std::vector<double>(m));
  for (std::size_t j = 0; j < m; ++j) {
    const std::array<double, 4> x = grid.point(begin + j);
    for (std::size_t c = 0; c < dim; ++c) coords[c][j] = x[c];
  }
  std::vector<std::span<const double>> columns(coords.begin(), coords.end());
  coordinates_to_pairs(form, columns, pairs, valid, jacobian);
}

void coordinates_to_pairs(Form form, std::span<const std::span<const double>> columns,
                          std::span<DirPair<double>> pairs, std::span<std::uint8_t> valid,
                          std::span<double> jacobian) {
  const std::size_t m = pairs.size();
  if (columns.size() != dimension(form) || valid.size() != m ||
      (!jacobian.empty() && jacobian.size() != m))
    throw std::invalid_argument("coordinates_to_pairs: column count or sizes do not match");
  std::vector<ConstColumn<double>> in;
  for (std::span<const double> c : columns) {
    if (c.size() != m) throw std::invalid_argument("coordinates_to_pairs: columns differ in size");
    in.push_back({c.data(), 1});
  }
  // The engine writes straight into the pairs: a DirPair<double> is 6 contiguous doubles.
  static_assert(sizeof(DirPair<double>) == 6 * sizeof(double));
  double* base = &pairs.data()->wi.x;
  std::vector<Column<double>> out(6);
  for (std::size_t c = 0; c < 6; ++c) out[c] = {base + c, 6};
  ConvertOutput<double> conv;
  conv.columns = out;
  conv.valid = valid.data();
  if (!jacobian.empty()) conv.jacobian = {jacobian.data(), 1};
  convert<double>(form, Form{Space::dirs, false}, in, m, conv, BatchOptions{1});
}

ResampledTable resample(const Brdf& brdf, const GridSpec& grid, const ResampleOptions& options) {
  validate(grid);
  ResampledTable t;
  t.grid = grid;
  t.brdf_name = brdf.name();
  t.brdf_description = brdf.description();
  const std::size_t n = grid.points();
  t.rgb.assign(3 * n, kNaN);
  t.valid.assign(n, 0);

  // Blocks of points: coordinates -> pairs (the core's checked batch inverse) -> ρ.
  constexpr std::size_t kBlock = 4096;
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  const auto run_blocks = [&](std::size_t b0, std::size_t b1) {
    std::vector<DirPair<double>> pairs(kBlock);
    std::vector<std::uint8_t> ok(kBlock);
    for (std::size_t b = b0; b < b1; ++b) {
      const std::size_t begin = b * kBlock, m = std::min(kBlock, n - begin);
      grid_pairs(grid, begin, std::span(pairs).first(m), std::span(ok).first(m));
      for (std::size_t j = 0; j < m; ++j) {
        if (!ok[j]) continue;
        const Rgb rho = brdf.eval(pairs[j]);
        const std::size_t p = begin + j;
        t.valid[p] = 1;
        t.rgb[3 * p] = rho.r;
        t.rgb[3 * p + 1] = rho.g;
        t.rgb[3 * p + 2] = rho.b;
      }
    }
  };
  parallel_for(blocks, 1, run_blocks, options.threads);
  return t;
}

}  // namespace halfback
