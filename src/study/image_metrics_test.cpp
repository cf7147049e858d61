// The image metrics against published values (CIEDE2000, CIELAB) and cases known exactly.
#include "halfback/study/image_metrics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

namespace halfback::study {
namespace {

struct Pair {
  Lab x, y;
  double delta_e;
};

// Sharma, Wu & Dalal (2005), Table 1: all 34 pairs, in the table's order. Pairs 7–8 have a
// neutral colour (atan2(0, 0)); 9–15 straddle the ±180° hue difference and mean hue boundaries
// (14 sits exactly on it, at Δh = 180°); 16 are hues 90° apart across 0°.
const Pair kSharma[] = {
    {{50.0000, 2.6772, -79.7751}, {50.0000, 0.0000, -82.7485}, 2.0425},
    {{50.0000, 3.1571, -77.2803}, {50.0000, 0.0000, -82.7485}, 2.8615},
    {{50.0000, 2.8361, -74.0200}, {50.0000, 0.0000, -82.7485}, 3.4412},
    {{50.0000, -1.3802, -84.2814}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, -1.1848, -84.8006}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, -0.9009, -85.5211}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, 0.0000, 0.0000}, {50.0000, -1.0000, 2.0000}, 2.3669},
    {{50.0000, -1.0000, 2.0000}, {50.0000, 0.0000, 0.0000}, 2.3669},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0009}, 7.1792},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0010}, 7.1792},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0011}, 7.2195},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0012}, 7.2195},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0009, -2.4900}, 4.8045},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0010, -2.4900}, 4.8045},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0011, -2.4900}, 4.7461},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 0.0000, -2.5000}, 4.3065},
    {{50.0000, 2.5000, 0.0000}, {73.0000, 25.0000, -18.0000}, 27.1492},
    {{50.0000, 2.5000, 0.0000}, {61.0000, -5.0000, 29.0000}, 22.8977},
    {{50.0000, 2.5000, 0.0000}, {56.0000, -27.0000, -3.0000}, 31.9030},
    {{50.0000, 2.5000, 0.0000}, {58.0000, 24.0000, 15.0000}, 19.4535},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.1736, 0.5854}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.2972, 0.0000}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 1.8634, 0.5757}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.2592, 0.3350}, 1.0000},
    {{60.2574, -34.0099, 36.2677}, {60.4626, -34.1751, 39.4387}, 1.2644},
    {{63.0109, -31.0961, -5.8663}, {62.8187, -29.7946, -4.0864}, 1.2630},
    {{61.2901, 3.7196, -5.3901}, {61.4292, 2.2480, -4.9620}, 1.8731},
    {{35.0831, -44.1164, 3.7933}, {35.0232, -40.0716, 1.5901}, 1.8645},
    {{22.7233, 20.0904, -46.6940}, {23.0331, 14.9730, -42.5619}, 2.0373},
    {{36.4612, 47.8580, 18.3852}, {36.2715, 50.5065, 21.2231}, 1.4146},
    {{90.8027, -2.0831, 1.4410}, {91.1528, -1.6435, 0.0447}, 1.4441},
    {{90.9257, -0.5406, -0.9208}, {88.6381, -0.8985, -0.7239}, 1.5381},
    {{6.7747, -0.2908, -2.4247}, {5.8714, -0.0985, -2.2286}, 0.6377},
    {{2.0776, 0.0795, -1.1350}, {0.9033, -0.0636, -0.5514}, 0.9082},
};

TEST(Ciede2000, MatchesSharmaTable1) {
  // The table gives ΔE00 to four decimals: 1e-4 allows for its rounding (≤ 5e-5) only.
  for (std::size_t i = 0; i < std::size(kSharma); ++i) {
    const Pair& p = kSharma[i];
    EXPECT_NEAR(ciede2000(p.x, p.y), p.delta_e, 1e-4) << "pair " << i + 1;
    EXPECT_NEAR(ciede2000(p.y, p.x), p.delta_e, 1e-4) << "pair " << i + 1 << ", reversed";
  }
}

