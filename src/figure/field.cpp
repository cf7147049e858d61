#include "halfback/figure/field.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <mutex>
#include <thread>

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

void parallel_rows(std::size_t rows, unsigned threads,
                   const std::function<void(std::size_t)>& body) {
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  const std::size_t n =
      std::min<std::size_t>(threads == 0 ? hw : threads, std::max<std::size_t>(rows, 1));
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    try {
      for (std::size_t j; (j = next.fetch_add(1)) < rows;) body(j);
    } catch (...) {
      std::lock_guard lock(error_mutex);
      if (!error) error = std::current_exception();
      next = rows;  // stop handing out rows
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < n; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

ScalarField sample(const Grid& grid, const std::function<double(double, double)>& f,
                   unsigned threads) {
  ScalarField out(grid);
  out.valid.assign(grid.size(), 0);
  parallel_rows(grid.ny, threads, [&](std::size_t j) {
    const double y = grid.y(j);
    for (std::size_t i = 0; i < grid.nx; ++i) {
      const double v = f(grid.x(i), y);
      out.values[grid.index(i, j)] = v;
      out.valid[grid.index(i, j)] = std::isfinite(v) ? 1 : 0;
    }
  });
  return out;
}

}  // namespace halfback::figure
