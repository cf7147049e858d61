// Piecewise-constant 1D and 2D distributions over cells, for importance sampling of environment
// maps and tabulated BRDFs. Weights are non-negative; a cell of weight 0 is never sampled.
//
// Sampling inverts the CDF in O(1) expected time with a guide table (Chen and Asau 1974): bucket k
// of size() equal buckets of [0, 1) stores the cell that u = k / size() falls in, and the search
// starts there. It returns exactly the cell (and remapped number) of a binary search of the CDF,
// so the map u -> cell stays monotonic and a stratified u stays stratified (an alias table would
// not keep that; docs/render.md, "Speed").
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace halfback::render {

class Distribution1D {
 public:
  Distribution1D() = default;
  // Throws std::invalid_argument for an empty list or a negative or non-finite weight.
  explicit Distribution1D(std::span<const double> weights);

  struct Sample {
    std::size_t index = 0;   // the cell
    double probability = 0;  // its probability; 0 only when every weight is 0
    double remapped = 0;     // u rescaled within the cell, in [0, 1): reusable as a fresh number
  };
  // u in [0, 1).
  Sample sample(double u) const;
  // The same by a binary search of the CDF (the reference the guide table is tested against).
  Sample sample_by_search(double u) const;
  double probability(std::size_t index) const { return cells_[index].probability; }
  double total() const { return total_; }
  std::size_t size() const { return cells_.empty() ? 0 : cells_.size() - 1; }

 private:
  Sample finish(std::size_t i, double u) const;

  // The CDF at the cell's lower edge and the cell's probability side by side, so that a sample
  // reads one cache line: size() + 1 entries, the last {1, 0}.
  struct Cell {
    double cdf = 0, probability = 0;
  };
  std::vector<Cell> cells_;
  std::vector<std::uint32_t> guide_;  // size() buckets: the cell of u = k / size()
  double total_ = 0;
};

// rows × cols cells, weights row-major: a marginal over rows and one conditional per row.
class Distribution2D {
 public:
  Distribution2D() = default;
  Distribution2D(std::size_t rows, std::size_t cols, std::span<const double> weights);

  struct Sample {
    std::size_t row = 0, col = 0;
    double probability = 0;                     // of the cell
    double remapped_row = 0, remapped_col = 0;  // in [0, 1), the position inside the cell
  };
  Sample sample(double u1, double u2) const;
  // sample() of each (u1[i], u2[i]), equal to it: all the rows first, then all the columns, so
  // that the table lookups of different samples overlap. The spans have the same size.
  void sample(std::span<const double> u1, std::span<const double> u2, std::span<Sample> out) const;
  double probability(std::size_t row, std::size_t col) const;
  double total() const { return marginal_.total(); }
  std::size_t rows() const { return rows_; }
  std::size_t cols() const { return cols_; }

 private:
  std::size_t rows_ = 0, cols_ = 0;
  Distribution1D marginal_;
  std::vector<Distribution1D> conditional_;
};

}  // namespace halfback::render