TEST(Ciede2000, SymmetricAndZeroForEqualColours) {
  std::vector<Lab> colours;
  for (const Pair& p : kSharma) {
    colours.push_back(p.x);
    colours.push_back(p.y);
  }
  // Hues on both sides of 0° and of 180°, and colours far apart.
  colours.insert(colours.end(), {{30, 40, -0.5},
                                 {70, 35, 0.5},
                                 {55, -60, 1},
                                 {45, -50, -1},
                                 {0, 0, 0},
                                 {100, 0, 0},
                                 {80, 90, 90},
                                 {10, -80, -100}});
  for (const Lab& x : colours) {
    EXPECT_EQ(ciede2000(x, x), 0.0) << x.L << " " << x.a << " " << x.b;
    for (const Lab& y : colours) EXPECT_EQ(ciede2000(x, y), ciede2000(y, x));
  }
}

TEST(Ciede2000, NeutralColoursDifferByWeightedLightnessOnly) {
  // With a = b = 0 only the lightness term remains: |ΔL| / S_L, S_L = 1 at a mean L of 50.
  EXPECT_NEAR(ciede2000({40, 0, 0}, {60, 0, 0}), 20.0, 1e-12);
  const double l50 = 25.0 * 25.0;  // mean L = 75
  EXPECT_NEAR(ciede2000({70, 0, 0}, {80, 0, 0}), 10 / (1 + 0.015 * l50 / std::sqrt(20 + l50)),
              1e-12);
}

TEST(SrgbLinearToLab, WhiteAndBlack) {
  const Lab white = srgb_linear_to_lab(1, 1, 1);
  EXPECT_NEAR(white.L, 100, 1e-3);
  EXPECT_NEAR(white.a, 0, 1e-3);
  EXPECT_NEAR(white.b, 0, 1e-3);
  const Lab black = srgb_linear_to_lab(0, 0, 0);
  EXPECT_NEAR(black.L, 0, 1e-12);
  EXPECT_NEAR(black.a, 0, 1e-12);
  EXPECT_NEAR(black.b, 0, 1e-12);
}

TEST(SrgbLinearToLab, GreysAreNeutralOnBothBranchesOfF) {
  // 18 % grey is on the cube-root branch: L = 116 · 0.18^⅓ − 16 ≈ 49.50.
  const Lab grey = srgb_linear_to_lab(0.18, 0.18, 0.18);
  EXPECT_NEAR(grey.L, 116 * std::cbrt(0.18) - 16, 1e-6);
  EXPECT_NEAR(grey.a, 0, 1e-6);
  EXPECT_NEAR(grey.b, 0, 1e-6);
  // Y = 0.001 < (6/29)³ is on the linear one: L = (29/3)³ Y ≈ 0.9033.
  const Lab dark = srgb_linear_to_lab(0.001, 0.001, 0.001);
  EXPECT_NEAR(dark.L, std::pow(29.0 / 3, 3) * 0.001, 1e-6);
  EXPECT_NEAR(dark.a, 0, 1e-6);
  EXPECT_NEAR(dark.b, 0, 1e-6);
}

TEST(SrgbLinearToLab, Primaries) {
  // Published CIELAB values of the sRGB primaries under D65 (e.g. Lindbloom's calculator).
  const Lab red = srgb_linear_to_lab(1, 0, 0);
  EXPECT_NEAR(red.L, 53.24, 0.02);
  EXPECT_NEAR(red.a, 80.09, 0.02);
  EXPECT_NEAR(red.b, 67.20, 0.02);
  const Lab green = srgb_linear_to_lab(0, 1, 0);
  EXPECT_NEAR(green.L, 87.73, 0.02);
  EXPECT_NEAR(green.a, -86.18, 0.02);
  EXPECT_NEAR(green.b, 83.18, 0.02);
  const Lab blue = srgb_linear_to_lab(0, 0, 1);
  EXPECT_NEAR(blue.L, 32.30, 0.02);
  EXPECT_NEAR(blue.a, 79.19, 0.02);
  EXPECT_NEAR(blue.b, -107.86, 0.02);
}

