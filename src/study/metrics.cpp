#include "halfback/study/metrics.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "halfback/brdf/resample.hpp"
#include "svd.hpp"

namespace halfback::study {

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

// Row i of `side` from the symmetric system whose upper triangle is row i of `normals` (packed
// row by row) and whose right-hand side is row i of `rhs`; a row without weight is 0.
template <class Small>
void solve_normal_rows(const Eigen::MatrixXd& normals, const Eigen::MatrixXd& rhs,
                       Eigen::MatrixXd& side) {
  const auto r = rhs.cols();
  Small n(r, r);
  for (Eigen::Index i = 0; i < normals.rows(); ++i) {
    for (Eigen::Index a = 0, c = 0; a < r; ++a)
      for (Eigen::Index b = a; b < r; ++b, ++c) n(a, b) = n(b, a) = normals(i, c);
    const double trace = n.trace();
    if (!(trace > 0)) {  // no weight in this row: it does not count
      side.row(i).setZero();
      continue;
    }
    n.diagonal().array() += 1e-14 * trace;
    side.row(i) = n.ldlt().solve(rhs.row(i).transpose()).transpose();
  }
}

// The relative error of the best rank-r approximation of M in the weighted norm
// Σ w_ij (M_ij − (U Vᵀ)_ij)², by alternating weighted least squares started from `svd`, the SVD of
// √w ∘ M (the exact answer when the weights are separable). Entries of weight 0 do not count, so a
// table that is of rank r on the domain has error 0 whatever the shape of the domain.
// `norm` = Σ w_ij M_ij² > 0 and 0 < r <= min(rows, cols).
double weighted_rank_error(const Eigen::MatrixXd& m, const Eigen::MatrixXd& w, double norm,
                           const detail::ThinSvd& svd, int r) {
  Eigen::MatrixXd u = svd.u.leftCols(r) * svd.values.head(r).asDiagonal();
  Eigen::MatrixXd v = svd.v.leftCols(r);
  auto error = [&] { return (w.array() * (m - u * v.transpose()).array().square()).sum(); };
  // One side given the other: an r × r weighted normal system per row (or column), all their
  // matrices from one product W · (v_a v_b)_{a <= b} (the systems are symmetric: r(r+1)/2
  // columns, not r²) and right-hand sides from (W ∘ M) · V.
  const Eigen::MatrixXd wm = w.cwiseProduct(m), wt = w.transpose(), wmt = wm.transpose();
  auto solve = [&](const Eigen::MatrixXd& weights, const Eigen::MatrixXd& weighted_target,
                   const Eigen::MatrixXd& other, Eigen::MatrixXd& side) {
    Eigen::MatrixXd outer(other.rows(), r * (r + 1) / 2);
    for (int a = 0, c = 0; a < r; ++a)
      for (int b = a; b < r; ++b) outer.col(c++) = other.col(a).cwiseProduct(other.col(b));
    const Eigen::MatrixXd normals = weights * outer;
    const Eigen::MatrixXd rhs = weighted_target * other;
    if (r <= 8)  // the usual ranks: the small systems on the stack
      solve_normal_rows<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 8, 8>>(normals,
                                                                                        rhs, side);
    else
      solve_normal_rows<Eigen::MatrixXd>(normals, rhs, side);
  };
  double last = error();
  for (int it = 0; it < 200 && last > 1e-30 * norm; ++it) {
    solve(w, wm, v, u);
    solve(wt, wmt, u, v);
    const double e = error();
    if (last - e <= 1e-12 * last) {
      last = e;
      break;
    }
    last = e;
  }
  return std::sqrt(std::max(last, 0.0) / norm);
}

// One SVD for all the ranks (it does not depend on r).
std::vector<double> rank_errors(const Eigen::MatrixXd& m, const Eigen::MatrixXd& w,
                                const std::vector<int>& ranks) {
  for (int r : ranks)
    if (r < 0) throw std::invalid_argument("separability: a rank must be >= 0");
  const double norm = (w.array() * m.array().square()).sum();
  const Eigen::Index most = std::min(m.rows(), m.cols());
  std::optional<detail::ThinSvd> svd;
  std::vector<double> out;
  for (int r : ranks) {
    r = int(std::min<Eigen::Index>(r, most));
    if (norm <= 0) {
      out.push_back(0.0);
    } else if (r == 0) {
      out.push_back(1.0);
    } else {
      if (!svd) svd = detail::thin_svd(w.array().sqrt() * m.array());
      out.push_back(weighted_rank_error(m, w, norm, *svd, r));
    }
  }
  return out;
}

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

// The relative error of replacing each run of `group` consecutive values by its weighted mean.
double group_mean_error(const std::vector<double>& value, const std::vector<double>& weight,
                        std::size_t group) {
  double err = 0, norm = 0;
  for (std::size_t i = 0; i + group <= value.size(); i += group) {
    double w = 0, m = 0;
    for (std::size_t k = i; k < i + group; ++k) {
      w += weight[k];
      m += weight[k] * value[k];
    }
    if (w <= 0) continue;
    m /= w;
    for (std::size_t k = i; k < i + group; ++k) {
      err += weight[k] * (value[k] - m) * (value[k] - m);
      norm += weight[k] * value[k] * value[k];
    }
  }
  return norm > 0 ? std::sqrt(err / norm) : 0.0;
}

// The table as a rows × cols matrix (row-major flat index = row · cols + col) and its weights.
std::vector<double> unfolded_rank_errors(const std::vector<double>& value,
                                         const std::vector<double>& weight, std::size_t cols,
                                         const std::vector<int>& ranks) {
  const auto rows = static_cast<Eigen::Index>(value.size() / cols);
  const auto c = static_cast<Eigen::Index>(cols);
  Eigen::MatrixXd m(rows, c), w(rows, c);
  for (Eigen::Index i = 0; i < rows; ++i)
    for (Eigen::Index k = 0; k < c; ++k) {
      m(i, k) = value[std::size_t(i * c + k)];
      w(i, k) = weight[std::size_t(i * c + k)];
    }
  return rank_errors(m, w, ranks);
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

double azimuthal_error(const FullSamples& s) {
  return group_mean_error(s.value, s.weight, s.counts[3]);
}

std::vector<double> separability_4d(const FullSamples& s, const std::vector<int>& ranks) {
  return unfolded_rank_errors(s.value, s.weight, s.counts[2] * s.counts[3], ranks);
}

double azimuthal_error(const IsoSamples& s) {
  return group_mean_error(s.value, s.weight, s.grid.phi);
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
  return unfolded_rank_errors(s.value, s.weight, s.grid.phi, ranks);
}

}  // namespace halfback::study
