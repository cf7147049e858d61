#include "halfback/acquire/gonio.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "halfback/core/batch.hpp"

namespace halfback::acquire {

std::string_view name_of(Design d) {
  switch (d) {
    case Design::regular:
      return "regular";
    case Design::stratified:
      return "stratified";
    case Design::dupuy_jakob:
      return "dupuy-jakob";
    case Design::nielsen:
      return "nielsen";
    case Design::sequential:
      return "sequential";
  }
  return "?";
}

std::optional<Design> parse_design(std::string_view name) {
  for (Design d : kAllDesigns)
    if (name_of(d) == name) return d;
  return std::nullopt;
}

namespace {

constexpr std::size_t kBlock = 1 << 16;
constexpr int kStratifiedTries = 8;

bool is_azimuth(const GridAxis& a) {
  return a.name.find("phi") != std::string::npos;
}

GridSpec cells_for(const GonioSetup& s, std::size_t n) {
  GridSpec g = default_grid(s.space, s.isotropic ? GridKind::isotropic : GridKind::full, {1});
  for (GridAxis& a : g.axes) a.count = is_azimuth(a) ? 2 * n : n;
  return g;
}

// The cells whose centres, mapped back through the warps, are pairs of directions.
std::size_t cells_inside(const GridSpec& g, const std::vector<AxisWarp>& warps) {
  const std::size_t n = g.points(), dim = g.axes.size();
  std::vector<std::vector<double>> coords(dim, std::vector<double>(std::min(n, kBlock)));
  std::vector<DirPair<double>> pairs(std::min(n, kBlock));
  std::vector<std::uint8_t> ok(pairs.size());
  std::size_t inside = 0;
  for (std::size_t begin = 0; begin < n; begin += kBlock) {
    const std::size_t m = std::min(kBlock, n - begin);
    for (std::size_t a = 0, stride = n; a < dim; ++a) {
      const GridAxis& ax = g.axes[a];
      stride /= ax.count;
      const double step = (ax.hi - ax.lo) / double(ax.count);
      for (std::size_t j = 0; j < m; ++j) {
        const std::size_t i = (begin + j) / stride % ax.count;
        coords[a][j] = warps[a].inverse(ax.lo + (double(i) + 0.5) * step);
      }
    }
    std::vector<std::span<const double>> columns;
    for (const auto& c : coords) columns.emplace_back(c.data(), m);
    coordinates_to_pairs(g.form(), columns, std::span(pairs).first(m), std::span(ok).first(m));
    inside += std::size_t(std::count(ok.begin(), ok.begin() + std::ptrdiff_t(m), 1));
  }
  return inside;
}

const LearnedWarps* learned_of(const GonioSetup& s) {
  return s.learned ? &*s.learned : nullptr;
}

// A reproducible uniform number in [0, 1) for (seed, cell, try, axis): SplitMix64 of a hash.
double uniform(std::uint64_t seed, std::uint64_t cell, std::uint64_t attempt, std::uint64_t axis) {
  std::uint64_t z = seed * 0x9E3779B97F4A7C15ull ^ (cell * 0xBF58476D1CE4E5B9ull) ^
                    (attempt << 56) ^ (axis << 60);
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return double(z >> 11) * 0x1.0p-53;
}

bool finite(const Rgb& c) {
  return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b);
}

}  // namespace

