#include "halfback/figure/hemisphere.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "halfback/figure/plot.hpp"
#include "halfback/figure/render.hpp"

namespace halfback::figure {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180;

double angle_between(const Vec3<double>& a, const Vec3<double>& b) {
  const double c = a.x * b.x + a.y * b.y + a.z * b.z;
  const double s =
      std::sqrt(std::pow(a.y * b.z - a.z * b.y, 2) + std::pow(a.z * b.x - a.x * b.z, 2) +
                std::pow(a.x * b.y - a.y * b.x, 2));
  return std::atan2(s, c);
}

// The raster pixel (column, row counted from the top) under page point p at `scale` px/pt.
std::pair<std::size_t, std::size_t> pixel_of(Point p, double scale) {
  return {std::size_t(std::floor(p.x * scale)), std::size_t(std::floor(p.y * scale))};
}

TEST(HemisphereView, ProjectionsRoundTripAndAreEqualArea) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (Projection proj :
       {Projection::equal_area, Projection::orthographic, Projection::equidistant})
    for (ViewCentre which : {ViewCentre::normal, ViewCentre::mirror, ViewCentre::back}) {
      const auto view = HemisphereView::make(which, outgoing_direction(50 * kDeg), proj);
      for (int n = 0; n < 2000; ++n) {
        const double a = u(rng), b = u(rng);
        const auto w = view.direction(a, b);
        if (std::hypot(a, b) > 1) {
          EXPECT_FALSE(w.has_value());
          continue;
        }
        ASSERT_TRUE(w.has_value());
        EXPECT_NEAR(w->x * w->x + w->y * w->y + w->z * w->z, 1.0, 1e-14);
        const auto back = view.project(*w);
        ASSERT_TRUE(back.has_value());
        EXPECT_NEAR(back->x, a, 1e-9);
        EXPECT_NEAR(back->y, b, 1e-9);
      }
    }
  // Equal area: the cap within ψ of the centre has solid angle 2π(1 − cos ψ) and covers the
  // fraction (1 − cos ψ) of the disk, r² = 1 − cos ψ.
  const auto view = HemisphereView::around({0, 0, 1}, Projection::equal_area);
  for (double psi : {10.0, 45.0, 60.0, 89.0}) {
    const auto p = view.project({std::sin(psi * kDeg), 0, std::cos(psi * kDeg)});
    EXPECT_NEAR(p->x * p->x, 1 - std::cos(psi * kDeg), 1e-14);
  }
  // The normal view is the top view: x right, y up.
  EXPECT_NEAR(view.project({1, 0, 0})->x, 1.0, 1e-15);
  EXPECT_NEAR(view.project({0, 1, 0})->y, 1.0, 1e-15);
  EXPECT_FALSE(view.project({0, 0, -1}).has_value());
}

TEST(HemisphereFigure, MirrorPixelHasZeroThetaH) {
  HemisphereOptions o;
  o.params = {space_of<HalfDiff>};
  o.elevations_deg = {35};  // θd = 35° at the mirror pair: not an isoline level
  o.markers = false;
  o.threads = 2;
  const auto fig = hemisphere_figure(o);
  ASSERT_EQ(fig.panels.size(), 1u);
  const auto& p = fig.panels[0];
  const Vec3<double> m = mirror_direction(p.wo);
  EXPECT_NEAR(m.x, std::sin(35 * kDeg), 1e-15);  // on the right of the disk
  const auto disk = p.view.project(m);
  ASSERT_TRUE(disk.has_value());
  const Point page = p.map.to_page(disk->x, disk->y);
  // The sample at that pixel: θh within the angular size of a pixel (2/D·o.ppp of the disk
  // radius; dψ/dr ≤ 90°·√2/… < 1.6 rad per unit radius for equal-area).
  const auto [px, py] = pixel_of(page, o.pixels_per_point);
  const std::size_t i = px - std::size_t(std::lround(p.map.rect.x * o.pixels_per_point));
  const std::size_t j =
      p.sample.grid.ny - 1 - (py - std::size_t(std::lround(p.map.rect.y * o.pixels_per_point)));
  const double pixel_radius = 2.0 / double(p.sample.grid.nx);
  const double theta_h = p.sample.first.at(i, j);
  EXPECT_LT(theta_h, 1.6 * pixel_radius) << theta_h;
  // …and it is the minimum of θh over the disk.
  double min_theta_h = INFINITY;
  for (std::size_t k = 0; k < p.sample.first.values.size(); ++k)
    if (p.sample.region[k] == 2) min_theta_h = std::min(min_theta_h, p.sample.first.values[k]);
  EXPECT_NEAR(theta_h, min_theta_h, 1.6 * pixel_radius);
  // On the rendered image: red = θh / 90° is (almost) 0 there, green = θd / 90° = 35°/90°.
  const Raster r = decode_png(render(fig.scene, Format::png, {o.pixels_per_point}));
  const auto c = r.pixel(px, py);
  EXPECT_LE(c[0], 6);
  EXPECT_NEAR(c[1], 255 * 35.0 / 90.0, 4);
  EXPECT_EQ(c[2], 0);
  // The back direction ωi = ωo: θd = 0, green 0.
  const auto b = p.view.project(p.wo);
  const auto [bx, by] = pixel_of(p.map.to_page(b->x, b->y), o.pixels_per_point);
  EXPECT_LE(r.pixel(bx, by)[1], 6);
}

