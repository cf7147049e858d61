// Weighted CP (canonical polyadic) decomposition by alternating least squares (fit/factor.hpp;
// docs/fit.md, "Factored models").
#include "halfback/fit/factor.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "halfback/core/batch.hpp"
#include "halfback/core/parallel.hpp"

namespace halfback::fit {

namespace {

// One channel's data on the grid: T = log(1 + ρ) and the μ-weight of each cell (0 outside).
struct Channel {
  std::vector<double> t;
};

struct Sampled {
  std::array<std::size_t, 3> n{};
  std::vector<double> weight;
  std::array<Channel, 3> channels;
};

Sampled sample(const Brdf& brdf, const GridSpec& grid, int threads) {
  Sampled s;
  for (std::size_t k = 0; k < 3; ++k) s.n[k] = grid.axes[k].count;
  const std::size_t total = s.n[0] * s.n[1] * s.n[2];
  s.weight.assign(total, 0);
  for (Channel& c : s.channels) c.t.assign(total, 0);
  const Form iso = grid.form(), dirs{Space::dirs, false};
  const double cell = [&] {
    double v = 1;
    for (const GridAxis& a : grid.axes) v *= (a.hi - a.lo) / double(a.count);
    return v;
  }();
  std::vector<std::string> bad(total);
  parallel_for(
      total, 256,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
          const std::array<double, 4> q = grid.point(i);
          double d[6], jac = 0;
          if (!convert_one<double>(iso, dirs, std::span<const double>(q.data(), 3), d, &jac) ||
              !(d[2] > 0 && d[5] > 0 && std::isfinite(jac) && jac > 0))
            continue;
          const Rgb v = brdf.eval({{d[0], d[1], d[2]}, {d[3], d[4], d[5]}});
          const double rgb[3] = {v.r, v.g, v.b};
          for (std::size_t c = 0; c < 3; ++c) {
            if (!(std::isfinite(rgb[c]) && rgb[c] >= 0)) {
              bad[i] = fmt::format("rho = ({}, {}, {}) at {} = ({}, {}, {})", v.r, v.g, v.b,
                                   name_of(grid.space), q[0], q[1], q[2]);
              break;
            }
            s.channels[c].t[i] = std::log1p(rgb[c]);
          }
          s.weight[i] = jac * d[2] * d[5] * cell;
        }
      },
      threads);
  for (const std::string& b : bad)
    if (!b.empty()) throw std::runtime_error("factor: the BRDF is not finite and >= 0: " + b);
  return s;
}

// The factors of one channel: rank × n[axis] each, term r's value at i is f[axis](r, i).
using Factors = std::array<Eigen::MatrixXd, 3>;

// Index of cell (i0, i1, i2), the last axis fastest.
std::size_t flat(const std::array<std::size_t, 3>& n, std::size_t i0, std::size_t i1,
                 std::size_t i2) {
  return (i0 * n[1] + i1) * n[2] + i2;
}

// Updates the factors of `axis` to their weighted least-squares best, the others held. A slice
// without weight (wholly outside the domain) takes the factors of the nearest slice with weight,
// so that interpolation towards the domain's edge does not fall to 0.
void update(Factors& f, std::size_t axis, const Sampled& s, const std::vector<double>& t) {
  const std::size_t rank = std::size_t(f[0].rows());
  const std::size_t o1 = (axis + 1) % 3, o2 = (axis + 2) % 3;
  std::vector<bool> empty(s.n[axis], true);
  for (std::size_t i = 0; i < s.n[axis]; ++i) {
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(Eigen::Index(rank), Eigen::Index(rank));
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(Eigen::Index(rank));
    Eigen::VectorXd z{Eigen::Index(rank)};
    for (std::size_t j = 0; j < s.n[o1]; ++j)
      for (std::size_t k = 0; k < s.n[o2]; ++k) {
        std::array<std::size_t, 3> idx{};
        idx[axis] = i, idx[o1] = j, idx[o2] = k;
        const std::size_t c = flat(s.n, idx[0], idx[1], idx[2]);
        const double w = s.weight[c];
        if (w == 0) continue;
        empty[i] = false;
        z = f[o1].col(Eigen::Index(j)).cwiseProduct(f[o2].col(Eigen::Index(k)));
        a.noalias() += w * z * z.transpose();
        rhs.noalias() += w * t[c] * z;
      }
    if (empty[i]) continue;
    // A small ridge keeps the system solvable when two terms coincide.
    a.diagonal().array() += 1e-10 * a.trace() / double(rank) + 1e-300;
    f[axis].col(Eigen::Index(i)) = a.ldlt().solve(rhs);
  }
  for (std::size_t i = 0; i < s.n[axis]; ++i) {
    if (!empty[i]) continue;
    std::size_t best = i;
    for (std::size_t d = 1; d < s.n[axis] && best == i; ++d) {
      if (i >= d && !empty[i - d])
        best = i - d;
      else if (i + d < s.n[axis] && !empty[i + d])
        best = i + d;
    }
    f[axis].col(Eigen::Index(i)) = f[axis].col(Eigen::Index(best));
  }
}

