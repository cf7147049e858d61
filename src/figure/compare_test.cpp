// The comparison figure (compare.hpp): its log-ratio panels and albedo curves hold the values
// known for pairs of BRDFs where they are known.
#include "halfback/figure/compare.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <variant>

#include "halfback/figure/color.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::figure {
namespace {

CompareFigureOptions small(const std::string& a, const std::string& b) {
  CompareFigureOptions o;
  o.reference = load_brdf(a);
  o.compared = load_brdf(b);
  o.panel_size = 40;
  o.pixels_per_point = 1;
  o.albedo_step_deg = 15;
  o.albedo_samples = 16;
  return o;
}

std::vector<const ImageItem*> images(const Scene& s) {
  std::vector<const ImageItem*> out;
  for (const Item& i : s.items)
    if (const auto* im = std::get_if<ImageItem>(&i)) out.push_back(im);
  return out;
}

// Every pixel of a log-ratio panel (the third raster of each column: A, B, ratio) is either the
// hatching outside the domain or `expected`; returns the count of the latter.
std::size_t count_ratio_pixels(const ImageItem& im, const Color& expected) {
  const std::uint8_t e[3] = {to_byte(expected.r), to_byte(expected.g), to_byte(expected.b)};
  const std::uint8_t light = to_byte(kInvalidLight.r), dark = to_byte(kInvalidDark.r);
  std::size_t n = 0;
  for (std::size_t p = 0; p < im.px_width * im.px_height; ++p) {
    const std::uint8_t* c = &im.rgba[4 * p];
    if (c[0] == e[0] && c[1] == e[1] && c[2] == e[2]) {
      ++n;
      continue;
    }
    EXPECT_TRUE((c[0] == light || c[0] == dark) && c[0] == c[1] && c[1] == c[2])
        << "pixel " << p << ": " << int(c[0]) << ", " << int(c[1]) << ", " << int(c[2]);
  }
  return n;
}

// ρ_B / ρ_A = 1.2 everywhere: log10 1.2 = 0.0792, whose scale rounds up to 0.080; the albedos are
// 0.5 and 0.6 at every incidence (the cosine estimator of a constant ρ is exact).
TEST(CompareFigure, TwoLambertiansHaveAConstantRatioAndFlatAlbedos) {
  const CompareFigure f = compare_figure(small("lambert:albedo=0.5", "lambert:albedo=0.6"));
  EXPECT_DOUBLE_EQ(f.ratio_range, 0.08);
  const Color expected = diverging(0.5 + 0.5 * std::log10(1.2) / 0.08);
  const auto im = images(f.scene);
  ASSERT_EQ(im.size(), 3u * 3 + 2);  // three columns of three panels, two colour bars
  for (std::size_t c = 0; c < 3; ++c) EXPECT_GT(count_ratio_pixels(*im[3 * c + 2], expected), 500u);
  ASSERT_EQ(f.albedo_theta_deg.size(), 6u);  // 0, 15, ..., 75
  for (std::size_t k = 0; k < f.albedo_theta_deg.size(); ++k) {
    EXPECT_NEAR(f.albedo_reference[k], 0.5, 1e-9);
    EXPECT_NEAR(f.albedo_compared[k], 0.6, 1e-9);
  }
}

// A BRDF against itself: the ratio is 1, drawn white on the smallest scale; the curves coincide.
TEST(CompareFigure, ABrdfAgainstItselfIsWhiteAndItsCurvesCoincide) {
  const CompareFigure f = compare_figure(small("ggx:alpha=0.2", "ggx:alpha=0.2"));
  EXPECT_DOUBLE_EQ(f.ratio_range, 0.01);
  EXPECT_LT(f.log_lo, f.log_hi);
  const auto im = images(f.scene);
  ASSERT_EQ(im.size(), 11u);
  for (std::size_t c = 0; c < 3; ++c) EXPECT_GT(count_ratio_pixels(*im[3 * c + 2], kWhite), 500u);
  EXPECT_EQ(f.albedo_reference, f.albedo_compared);
}

TEST(CompareFigure, DivergingMapIsWhiteAtTheCentreAndBlueToRed) {
  EXPECT_EQ(diverging(0.5), (Color{1, 1, 1, 1}));
  const Color lo = diverging(0), hi = diverging(1);
  EXPECT_GT(lo.b, lo.r);
  EXPECT_GT(hi.r, hi.b);
  EXPECT_EQ(diverging(-1), lo);  // clamped
  EXPECT_TRUE(std::isnan(diverging(std::nan("")).r));
}

TEST(CompareFigure, RefusesBadOptions) {
  CompareFigureOptions o = small("lambert", "ggx");
  o.compared = nullptr;
  EXPECT_THROW(compare_figure(o), std::invalid_argument);
  o = small("lambert", "ggx");
  o.azimuths_deg.clear();
  EXPECT_THROW(compare_figure(o), std::invalid_argument);
  o = small("lambert", "ggx");
  o.albedo_step_deg = 0;
  EXPECT_THROW(compare_figure(o), std::invalid_argument);
  o = small("lambert", "ggx");
  o.param = Space::dirs;
  EXPECT_THROW(compare_figure(o), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::figure