std::size_t count(const std::vector<std::uint8_t>& mask) {
  return std::size_t(std::count_if(mask.begin(), mask.end(), [](std::uint8_t m) { return m; }));
}

TEST(SphereMask, IsTheDiscInsetByTheMargin) {
  // 200 px span 2.5 units, so the unit disc has a radius of 80 px; the margin insets it.
  for (double margin : {0.0, 1.5, 4.0}) {
    const auto mask = sphere_mask(200, 200, 1.25, margin);
    ASSERT_EQ(mask.size(), 200u * 200u);
    const double r = 80 - margin;
    EXPECT_NEAR(double(count(mask)), std::numbers::pi * r * r, 0.02 * std::numbers::pi * r * r)
        << "margin " << margin;
    EXPECT_EQ(mask[0], 0);
    EXPECT_EQ(mask[199], 0);
    EXPECT_EQ(mask[199 * 200], 0);
    EXPECT_EQ(mask[199 * 200 + 199], 0);
    EXPECT_EQ(mask[100 * 200 + 100], 1);
    EXPECT_EQ(mask[99 * 200 + 99], 1);
    // Along the middle row, the pixels with centres |x + 0.5 − 100| ≤ r exactly.
    for (int i = 0; i < 200; ++i) {
      const double u = i + 0.5 - 100, v = 0.5;
      EXPECT_EQ(mask[100 * 200 + i], u * u + v * v <= r * r ? 1 : 0) << "column " << i;
    }
  }
  // The default margin is 1.5 px.
  EXPECT_EQ(sphere_mask(200, 200), sphere_mask(200, 200, 1.25, 1.5));
}

TEST(SphereMask, WideImagesCentreTheDiscWithSquarePixels) {
  // 300 × 100 px spanning 2 units vertically: a disc of radius 50 px in the middle third.
  const auto mask = sphere_mask(300, 100, 1.0, 0.0);
  ASSERT_EQ(mask.size(), 300u * 100u);
  EXPECT_NEAR(double(count(mask)), std::numbers::pi * 2500, 0.02 * std::numbers::pi * 2500);
  for (int j = 0; j < 100; ++j) {
    for (int i = 0; i < 300; ++i) {
      if (i < 100 || i >= 200) {
        EXPECT_EQ(mask[std::size_t(j) * 300 + i], 0) << i << ", " << j;
      }
    }
  }
  // Symmetric under flips: the disc is centred, and row 0 at the top changes nothing here.
  for (int j = 0; j < 100; ++j)
    for (int i = 0; i < 300; ++i)
      ASSERT_EQ(mask[std::size_t(j) * 300 + i], mask[std::size_t(99 - j) * 300 + (299 - i)]);
  // A disc smaller than the image in both directions: the image spans 5 units vertically.
  EXPECT_NEAR(double(count(sphere_mask(100, 50, 2.5, 0.0))), std::numbers::pi * 100,
              0.05 * std::numbers::pi * 100);
}

