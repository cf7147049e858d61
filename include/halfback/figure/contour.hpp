// Marching squares: isolines of sampled scalar fields, and boundaries of regions.
//
// A cell is the square between four neighbouring grid nodes. A node is "above" when its value is
// >= the level. Where the level separates the two nodes of a cell edge, the isoline crosses that
// edge at the point given by linear interpolation of the two sampled values, so a field that is
// linear along the edges (a ramp, or x on an ortho slice) is contoured exactly. Saddle cells (the
// two diagonals on opposite sides) are resolved with the asymptotic decider: the value of the
// bilinear interpolant at its saddle point says whether the "above" corners are connected.
// Cells with a corner that is invalid or not finite are skipped: isolines stop there.
// Segments are joined into polylines through their shared edge points; a polyline that comes back
// to its start is marked closed (and does not repeat its first point).
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "halfback/figure/field.hpp"

namespace halfback::figure {

struct Point {
  double x = 0, y = 0;
  friend bool operator==(const Point&, const Point&) = default;
};

struct Polyline {
  std::vector<Point> points;
  bool closed = false;
};

// The isolines of `field` at `level`, in the field's data coordinates.
std::vector<Polyline> contour(const ScalarField& field, double level);

// The boundary of the region where inside(x, y) is true, traced through the grid: `flags` holds
// inside() at every node (grid.size() values). Where two neighbouring nodes differ, the crossing is
// located by bisection on inside() along the edge, to `bisections` halvings of the edge (30:
// ~1e-9 of a cell), so a curved domain boundary is placed exactly, not at a pixel staircase.
std::vector<Polyline> region_boundary(const Grid& grid, std::span<const std::uint8_t> flags,
                                      const std::function<bool(double, double)>& inside,
                                      int bisections = 30);

}  // namespace halfback::figure
