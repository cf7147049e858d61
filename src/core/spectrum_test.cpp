// Spectra ↔ RGB (core/spectrum.hpp): the colour matching functions and the matrix against
// published CIE and IEC values, the conversion's white point, and RGB → spectrum → RGB round trips
// with non-negative spectra.
#include "halfback/core/spectrum.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

namespace halfback::spectral {
namespace {

std::array<double, 3> integrate_xyz(double (*weight)(double, double), double param) {
  std::array<double, 3> sum{0, 0, 0};
  for (double l = kLambdaMin + 0.05; l < kLambdaMax; l += 0.1) {
    const std::array<double, 3> c = cie_1931(l);
    for (int i = 0; i < 3; ++i) sum[i] += 0.1 * c[i] * weight(l, param);
  }
  return sum;
}

TEST(Spectrum, ColourMatchingFunctionsAgreeWithTheCieTables) {
  // The CIE 1931 tables' integrals over 360–830 nm are all 106.857 (equal-energy white has
  // x = y = 1/3), and ȳ(555 nm) = 1; the fit is within a few tenths of a percent of both.
  const auto flat = integrate_xyz([](double, double) { return 1.0; }, 0);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(flat[i], 106.857, 0.003 * 106.857) << "channel " << i;
  EXPECT_NEAR(cie_1931(555)[1], 1.0, 0.005);
  EXPECT_LT(cie_1931(380)[1], 1e-3);
  EXPECT_LT(cie_1931(780)[1], 1e-3);
}

TEST(Spectrum, PlanckSpectraLieOnThePlanckianLocus) {
  // Chromaticities of blackbodies in the CIE 1931 observer (CIE 15:2004): illuminant A (2856 K)
  // is (0.44757, 0.40745); 6500 K is (0.31352, 0.32363). Tolerance: the fit's accuracy.
  struct Point {
    double kelvin, x, y;
  };
  for (const Point p : {Point{2856, 0.44757, 0.40745}, Point{6500, 0.31352, 0.32363}}) {
    const auto xyz = integrate_xyz(&planck, p.kelvin);
    const double s = xyz[0] + xyz[1] + xyz[2];
    EXPECT_NEAR(xyz[0] / s, p.x, 2e-3) << p.kelvin;
    EXPECT_NEAR(xyz[1] / s, p.y, 2e-3) << p.kelvin;
  }
  EXPECT_DOUBLE_EQ(planck(560, 6504), 1.0);
  EXPECT_DOUBLE_EQ(illuminant(450), planck(450, 6504));
}

TEST(Spectrum, DerivedMatrixIsTheSrgbMatrixForD65) {
  // IEC 61966-2-1's XYZ → linear sRGB matrix (to its 4 printed decimals), from the primaries and
  // the D65 white (0.3127, 0.3290).
  const Matrix3 iec{
      {{3.2406, -1.5372, -0.4986}, {-0.9689, 1.8758, 0.0415}, {0.0557, -0.2040, 1.0570}}};
  const Matrix3 m = rgb_from_xyz({0.3127 / 0.3290, 1.0, (1 - 0.3127 - 0.3290) / 0.3290});
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(m[i][j], iec[i][j], 6e-4) << i << "," << j;
}

TEST(Spectrum, TheConstantSpectrumIsWhiteOnAnyGrid) {
  for (const std::vector<double>& grid :
       {default_wavelengths(), std::vector<double>{400, 410, 500, 505, 700, 1000},
        std::vector<double>{300, 900}}) {
    const SpectrumToRgb to_rgb(grid);
    const std::vector<double> ones(grid.size(), 2.5);
    const Rgb c = to_rgb(ones);
    EXPECT_NEAR(c.r, 2.5, 1e-12);
    EXPECT_NEAR(c.g, 2.5, 1e-12);
    EXPECT_NEAR(c.b, 2.5, 1e-12);
  }
  EXPECT_EQ(default_wavelengths().size(), 95u);
  EXPECT_EQ(default_wavelengths().front(), 360);
  EXPECT_EQ(default_wavelengths().back(), 830);
}

TEST(Spectrum, IntegrationConvergesWithTheGrid) {
  // A smooth spectrum sampled every 5 nm integrates like it sampled every 0.5 nm, within the
  // linear interpolation's error.
  const SigmoidSpectrum s{{-3, 1, 0.5}, 1.7};
  auto rgb_on = [&](double step) {
    std::vector<double> grid, values;
    for (double l = kLambdaMin; l <= kLambdaMax + 1e-9; l += step)
      grid.push_back(l), values.push_back(s(l));
    return SpectrumToRgb(grid)(values);
  };
  const Rgb coarse = rgb_on(5), fine = rgb_on(0.5);
  EXPECT_NEAR(coarse.r, fine.r, 2e-3 * fine.max_channel());
  EXPECT_NEAR(coarse.g, fine.g, 2e-3 * fine.max_channel());
  EXPECT_NEAR(coarse.b, fine.b, 2e-3 * fine.max_channel());
}

TEST(Spectrum, RefusesBadWavelengths) {
  EXPECT_THROW(SpectrumToRgb({500}), std::invalid_argument);
  EXPECT_THROW(SpectrumToRgb({500, 400}), std::invalid_argument);
  EXPECT_THROW(SpectrumToRgb({400, 500, 500}), std::invalid_argument);
  EXPECT_THROW(SpectrumToRgb({400, NAN}), std::invalid_argument);
}

// The fitted spectrum sampled on the grid, non-negative, and integrated back.
void expect_round_trip(const RgbToSpectrum& up, const Rgb& target, double tolerance) {
  const SpectrumFit f = up.fit(target);
  std::vector<double> values;
  for (double l : up.to_rgb().wavelengths()) {
    values.push_back(f.spectrum(l));
    ASSERT_GE(values.back(), 0) << l;
  }
  const Rgb back = up.to_rgb()(values);
  const double m = target.max_channel();
  EXPECT_LE(f.error, tolerance);
  EXPECT_NEAR(back.r, target.r, tolerance * m) << target.r << " " << target.g << " " << target.b;
  EXPECT_NEAR(back.g, target.g, tolerance * m) << target.r << " " << target.g << " " << target.b;
  EXPECT_NEAR(back.b, target.b, tolerance * m) << target.r << " " << target.g << " " << target.b;
}

TEST(Spectrum, UpsampledSpectraIntegrateBackToTheirRgb) {
  const RgbToSpectrum up(default_wavelengths());
  // The primaries, secondaries and greys of the gamut, and random colours over four decades.
  for (const Rgb& c : {Rgb{1, 0, 0}, Rgb{0, 1, 0}, Rgb{0, 0, 1}, Rgb{1, 1, 0}, Rgb{0, 1, 1},
                       Rgb{1, 0, 1}, Rgb{1, 1, 1}, Rgb{0.01, 0.01, 0.01}, Rgb{30, 30, 30}})
    expect_round_trip(up, c, 1e-6);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uni(0, 1);
  for (int k = 0; k < 2000; ++k) {
    const Rgb c = Rgb{uni(rng), uni(rng), uni(rng)} * std::pow(10.0, 4 * uni(rng) - 2);
    expect_round_trip(up, c, 1e-6);
  }
}

TEST(Spectrum, NegativeChannelsAreRaisedToZeroAndBlackIsZero) {
  const RgbToSpectrum up(default_wavelengths());
  const SpectrumFit f = up.fit({0.5, -0.1, 0.2});
  EXPECT_NEAR(f.rgb.r, 0.5, 1e-6);
  EXPECT_NEAR(f.rgb.g, 0.0, 1e-6);
  EXPECT_NEAR(f.rgb.b, 0.2, 1e-6);
  for (const Rgb& black : {Rgb{0, 0, 0}, Rgb{-1, -2, 0}}) {
    const SpectrumFit z = up.fit(black);
    EXPECT_EQ(z.spectrum.scale, 0);
    EXPECT_EQ(z.spectrum(500), 0);
    EXPECT_EQ(z.error, 0);
  }
  EXPECT_THROW(up.fit({NAN, 0, 0}), std::invalid_argument);
  EXPECT_THROW(up.fit({0, INFINITY, 0}), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::spectral