TEST(SphereMask, RejectsInvalidArguments) {
  EXPECT_THROW(sphere_mask(0, 10), std::invalid_argument);
  EXPECT_THROW(sphere_mask(10, -1), std::invalid_argument);
  EXPECT_THROW(sphere_mask(10, 10, 0.0), std::invalid_argument);
  EXPECT_THROW(sphere_mask(10, 10, 1.25, -1.0), std::invalid_argument);
  EXPECT_THROW(sphere_mask(10, 10, std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);
  // A margin wider than the disc leaves nothing, which is not an error.
  EXPECT_EQ(count(sphere_mask(10, 10, 1.25, 100.0)), 0u);
}

render::Image image(int width, int height, std::vector<float> rgb) {
  render::Image im;
  im.width = width;
  im.height = height;
  im.rgb = std::move(rgb);
  return im;
}

// A colourful 8 × 6 image whose values are multiples of 10, so that 1.1 × them is exact in
// float (11 × an integer) and the relative error of 1.1 × it is 0.1 up to double rounding only.
render::Image pattern() {
  std::vector<float> rgb(8 * 6 * 3);
  for (std::size_t k = 0; k < rgb.size(); ++k) rgb[k] = float(10 * ((k * 7) % 13 + 1));
  return image(8, 6, std::move(rgb));
}

TEST(CompareImages, IdenticalImagesHaveNoError) {
  const render::Image ref = pattern();
  const std::vector<std::uint8_t> all(48, 1);
  const ImageError e = compare_images(ref, ref, all);
  EXPECT_EQ(e.relative_rmse, 0.0);
  EXPECT_EQ(e.mean_delta_e, 0.0);
  EXPECT_EQ(e.p95_delta_e, 0.0);
  EXPECT_EQ(e.pixels, 48u);
  // All zero: no error either, rather than 0 / 0.
  const render::Image black = image(8, 6, std::vector<float>(144, 0.0f));
  const ImageError z = compare_images(black, black, all);
  EXPECT_EQ(z.relative_rmse, 0.0);
  EXPECT_EQ(z.mean_delta_e, 0.0);
}

TEST(CompareImages, RelativeRmseOfAScaledImage) {
  const render::Image ref = pattern();
  render::Image test = ref;
  for (float& v : test.rgb) v = float(11 * (v / 10));
  const std::vector<std::uint8_t> all(48, 1);
  const ImageError e = compare_images(test, ref, all);
  EXPECT_NEAR(e.relative_rmse, 0.1, 1e-12);
  EXPECT_GT(e.mean_delta_e, 0.0);
  EXPECT_GE(e.p95_delta_e, e.mean_delta_e * 0.5);
  // Against a black reference the relative error is unbounded.
  const render::Image black = image(8, 6, std::vector<float>(144, 0.0f));
  EXPECT_EQ(compare_images(ref, black, all).relative_rmse, std::numeric_limits<double>::infinity());
}

TEST(CompareImages, OnlyMaskedPixelsCount) {
  // Pixel 0 is masked out and differs wildly (and is NaN in the test image): no effect, no throw.
  render::Image ref = image(2, 1, {1, 2, 3, 4, 5, 6});
  render::Image test = image(2, 1, {std::numeric_limits<float>::quiet_NaN(), 0, 0, 4, 5, 6});
  const std::vector<std::uint8_t> mask = {0, 255};  // any nonzero entry selects
  const ImageError e = compare_images(test, ref, mask);
  EXPECT_EQ(e.pixels, 1u);
  EXPECT_EQ(e.relative_rmse, 0.0);
  EXPECT_EQ(e.mean_delta_e, 0.0);
}

TEST(CompareImages, DeltaEOfTheToneMappedGreys) {
  // Reference grey 2 (its 99th percentile luminance is 2, so it maps to white), test grey 1,
  // which maps to 0.5: every pixel has ΔE00 between (100, 0, 0) and the Lab of 0.5 grey.
  const render::Image ref = image(3, 2, std::vector<float>(18, 2.0f));
  const render::Image test = image(3, 2, std::vector<float>(18, 1.0f));
  const std::vector<std::uint8_t> all(6, 1);
  const ImageError e = compare_images(test, ref, all);
  const double expected = ciede2000(srgb_linear_to_lab(0.5, 0.5, 0.5), {100, 0, 0});
  EXPECT_GT(expected, 10.0);
  EXPECT_NEAR(e.mean_delta_e, expected, 1e-9);
  EXPECT_NEAR(e.p95_delta_e, expected, 1e-9);
  EXPECT_NEAR(e.relative_rmse, 0.5, 1e-12);
}

// ΔE00 of a test grey against a white reference, as compare_images computes it.
double delta_e_of_grey(float grey) {
  const double g = grey;
  return ciede2000(srgb_linear_to_lab(g, g, g), srgb_linear_to_lab(1, 1, 1));
}

TEST(CompareImages, MeanAndPercentileOfTheDeltaE) {
  // Reference white (scale 1); test greys k/(n − 1), k = 0..n−1, in a scrambled order. ΔE falls
  // as the grey rises, so the i-th smallest ΔE is that of grey (n − 1 − i)/(n − 1).
  for (int n : {21, 11}) {
    const render::Image ref = image(n, 1, std::vector<float>(3 * n, 1.0f));
    std::vector<float> rgb;
    double sum = 0;
    for (int k = 0; k < n; ++k) {
      const float grey = float((5 * k) % n) / float(n - 1);  // 5 is prime to 21 and 11
      rgb.insert(rgb.end(), 3, grey);
      sum += delta_e_of_grey(grey);
    }
    const ImageError e = compare_images(image(n, 1, rgb), ref, std::vector<std::uint8_t>(n, 1));
    EXPECT_NEAR(e.mean_delta_e, sum / n, 1e-9) << n;
    if (n == 21) {
      // Rank 0.95 · 20 = 19: the 20th smallest, that of grey 1/20.
      EXPECT_NEAR(e.p95_delta_e, delta_e_of_grey(1.0f / 20), 1e-9);
    } else {
      // Rank 0.95 · 10 = 9.5: halfway between the 10th and 11th smallest, greys 1/10 and 0.
      EXPECT_NEAR(e.p95_delta_e, (delta_e_of_grey(1.0f / 10) + delta_e_of_grey(0)) / 2, 1e-9);
    }
  }
}

TEST(CompareImages, ExposureIgnoresTheBrightestPercent) {
  // 100 pixels of 1 and one highlight of 1000: the 99th percentile of 101 values is the 100th
  // smallest, 1, so 1 maps to white and the highlight (1000 or 500) clips to white in both.
  std::vector<float> ref_rgb(3 * 101, 1.0f), test_rgb(3 * 101, 1.0f);
  std::fill_n(ref_rgb.end() - 3, 3, 1000.0f);
  std::fill_n(test_rgb.end() - 3, 3, 500.0f);
  const std::vector<std::uint8_t> all(101, 1);
  const ImageError e = compare_images(image(101, 1, test_rgb), image(101, 1, ref_rgb), all);
  EXPECT_EQ(e.mean_delta_e, 0.0);
  EXPECT_GT(e.relative_rmse, 0.4);
  // Scaling both images by the same power of 2 changes nothing: the exposure follows.
  for (float& v : ref_rgb) v *= 4;
  for (float& v : test_rgb) v *= 4;
  ref_rgb[0] = 0.5f * 4;  // one darker pixel so that ΔE is not 0
  std::vector<float> ref1 = ref_rgb, test1 = test_rgb;
  for (float& v : ref1) v /= 4;
  for (float& v : test1) v /= 4;
  const ImageError big = compare_images(image(101, 1, test_rgb), image(101, 1, ref_rgb), all);
  const ImageError small = compare_images(image(101, 1, test1), image(101, 1, ref1), all);
  EXPECT_GT(big.mean_delta_e, 0.0);
  EXPECT_EQ(big.mean_delta_e, small.mean_delta_e);
  EXPECT_EQ(big.p95_delta_e, small.p95_delta_e);
  EXPECT_DOUBLE_EQ(big.relative_rmse, small.relative_rmse);
}

TEST(CompareImages, RejectsInvalidInput) {
  const render::Image ref = pattern();
  const std::vector<std::uint8_t> all(48, 1);
  // Sizes that differ.
  EXPECT_THROW(compare_images(image(6, 8, ref.rgb), ref, all), std::invalid_argument);
  EXPECT_THROW(compare_images(ref, image(4, 6, std::vector<float>(72, 1.0f)), all),
               std::invalid_argument);
  // An image that does not hold width × height × 3 values.
  EXPECT_THROW(compare_images(image(8, 6, std::vector<float>(10, 1.0f)), ref, all),
               std::invalid_argument);
  // A mask of the wrong size, or one selecting nothing.
  EXPECT_THROW(compare_images(ref, ref, std::vector<std::uint8_t>(47, 1)), std::invalid_argument);
  EXPECT_THROW(compare_images(ref, ref, std::vector<std::uint8_t>(48, 0)), std::invalid_argument);
  // Non-finite masked values in either image.
  for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                    -std::numeric_limits<float>::infinity()}) {
    render::Image t = ref;
    t.rgb[3 * 17 + 1] = bad;
    EXPECT_THROW(compare_images(t, ref, all), std::invalid_argument);
    EXPECT_THROW(compare_images(ref, t, all), std::invalid_argument);
  }
  // The message says what is wrong.
  try {
    compare_images(ref, ref, std::vector<std::uint8_t>(48, 0));
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("selects no pixel"), std::string::npos) << e.what();
  }
}

