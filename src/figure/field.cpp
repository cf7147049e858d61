#include "halfback/figure/field.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <mutex>
#include <thread>

#include "halfback/core/parallel.hpp"

namespace halfback::figure {

Grid Grid::pixel_centres(std::size_t w, std::size_t h, double x0, double x1, double y0, double y1) {
  const double dx = (x1 - x0) / double(w), dy = (y1 - y0) / double(h);
  return {w, h, x0 + 0.5 * dx, x1 - 0.5 * dx, y0 + 0.5 * dy, y1 - 0.5 * dy};
}

ScalarField::ScalarField(const Grid& g) : grid(g), values(g.size(), 0.0) {}

bool ScalarField::usable(std::size_t i, std::size_t j) const {
  const std::size_t k = grid.index(i, j);
  return (valid.empty() || valid[k] != 0) && std::isfinite(values[k]);
}

ScalarField sample(const Grid& grid, const std::function<double(double, double)>& f, int threads) {
  ScalarField out(grid);
  out.valid.assign(grid.size(), 0);
  parallel_for(
      grid.ny, 1,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j) {
          const double y = grid.y(j);
          for (std::size_t i = 0; i < grid.nx; ++i) {
            const double v = f(grid.x(i), y);
            out.values[grid.index(i, j)] = v;
            out.valid[grid.index(i, j)] = std::isfinite(v) ? 1 : 0;
          }
        }
      },
      threads);
  return out;
}

}  // namespace halfback::figure
