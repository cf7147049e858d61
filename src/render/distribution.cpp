#include "halfback/render/distribution.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace halfback::render {

namespace {
// The largest double below 1: remapped numbers must stay in [0, 1).
constexpr double kOneMinusEpsilon = 0x1.fffffffffffffp-1;
}  // namespace

Distribution1D::Distribution1D(std::span<const double> weights) {
  if (weights.empty()) throw std::invalid_argument("Distribution1D: no cells");
  if (weights.size() > std::size_t(UINT32_MAX))
    throw std::invalid_argument("Distribution1D: more than 2^32 - 1 cells");
  const std::size_t n = weights.size();
  std::vector<double> cdf(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double w = weights[i];
    if (!std::isfinite(w) || w < 0)
      throw std::invalid_argument("Distribution1D: weight " + std::to_string(i) +
                                  " is negative or not finite");
    cdf[i + 1] = cdf[i] + w;
  }
  total_ = cdf.back();
  if (!std::isfinite(total_)) throw std::invalid_argument("Distribution1D: weights overflow");
  if (total_ > 0) {
    for (double& c : cdf) c /= total_;
  } else {
    for (std::size_t i = 0; i <= n; ++i) cdf[i] = double(i) / double(n);
  }
  cdf.back() = 1;
  cells_.resize(n + 1);
  for (std::size_t i = 0; i <= n; ++i)
    cells_[i] = {cdf[i], i < n && total_ > 0 ? weights[i] / total_ : 0.0};
  // Bucket k starts at the cell a search for u = k / n finds (one pass: both are increasing).
  guide_.resize(n);
  std::size_t cell = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double u = double(k) / double(n);
    while (cell + 1 < n && !(cdf[cell + 1] > u)) ++cell;
    guide_[k] = std::uint32_t(cell);
  }
}

Distribution1D::Sample Distribution1D::sample(double u) const {
  if (!(total_ > 0)) return {};
  u = u >= 0 ? std::min(u, kOneMinusEpsilon) : 0.0;  // NaN too: the index below must be valid
  const std::size_t n = size();
  std::size_t i = guide_[std::min(std::size_t(u * double(n)), n - 1)];
  // The first cell whose upper bound exceeds u, as the binary search finds it; the guide may be
  // one cell ahead when u * n rounded up to the next bucket.
  while (i > 0 && cells_[i].cdf > u) --i;
  while (i + 1 < n && !(cells_[i + 1].cdf > u)) ++i;
  return finish(i, u);
}

Distribution1D::Sample Distribution1D::sample_by_search(double u) const {
  if (!(total_ > 0)) return {};
  u = u >= 0 ? std::min(u, kOneMinusEpsilon) : 0.0;
  // The first cell whose upper bound exceeds u: cells of weight 0 have an empty interval.
  const auto it = std::upper_bound(cells_.begin() + 1, cells_.end(), u,
                                   [](double v, const Cell& c) { return v < c.cdf; });
  const std::size_t i = std::size_t(it - cells_.begin()) - 1;
  return finish(std::min(i, size() - 1), u);
}

Distribution1D::Sample Distribution1D::finish(std::size_t i, double u) const {
  Sample s;
  while (cells_[i].probability == 0 && i > 0) --i;  // rounding at the last cell: a live cell
  s.index = i;
  s.probability = cells_[i].probability;
  const double width = cells_[i + 1].cdf - cells_[i].cdf;
  s.remapped = width > 0 ? std::clamp((u - cells_[i].cdf) / width, 0.0, kOneMinusEpsilon) : 0.5;
  return s;
}

Distribution2D::Distribution2D(std::size_t rows, std::size_t cols, std::span<const double> weights)
    : rows_(rows), cols_(cols) {
  if (rows == 0 || cols == 0 || weights.size() != rows * cols)
    throw std::invalid_argument("Distribution2D: " + std::to_string(weights.size()) +
                                " weights for " + std::to_string(rows) + " x " +
                                std::to_string(cols) + " cells");
  std::vector<double> row_weights(rows);
  conditional_.reserve(rows);
  for (std::size_t r = 0; r < rows; ++r) {
    conditional_.emplace_back(weights.subspan(r * cols, cols));
    row_weights[r] = conditional_.back().total();
  }
  marginal_ = Distribution1D(row_weights);
}

Distribution2D::Sample Distribution2D::sample(double u1, double u2) const {
  Sample s;
  const auto r = marginal_.sample(u1);
  if (r.probability <= 0) return s;
  const auto c = conditional_[r.index].sample(u2);
  s.row = r.index;
  s.col = c.index;
  s.probability = r.probability * c.probability;
  s.remapped_row = r.remapped;
  s.remapped_col = c.remapped;
  return s;
}

void Distribution2D::sample(std::span<const double> u1, std::span<const double> u2,
                            std::span<Sample> out) const {
  for (std::size_t i = 0; i < out.size(); ++i) {
    const auto r = marginal_.sample(u1[i]);
    out[i] = Sample{};
    out[i].row = r.index;
    out[i].probability = r.probability;
    out[i].remapped_row = r.remapped;
  }
  for (std::size_t i = 0; i < out.size(); ++i) {
    Sample& s = out[i];
    if (s.probability <= 0) {
      s = Sample{};
      continue;
    }
    const auto c = conditional_[s.row].sample(u2[i]);
    s.col = c.index;
    s.probability *= c.probability;
    s.remapped_col = c.remapped;
  }
}

double Distribution2D::probability(std::size_t row, std::size_t col) const {
  if (row >= rows_ || col >= cols_) return 0;
  return marginal_.probability(row) * conditional_[row].probability(col);
}

}  // namespace halfback::render
