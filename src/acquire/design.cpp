#include "halfback/acquire/design.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace halfback::acquire {

std::string_view name_of(Spacing s) {
  switch (s) {
    case Spacing::own:
      return "own";
    case Spacing::angle:
      return "angle";
    case Spacing::merl:
      return "merl";
    case Spacing::learned:
      break;
  }
  return "learned";
}

std::optional<Spacing> parse_spacing(std::string_view name) {
  for (Spacing s : kSpacings)
    if (name_of(s) == name) return s;
  return std::nullopt;
}

namespace {

constexpr double kHalfPi = std::numbers::pi / 2;
constexpr double kUniformShare = 0.2;  // of the learned density: the floor of learn_warps()

// The descriptor's axis that a grid axis samples.
const Axis& descriptor_axis(const GridSpec& g, const GridAxis& a) {
  for (const Axis& axis : g.space.param().axes(g.kind != GridKind::full))
    if (axis.column == a.name) return axis;
  throw std::invalid_argument(fmt::format("{} has no coordinate '{}'", name_of(g.space), a.name));
}

// The learned warp of a grid axis: the one learned for the isotropic coordinate of the same
// name (a: 0, b: 1, the relative azimuth: 2); the identity for an azimuth of the full form and for
// a coordinate the isotropic form does not have (the Cartesian ones of the stereographic maps).
AxisWarp learned_warp(const GridSpec& cells, const GridAxis& a, const LearnedWarps& learned) {
  const bool full = cells.kind == GridKind::full;
  if (full && descriptor_axis(cells, a).kind == AxisKind::azimuth)
    return AxisWarp(AxisWarp::Kind::identity, a.lo, a.hi);
  const auto iso = cells.space.param().axes(true);
  for (std::size_t k = 0; k < iso.size() && k < learned.axes.size(); ++k)
    if (iso[k].column == a.name) return learned.axes[k];
  return AxisWarp(AxisWarp::Kind::identity, a.lo, a.hi);
}

}  // namespace

AxisWarp::AxisWarp(Kind kind, double lo, double hi) : kind_(kind), lo_(lo), hi_(hi) {
  if (!(std::isfinite(lo) && std::isfinite(hi) && lo < hi))
    throw std::invalid_argument("axis warp: the range must be finite with lo < hi");
  if (kind == Kind::table)
    throw std::invalid_argument("axis warp: a table is made by AxisWarp::from_cdf");
  // The arcsine warps map [0, 1] (a sine); the MERL warp of an angle starts at 0.
  if ((kind == Kind::arcsine || kind == Kind::merl_arcsine) && (lo != 0 || hi != 1))
    throw std::invalid_argument("axis warp: the arcsine warps take the range [0, 1]");
  if (kind == Kind::merl_angle && lo != 0)
    throw std::invalid_argument("axis warp: MERL's warp of an angle takes a range from 0");
}

AxisWarp AxisWarp::from_cdf(double lo, double hi, std::vector<double> cdf) {
  AxisWarp w(Kind::identity, lo, hi);
  if (cdf.size() < 2 || cdf.front() != 0 || cdf.back() != 1)
    throw std::invalid_argument("axis warp: a table runs from 0 to 1 in at least two nodes");
  for (std::size_t i = 1; i < cdf.size(); ++i)
    if (!(cdf[i] > cdf[i - 1]))
      throw std::invalid_argument("axis warp: a table must be strictly increasing");
  w.kind_ = Kind::table;
  w.cdf_ = std::move(cdf);
  return w;
}

double AxisWarp::forward(double x) const {
  const double t = std::clamp((x - lo_) / (hi_ - lo_), 0.0, 1.0);
  double f = t;
  switch (kind_) {
    case Kind::identity:
      break;
    case Kind::arcsine:
      f = std::asin(t) / kHalfPi;
      break;
    case Kind::merl_angle:
      f = std::sqrt(t);
      break;
    case Kind::merl_arcsine:
      f = std::sqrt(std::asin(t) / kHalfPi);
      break;
    case Kind::table: {
      const double n = double(cdf_.size() - 1), s = t * n;
      const auto i = std::min(std::size_t(s), cdf_.size() - 2);
      f = cdf_[i] + (s - double(i)) * (cdf_[i + 1] - cdf_[i]);
      break;
    }
  }
  return lo_ + std::clamp(f, 0.0, 1.0) * (hi_ - lo_);
}

