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

using acquire::FullSamples;
using acquire::IsoSamples;

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