GridSpec gonio_cells(const GonioSetup& s) {
  if (s.space == Space::dirs)
    throw std::invalid_argument("the gonio-reflectometer needs a parameterization, not dirs");
  if (s.budget == 0) throw std::invalid_argument("the gonio-reflectometer needs a budget >= 1");
  if (s.design == Design::dupuy_jakob)
    throw std::invalid_argument(
        "the dupuy-jakob design is export-rgl's acquisition (dupuy_jakob_design.hpp), not a grid");
  if (s.design == Design::sequential)
    throw std::invalid_argument(
        "the sequential design is two grids, a pilot and the main stage (sequential_design.hpp)");
  if (s.design == Design::nielsen)
    throw std::invalid_argument(
        "the nielsen design is a database's principal components (nielsen.hpp), not a grid");
  if (!(s.max_theta_deg > 0 && s.max_theta_deg <= 90))
    throw std::invalid_argument("the gonio-reflectometer's reach must be in (0, 90] degrees");
  // A first guess from the fraction of the box inside the domain, then the nearest n.
  const GridSpec probe = cells_for(s, 8);
  const std::vector<AxisWarp> warps = design_warps(probe, s.spacing, learned_of(s));
  const double fraction = double(cells_inside(probe, warps)) / double(probe.points());
  const double per_n = fraction * double(probe.points()) / std::pow(8.0, double(probe.axes.size()));
  auto n = std::size_t(std::max(
      1.0, std::round(std::pow(double(s.budget) / per_n, 1.0 / double(probe.axes.size())))));
  std::map<std::size_t, std::size_t> counted;  // n -> cells inside: each grid counted once
  auto inside = [&](std::size_t m) {
    const auto [it, fresh] = counted.try_emplace(m, 0);
    if (fresh) it->second = cells_inside(cells_for(s, m), warps);
    return it->second;
  };
  while (n > 1 && inside(n - 1) >= s.budget) --n;
  while (inside(n) < s.budget) ++n;
  if (n > 1) {
    const double lo = double(inside(n - 1)), hi = double(inside(n));
    if (lo > 0 && std::log(double(s.budget) / lo) < std::log(hi / double(s.budget))) --n;
  }
  return cells_for(s, n);
}

namespace {

// Where a cell is measured at a try, in cell units from its lower corner.
std::array<float, 4> measurement_offset(const GonioSetup& s, std::size_t dim, std::size_t cell,
                                        int attempt) {
  std::array<float, 4> offset{0.5f, 0.5f, 0.5f, 0.5f};
  if (s.design == Design::stratified)
    for (std::size_t a = 0; a < dim; ++a)
      offset[a] = std::min(float(uniform(s.seed, cell, std::uint64_t(attempt), a)),
                           std::nextafter(1.0f, 0.0f));
  return offset;
}

// The points of `cells` at a try that the instrument reaches, into `plan`; the others into
// `missed`.
void locate_block(GonioPlan& plan, std::span<const std::size_t> cells, int attempt, double min_z,
                  std::vector<std::size_t>& missed) {
  const GridSpec& g = plan.cells;
  const std::size_t m = cells.size(), dim = g.axes.size();
  std::vector<std::vector<double>> coords(dim, std::vector<double>(m));
  std::vector<std::array<float, 4>> offsets(m);
  for (std::size_t j = 0; j < m; ++j) {
    offsets[j] = measurement_offset(plan.setup, dim, cells[j], attempt);
    for (std::size_t a = 0, stride = g.points(); a < dim; ++a) {
      const GridAxis& ax = g.axes[a];
      stride /= ax.count;
      const std::size_t i = cells[j] / stride % ax.count;
      coords[a][j] = plan.warps[a].inverse(ax.lo + (double(i) + offsets[j][a]) * (ax.hi - ax.lo) /
                                                       double(ax.count));
    }
  }
  std::vector<DirPair<double>> pairs(m);
  std::vector<std::uint8_t> ok(m);
  const std::vector<std::span<const double>> columns(coords.begin(), coords.end());
  coordinates_to_pairs(g.form(), columns, pairs, ok);
  for (std::size_t j = 0; j < m; ++j) {
    if (ok[j] && pairs[j].wi.z >= min_z && pairs[j].wo.z >= min_z)
      plan.points.push_back({cells[j], offsets[j], pairs[j]});
    else
      missed.push_back(cells[j]);
  }
}

}  // namespace

