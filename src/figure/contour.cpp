#include "halfback/figure/contour.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <utility>

namespace halfback::figure {
namespace {

// Corners of cell (i, j): 0 = (i, j), 1 = (i+1, j), 2 = (i+1, j+1), 3 = (i, j+1).
// Edges: 0 = corners 0–1 (bottom), 1 = 1–2 (right), 2 = 3–2 (top), 3 = 0–3 (left).
struct Segment {
  std::size_t edge[2];
};

struct Sweep {
  const Grid& grid;
  std::size_t horizontal_edges() const { return (grid.nx - 1) * grid.ny; }
  // Global id of local edge e of cell (i, j).
  std::size_t edge_id(std::size_t i, std::size_t j, int e) const {
    switch (e) {
      case 0:
        return j * (grid.nx - 1) + i;
      case 2:
        return (j + 1) * (grid.nx - 1) + i;
      case 3:
        return horizontal_edges() + j * grid.nx + i;
      default:
        return horizontal_edges() + j * grid.nx + i + 1;
    }
  }
  // The two node indices of a global edge id.
  std::pair<std::size_t, std::size_t> nodes(std::size_t id) const {
    if (id < horizontal_edges()) {
      const std::size_t j = id / (grid.nx - 1), i = id % (grid.nx - 1);
      return {grid.index(i, j), grid.index(i + 1, j)};
    }
    id -= horizontal_edges();
    const std::size_t j = id / grid.nx, i = id % grid.nx;
    return {grid.index(i, j), grid.index(i, j + 1)};
  }
  Point node_point(std::size_t k) const { return {grid.x(k % grid.nx), grid.y(k / grid.nx)}; }
};

// usable(k): node k may be used; above(k): classification; saddle_centre_above(i, j) resolves
// saddles; crossing(a, b): the point on the edge between nodes a and b.
template <class Usable, class Above, class Saddle, class Crossing>
std::vector<Polyline> march(const Grid& grid, Usable usable, Above above, Saddle saddle_above,
                            Crossing crossing) {
  std::vector<Polyline> lines;
  if (grid.nx < 2 || grid.ny < 2) return lines;
  const Sweep sweep{grid};
  std::vector<Segment> segments;
  for (std::size_t j = 0; j + 1 < grid.ny; ++j) {
    for (std::size_t i = 0; i + 1 < grid.nx; ++i) {
      const std::array<std::size_t, 4> k{grid.index(i, j), grid.index(i + 1, j),
                                         grid.index(i + 1, j + 1), grid.index(i, j + 1)};
      if (!usable(k[0]) || !usable(k[1]) || !usable(k[2]) || !usable(k[3])) continue;
      const int code = (above(k[0]) ? 1 : 0) | (above(k[1]) ? 2 : 0) | (above(k[2]) ? 4 : 0) |
                       (above(k[3]) ? 8 : 0);
      if (code == 0 || code == 15) continue;
      auto add = [&](int a, int b) {
        segments.push_back({{sweep.edge_id(i, j, a), sweep.edge_id(i, j, b)}});
      };
      if (code == 5 || code == 10) {
        // Corners 0, 2 above (5) or 1, 3 above (10). If the above corners connect through the
        // centre, the isoline cuts off the two below corners, else the two above ones.
        const bool centre = saddle_above(i, j);
        const bool cut_13 = (code == 5) == centre;  // cut off corners 1 and 3
        if (cut_13) {
          add(0, 1);
          add(2, 3);
        } else {
          add(0, 3);
          add(1, 2);
        }
        continue;
      }
      // One segment through the two edges whose corners differ.
      static constexpr std::array<std::array<int, 2>, 4> corners{{{0, 1}, {1, 2}, {3, 2}, {0, 3}}};
      int found[2], n = 0;
      for (int e = 0; e < 4; ++e) {
        const bool a = (code >> corners[e][0]) & 1, b = (code >> corners[e][1]) & 1;
        if (a != b) found[n++] = e;
      }
      add(found[0], found[1]);
    }
  }
  if (segments.empty()) return lines;

  // Join: each edge point is shared by at most two segment ends.
  const std::size_t ends = 2 * segments.size();
  std::vector<std::pair<std::size_t, std::size_t>> by_edge(ends);  // (edge id, end)
  for (std::size_t s = 0; s < segments.size(); ++s) {
    by_edge[2 * s] = {segments[s].edge[0], 2 * s};
    by_edge[2 * s + 1] = {segments[s].edge[1], 2 * s + 1};
  }
  std::sort(by_edge.begin(), by_edge.end());
  constexpr std::size_t none = static_cast<std::size_t>(-1);
  std::vector<std::size_t> neighbour(ends, none);
  std::vector<Point> point(ends);
  for (std::size_t a = 0; a < ends;) {
    std::size_t b = a + 1;
    while (b < ends && by_edge[b].first == by_edge[a].first) ++b;
    const auto [n0, n1] = sweep.nodes(by_edge[a].first);
    const Point p = crossing(n0, n1);
    for (std::size_t c = a; c < b; ++c) point[by_edge[c].second] = p;
    if (b - a == 2) {
      neighbour[by_edge[a].second] = by_edge[a + 1].second;
      neighbour[by_edge[a + 1].second] = by_edge[a].second;
    }
    a = b;
  }

  std::vector<std::uint8_t> used(segments.size(), 0);
  // Walks from end `start` (the entry end of its segment) until the chain stops or closes.
  auto walk = [&](std::size_t start) {
    Polyline line;
    line.points.push_back(point[start]);
    std::size_t entry = start;
    for (;;) {
      const std::size_t s = entry / 2, exit = entry ^ 1;
      used[s] = 1;
      const std::size_t next = neighbour[exit];
      if (next == start) {  // back at the first point
        line.closed = true;
        break;
      }
      line.points.push_back(point[exit]);
      if (next == none || used[next / 2]) break;
      entry = next;
    }
    lines.push_back(std::move(line));
  };
  for (std::size_t e = 0; e < ends; ++e)
    if (neighbour[e] == none && !used[e / 2]) walk(e);
  for (std::size_t s = 0; s < segments.size(); ++s)
    if (!used[s]) walk(2 * s);
  return lines;
}

}  // namespace

std::vector<Polyline> contour(const ScalarField& field, double level) {
  const Grid& g = field.grid;
  const Sweep sweep{g};
  const double* v = field.values.data();
  auto usable = [&](std::size_t k) {
    return (field.valid.empty() || field.valid[k] != 0) && std::isfinite(v[k]);
  };
  auto above = [&](std::size_t k) { return v[k] >= level; };
  auto saddle = [&](std::size_t i, std::size_t j) {
    const double a = field.at(i, j), b = field.at(i + 1, j), c = field.at(i + 1, j + 1),
                 d = field.at(i, j + 1);
    // Bilinear f = a(1-s)(1-t) + b s(1-t) + c s t + d (1-s) t has its saddle value
    // (a c - b d) / (a + c - b - d); the denominator is nonzero in a saddle cell.
    return (a * c - b * d) / (a + c - b - d) >= level;
  };
  auto crossing = [&](std::size_t a, std::size_t b) {
    const Point pa = sweep.node_point(a), pb = sweep.node_point(b);
    const double t = (level - v[a]) / (v[b] - v[a]);
    return Point{pa.x + t * (pb.x - pa.x), pa.y + t * (pb.y - pa.y)};
  };
  return march(g, usable, above, saddle, crossing);
}

std::vector<Polyline> region_boundary(const Grid& g, std::span<const std::uint8_t> flags,
                                      const std::function<bool(double, double)>& inside,
                                      int bisections) {
  const Sweep sweep{g};
  auto usable = [](std::size_t) { return true; };
  auto above = [&](std::size_t k) { return flags[k] != 0; };
  auto saddle = [&](std::size_t i, std::size_t j) {
    return inside(0.5 * (g.x(i) + g.x(i + 1)), 0.5 * (g.y(j) + g.y(j + 1)));
  };
  auto crossing = [&](std::size_t a, std::size_t b) {
    Point in = sweep.node_point(a), out = sweep.node_point(b);
    if (flags[a] == 0) std::swap(in, out);
    for (int it = 0; it < bisections; ++it) {
      const Point mid{0.5 * (in.x + out.x), 0.5 * (in.y + out.y)};
      (inside(mid.x, mid.y) ? in : out) = mid;
    }
    return Point{0.5 * (in.x + out.x), 0.5 * (in.y + out.y)};
  };
  return march(g, usable, above, saddle, crossing);
}

}  // namespace halfback::figure
