#include "halfback/brdf/test_functions.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace halfback {
namespace {

Vec3<double> dir(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

double value(TestFunction f, const DirPair<double>& p) {
  const Rgb c = TestFunctionBrdf(f).eval(p);
  EXPECT_EQ(c.r, c.g);
  EXPECT_EQ(c.r, c.b);
  return c.r;
}

constexpr double kPi = std::numbers::pi;
const Vec3<double> kN{0, 0, 1}, kT{1, 0, 0};

TEST(TestFunctions, KnownPairs) {
  // ωi = ωo = n: h = n, h̄ = 0, θd = 0, both cosines 1.
  const DirPair<double> normal{kN, kN};
  EXPECT_DOUBLE_EQ(value(TestFunction::fresnel, normal), 0.0);
  EXPECT_DOUBLE_EQ(value(TestFunction::specular, normal), 1.0);
  EXPECT_DOUBLE_EQ(value(TestFunction::grazing, normal), 0.0);

  // ωi = n, ωo = t (docs/math.md's counter-example): h = (1/2, 0, 1/2), ‖h‖ = cos θd = 1/√2,
  // ‖h̄‖ = 1/2, (ωi·n)(ωo·n) = 0.
  const DirPair<double> nt{kN, kT};
  EXPECT_NEAR(value(TestFunction::fresnel, nt), 1.0 - std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(value(TestFunction::specular, nt), 0.5, 1e-15);
  EXPECT_NEAR(value(TestFunction::grazing, nt), 1.0, 1e-15);

  // Retro-reflection at 60°: ωi = ωo, θd = 0, h̄ = ωi's planar part of length sin 60°.
  const Vec3<double> w = dir(kPi / 3, 0.7);
  EXPECT_NEAR(value(TestFunction::fresnel, {w, w}), 0.0, 1e-15);
  EXPECT_NEAR(value(TestFunction::specular, {w, w}), 1.0 - std::sin(kPi / 3), 1e-15);
  EXPECT_NEAR(value(TestFunction::grazing, {w, w}), 1.0 - 0.25, 1e-15);

  // Mirror configuration at 60°: h̄ = 0, so S = 1; θd = 60°, so F = 1/2.
  const Vec3<double> m{-w.x, -w.y, w.z};
  EXPECT_NEAR(value(TestFunction::specular, {w, m}), 1.0, 1e-15);
  EXPECT_NEAR(value(TestFunction::fresnel, {w, m}), 0.5, 1e-15);
  EXPECT_NEAR(value(TestFunction::grazing, {w, m}), 0.75, 1e-15);

  // Both grazing and opposite: h = 0, so F = 1 and S = 1; G = 1.
  const DirPair<double> opposite{kT, {-1, 0, 0}};
  EXPECT_NEAR(value(TestFunction::fresnel, opposite), 1.0, 1e-15);
  EXPECT_NEAR(value(TestFunction::specular, opposite), 1.0, 1e-15);
  EXPECT_NEAR(value(TestFunction::grazing, opposite), 1.0, 1e-15);
}

TEST(TestFunctions, AgreeWithTheParameterizations) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (int n = 0; n < 10000; ++n) {
    const DirPair<double> p{dir(std::acos(u(rng)), 2 * kPi * u(rng)),
                            dir(std::acos(u(rng)), 2 * kPi * u(rng))};
    const Tuple4<double> hd = HalfDiff::forward(p), hy = Hybrid::forward(p);
    EXPECT_NEAR(value(TestFunction::fresnel, p), 1 - std::cos(hd[2]), 1e-12);
    EXPECT_NEAR(value(TestFunction::specular, p), 1 - hy[0], 1e-12);
    EXPECT_NEAR(value(TestFunction::specular, p), 1 - std::sin(hd[0]) * std::cos(hd[2]), 1e-12);
    EXPECT_NEAR(value(TestFunction::grazing, p), 1 - p.wi.z * p.wo.z, 1e-15);
    for (TestFunction f : {TestFunction::fresnel, TestFunction::specular, TestFunction::grazing}) {
      const double v = value(f, p);
      EXPECT_GE(v, -1e-15);
      EXPECT_LE(v, 1 + 1e-15);
      EXPECT_NEAR(v, value(f, {p.wo, p.wi}), 1e-15) << "reciprocity";
    }
  }
}

TEST(TestFunctions, BelowHorizonIsZeroAndNames) {
  const DirPair<double> below{{0, 0.6, -0.8}, kN};
  for (TestFunction f : {TestFunction::fresnel, TestFunction::specular, TestFunction::grazing}) {
    EXPECT_EQ(TestFunctionBrdf(f).eval(below), (Rgb{0, 0, 0}));
    EXPECT_EQ(test_function_from_name(letter_of(f)), f);
    EXPECT_EQ(test_function_from_name(name_of(f)), f);
    const TestFunctionBrdf b(f);
    EXPECT_EQ(b.name(), "test:" + std::string(letter_of(f)));
    EXPECT_TRUE(b.isotropic());
    EXPECT_TRUE(b.reciprocal());
    EXPECT_FALSE(b.description().empty());
  }
  EXPECT_FALSE(test_function_from_name("X").has_value());
  EXPECT_FALSE(test_function_from_name("s").has_value());
}

}  // namespace
}  // namespace halfback