GonioPlan gonio_plan(const GonioSetup& setup) {
  GonioPlan plan{setup, gonio_cells(setup), {}, {}};
  plan.warps = design_warps(plan.cells, setup.spacing, learned_of(setup));
  const std::size_t n = plan.cells.points();
  std::vector<std::size_t> todo(n);
  for (std::size_t c = 0; c < n; ++c) todo[c] = c;
  const int tries = setup.design == Design::regular ? 1 : kStratifiedTries;
  // The instrument's reach (a full reach takes every pair the inverse map accepts).
  const double min_z = setup.max_theta_deg >= 90
                           ? -std::numeric_limits<double>::infinity()
                           : std::cos(setup.max_theta_deg * std::numbers::pi / 180);
  for (int attempt = 0; attempt < tries && !todo.empty(); ++attempt) {
    std::vector<std::size_t> again;
    for (std::size_t b = 0; b < todo.size(); b += kBlock)
      locate_block(plan,
                   std::span<const std::size_t>(todo).subspan(b, std::min(kBlock, todo.size() - b)),
                   attempt, min_z, again);
    todo = std::move(again);
  }
  std::sort(plan.points.begin(), plan.points.end(),
            [](const PlannedPoint& a, const PlannedPoint& b) { return a.cell < b.cell; });
  return plan;
}

namespace {

// The truth at every point of the plan.
std::vector<Rgb> measured_values(const Brdf& truth, const GonioPlan& plan) {
  std::vector<DirPair<double>> pairs(plan.points.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) pairs[k] = plan.points[k].pair;
  std::vector<Rgb> values(pairs.size());
  for (std::size_t b = 0; b < pairs.size(); b += kBlock) {
    const std::size_t m = std::min(kBlock, pairs.size() - b);
    truth.eval_batch(std::span(pairs).subspan(b, m), std::span(values).subspan(b, m));
  }
  return values;
}

}  // namespace

GonioReconstruction::GonioReconstruction(const Brdf& truth, const GonioSetup& setup)
    : truth_name_(truth.name()) {
  GonioPlan plan = gonio_plan(setup);
  const std::vector<Rgb> values = measured_values(truth, plan);
  init(std::move(plan), values);
}

GonioReconstruction::GonioReconstruction(GonioPlan plan, std::span<const Rgb> values,
                                         std::string measured)
    : truth_name_(std::move(measured)) {
  if (values.size() != plan.points.size())
    throw std::invalid_argument(
        fmt::format("gonio-reflectometer: {} values for the {} points of "
                    "the plan",
                    values.size(), plan.points.size()));
  init(std::move(plan), values);
}

void GonioReconstruction::init(GonioPlan plan, std::span<const Rgb> values) {
  setup_ = plan.setup;
  cells_ = std::move(plan.cells);
  warps_ = std::move(plan.warps);
  dim_ = cells_.axes.size();
  for (std::size_t a = dim_, stride = 1; a-- > 0;) {
    periodic_[a] = is_azimuth(cells_.axes[a]);
    stride_[a] = stride;
    stride *= cells_.axes[a].count;
  }
  const std::size_t n = cells_.points();
  offset_.assign(n, {0.5f, 0.5f, 0.5f, 0.5f});
  value_.assign(n, Rgb{});
  std::vector<std::uint8_t> filled(n, 0);
  for (std::size_t k = 0; k < plan.points.size(); ++k) {
    if (!finite(values[k])) continue;  // no data there: the cell is filled by fill_unmeasured()
    const PlannedPoint& p = plan.points[k];
    value_[p.cell] = values[k];
    offset_[p.cell] = p.offset;
    filled[p.cell] = 1;
    ++samples_;
  }
  if (samples_ == 0)
    throw std::runtime_error(
        fmt::format("gonio-reflectometer: {} has no finite value at any of the {} cells of {}",
                    truth_name_, n, name_of(setup_.space)));
  fill_unmeasured(filled);
}

std::optional<std::size_t> GonioReconstruction::neighbour(std::size_t c, std::size_t a,
                                                          int step) const {
  const std::size_t len = cells_.axes[a].count, i = c / stride_[a] % len;
  std::size_t j;
  if (step < 0 ? i > 0 : i + 1 < len)
    j = step < 0 ? i - 1 : i + 1;
  else if (periodic_[a] && len > 2)
    j = step < 0 ? len - 1 : 0;
  else
    return std::nullopt;
  return c - i * stride_[a] + j * stride_[a];
}

namespace {

// The smaller in magnitude of two slopes of the same sign, else 0 (a turn: an extremum or noise).
double minmod(double a, double b) {
  if (a * b <= 0) return 0;
  return a > 0 ? std::min(a, b) : std::max(a, b);
}

}  // namespace