// SSIM (Wang et al. 2004) on hand-computed cases; tests/python/test_study_metrics.py checks it
// against a NumPy port on a fixed pair of images.
TEST(Ssim, EqualImagesAreOneAndConstantImagesFollowTheLuminanceTerm) {
  const int w = 15, h = 13;
  std::vector<double> x(w * h), y(w * h, 0.4);
  for (std::size_t k = 0; k < x.size(); ++k) x[k] = 0.5 + 0.4 * std::sin(0.7 * double(k));
  const std::vector<std::uint8_t> all(w * h, 1);
  EXPECT_NEAR(ssim(x, x, w, h, all), 1.0, 1e-12);
  // Constant images a and b: σ = 0, so SSIM = (2ab + C1) / (a² + b² + C1), C1 = 0.01².
  const std::vector<double> a(w * h, 0.2);
  EXPECT_NEAR(ssim(a, y, w, h, all), (2 * 0.2 * 0.4 + 1e-4) / (0.04 + 0.16 + 1e-4), 1e-12);
  // A constant against a varying image: the structure term is C2 / (σx² + C2) < 1.
  EXPECT_LT(ssim(x, y, w, h, all), ssim(a, y, w, h, all));
}

TEST(Ssim, OnlyMaskedPixelsWithTheirWholeWindowCount) {
  const int w = 12, h = 11;  // the 11 × 11 window fits at (5, 5) and (6, 5) only
  std::vector<double> x(w * h, 0.5), y(w * h, 0.5);
  y[5 * w + 11] = 0.9;  // inside the window of (6, 5) only
  std::vector<std::uint8_t> mask(w * h, 1);
  const double both = ssim(x, y, w, h, mask);
  EXPECT_LT(both, 1.0);
  mask[5 * w + 6] = 0;  // (6, 5) left out: only (5, 5), which does not see the change
  EXPECT_NEAR(ssim(x, y, w, h, mask), 1.0, 1e-12);
  mask[5 * w + 5] = 0;
  EXPECT_THROW(ssim(x, y, w, h, mask), std::invalid_argument);
  EXPECT_THROW(ssim(x, y, w, h + 1, mask), std::invalid_argument);
}

