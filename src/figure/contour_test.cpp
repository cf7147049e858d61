#include "halfback/figure/contour.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace halfback::figure {
namespace {

ScalarField field(std::size_t n, double lo, double hi,
                  const std::function<double(double, double)>& f) {
  return sample(Grid{n, n, lo, hi, lo, hi}, f, 1);
}

std::size_t total_points(const std::vector<Polyline>& lines) {
  std::size_t n = 0;
  for (const auto& l : lines) n += l.points.size();
  return n;
}

TEST(MarchingSquares, LinearRampIsExact) {
  // f = 0.3 x + 0.7 y: linear, so every crossing is exact, and the isoline is one open polyline
  // from border to border.
  const ScalarField f = field(41, -1, 1, [](double x, double y) { return 0.3 * x + 0.7 * y; });
  for (double level : {-0.5, 0.0, 0.123, 0.6}) {
    const auto lines = contour(f, level);
    ASSERT_EQ(lines.size(), 1u) << level;
    EXPECT_FALSE(lines[0].closed);
    EXPECT_GT(lines[0].points.size(), 10u);
    for (const Point& p : lines[0].points) EXPECT_NEAR(0.3 * p.x + 0.7 * p.y, level, 1e-12);
    // Ends on the border of the grid.
    for (const Point& e : {lines[0].points.front(), lines[0].points.back()})
      EXPECT_NEAR(std::max(std::abs(e.x), std::abs(e.y)), 1.0, 1e-12);
  }
  EXPECT_TRUE(contour(f, 5.0).empty());
}

TEST(MarchingSquares, CircleIsOneClosedLoop) {
  // f = r: the isoline at 0.6 is a circle, found within the interpolation error of a 1/50 grid.
  const ScalarField f = field(101, -1, 1, [](double x, double y) { return std::hypot(x, y); });
  const double h = 2.0 / 100;
  for (double radius : {0.6, 0.25, 0.9}) {
    const auto lines = contour(f, radius);
    ASSERT_EQ(lines.size(), 1u);
    EXPECT_TRUE(lines[0].closed);
    for (const Point& p : lines[0].points)
      EXPECT_NEAR(std::hypot(p.x, p.y), radius, h * h / radius);
    // Closed: the last point is a neighbour of the first, not a repeat of it.
    const Point a = lines[0].points.front(), b = lines[0].points.back();
    EXPECT_GT(std::hypot(a.x - b.x, a.y - b.y), 0.0);
    EXPECT_LT(std::hypot(a.x - b.x, a.y - b.y), 2 * h);
    // The polygon's area is that of the disk.
    double area = 0;
    const auto& q = lines[0].points;
    for (std::size_t i = 0; i < q.size(); ++i) {
      const Point& u = q[i];
      const Point& v = q[(i + 1) % q.size()];
      area += 0.5 * (u.x * v.y - v.x * u.y);
    }
    EXPECT_NEAR(std::abs(area), std::numbers::pi * radius * radius, 2e-3);
  }
  // r² is not linear along edges, but still gives a circle within O(h²).
  const ScalarField g = field(101, -1, 1, [](double x, double y) { return x * x + y * y; });
  const auto lines = contour(g, 0.25);
  ASSERT_EQ(lines.size(), 1u);
  for (const Point& p : lines[0].points) EXPECT_NEAR(std::hypot(p.x, p.y), 0.5, 1e-3);
}

TEST(MarchingSquares, SaddleUsesTheAsymptoticDecider) {
  // f = x y on a grid whose only cell straddling 0 is the centre... use f = x y - c. The exact
  // isolines of x y = c are two hyperbola branches in opposite quadrants; a wrong saddle choice
  // connects them across the centre cell.
  for (double c : {0.01, -0.01}) {
    const ScalarField f = field(11, -1, 1, [c](double x, double y) { return x * y - c; });
    const auto lines = contour(f, 0.0);
    ASSERT_EQ(lines.size(), 2u) << c;
    for (const auto& l : lines) {
      EXPECT_FALSE(l.closed);
      // Each branch stays in one pair of quadrants: x y has the sign of c everywhere on it.
      for (const Point& p : l.points) EXPECT_GT(p.x * p.y * c, 0.0) << c;
      // Points on grid edges interpolate a function linear along the edge: exact.
      for (const Point& p : l.points) EXPECT_NEAR(p.x * p.y, c, 1e-12);
    }
  }
  // A single saddle cell: corners (0,0)=1, (1,0)=-1, (1,1)=1, (0,1)=-1 at level 0.1 and -0.1.
  Grid g{2, 2, 0, 1, 0, 1};
  ScalarField s(g);
  s.values = {1, -1, -1, 1};  // (0,0), (1,0), (0,1), (1,1): x y-like saddle, centre value 0
  for (double level : {0.1, -0.1}) {
    const auto lines = contour(s, level);
    ASSERT_EQ(lines.size(), 2u);
    // Centre value 0: at level 0.1 the centre is below, so the isoline cuts off the two "above"
    // corners (0,0) and (1,1) (segment midpoints on the main diagonal); at −0.1 it cuts off the
    // "below" corners (1,0) and (0,1) (midpoints on the other diagonal).
    for (const auto& l : lines) {
      ASSERT_EQ(l.points.size(), 2u);
      const Point mid{0.5 * (l.points[0].x + l.points[1].x), 0.5 * (l.points[0].y + l.points[1].y)};
      const bool main_diagonal = std::abs(mid.x - mid.y) < 1e-12;
      const bool other_diagonal = std::abs(mid.x + mid.y - 1) < 1e-12;
      EXPECT_EQ(main_diagonal, level > 0) << level;
      EXPECT_EQ(other_diagonal, level < 0) << level;
    }
  }
}

TEST(MarchingSquares, MaskStopsIsolines) {
  // Half the grid invalid: the isoline x = 0.3 of f = x exists only where y < 0.
  ScalarField f = field(21, -1, 1, [](double x, double) { return x; });
  for (std::size_t j = 0; j < f.grid.ny; ++j)
    for (std::size_t i = 0; i < f.grid.nx; ++i)
      if (f.grid.y(j) > 1e-12) f.valid[f.grid.index(i, j)] = 0;
  const auto lines = contour(f, 0.3);
  ASSERT_EQ(lines.size(), 1u);
  for (const Point& p : lines[0].points) {
    EXPECT_NEAR(p.x, 0.3, 1e-12);
    EXPECT_LE(p.y, 1e-12);
  }
  // NaN values are skipped too.
  ScalarField g = field(21, -1, 1, [](double x, double y) { return y > 0.5 ? NAN : x; });
  for (const auto& l : contour(g, 0.3))
    for (const Point& p : l.points) EXPECT_LE(p.y, 0.5);
  EXPECT_EQ(total_points(contour(g, 0.3)), 16u);  // y = −1 … 0.5 in steps of 0.1
}

TEST(MarchingSquares, RegionBoundaryIsExact) {
  // The unit disk sampled on a coarse grid: bisection puts the boundary on the circle.
  const Grid g{17, 17, -1.3, 1.3, -1.3, 1.3};
  auto inside = [](double x, double y) { return x * x + y * y <= 1.0; };
  std::vector<std::uint8_t> flags(g.size());
  for (std::size_t j = 0; j < g.ny; ++j)
    for (std::size_t i = 0; i < g.nx; ++i) flags[g.index(i, j)] = inside(g.x(i), g.y(j));
  const auto lines = region_boundary(g, flags, inside);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_TRUE(lines[0].closed);
  for (const Point& p : lines[0].points) EXPECT_NEAR(std::hypot(p.x, p.y), 1.0, 1e-8);
}

}  // namespace
}  // namespace halfback::figure