std::optional<Rgb> GonioReconstruction::dilated_value(
    std::size_t c, const std::vector<std::uint8_t>& filled) const {
  // Linear estimates where two filled cells line up, else the filled neighbours' values.
  Rgb linear{}, near{};
  int n_linear = 0, n_near = 0;
  for (std::size_t a = 0; a < dim_; ++a)
    for (int step : {-1, 1}) {
      const auto n1 = neighbour(c, a, step);
      if (!n1 || !filled[*n1]) continue;
      const Rgb& v1 = value_[*n1];
      near += v1;
      ++n_near;
      const auto n2 = neighbour(*n1, a, step);
      if (n2 && filled[*n2] && *n2 != c) {
        const Rgb& v2 = value_[*n2];
        // The slope limited by the next one (minmod), so that values that alternate (noise)
        // are not amplified at each round, while affine ones stay exact; without a third cell
        // in line, no slope.
        const auto n3 = neighbour(*n2, a, step);
        if (n3 && filled[*n3] && *n3 != c && *n3 != *n1) {
          const Rgb slope = v1 - v2, next = v2 - value_[*n3];
          linear +=
              v1 + Rgb{minmod(slope.r, next.r), minmod(slope.g, next.g), minmod(slope.b, next.b)};
          ++n_linear;
        }
      }
    }
  if (n_near == 0) return std::nullopt;
  const Rgb& sum = n_linear ? linear : near;
  const double count = n_linear ? n_linear : n_near;
  return Rgb{std::max(sum.r / count, 0.0), std::max(sum.g / count, 0.0),
             std::max(sum.b / count, 0.0)};
}

// Dilation: each round, every empty cell next to filled ones takes the mean of the linear
// extrapolations from them (v₁ + (v₁ − v₂) along an axis where two filled cells line up, the
// slope limited to minmod(v₁ − v₂, v₂ − v₃) where a third does; the mean of the neighbours v₁
// where none do), at its centre, clamped to >= 0. Linear extrapolation keeps affine functions
// exact up to the domain's edge, where a plain mean would make an O(h) error in every cell the
// edge cuts; the limiter keeps it from amplifying values that alternate (noisy measurements:
// 2 v₁ − v₂ at each round made a fill of up to 4 times the largest measurement).
void GonioReconstruction::fill_unmeasured(std::vector<std::uint8_t>& filled) {
  std::vector<std::size_t> empty;
  for (std::size_t c = 0; c < filled.size(); ++c)
    if (!filled[c]) empty.push_back(c);
  while (!empty.empty()) {
    std::vector<std::pair<std::size_t, Rgb>> round;
    std::vector<std::size_t> still;
    for (std::size_t c : empty) {
      if (const std::optional<Rgb> v = dilated_value(c, filled))
        round.push_back({c, *v});
      else
        still.push_back(c);
    }
    if (round.empty()) break;  // cannot happen: the cells are connected and one is measured
    for (const auto& [c, v] : round) {
      value_[c] = v;
      filled[c] = 1;
    }
    empty = std::move(still);
  }
}

std::string GonioReconstruction::name() const {
  return fmt::format("gonio:{}/{}/{}/{}:{}", name_of(setup_.space), name_of(setup_.spacing),
                     name_of(setup_.design), samples_, truth_name_);
}

std::string GonioReconstruction::description() const {
  std::string counts;
  for (const GridAxis& a : cells_.axes)
    counts += fmt::format("{}{} {}", counts.empty() ? "" : " x ", a.count, a.name);
  return fmt::format(
      "{} measured at {} points of a {} layout spaced {} in the {} {} form ({} cells), "
      "reconstructed by {}",
      truth_name_, samples_, name_of(setup_.design), name_of(setup_.spacing),
      setup_.isotropic ? "isotropic" : "full", name_of(setup_.space), counts,
      setup_.design == Design::regular ? "multilinear interpolation" : "local affine fits");
}

