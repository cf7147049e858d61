#include "halfback/figure/slices.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "halfback/figure/plot.hpp"
#include "halfback/figure/render.hpp"

namespace halfback::figure {
namespace {

constexpr double kDeg = std::numbers::pi / 180;

// Raster pixel (column, row from the top) of data point (x, y) of a panel.
std::pair<std::size_t, std::size_t> pixel_of(const PanelMap& m, double x, double y, double scale) {
  const Point p = m.to_page(x, y);
  return {std::size_t(std::floor(p.x * scale)), std::size_t(std::floor(p.y * scale))};
}

bool is_invalid_style(const std::array<std::uint8_t, 4>& c) {
  for (const Color& h : {kInvalidLight, kInvalidDark})
    if (c[0] == to_byte(h.r) && c[1] == to_byte(h.g) && c[2] == to_byte(h.b)) return true;
  return false;
}

TEST(Slices, OutsideTheDomainIsDrawnInvalid) {
  SliceOptions o;
  o.params = {space_of<Ortho>, space_of<Hybrid>, space_of<HalfDiff>};
  o.azimuths_deg = {0};
  o.threads = 2;
  const auto fig = slice_figure(o);
  const Raster r = rasterize(fig.scene, o.pixels_per_point);
  // ortho at Δφ = 0: valid iff ‖h̄‖ + ‖k̄‖ ≤ 1; hybrid: iff ‖h̄‖² + ‖k‖² ≤ 1 and the elevations
  // are ≥ 0; halfdiff at φd = 0: iff θh + θd ≤ 90°.
  struct Probe {
    std::size_t panel;
    double x, y;
    bool valid;
  };
  for (const Probe& p :
       {Probe{0, 0.9, 0.9, false}, Probe{0, 0.6, 0.5, false}, Probe{0, 0.3, 0.2, true},
        Probe{1, 0.9, 0.9, false}, Probe{1, 0.8, 0.5, false}, Probe{1, 0.2, 0.3, true},
        Probe{2, 60 * kDeg, 50 * kDeg, false}, Probe{2, 30 * kDeg, 20 * kDeg, true}}) {
    const auto& panel = fig.panels[p.panel];
    const auto [px, py] = pixel_of(panel.map, p.x, p.y, o.pixels_per_point);
    EXPECT_EQ(is_invalid_style(r.pixel(px, py)), !p.valid)
        << name_of(panel.param) << " " << p.x << " " << p.y;
  }
  // Every sample: the mask is valid_iso, and the invalid ones are hatched, never black.
  for (const auto& panel : fig.panels) {
    std::size_t invalid = 0;
    for (std::size_t k = 0; k < panel.sample.valid.size(); ++k) invalid += !panel.sample.valid[k];
    EXPECT_GT(invalid, panel.sample.valid.size() / 5) << name_of(panel.param);
  }
}

TEST(Slices, SpecularIsolineIsAVerticalLineInOrthoAndHybrid) {
  // S = 1 − ‖h̄‖, and x = ‖h̄‖: the isoline S = 1 − c is the line x = c, on every slice.
  for (double c : {0.2, 0.35, 0.5, 0.77}) {
    SliceOptions o;
    o.params = {space_of<Ortho>, space_of<Hybrid>};
    o.azimuths_deg = {0, 45, 90, 150};
    o.test_functions = {TestFunction::specular};
    o.levels = {1 - c};
    o.pixels_per_point = 2;
    const auto fig = slice_figure(o);
    const Raster r = rasterize(fig.scene, o.pixels_per_point);
    for (const auto& p : fig.panels) {
      // The marching-squares geometry: exact up to rounding.
      const auto lines = contour(test_function_field(p.sample, TestFunction::specular), 1 - c);
      ASSERT_FALSE(lines.empty());
      std::size_t points = 0;
      for (const auto& l : lines)
        for (const Point& q : l.points) {
          EXPECT_NEAR(q.x, c, 1e-12);
          ++points;
        }
      EXPECT_GT(points, 20u);
      // The rendered image: along the line x = c, inside the domain, the pixel is red; three
      // pixels to either side it is the dark background.
      const auto [px, py] = pixel_of(p.map, c, 0.05, o.pixels_per_point);
      const auto on = r.pixel(px, py);
      EXPECT_GT(on[0], 150) << name_of(p.param) << " " << p.azimuth_deg << " " << c;
      EXPECT_LT(on[2], 120);
      for (int d : {-3, 3}) {
        const auto off = r.pixel(std::size_t(int(px) + d), py);
        EXPECT_LT(off[0], 40) << name_of(p.param) << " " << p.azimuth_deg << " " << c;
      }
    }
  }
}

TEST(Slices, OrthoAndHybridCoincideAt90Degrees) {
  SliceOptions o;
  o.params = {space_of<Ortho>, space_of<Hybrid>};
  o.azimuths_deg = {90};
  const auto fig = slice_figure(o);
  const auto& a = fig.panels[0].sample;
  const auto& b = fig.panels[1].sample;
  ASSERT_EQ(a.valid.size(), b.valid.size());
  std::size_t mask_differences = 0;
  for (std::size_t k = 0; k < a.valid.size(); ++k) {
    mask_differences += a.valid[k] != b.valid[k];
    if (!a.valid[k] || !b.valid[k]) continue;
    for (auto [u, v] :
         {std::pair{a.pairs[k].wi, b.pairs[k].wi}, std::pair{a.pairs[k].wo, b.pairs[k].wo}}) {
      EXPECT_NEAR(u.x, v.x, 1e-12);
      EXPECT_NEAR(u.y, v.y, 1e-12);
      EXPECT_NEAR(u.z, v.z, 1e-12);
    }
  }
  EXPECT_EQ(mask_differences, 0u);
  // The two panels are drawn identically (same column, rows a whole number of pixels apart).
  const Raster r = rasterize(fig.scene, o.pixels_per_point);
  const auto& ma = fig.panels[0].map;
  const auto& mb = fig.panels[1].map;
  const std::size_t x0 = std::size_t(ma.rect.x * 2) + 2, y0a = std::size_t(ma.rect.y * 2) + 2,
                    y0b = std::size_t(mb.rect.y * 2) + 2;
  const std::size_t w = std::size_t(ma.rect.w * 2) - 4, h = std::size_t(ma.rect.h * 2) - 4;
  std::size_t differing = 0;
  for (std::size_t y = 0; y < h; ++y)
    for (std::size_t x = 0; x < w; ++x) {
      const auto pa = r.pixel(x0 + x, y0a + y), pb = r.pixel(x0 + x, y0b + y);
      for (int ch = 0; ch < 3; ++ch) differing += std::abs(int(pa[ch]) - int(pb[ch])) > 1;
    }
  EXPECT_EQ(differing, 0u);
  // Not the case at 0°, where hybrid's domain is larger.
  o.azimuths_deg = {0};
  const auto other = slice_figure(o);
  std::size_t diff0 = 0;
  for (std::size_t k = 0; k < other.panels[0].sample.valid.size(); ++k)
    diff0 += other.panels[0].sample.valid[k] != other.panels[1].sample.valid[k];
  EXPECT_GT(diff0, 1000u);
}

TEST(Slices, GrazingIsCircularInHybridOnlyAt90Degrees) {
  // G = 1 − zi zo = ‖h̄‖² + ‖k‖² where kz = 0 (docs/math.md §8): circles at 90° only.
  SliceOptions o;
  o.params = {space_of<Hybrid>};
  o.azimuths_deg = {90, 0};
  o.pixels_per_point = 1;
  const auto fig = slice_figure(o);
  const double level = 0.5;
  double worst90 = 0, worst0 = 0;
  for (const auto& p : fig.panels) {
    for (const auto& l : contour(test_function_field(p.sample, TestFunction::grazing), level))
      for (const Point& q : l.points) {
        const double e = std::abs(q.x * q.x + q.y * q.y - level);
        (p.azimuth_deg == 90 ? worst90 : worst0) =
            std::max(p.azimuth_deg == 90 ? worst90 : worst0, e);
      }
  }
  EXPECT_LT(worst90, 1e-4);
  EXPECT_GT(worst0, 0.05);
}

TEST(Slices, GenericBrdfMode) {
  SliceOptions o;
  o.params = {space_of<HalfDiff>, space_of<Hybrid>};
  o.azimuths_deg = {0, 90};
  o.brdf = std::make_shared<TestFunctionBrdf>(TestFunction::grazing);
  o.pixels_per_point = 1;
  const auto fig = slice_figure(o);
  // G ranges over (0, 1]: the shared scale ends at its maximum, log10 1 = 0, and the isoline
  // levels are log-spaced inside it.
  EXPECT_NEAR(fig.log_hi, 0.0, 1e-3);
  EXPECT_LT(fig.log_lo, -1.0);
  ASSERT_GE(fig.log_levels.size(), 3u);
  EXPECT_LE(fig.log_levels.size(), o.luminance_levels);
  for (double l : fig.log_levels) {
    EXPECT_GT(l, fig.log_lo);
    EXPECT_LT(l, fig.log_hi);
  }
  // A valid pixel is drawn in viridis of its log luminance.
  const Raster r = rasterize(fig.scene, 1);
  const auto& p = fig.panels[1];
  const double x = 0.3, y = 0.4;
  const auto [px, py] = pixel_of(p.map, x, y, 1);
  const Grid& g = p.sample.grid;
  const std::size_t i = px - std::size_t(p.map.rect.x),
                    j = g.ny - 1 - (py - std::size_t(p.map.rect.y));
  const auto& pair = p.sample.pairs[g.index(i, j)];
  const double lum = 1 - pair.wi.z * pair.wo.z;
  const Color expect = viridis((std::log10(lum) - fig.log_lo) / (fig.log_hi - fig.log_lo));
  const auto c = r.pixel(px, py);
  EXPECT_NEAR(c[0], 255 * expect.r, 1.01);
  EXPECT_NEAR(c[1], 255 * expect.g, 1.01);
  EXPECT_NEAR(c[2], 255 * expect.b, 1.01);
  // RGB mode renders too, on the same slices.
  o.colouring = SliceColouring::rgb;
  EXPECT_NO_THROW(slice_figure(o));
}

// Every left-aligned text lies inside the page by the layout's own width estimate, and the
// legend's strips too, whatever the columns: with one column the heading and the test functions'
// legend were cut at the page's right edge; they wrap into lines and rows now.
TEST(Slices, TextsAndLegendFitThePageWhateverTheColumns) {
  for (const bool generic : {false, true})
    for (const std::vector<double>& azimuths :
         {std::vector<double>{90}, std::vector<double>{0, 45, 90}}) {
      SliceOptions o;
      o.params = {space_of<Hybrid>};
      o.azimuths_deg = azimuths;
      if (generic) o.brdf = std::make_shared<TestFunctionBrdf>(TestFunction::grazing);
      o.pixels_per_point = 0.2;
      const auto fig = slice_figure(o);
      const std::string where = (generic ? "generic, " : "test functions, ") +
                                std::to_string(azimuths.size()) + " columns";
      double lowest = 0;
      for (const Item& item : fig.scene.items) {
        if (const auto* t = std::get_if<TextItem>(&item);
            t && t->halign == HAlign::left && t->angle == 0) {
          EXPECT_LE(t->at.x + approx_text_width(t->text, t->size), fig.scene.width)
              << where << ": " << t->text;
          lowest = std::max(lowest, t->at.y);
        }
        if (const auto* p = std::get_if<PathItem>(&item); p && p->fill) {
          for (const Point& q : p->points) {
            EXPECT_LE(q.x, fig.scene.width + 1e-9) << where;
          }
        }
      }
      EXPECT_LT(lowest, fig.scene.height) << where;
    }
}

TEST(Slices, LogLevels) {
  EXPECT_EQ(log_levels(-3.5, 0.5, 10), (std::vector<double>{-3, -2, -1, 0}));
  const auto l = log_levels(-1.01, 0.01, 5);  // 1-2-5 steps over one decade
  ASSERT_EQ(l.size(), 4u);
  EXPECT_NEAR(l[1], std::log10(0.2), 1e-12);
  EXPECT_EQ(log_levels(-1.01, 0.01, 10).size(), 10u);  // 1, 2, …, 9, 10
  EXPECT_EQ(log_levels(-30, 0, 5).size(), 5u);         // every 6th decade
}

TEST(Slices, BadInput) {
  SliceOptions o;
  o.azimuths_deg = {};
  try {
    slice_figure(o);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no azimuth"), std::string::npos);
  }
  o.azimuths_deg = {0};
  o.params = {Space::dirs};
  EXPECT_THROW(slice_figure(o), std::invalid_argument);
  o.params = {};
  EXPECT_THROW(slice_figure(o), std::invalid_argument);
  o.params = {space_of<Hybrid>};
  o.test_functions = {};
  EXPECT_THROW(slice_figure(o), std::invalid_argument);
  o.test_functions = {TestFunction::fresnel};
  o.azimuths_deg = {NAN};
  EXPECT_THROW(slice_figure(o), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::figure