TEST(HemisphereFigure, CentredViews) {
  for (ViewCentre which : {ViewCentre::mirror, ViewCentre::back}) {
    HemisphereOptions o;
    o.params = {space_of<HalfDiff>, space_of<Hybrid>};
    o.elevations_deg = {80};
    o.centre = which;
    o.markers = false;
    const auto fig = hemisphere_figure(o);
    const auto& p = fig.panels[0];
    const Vec3<double> target = which == ViewCentre::mirror ? mirror_direction(p.wo) : p.wo;
    EXPECT_LT(angle_between(*p.view.direction(0, 0), target), 1e-15);
    // The pixel next to the centre: θh = 0 (mirror) or θd = 0 (back) within its angular distance
    // from the centre, ψ ≈ √2 r = 2/n; ĥ turns by up to ψ / (2 cos θd) when ωi turns by ψ.
    const std::size_t n = p.sample.grid.nx;
    const double centre_value =
        (which == ViewCentre::mirror ? p.sample.first : p.sample.second).at(n / 2, n / 2);
    EXPECT_LT(centre_value, 1.2 * (2.0 / double(n)) / (2 * std::cos(80 * kDeg))) << name_of(which);
    // The right edge of the disk is 90° from a centre at 80° from n towards the horizon: below
    // it, and drawn with the below-horizon hatching.
    const Raster r = rasterize(fig.scene, o.pixels_per_point);
    const double sign = which == ViewCentre::mirror ? 1 : -1;  // away from n
    // Mirror: e1 points away from n; back: ωo is at azimuth π, so e1 (b × ωo) points towards n.
    const auto w = p.view.direction(sign * 0.93, 0.0);
    ASSERT_TRUE(w.has_value());
    EXPECT_LT(w->z, 0) << name_of(which);
    const auto [px, py] = pixel_of(p.map.to_page(sign * 0.93, 0.0), o.pixels_per_point);
    const auto c = r.pixel(px, py);
    const bool light =
        c[0] == to_byte(kBelowHorizonLight.r) && c[1] == to_byte(kBelowHorizonLight.g);
    const bool dark = c[0] == to_byte(kBelowHorizonDark.r) && c[1] == to_byte(kBelowHorizonDark.g);
    EXPECT_TRUE(light || dark) << int(c[0]) << " " << int(c[1]) << " " << int(c[2]);
    const std::size_t i = px - std::size_t(std::lround(p.map.rect.x * o.pixels_per_point));
    EXPECT_EQ(p.sample.region[p.sample.grid.index(i, n / 2)], 1);
  }
}

TEST(HemisphereFigure, NormalViewHasNoBelowHorizonAndColoursAreTheCoordinates) {
  HemisphereOptions o;
  o.params = {space_of<Ortho>};
  o.elevations_deg = {0, 60};
  o.pixels_per_point = 1;
  const auto fig = hemisphere_figure(o);
  for (const auto& p : fig.panels) {
    for (std::size_t k = 0; k < p.sample.region.size(); ++k) EXPECT_NE(p.sample.region[k], 1);
    // Spot check: the sampled coordinates are the forward map of the pixel's pair.
    const Grid& g = p.sample.grid;
    const std::size_t i = g.nx / 3, j = g.ny / 4, k = g.index(i, j);
    ASSERT_EQ(p.sample.region[k], 2);
    const auto w = p.view.direction(g.x(i), g.y(j));
    const Tuple3<double> q = Ortho::forward_iso(DirPair<double>{*w, p.wo});
    EXPECT_EQ(p.sample.first.values[k], q[0]);
    EXPECT_EQ(p.sample.second.values[k], q[1]);
  }
}

// Every text of the figure lies inside the page, by the layout's own width estimate: with one
// column the heading, subtitle and notes are wider than the panels and were cut at the page's
// right edge; they wrap now, and the page grows in height for their lines.
TEST(HemisphereFigure, TextsFitThePageWhateverTheColumns) {
  for (const std::vector<double>& elevations :
       {std::vector<double>{30}, std::vector<double>{0, 60}, std::vector<double>{0, 40, 80}}) {
    HemisphereOptions o;
    o.params = {space_of<Hybrid>};
    o.elevations_deg = elevations;
    o.pixels_per_point = 0.2;
    const auto fig = hemisphere_figure(o);
    double lowest = 0;
    for (const Item& item : fig.scene.items) {
      const auto* t = std::get_if<TextItem>(&item);
      if (!t || t->halign != HAlign::left || t->angle != 0) continue;
      EXPECT_LE(t->at.x + approx_text_width(t->text, t->size), fig.scene.width)
          << elevations.size() << " columns: " << t->text;
      lowest = std::max(lowest, t->at.y);
    }
    EXPECT_LT(lowest, fig.scene.height) << elevations.size() << " columns";
  }
}

TEST(HemisphereFigure, BadInput) {
  HemisphereOptions o;
  o.params = {};
  EXPECT_THROW(hemisphere_figure(o), std::invalid_argument);
  o.params = {Space::dirs};
  EXPECT_THROW(hemisphere_figure(o), std::invalid_argument);
  o.params = {space_of<Hybrid>};
  o.elevations_deg = {};
  EXPECT_THROW(hemisphere_figure(o), std::invalid_argument);
  o.elevations_deg = {95};
  EXPECT_THROW(hemisphere_figure(o), std::invalid_argument);
  o.elevations_deg = {NAN};
  EXPECT_THROW(hemisphere_figure(o), std::invalid_argument);
  // Too many panels for an image: refused from the layout, before any field is sampled (901
  // elevations once took 48 s and 5.7 GB before Cairo refused the page).
  o.elevations_deg.assign(901, 30.0);
  try {
    hemisphere_figure(o);
    ADD_FAILURE() << "no error for 901 elevations";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fewer elevations (901 given)"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("32767 pixels per side"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(projection_from_name("mercator").has_value());
  EXPECT_EQ(projection_from_name("equal-area"), Projection::equal_area);
  EXPECT_EQ(view_centre_from_name("back"), ViewCentre::back);
}

}  // namespace
}  // namespace halfback::figure