// Beyond the outermost centres of a non-periodic axis (t < 0 or t > 1), the multilinear value
// extrapolates each line of cells along it from its edge cell e and the next one in, i: there,
// the inner corner becomes e − minmod(e − i, i − j), j the cell after i, so that the slope is
// limited by the next one as in the dilation (affine values stay exact; alternating ones are not
// extrapolated past the edge cell: 3 × 1.5 half cells made up to twice the largest value).
void GonioReconstruction::limit_edge_slopes(const double* t, const std::size_t* cell,
                                            Rgb* corner) const {
  for (std::size_t a = 0; a < dim_; ++a) {
    if (periodic_[a] || cells_.axes[a].count < 3 || (t[a] >= 0 && t[a] <= 1)) continue;
    const bool low = t[a] < 0;  // the edge is the lower corner (index 0), else the upper
    const unsigned bit = 1u << a;
    for (unsigned k = 0; k < (1u << dim_); ++k) {
      if (bool(k & bit) != !low) continue;  // k: an edge corner
      const unsigned inner = k ^ bit;
      const std::size_t beyond = low ? cell[inner] + stride_[a] : cell[inner] - stride_[a];  // j
      const Rgb slope = corner[k] - corner[inner], next = corner[inner] - value_[beyond];
      corner[inner] = corner[k] - Rgb{minmod(slope.r, next.r), minmod(slope.g, next.g),
                                      minmod(slope.b, next.b)};
    }
  }
}

Rgb GonioReconstruction::reconstruct(const double* x) const {
  // Cell coordinates of x and the lower corner of the 2^d cells whose centres bracket it.
  double xn[4], t[4];
  long lower[4];
  for (std::size_t a = 0; a < dim_; ++a) {
    const GridAxis& ax = cells_.axes[a];
    const auto len = double(ax.count);
    double xa = x[a];
    if (periodic_[a]) {  // into [lo, hi) before the warp, which clamps
      xa = std::fmod(xa - ax.lo, ax.hi - ax.lo);
      xa += ax.lo + (xa < 0 ? ax.hi - ax.lo : 0.0);
    }
    xa = warps_[a].forward(xa);
    double u = (xa - ax.lo) / (ax.hi - ax.lo) * len;
    if (periodic_[a]) {
      u = std::fmod(u, len);
      if (u < 0) u += len;
      const double c = u - 0.5, f = std::floor(c);
      lower[a] = long(f);
      t[a] = c - f;
    } else {
      // Between the box's edge and the outermost centres, t < 0 or t > 1: linear extrapolation
      // from the two outermost cells (a clamp would make an O(h) error in those half cells).
      const double c = u - 0.5;
      const double f = ax.count > 1 ? std::clamp(std::floor(c), 0.0, len - 2) : 0.0;
      lower[a] = long(f);
      t[a] = ax.count > 1 ? c - f : 0.0;
    }
    xn[a] = u;
  }
  const unsigned corners = 1u << dim_;
  std::size_t cell[16];
  for (unsigned k = 0; k < corners; ++k) {
    std::size_t flat = 0;
    for (std::size_t a = 0; a < dim_; ++a) {
      long i = lower[a] + long((k >> a) & 1u);
      const auto len = long(cells_.axes[a].count);
      if (periodic_[a]) i = (i % len + len) % len;
      flat += std::size_t(std::min(i, len - 1)) * stride_[a];
    }
    cell[k] = flat;
  }
  Rgb corner[16];
  for (unsigned k = 0; k < corners; ++k) corner[k] = value_[cell[k]];
  auto multilinear = [&] {
    Rgb v{};
    for (unsigned k = 0; k < corners; ++k) {
      double w = 1;
      for (std::size_t a = 0; a < dim_; ++a) w *= (k >> a) & 1u ? t[a] : 1 - t[a];
      v += w * corner[k];
    }
    return v;
  };
  if (setup_.design == Design::regular) {
    limit_edge_slopes(t, cell, corner);
    const Rgb v = multilinear();  // may extrapolate below 0 near the box's edge
    return {std::max(v.r, 0.0), std::max(v.g, 0.0), std::max(v.b, 0.0)};
  }

  // Affine least squares in cell units about x: the constant term is the value at x. M = d + 1
  // unknowns, a fixed size (d is 3 or 4) so that the small system needs no dynamic sizes.
  auto affine_fit = [&]<int M>() -> std::optional<Eigen::Matrix<double, M, 3>> {
    Eigen::Matrix<double, M, M> normal = Eigen::Matrix<double, M, M>::Zero();
    Eigen::Matrix<double, M, 3> rhs = Eigen::Matrix<double, M, 3>::Zero();
    Eigen::Matrix<double, M, 1> row;
    for (unsigned k = 0; k < corners; ++k) {
      row(0) = 1;
      for (std::size_t a = 0; a < dim_; ++a)
        row(Eigen::Index(a + 1)) =
            double(lower[a] + long((k >> a) & 1u)) + offset_[cell[k]][a] - xn[a];
      normal.noalias() += row * row.transpose();
      const Rgb& v = value_[cell[k]];
      rhs.col(0) += row * v.r;
      rhs.col(1) += row * v.g;
      rhs.col(2) += row * v.b;
    }
    const Eigen::LDLT<Eigen::Matrix<double, M, M>> ldlt(normal);
    if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-9)) return std::nullopt;
    return Eigen::Matrix<double, M, 3>(ldlt.solve(rhs));
  };
  double c[3];
  if (dim_ == 3) {
    const auto fit = affine_fit.template operator()<4>();
    if (!fit) return multilinear();
    for (int ch = 0; ch < 3; ++ch) c[ch] = (*fit)(0, ch);
  } else {
    const auto fit = affine_fit.template operator()<5>();
    if (!fit) return multilinear();
    for (int ch = 0; ch < 3; ++ch) c[ch] = (*fit)(0, ch);
  }
  // Limited to the range of the measurements used: an affine fit through a narrow peak would
  // otherwise overshoot (and undershoot below 0) around it.
  Rgb lo = value_[cell[0]], hi = lo;
  for (unsigned k = 1; k < corners; ++k) {
    const Rgb& v = value_[cell[k]];
    lo = {std::min(lo.r, v.r), std::min(lo.g, v.g), std::min(lo.b, v.b)};
    hi = {std::max(hi.r, v.r), std::max(hi.g, v.g), std::max(hi.b, v.b)};
  }
  return Rgb{std::clamp(c[0], lo.r, hi.r), std::clamp(c[1], lo.g, hi.g),
             std::clamp(c[2], lo.b, hi.b)};
}

