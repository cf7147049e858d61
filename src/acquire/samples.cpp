#include "halfback/acquire/samples.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "halfback/brdf/resample.hpp"

namespace halfback::acquire {

std::string_view name_of(ErrorSpace s) {
  switch (s) {
    case ErrorSpace::linear:
      return "linear";
    case ErrorSpace::log:
      return "log";
    case ErrorSpace::cbrt:
      return "cbrt";
    case ErrorSpace::nielsen:
      return "nielsen";
    case ErrorSpace::low:
      break;
  }
  return "low";
}

std::optional<ErrorSpace> parse_error_space(std::string_view name) {
  for (ErrorSpace s : kErrorSpaces)
    if (name_of(s) == name) return s;
  return std::nullopt;
}

double IsoSamples::total_weight() const {
  return std::accumulate(weight.begin(), weight.end(), 0.0);
}

double to_error_space(double y, ErrorSpace es, double cos_i, double cos_o) {
  // Nielsen et al.'s constants (their code release): ε and the smallest cosine product.
  constexpr double kNielsenEpsilon = 0.001, kNielsenMinCosines = 0.01;
  switch (es) {
    case ErrorSpace::linear:
      return y;
    case ErrorSpace::log:
      return std::log1p(std::max(y, 0.0));
    case ErrorSpace::cbrt:
      return std::cbrt(y);
    case ErrorSpace::nielsen: {
      const double c = std::clamp(cos_i * cos_o, kNielsenMinCosines, 1.0);
      return std::log1p(std::max(y, 0.0) * c / kNielsenEpsilon);
    }
    case ErrorSpace::low:
      break;
  }
  return std::log1p(std::max(y, 0.0) * std::clamp(cos_i, 0.0, 1.0));
}

double FullSamples::total_weight() const {
  return std::accumulate(weight.begin(), weight.end(), 0.0);
}

namespace {

// The BRDF at the cell centres of a grid: values in the error space and dμ weights (0 outside
// the domain, where the Jacobian is not finite, or where ρ is not finite: no data there).
// The grid's cells with `rho` (one value per cell, or one per pair of the domain when `brdf` is
// given, evaluated here) as values in the error space and weights of the measure.
void sample_grid(const Brdf* brdf, std::span<const Rgb> per_cell, const GridSpec& g, ErrorSpace es,
                 std::vector<double>& value, std::vector<double>& weight) {
  const std::size_t n = g.points();
  std::vector<DirPair<double>> all(n);
  std::vector<std::uint8_t> ok(n);
  std::vector<double> jac(n);
  grid_pairs(g, 0, all, ok, jac);
  std::vector<DirPair<double>> pairs;
  std::vector<std::size_t> where;
  for (std::size_t p = 0; p < n; ++p)
    if (ok[p] && std::isfinite(jac[p])) {
      pairs.push_back(all[p]);
      where.push_back(p);
    }
  std::vector<Rgb> rho(pairs.size());
  if (brdf)
    brdf->eval_batch(pairs, rho);
  else
    for (std::size_t k = 0; k < pairs.size(); ++k) rho[k] = per_cell[where[k]];
  value.assign(n, 0.0);
  weight.assign(n, 0.0);
  double cell = 1;
  for (const GridAxis& a : g.axes) cell *= (a.hi - a.lo) / double(a.count);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const std::size_t p = where[k];
    const double y = rho[k].luminance();
    if (!std::isfinite(y)) continue;
    value[p] = to_error_space(y, es, pairs[k].wi.z, pairs[k].wo.z);
    weight[p] = jac[p] * pairs[k].wi.z * pairs[k].wo.z * cell;
  }
}

}  // namespace

IsoSamples sample_isotropic(const Brdf& brdf, Space space, const IsoGrid& grid, ErrorSpace es) {
  if (grid.a == 0 || grid.b == 0 || grid.phi == 0)
    throw std::invalid_argument("study grid: every axis needs at least one cell");
  IsoSamples s;
  s.space = space;
  s.grid = grid;
  sample_grid(&brdf, {}, default_grid(space, GridKind::isotropic, {grid.a, grid.b, grid.phi}), es,
              s.value, s.weight);
  return s;
}

IsoSamples isotropic_samples_of(std::span<const Rgb> values, Space space, const IsoGrid& grid,
                                ErrorSpace es) {
  if (grid.a == 0 || grid.b == 0 || grid.phi == 0)
    throw std::invalid_argument("study grid: every axis needs at least one cell");
  if (values.size() != grid.a * grid.b * grid.phi)
    throw std::invalid_argument("study grid: one value per cell");
  IsoSamples s;
  s.space = space;
  s.grid = grid;
  sample_grid(nullptr, values, default_grid(space, GridKind::isotropic, {grid.a, grid.b, grid.phi}),
              es, s.value, s.weight);
  return s;
}

FullSamples sample_full(const Brdf& brdf, Space space, const std::array<std::size_t, 4>& counts,
                        ErrorSpace es) {
  for (std::size_t c : counts)
    if (c == 0) throw std::invalid_argument("study grid: every axis needs at least one cell");
  FullSamples s;
  s.space = space;
  s.counts = counts;
  sample_grid(&brdf, {}, default_grid(space, GridKind::full, {counts.begin(), counts.end()}), es,
              s.value, s.weight);
  return s;
}

}  // namespace halfback::acquire