double weighted_error(const Factors& f, const Sampled& s, const std::vector<double>& t) {
  double num = 0, den = 0;
  for (std::size_t i = 0; i < s.n[0]; ++i)
    for (std::size_t j = 0; j < s.n[1]; ++j)
      for (std::size_t k = 0; k < s.n[2]; ++k) {
        const std::size_t c = flat(s.n, i, j, k);
        if (s.weight[c] == 0) continue;
        const double m = f[0].col(Eigen::Index(i))
                             .cwiseProduct(f[1].col(Eigen::Index(j)))
                             .dot(f[2].col(Eigen::Index(k)));
        num += s.weight[c] * (m - t[c]) * (m - t[c]);
        den += s.weight[c] * t[c] * t[c];
      }
  return den > 0 ? std::sqrt(num / den) : 0;
}

// Rank-r ALS from a deterministic start: term 0 constant, the others small ramps of different
// frequencies, so that the terms start apart.
Factors start(const Sampled& s, std::size_t rank) {
  Factors f;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    f[axis] = Eigen::MatrixXd::Ones(Eigen::Index(rank), Eigen::Index(s.n[axis]));
    for (std::size_t r = 1; r < rank; ++r)
      for (std::size_t i = 0; i < s.n[axis]; ++i)
        f[axis](Eigen::Index(r), Eigen::Index(i)) =
            0.1 * std::cos(double(r) * std::numbers::pi * (double(i) + 0.5) / double(s.n[axis]) +
                           double(axis));
  }
  return f;
}

}  // namespace

FactorResult factor_brdf(const Brdf& brdf, Space space, const FactorOptions& o) {
  if (space.is_dirs()) throw std::invalid_argument("factor: dirs is no parameterization");
  if (!brdf.isotropic())
    throw std::invalid_argument("factor: the BRDF is anisotropic; the factored model is isotropic");
  FactorResult result;
  result.model.space = space;
  result.model.name = brdf.name() + " factored";
  result.model.counts = o.counts;
  // Validates the counts and rank (FactoredBrdf's rules) before any work.
  for (auto& terms : result.model.channels)
    terms.assign(o.rank, FactoredTerm{std::vector<double>(o.counts[0], 0),
                                      std::vector<double>(o.counts[1], 0),
                                      std::vector<double>(o.counts[2], 0)});
  (void)FactoredBrdf(result.model);
  const Sampled s = sample(brdf, result.model.grid(), o.threads);
  double error_sum = 0;
  for (std::size_t c = 0; c < 3; ++c) {
    const std::vector<double>& t = s.channels[c].t;
    for (std::size_t i = 0; i < t.size(); ++i)
      if (s.weight[i] > 0) result.model.max_log[c] = std::max(result.model.max_log[c], t[i]);
    Factors f = start(s, o.rank);
    double previous = std::numeric_limits<double>::infinity(), error = 0;
    int sweep = 0;
    for (; sweep < o.sweeps; ++sweep) {
      for (std::size_t axis = 0; axis < 3; ++axis) update(f, axis, s, t);
      error = weighted_error(f, s, t);
      if (sweep > 0 && previous - error <= 1e-7 * previous) break;
      previous = error;
    }
    result.sweeps = std::max(result.sweeps, sweep + 1);
    error_sum += error;
    for (std::size_t r = 0; r < o.rank; ++r) {
      FactoredTerm& term = result.model.channels[c][r];
      for (std::size_t axis = 0; axis < 3; ++axis) {
        std::vector<double>& v = axis == 0 ? term.a : axis == 1 ? term.b : term.phi;
        for (std::size_t i = 0; i < s.n[axis]; ++i)
          v[i] = f[axis](Eigen::Index(r), Eigen::Index(i));
      }
    }
  }
  result.relative_error = error_sum / 3;
  return result;
}

}  // namespace halfback::fit
