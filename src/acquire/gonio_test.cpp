// The virtual gonio-reflectometer: budgets, exactness on affine functions, the order of
// convergence on smooth ones, the test-pair measure and the budget interpolation.
#include "halfback/acquire/gonio.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <random>

#include "support/test_brdfs.hpp"

namespace halfback::acquire {
namespace {

constexpr double kPi = std::numbers::pi;

// Unequal channels: a reconstruction that mixes them up shows.
struct Fn : test::FunctionBrdf {
  explicit Fn(std::function<double(const DirPair<double>&)> f)
      : test::FunctionBrdf(std::move(f), {1, 0.5, 2}) {}
};

Vec3<double> dir(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

double theta_of(const Vec3<double>& w) {
  return std::acos(std::clamp(w.z, -1.0, 1.0));
}

// Smooth in the spherical coordinates (θi, θo, φo − φi), and 2π-periodic in the azimuth.
double smooth_spherical(const DirPair<double>& p) {
  return 1 + 0.5 * p.wi.z * p.wo.z + 0.3 * (p.wi.x * p.wo.x + p.wi.y * p.wo.y);
}

TEST(Gonio, BudgetsAreMetWithinTheStepOfTheGrid) {
  for (Space s : kKernelSpaces)
    for (bool iso : {true, false})
      for (std::size_t budget : {std::size_t(1000), std::size_t(20000)}) {
        const GonioSetup setup{s, iso, Design::regular, budget, 1};
        const Fn one([](const DirPair<double>&) { return 1.0; });
        const GonioReconstruction r(one, setup);
        // n cells per magnitude: the nearest n in ratio is within the square root of the step
        // ((n + 1) / n)^d between two grids (5 % more for the domain's edge).
        const double n = double(r.cells().axes.front().count), d = double(r.cells().axes.size());
        const double slack = 1.05 * std::pow((n + 1) / n, d / 2);
        const double ratio = double(r.samples()) / double(budget);
        EXPECT_GT(ratio, 1 / slack) << name_of(s) << (iso ? " 3D " : " 4D ") << budget;
        EXPECT_LT(ratio, slack) << name_of(s) << (iso ? " 3D " : " 4D ") << budget;
        // The azimuths get twice the cells of the magnitudes.
        const GridSpec& g = r.cells();
        EXPECT_EQ(g.axes.back().count, 2 * g.axes.front().count);
      }
}

TEST(Gonio, AffineFunctionsAreReconstructedExactly) {
  // Affine in (θi, θo): exact inside the outermost cell centres, in the 3D and 4D forms of the
  // spherical parameterization.
  const Fn affine(
      [](const DirPair<double>& p) { return 0.2 + 0.5 * theta_of(p.wi) + 0.3 * theta_of(p.wo); });
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> theta(0.25, 1.3), phi(0, 2 * kPi);
  for (bool iso : {true, false})
    for (Design d : {Design::regular, Design::stratified}) {
      const GonioReconstruction r(affine, {space_of<Spherical>, iso, d, 4000, 3});
      int exact = 0;
      for (int i = 0; i < 200; ++i) {
        const DirPair<double> p{dir(theta(rng), phi(rng)), dir(theta(rng), phi(rng))};
        const Rgb got = r.eval(p), want = affine.eval(p);
        exact += std::abs(got.r - want.r) < 1e-9 && std::abs(got.b - want.b) < 1e-9;
        EXPECT_NEAR(got.r, want.r, 0.05) << name_of(d) << (iso ? " 3D" : " 4D");
      }
      // The stratified fit is limited to the range of its measurements: where the jittered
      // points all lie on one side of x, it is not exact.
      EXPECT_GE(exact, d == Design::regular ? 200 : 180) << name_of(d) << (iso ? " 3D" : " 4D");
    }
}

TEST(Gonio, AffineFunctionsStayExactAtTheDomainsEdgeAndTheReach) {
  // S = 1 − ‖h̄‖ is affine in the first coordinate of ortho and hybrid, whose domains are not
  // boxes: cells cut by the domain's edge or beyond the reach are filled by linear extrapolation,
  // and the box's outer half cells are extrapolated too, so that S is exact everywhere.
  const Fn s([](const DirPair<double>& p) {
    return 1 - std::hypot(p.wi.x + p.wo.x, p.wi.y + p.wo.y) / 2;
  });
  const TestPairs test = draw_test_pairs(s, 20000, 9, ErrorSpace::linear, 85);
  for (Space space : {space_of<Ortho>, space_of<Hybrid>}) {
    GonioSetup setup{space, true, Design::regular, 2000, 1};
    setup.max_theta_deg = 85;
    const GonioReconstruction r(s, setup);
    EXPECT_LT(reconstruction_error(r, test), 1e-12) << name_of(space);
  }
}

// The order p of the error in the cell size h ∝ N^(−1/d): E ∝ h^p.
double order(const Brdf& f, Space s, Design d, std::size_t n0, std::size_t n1,
             const TestPairs& test) {
  const GonioReconstruction a(f, {s, true, d, n0, 5}), b(f, {s, true, d, n1, 5});
  const double ea = reconstruction_error(a, test), eb = reconstruction_error(b, test);
  EXPECT_LT(eb, ea);
  return -3 * std::log(eb / ea) / std::log(double(b.samples()) / double(a.samples()));
}

TEST(Gonio, InterpolationErrorFallsAtSecondOrderForSmoothFunctions) {
  const Fn f(smooth_spherical);
  const TestPairs test = draw_test_pairs(f, 40000, 11, ErrorSpace::linear);
  const double regular = order(f, space_of<Spherical>, Design::regular, 1000, 64000, test);
  EXPECT_GT(regular, 1.7);
  EXPECT_LT(regular, 2.4);
  const double stratified = order(f, space_of<Spherical>, Design::stratified, 1000, 64000, test);
  EXPECT_GT(stratified, 1.5);
  EXPECT_LT(stratified, 2.6);
  // In hybrid, where the domain's edge cuts cells (filled by dilation), the error still falls.
  const Fn lobe([](const DirPair<double>& p) {
    const double hx = (p.wi.x + p.wo.x) / 2, hy = (p.wi.y + p.wo.y) / 2;
    return std::exp(-(hx * hx + hy * hy) / 0.1);
  });
  const TestPairs lobe_test = draw_test_pairs(lobe, 40000, 12, ErrorSpace::linear);
  EXPECT_GT(order(lobe, space_of<Hybrid>, Design::regular, 1000, 27000, lobe_test), 1.2);
}

TEST(Gonio, TestPairsFollowTheProjectedSolidAngleMeasure) {
  const Fn one([](const DirPair<double>&) { return 1.0; });
  const TestPairs t = draw_test_pairs(one, 20000, 3, ErrorSpace::linear);
  ASSERT_EQ(t.pairs.size(), 20000u);
  double zi = 0, zo = 0, xy = 0;
  for (const auto& p : t.pairs) {
    zi += p.wi.z;
    zo += p.wo.z;
    xy += p.wi.x * p.wo.x + p.wi.y * p.wo.y;
  }
  // Cosine-weighted: E[cos θ] = 2/3 (σ ≈ 0.24); independent directions: E[ωi,xy · ωo,xy] = 0.
  EXPECT_NEAR(zi / 20000, 2.0 / 3, 0.01);
  EXPECT_NEAR(zo / 20000, 2.0 / 3, 0.01);
  EXPECT_NEAR(xy / 20000, 0, 0.01);
  // Within a reach of 60°: cos θ in [1/2, 1] with density ∝ cos θ sin θ, mean 7/9.
  const TestPairs near = draw_test_pairs(one, 20000, 3, ErrorSpace::linear, 60);
  double z_min = 1, z_mean = 0;
  for (const auto& p : near.pairs) {
    z_min = std::min({z_min, p.wi.z, p.wo.z});
    z_mean += p.wi.z / 20000;
  }
  EXPECT_GE(z_min, 0.5 - 1e-12);
  EXPECT_NEAR(z_mean, 7.0 / 9, 0.005);
  // A BRDF without data somewhere keeps only the pairs where it has some.
  const Fn half([](const DirPair<double>& p) {
    return p.wi.x > 0 ? 1.0 : std::numeric_limits<double>::quiet_NaN();
  });
  const TestPairs h = draw_test_pairs(half, 20000, 3, ErrorSpace::linear);
  EXPECT_NEAR(double(h.pairs.size()) / 20000, 0.5, 0.02);
}

TEST(Gonio, ReconstructionErrorOfTheTruthIsZeroAndGrowsWithADifference) {
  const Fn f(smooth_spherical);
  const TestPairs t = draw_test_pairs(f, 5000, 4, ErrorSpace::log);
  EXPECT_EQ(reconstruction_error(f, t), 0.0);
  const Fn g([](const DirPair<double>& p) { return 1.5 * smooth_spherical(p); });
  EXPECT_GT(reconstruction_error(g, t), 0.05);
}

TEST(Gonio, StratifiedDesignsAreReproducibleAndDependOnTheSeed) {
  const Fn f(smooth_spherical);
  const TestPairs t = draw_test_pairs(f, 5000, 4, ErrorSpace::linear);
  const GonioReconstruction a(f, {space_of<Hybrid>, true, Design::stratified, 3000, 1});
  const GonioReconstruction b(f, {space_of<Hybrid>, true, Design::stratified, 3000, 1});
  const GonioReconstruction c(f, {space_of<Hybrid>, true, Design::stratified, 3000, 2});
  EXPECT_EQ(reconstruction_error(a, t), reconstruction_error(b, t));
  EXPECT_NE(reconstruction_error(a, t), reconstruction_error(c, t));
  // Redrawn points make the stratified design measure about as many cells as the regular one.
  const GonioReconstruction r(f, {space_of<Hybrid>, true, Design::regular, 3000, 1});
  EXPECT_GT(double(a.samples()), 0.95 * double(r.samples()));
}

TEST(Gonio, PairsOutsideTheHemisphereAndBadInput) {
  const Fn f(smooth_spherical);
  const GonioReconstruction r(f, {space_of<Ortho>, true, Design::regular, 1000, 1});
  const Rgb below = r.eval({dir(0.3, 0), {0.6, 0, -0.8}});
  EXPECT_EQ(below.r, 0.0);
  const Rgb nan = r.eval({{std::nan(""), 0, 1}, dir(0.3, 1)});
  EXPECT_TRUE(std::isnan(nan.r));
  EXPECT_NE(r.name().find("gonio:ortho/own/regular/"), std::string::npos);
  EXPECT_THROW(GonioReconstruction(f, {Space::dirs, true, Design::regular, 1000, 1}),
               std::invalid_argument);
  EXPECT_THROW(GonioReconstruction(f, {space_of<Hybrid>, true, Design::regular, 0, 1}),
               std::invalid_argument);
  const Fn none([](const DirPair<double>&) { return std::numeric_limits<double>::quiet_NaN(); });
  EXPECT_THROW(GonioReconstruction(none, {space_of<Hybrid>, true, Design::regular, 500, 1}),
               std::runtime_error);
}

TEST(Gonio, SamplesToReachInterpolatesLogLog) {
  const std::vector<double> n{100, 10000}, e{1, 0.1};  // E = 10 / √N
  EXPECT_NEAR(samples_to_reach(n, e, 0.1 * std::sqrt(10.0)), 1000, 1e-6);
  EXPECT_EQ(samples_to_reach(n, e, 2), 0);
  EXPECT_TRUE(std::isinf(samples_to_reach(n, e, 0.01)));
  EXPECT_THROW(samples_to_reach(n, std::vector<double>{1}, 0.5), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::acquire