TEST(CompareImages, PublishedMetricsOfToneMappedGreys) {
  // Reference grey 0.5 everywhere: its 99th percentile is 0.5, so it displays as 1; a test grey
  // of 0.25 displays as 0.5. MAE = RMSE = 0.5; SSIM of constants (2 · 0.5 + C1) / (1.25 + C1).
  const int w = 16, h = 16;
  const render::Image ref = image(w, h, std::vector<float>(w * h * 3, 0.5f));
  const render::Image test = image(w, h, std::vector<float>(w * h * 3, 0.25f));
  const std::vector<std::uint8_t> all(w * h, 1);
  const ImageError e = compare_images(test, ref, all);
  EXPECT_NEAR(e.mae, 0.5, 1e-12);
  EXPECT_NEAR(e.rmse, 0.5, 1e-12);
  EXPECT_NEAR(e.ssim, (1 + 1e-4) / (1.25 + 1e-4), 1e-12);
  const ImageError same = compare_images(ref, ref, all);
  EXPECT_EQ(same.mae, 0.0);
  EXPECT_NEAR(same.ssim, 1.0, 1e-12);
  // Too small for the window: SSIM is NaN, the other metrics are still there.
  EXPECT_TRUE(
      std::isnan(compare_images(pattern(), pattern(), std::vector<std::uint8_t>(48, 1)).ssim));
}

}  // namespace
}  // namespace halfback::study
