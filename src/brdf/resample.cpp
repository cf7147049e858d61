#include "halfback/brdf/resample.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "halfback/core/batch.hpp"
#include "parallel_for.hpp"

namespace halfback {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Whether a column name is an azimuth ([0, 2π)), a polar angle ([0, π/2]) or a length ([0, 1]).
std::pair<double, double> natural_range(std::string_view column) {
  if (column.starts_with("phi") || column == "dphi") return {0, 2 * kPi};
  if (column.starts_with("theta")) return {0, kPi / 2};
  return {0, 1};
}

// The axes of a kind: the columns of the form, without the relative azimuth for a slice.
std::vector<std::string_view> axis_names(Space space, GridKind kind) {
  const auto cols = column_names({space, kind != GridKind::full});
  std::vector<std::string_view> names(cols.begin(), cols.end());
  if (kind == GridKind::slice) names.pop_back();  // the isotropic forms end with their azimuth
  return names;
}

}  // namespace

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

std::size_t GridSpec::points() const {
  std::size_t n = 1;
  for (const GridAxis& a : axes) n *= a.count;
  return n;
}

GridSpec default_grid(Space space, GridKind kind, std::vector<std::size_t> counts,
                      double slice_azimuth) {
  if (space == Space::dirs)
    throw std::invalid_argument(
        "a grid needs a parameterization (spherical, halfdiff, ortho or "
        "hybrid), not dirs");
  const auto names = axis_names(space, kind);
  if (counts.size() == 1) counts.assign(names.size(), counts.front());
  if (counts.size() != names.size())
    throw std::invalid_argument(fmt::format("a {} grid of {} has {} axes, got {} sample counts",
                                            name_of(kind), name_of(space), names.size(),
                                            counts.size()));
  GridSpec g;
  g.space = space;
  g.kind = kind;
  g.slice_azimuth = slice_azimuth;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto [lo, hi] = natural_range(names[i]);
    g.axes.push_back({std::string(names[i]), lo, hi, counts[i]});
  }
  validate(g);
  return g;
}

void validate(const GridSpec& g) {
  if (g.space == Space::dirs) throw std::invalid_argument("a grid needs a parameterization");
  const auto names = axis_names(g.space, g.kind);
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
  if (points > double(std::size_t{1} << 31))
    throw std::invalid_argument(
        fmt::format("the grid has {:.3g} points, more than the 2^31 this tool tabulates", points));
}

std::size_t ResampledTable::valid_count() const {
  return std::size_t(std::count(valid.begin(), valid.end(), std::uint8_t{1}));
}

ResampledTable resample(const Brdf& brdf, const GridSpec& grid, const ResampleOptions& options) {
  validate(grid);
  ResampledTable t;
  t.grid = grid;
  t.brdf_name = brdf.name();
  t.brdf_description = brdf.description();
  const std::size_t n = grid.points(), k = grid.axes.size();
  t.rgb.assign(3 * n, kNaN);
  t.valid.assign(n, 0);

  // Sample positions per axis, computed once.
  std::vector<std::vector<double>> pos(k);
  for (std::size_t a = 0; a < k; ++a) {
    pos[a].resize(grid.axes[a].count);
    for (std::size_t i = 0; i < grid.axes[a].count; ++i)
      pos[a][i] = grid.axes[a].position(i, grid.sampling);
  }
  const Form form = grid.form();
  const std::size_t dim = dimension(form);

  // Blocks of points: coordinates -> pairs (the core's checked batch inverse) -> ρ.
  constexpr std::size_t kBlock = 4096;
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  const unsigned threads = options.threads;
  detail::parallel_for(blocks, threads == 1 ? blocks + 1 : 1, [&](std::size_t b0, std::size_t b1) {
    std::vector<std::vector<double>> coords(dim, std::vector<double>(kBlock));
    std::vector<std::vector<double>> dirs(6, std::vector<double>(kBlock));
    std::vector<std::uint8_t> ok(kBlock);
    std::vector<DirPair<double>> pairs;
    std::vector<Rgb> rho;
    std::vector<std::size_t> index;
    for (std::size_t b = b0; b < b1; ++b) {
      const std::size_t begin = b * kBlock, m = std::min(kBlock, n - begin);
      for (std::size_t j = 0; j < m; ++j) {
        std::size_t flat = begin + j;
        std::array<double, 4> x{};
        for (std::size_t a = k; a-- > 0;) {
          x[a] = pos[a][flat % grid.axes[a].count];
          flat /= grid.axes[a].count;
        }
        for (std::size_t c = 0; c < k; ++c) coords[c][j] = x[c];
        if (grid.kind == GridKind::slice) coords[2][j] = grid.slice_azimuth;
      }
      std::vector<ConstColumn<double>> in(dim);
      for (std::size_t c = 0; c < dim; ++c) in[c] = {coords[c].data(), 1};
      std::vector<Column<double>> out(6);
      for (std::size_t c = 0; c < 6; ++c) out[c] = {dirs[c].data(), 1};
      ConvertOutput<double> conv;
      conv.columns = out;
      conv.valid = ok.data();
      convert<double>(form, Form{Space::dirs, false}, in, m, conv, BatchOptions{1});
      pairs.clear();
      index.clear();
      for (std::size_t j = 0; j < m; ++j) {
        if (!ok[j]) continue;
        pairs.push_back(
            {{dirs[0][j], dirs[1][j], dirs[2][j]}, {dirs[3][j], dirs[4][j], dirs[5][j]}});
        index.push_back(begin + j);
      }
      rho.resize(pairs.size());
      for (std::size_t j = 0; j < pairs.size(); ++j) rho[j] = brdf.eval(pairs[j]);
      for (std::size_t j = 0; j < pairs.size(); ++j) {
        const std::size_t p = index[j];
        t.valid[p] = 1;
        t.rgb[3 * p] = rho[j].r;
        t.rgb[3 * p + 1] = rho[j].g;
        t.rgb[3 * p + 2] = rho[j].b;
      }
    }
  });
  return t;
}

}  // namespace halfback