Rgb GonioReconstruction::outside(const DirPair<double>& p) {
  // Below the horizon: 0, as the models; not a pair of directions: NaN.
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const bool number = std::isfinite(p.wi.x + p.wi.y + p.wi.z + p.wo.x + p.wo.y + p.wo.z);
  return number ? Rgb{} : Rgb{kNaN, kNaN, kNaN};
}

Rgb GonioReconstruction::eval(const DirPair<double>& pair) const {
  // One pair (the renderer's calls): the core's single-row path, no scratch buffers.
  static_assert(sizeof(DirPair<double>) == 6 * sizeof(double));
  double x[4];
  if (!convert_one<double>(Form{Space::dirs, false}, cells_.form(),
                           std::span<const double>(&pair.wi.x, 6), std::span<double>(x, dim_)))
    return outside(pair);
  return reconstruct(x);
}

void GonioReconstruction::eval_batch(std::span<const DirPair<double>> pairs,
                                     std::span<Rgb> out) const {
  if (out.size() != pairs.size())
    throw std::invalid_argument("GonioReconstruction::eval: output size does not match");
  const Form form = cells_.form();
  constexpr std::size_t kChunk = 1024;
  const std::size_t chunk = std::min(kChunk, pairs.size());
  std::vector<double> coords(dim_ * chunk);
  std::vector<std::uint8_t> ok(chunk);
  std::vector<Column<double>> cols(dim_);
  for (std::size_t c = 0; c < dim_; ++c) cols[c] = {coords.data() + c * chunk, 1};
  ConvertOutput<double> conv;
  conv.columns = cols;
  conv.valid = ok.data();
  std::vector<ConstColumn<double>> in(6);
  for (std::size_t b = 0; b < pairs.size(); b += chunk) {
    const std::size_t m = std::min(chunk, pairs.size() - b);
    const double* base = &pairs[b].wi.x;
    for (std::size_t c = 0; c < 6; ++c) in[c] = {base + c, 6};
    convert<double>(Form{Space::dirs, false}, form, in, m, conv, BatchOptions{1});
    for (std::size_t j = 0; j < m; ++j) {
      if (!ok[j]) {
        out[b + j] = outside(pairs[b + j]);
        continue;
      }
      double x[4];
      for (std::size_t c = 0; c < dim_; ++c) x[c] = coords[c * chunk + j];
      out[b + j] = reconstruct(x);
    }
  }
}