double AxisWarp::inverse(double u) const {
  const double f = std::clamp((u - lo_) / (hi_ - lo_), 0.0, 1.0);
  double t = f;
  switch (kind_) {
    case Kind::identity:
      break;
    case Kind::arcsine:
      t = std::sin(kHalfPi * f);
      break;
    case Kind::merl_angle:
      t = f * f;
      break;
    case Kind::merl_arcsine:
      t = std::sin(kHalfPi * f * f);
      break;
    case Kind::table: {
      // The segment whose values bracket f, then linear inside it.
      const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), f);
      const auto i = std::size_t(
          std::clamp<std::ptrdiff_t>(it - cdf_.begin() - 1, 0, std::ptrdiff_t(cdf_.size()) - 2));
      const double n = double(cdf_.size() - 1);
      t = (double(i) + (f - cdf_[i]) / (cdf_[i + 1] - cdf_[i])) / n;
      break;
    }
  }
  return lo_ + std::clamp(t, 0.0, 1.0) * (hi_ - lo_);
}

std::vector<AxisWarp> design_warps(const GridSpec& cells, Spacing spacing,
                                   const LearnedWarps* learned) {
  if (spacing == Spacing::learned && (!learned || learned->space != cells.space))
    throw std::invalid_argument(
        fmt::format("the learned design of {} needs warps learned for {} (acquire::learn_warps)",
                    name_of(cells.space), name_of(cells.space)));
  std::vector<AxisWarp> warps;
  for (const GridAxis& a : cells.axes) {
    using K = AxisWarp::Kind;
    if (spacing == Spacing::learned) {
      warps.push_back(learned_warp(cells, a, *learned));
      continue;
    }
    const Axis& axis = descriptor_axis(cells, a);
    const bool sine = axis.encoding == AngleEncoding::sine;
    K kind = K::identity;
    if (spacing != Spacing::own && sine) kind = K::arcsine;
    if (spacing == Spacing::merl && axis.half_vector_tilt)
      kind = sine ? K::merl_arcsine : K::merl_angle;
    warps.emplace_back(kind, a.lo, a.hi);
  }
  return warps;
}

bool same_as_own(Space space, bool isotropic, Spacing spacing) {
  if (spacing == Spacing::own) return true;
  if (spacing == Spacing::learned) return false;
  const GridSpec g = default_grid(space, isotropic ? GridKind::isotropic : GridKind::full, {1});
  for (const AxisWarp& w : design_warps(g, spacing, nullptr))
    if (w.kind() != AxisWarp::Kind::identity) return false;
  return true;
}

AxisDemand axis_demand(const IsoSamples& s) {
  const std::array<std::size_t, 3> n{s.grid.a, s.grid.b, s.grid.phi};
  const std::array<std::size_t, 3> stride{n[1] * n[2], n[2], 1};
  AxisDemand d;
  d.space = s.space;
  double norm = 0;
  for (std::size_t p = 0; p < s.value.size(); ++p) norm += s.weight[p] * s.value[p] * s.value[p];
  for (std::size_t axis = 0; axis < 3; ++axis) {
    std::vector<double>& out = d.demand[axis];
    out.assign(n[axis], 0.0);
    const bool periodic = axis == 2;
    // The cell k steps from p along the axis (wrapping around an azimuth), if it holds a value.
    auto along = [&](std::size_t p, long k) -> std::optional<std::size_t> {
      const std::size_t here = p / stride[axis] % n[axis];
      const long i = long(here) + k, m = long(n[axis]);
      if (!periodic && (i < 0 || i >= m)) return std::nullopt;
      const std::size_t q = p - here * stride[axis] + std::size_t(((i % m) + m) % m) * stride[axis];
      if (s.weight[q] <= 0) return std::nullopt;
      return q;
    };
    for (std::size_t p = 0; p < s.value.size(); ++p) {
      const std::size_t i = p / stride[axis] % n[axis];
      if (s.weight[p] <= 0 || n[axis] < 3) continue;
      // The centred second difference, or at an end of the values along the axis (a magnitude's
      // end, the domain's edge, the instrument's reach) the one-sided one from the two cells
      // inside: an edge has as much curvature as the cells next to it, not none.
      const auto lo = along(p, -1), hi = along(p, 1);
      std::optional<std::size_t> far;
      double second;
      if (lo && hi)
        second = s.value[*lo] - 2 * s.value[p] + s.value[*hi];
      else if (hi && (far = along(p, 2)))
        second = s.value[p] - 2 * s.value[*hi] + s.value[*far];
      else if (lo && (far = along(p, -2)))
        second = s.value[p] - 2 * s.value[*lo] + s.value[*far];
      else
        continue;
      out[i] += s.weight[p] * second * second;
    }
    if (norm > 0)
      for (double& v : out) v /= norm;
  }
  return d;
}

