// A static k-d tree over points in R^D for k-nearest-neighbour queries (private header).
// Built once by median splits (std::nth_element) into an implicit balanced tree: the node of a
// range [lo, hi) is the point at its middle, its children the two halves.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>
#include <numeric>
#include <vector>

namespace halfback::io_detail {

template <std::size_t D>
class KdTree {
 public:
  using Point = std::array<double, D>;

  struct Neighbour {
    double dist2;
    std::size_t index;  // into the points given to the constructor
  };

  KdTree() = default;
  explicit KdTree(std::vector<Point> points) : points_(std::move(points)) {
    order_.resize(points_.size());
    std::iota(order_.begin(), order_.end(), std::size_t{0});
    axis_.assign(points_.size(), 0);
    build(0, points_.size());
  }

  std::size_t size() const { return points_.size(); }
  const Point& point(std::size_t i) const { return points_[i]; }

  // The k nearest points to q, nearest first (fewer when the tree is smaller).
  void nearest(const Point& q, std::size_t k, std::vector<Neighbour>& out) const {
    out.clear();
    if (k == 0 || points_.empty()) return;
    search(0, points_.size(), q, k, out);
    std::sort_heap(out.begin(), out.end(), by_distance);
  }

 private:
  static bool by_distance(const Neighbour& a, const Neighbour& b) { return a.dist2 < b.dist2; }

  void build(std::size_t lo, std::size_t hi) {
    if (hi - lo <= 1) return;
    // Split along the axis of largest extent.
    Point mn, mx;
    mn.fill(std::numeric_limits<double>::infinity());
    mx.fill(-std::numeric_limits<double>::infinity());
    for (std::size_t i = lo; i < hi; ++i)
      for (std::size_t d = 0; d < D; ++d) {
        mn[d] = std::min(mn[d], points_[order_[i]][d]);
        mx[d] = std::max(mx[d], points_[order_[i]][d]);
      }
    std::size_t axis = 0;
    for (std::size_t d = 1; d < D; ++d)
      if (mx[d] - mn[d] > mx[axis] - mn[axis]) axis = d;
    const std::size_t mid = lo + (hi - lo) / 2;
    std::nth_element(
        order_.begin() + lo, order_.begin() + mid, order_.begin() + hi,
        [&](std::size_t a, std::size_t b) { return points_[a][axis] < points_[b][axis]; });
    axis_[mid] = static_cast<unsigned char>(axis);
    build(lo, mid);
    build(mid + 1, hi);
  }

  void search(std::size_t lo, std::size_t hi, const Point& q, std::size_t k,
              std::vector<Neighbour>& heap) const {
    if (lo >= hi) return;
    const std::size_t mid = lo + (hi - lo) / 2;
    const Point& p = points_[order_[mid]];
    double d2 = 0;
    for (std::size_t d = 0; d < D; ++d) d2 += (p[d] - q[d]) * (p[d] - q[d]);
    if (heap.size() < k) {
      heap.push_back({d2, order_[mid]});
      std::push_heap(heap.begin(), heap.end(), by_distance);
    } else if (d2 < heap.front().dist2) {
      std::pop_heap(heap.begin(), heap.end(), by_distance);
      heap.back() = {d2, order_[mid]};
      std::push_heap(heap.begin(), heap.end(), by_distance);
    }
    if (hi - lo == 1) return;
    const std::size_t axis = axis_[mid];
    const double diff = q[axis] - p[axis];
    const bool left_first = diff < 0;
    if (left_first)
      search(lo, mid, q, k, heap);
    else
      search(mid + 1, hi, q, k, heap);
    if (heap.size() < k || diff * diff < heap.front().dist2) {
      if (left_first)
        search(mid + 1, hi, q, k, heap);
      else
        search(lo, mid, q, k, heap);
    }
  }

  std::vector<Point> points_;
  std::vector<std::size_t> order_;
  std::vector<unsigned char> axis_;
};

}  // namespace halfback::io_detail