std::vector<DirPair<double>> test_pair_directions(std::size_t count, std::uint64_t seed,
                                                  double max_theta_deg) {
  if (!(max_theta_deg > 0 && max_theta_deg <= 90))
    throw std::invalid_argument("test pairs: the largest angle must be in (0, 90] degrees");
  // Independent cosine-weighted directions have the density cos θi cos θo / π² on pairs; with
  // z = √(1 − u), u uniform in [0, sin² θmax) keeps θ <= θmax.
  const double s = std::sin(max_theta_deg * std::numbers::pi / 180), u_max = s * s;
  auto cosine = [&](std::uint64_t i, std::uint64_t which) {
    const double u = uniform(seed, i, which, 0) * u_max, v = uniform(seed, i, which, 1);
    const double r = std::sqrt(u), phi = 2 * std::numbers::pi * v;
    return Vec3<double>{r * std::cos(phi), r * std::sin(phi), std::sqrt(1 - u)};
  };
  std::vector<DirPair<double>> all(count);
  for (std::size_t i = 0; i < count; ++i) all[i] = {cosine(i, 0), cosine(i, 1)};
  return all;
}

TestPairs draw_test_pairs(const Brdf& truth, std::size_t count, std::uint64_t seed, ErrorSpace es,
                          double max_theta_deg) {
  const std::vector<DirPair<double>> all = test_pair_directions(count, seed, max_theta_deg);
  std::vector<Rgb> rho(count);
  truth.eval_batch(all, rho);
  TestPairs t;
  t.space = es;
  for (std::size_t i = 0; i < count; ++i) {
    const double y = rho[i].luminance();
    if (!std::isfinite(y)) continue;
    t.pairs.push_back(all[i]);
    t.truth.push_back(to_error_space(y, es, all[i].wi.z, all[i].wo.z));
  }
  return t;
}

double reconstruction_error(const Brdf& reconstruction, const TestPairs& test) {
  std::vector<Rgb> rho(test.pairs.size());
  reconstruction.eval_batch(test.pairs, rho);
  double err = 0, norm = 0;
  for (std::size_t i = 0; i < rho.size(); ++i) {
    const double y =
        to_error_space(rho[i].luminance(), test.space, test.pairs[i].wi.z, test.pairs[i].wo.z);
    if (!std::isfinite(y))
      throw std::runtime_error(reconstruction.name() + ": a reconstructed value is not finite");
    err += (y - test.truth[i]) * (y - test.truth[i]);
    norm += test.truth[i] * test.truth[i];
  }
  return norm > 0 ? std::sqrt(err / norm) : (err > 0 ? 1.0 : 0.0);
}

double samples_to_reach(std::span<const double> samples, std::span<const double> errors,
                        double target) {
  if (samples.size() != errors.size() || samples.empty())
    throw std::invalid_argument("samples_to_reach: one error per budget, at least one");
  if (errors[0] <= target) return 0;
  for (std::size_t i = 1; i < samples.size(); ++i) {
    if (errors[i] > target) continue;
    const double x0 = std::log(samples[i - 1]), x1 = std::log(samples[i]);
    const double y0 = std::log(errors[i - 1]), y1 = std::log(errors[i]);
    const double y = std::log(target);
    return std::exp(y0 == y1 ? x1 : x0 + (y - y0) * (x1 - x0) / (y1 - y0));
  }
  return std::numeric_limits<double>::infinity();
}

}  // namespace halfback::acquire
