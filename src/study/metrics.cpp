#include "halfback/study/metrics.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "halfback/brdf/resample.hpp"

namespace halfback::study {

std::string_view name_of(ErrorSpace s) {
  switch (s) {
    case ErrorSpace::linear:
      return "linear";
    case ErrorSpace::log:
      return "log";
    case ErrorSpace::cbrt:
      break;
  }
  return "cbrt";
}

double IsoSamples::total_weight() const {
  return std::accumulate(weight.begin(), weight.end(), 0.0);
}

namespace {

double to_error_space(double y, ErrorSpace es) {
  switch (es) {
    case ErrorSpace::linear:
      return y;
    case ErrorSpace::log:
      return std::log1p(std::max(y, 0.0));
    case ErrorSpace::cbrt:
      break;
  }
  return std::cbrt(y);
}

// The relative error of the best rank-r approximation of M in the weighted norm
// Σ w_ij (M_ij − (U Vᵀ)_ij)², by alternating weighted least squares started from the SVD of
// √w ∘ M (the exact answer when the weights are separable). Entries of weight 0 do not count, so a
// table that is of rank r on the domain has error 0 whatever the shape of the domain.
double weighted_rank_error(const Eigen::MatrixXd& m, const Eigen::MatrixXd& w, int r) {
  const double norm = (w.array() * m.array().square()).sum();
  if (norm <= 0) return 0.0;
  const Eigen::Index rows = m.rows(), cols = m.cols();
  r = int(std::min<Eigen::Index>(r, std::min(rows, cols)));
  if (r == 0) return 1.0;
  const Eigen::MatrixXd scaled = w.array().sqrt() * m.array();
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeThinU | Eigen::ComputeThinV);
  Eigen::MatrixXd u = svd.matrixU().leftCols(r) * svd.singularValues().head(r).asDiagonal();
  Eigen::MatrixXd v = svd.matrixV().leftCols(r);
  auto error = [&] { return (w.array() * (m - u * v.transpose()).array().square()).sum(); };
  // One side given the other: a small r × r weighted normal system per row (or column).
  auto solve = [&](const Eigen::MatrixXd& target, const Eigen::MatrixXd& weights,
                   const Eigen::MatrixXd& other, Eigen::MatrixXd& side) {
    for (Eigen::Index i = 0; i < target.rows(); ++i) {
      const Eigen::VectorXd wi = weights.row(i).transpose();
      if (wi.sum() <= 0) {
        side.row(i).setZero();
        continue;
      }
      Eigen::MatrixXd a = other.transpose() * wi.asDiagonal() * other;
      a.diagonal().array() += 1e-14 * (a.trace() + 1e-300);
      const Eigen::VectorXd b =
          other.transpose() * (wi.array() * target.row(i).transpose().array()).matrix();
      side.row(i) = a.ldlt().solve(b).transpose();
    }
  };
  double last = error();
  for (int it = 0; it < 200 && last > 1e-30 * norm; ++it) {
    solve(m, w, v, u);
    const Eigen::MatrixXd mt = m.transpose(), wt = w.transpose();
    solve(mt, wt, u, v);
    const double e = error();
    if (last - e <= 1e-12 * last) {
      last = e;
      break;
    }
    last = e;
  }
  return std::sqrt(std::max(last, 0.0) / norm);
}

std::vector<double> rank_errors(const Eigen::MatrixXd& m, const Eigen::MatrixXd& w,
                                const std::vector<int>& ranks) {
  std::vector<double> out;
  for (int r : ranks) {
    if (r < 0) throw std::invalid_argument("separability: a rank must be >= 0");
    out.push_back(weighted_rank_error(m, w, r));
  }
  return out;
}

}  // namespace

IsoSamples sample_isotropic(const Brdf& brdf, Space space, const IsoGrid& grid, ErrorSpace es) {
  if (grid.a == 0 || grid.b == 0 || grid.phi == 0)
    throw std::invalid_argument("study grid: every axis needs at least one cell");
  const GridSpec g = default_grid(space, GridKind::isotropic, {grid.a, grid.b, grid.phi});
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
  brdf.eval(pairs, rho);

  IsoSamples s;
  s.space = space;
  s.grid = grid;
  s.value.assign(n, 0.0);
  s.weight.assign(n, 0.0);
  const double cell = (g.axes[0].hi - g.axes[0].lo) / double(grid.a) *
                      (g.axes[1].hi - g.axes[1].lo) / double(grid.b) *
                      (g.axes[2].hi - g.axes[2].lo) / double(grid.phi);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const std::size_t p = where[k];
    const double y = 0.2126 * rho[k].r + 0.7152 * rho[k].g + 0.0722 * rho[k].b;
    if (!std::isfinite(y)) continue;  // no data there (e.g. outside a measurement): left out
    s.value[p] = to_error_space(y, es);
    s.weight[p] = jac[p] * pairs[k].wi.z * pairs[k].wo.z * cell;
  }
  return s;
}

double azimuthal_error(const IsoSamples& s) {
  const std::size_t ab = s.grid.a * s.grid.b, nphi = s.grid.phi;
  double err = 0, norm = 0;
  for (std::size_t i = 0; i < ab; ++i) {
    double w = 0, m = 0;
    for (std::size_t k = 0; k < nphi; ++k) {
      w += s.weight[i * nphi + k];
      m += s.weight[i * nphi + k] * s.value[i * nphi + k];
    }
    if (w <= 0) continue;
    m /= w;
    for (std::size_t k = 0; k < nphi; ++k) {
      const double d = s.value[i * nphi + k] - m;
      err += s.weight[i * nphi + k] * d * d;
      norm += s.weight[i * nphi + k] * s.value[i * nphi + k] * s.value[i * nphi + k];
    }
  }
  return norm > 0 ? std::sqrt(err / norm) : 0.0;
}

std::vector<double> separability_2d(const IsoSamples& s, const std::vector<int>& ranks) {
  const std::size_t na = s.grid.a, nb = s.grid.b, nphi = s.grid.phi;
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(Eigen::Index(na), Eigen::Index(nb)), w = m;
  for (std::size_t i = 0; i < na; ++i)
    for (std::size_t j = 0; j < nb; ++j) {
      double wsum = 0, v = 0;
      for (std::size_t k = 0; k < nphi; ++k) {
        const std::size_t p = (i * nb + j) * nphi + k;
        wsum += s.weight[p];
        v += s.weight[p] * s.value[p];
      }
      if (wsum <= 0) continue;
      m(Eigen::Index(i), Eigen::Index(j)) = v / wsum;
      w(Eigen::Index(i), Eigen::Index(j)) = wsum;
    }
  return rank_errors(m, w, ranks);
}

std::vector<double> separability_unfolded(const IsoSamples& s, const std::vector<int>& ranks) {
  const std::size_t ab = s.grid.a * s.grid.b, nphi = s.grid.phi;
  const auto rows = static_cast<Eigen::Index>(ab), cols = static_cast<Eigen::Index>(nphi);
  Eigen::MatrixXd m(rows, cols), w(rows, cols);
  for (std::size_t i = 0; i < ab; ++i)
    for (std::size_t k = 0; k < nphi; ++k) {
      m(Eigen::Index(i), Eigen::Index(k)) = s.value[i * nphi + k];
      w(Eigen::Index(i), Eigen::Index(k)) = s.weight[i * nphi + k];
    }
  return rank_errors(m, w, ranks);
}

}  // namespace halfback::study
