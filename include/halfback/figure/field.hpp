// Scalar fields sampled on regular grids, with a validity mask.
//
// A Grid has nx × ny nodes; node (i, j) sits at data coordinates (x(i), y(j)), with x(0) = x0,
// x(nx−1) = x1 and likewise in y (y grows with j). Values are stored row by row: index j·nx + i.
// Figures sample their fields at the centres of the output pixels, so one node is one pixel.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace halfback::figure {

struct Grid {
  std::size_t nx = 0, ny = 0;
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;

  double x(std::size_t i) const {
    return nx > 1 ? x0 + (x1 - x0) * double(i) / double(nx - 1) : x0;
  }
  double y(std::size_t j) const {
    return ny > 1 ? y0 + (y1 - y0) * double(j) / double(ny - 1) : y0;
  }
  std::size_t size() const { return nx * ny; }
  std::size_t index(std::size_t i, std::size_t j) const { return j * nx + i; }

  // The grid whose nodes are the centres of a w × h pixel raster covering [x0, x1] × [y0, y1]
  // (row j = 0 at y0).
  static Grid pixel_centres(std::size_t w, std::size_t h, double x0, double x1, double y0,
                            double y1);
};

struct ScalarField {
  Grid grid;
  std::vector<double> values;       // grid.size() values; NaN allowed
  std::vector<std::uint8_t> valid;  // grid.size() flags; empty means "all valid"

  explicit ScalarField(const Grid& g = {});
  double at(std::size_t i, std::size_t j) const { return values[grid.index(i, j)]; }
  // Valid and finite.
  bool usable(std::size_t i, std::size_t j) const;
};

// Samples f(x, y) -> value on every node; a NaN value marks the node invalid.
ScalarField sample(const Grid& grid, const std::function<double(double, double)>& f,
                   int threads = 0);  // as in core/parallel.hpp

}  // namespace halfback::figure