DesignProfile design_profile(const Brdf& brdf, std::span<const Space> spaces, const IsoGrid& grid,
                             ErrorSpace es) {
  DesignProfile p;
  for (Space s : spaces) p.spaces.push_back(axis_demand(sample_isotropic(brdf, s, grid, es)));
  return p;
}

namespace {

// A strictly increasing CDF (n + 1 nodes) of the density ∝ (1 − share) D^(1/5)/mean + share.
std::vector<double> cdf_of_demand(const std::vector<double>& demand,
                                  double uniform_share = kUniformShare) {
  const std::size_t n = demand.size();
  std::vector<double> rho(n);
  double mean = 0;
  for (std::size_t i = 0; i < n; ++i) mean += (rho[i] = std::pow(std::max(demand[i], 0.0), 0.2));
  mean /= double(n);
  for (double& r : rho) r = mean > 0 ? (1 - uniform_share) * r / mean + uniform_share : 1.0;
  std::vector<double> cdf(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) cdf[i + 1] = cdf[i] + rho[i];
  for (double& c : cdf) c /= cdf.back();
  cdf.back() = 1;
  return cdf;
}

}  // namespace

LearnedWarps warps_for_demand(const AxisDemand& demand, double uniform_share) {
  if (!(uniform_share >= 0 && uniform_share <= 1))
    throw std::invalid_argument("warps_for_demand: the uniform share must be in [0, 1]");
  LearnedWarps w;
  w.space = demand.space;
  const GridSpec g = default_grid(demand.space, GridKind::isotropic, {1});
  for (std::size_t axis = 0; axis < 3; ++axis)
    w.axes[axis] = AxisWarp::from_cdf(g.axes[axis].lo, g.axes[axis].hi,
                                      cdf_of_demand(demand.demand[axis], uniform_share));
  return w;
}

std::vector<LearnedWarps> learn_warps(std::span<const DesignProfile> profiles,
                                      std::size_t held_out) {
  // The spaces and grid sizes of the first profile other than the held-out one.
  const DesignProfile* first = nullptr;
  for (std::size_t k = 0; k < profiles.size() && !first; ++k)
    if (k != held_out) first = &profiles[k];
  std::vector<LearnedWarps> out;
  if (!first) return out;
  for (const AxisDemand& shape : first->spaces) {
    LearnedWarps w;
    w.space = shape.space;
    const GridSpec g = default_grid(shape.space, GridKind::isotropic, {1});
    for (std::size_t axis = 0; axis < 3; ++axis) {
      std::vector<double> sum(shape.demand[axis].size(), 0.0);
      for (std::size_t k = 0; k < profiles.size(); ++k) {
        if (k == held_out) continue;
        for (const AxisDemand& d : profiles[k].spaces) {
          if (d.space != shape.space) continue;
          if (d.demand[axis].size() != sum.size())
            throw std::invalid_argument("learn_warps: the profiles were taken on different grids");
          for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += d.demand[axis][i];
        }
      }
      w.axes[axis] = AxisWarp::from_cdf(g.axes[axis].lo, g.axes[axis].hi, cdf_of_demand(sum));
    }
    out.push_back(std::move(w));
  }
  return out;
}

}  // namespace halfback::acquire
