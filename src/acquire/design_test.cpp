// Designs that separate coordinates from spacing (docs/study.md, "Designs"): the warps are monotone
// bijections of each axis, the analytic ones match their definitions, learned warps put their
// samples where a family of BRDFs varies and beat the uniform design there, and leave-one-out never
// reads the held-out BRDF.
#include "halfback/acquire/design.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "halfback/acquire/gonio.hpp"
#include "support/test_brdfs.hpp"

namespace halfback::acquire {
namespace {

constexpr double kPi = std::numbers::pi;

// A family of isotropic lobes around the mirror direction, narrow in θh (width sigma), on a
// constant base: their variation is concentrated at small θh.
test::FunctionBrdf lobe(double sigma) {
  return test::FunctionBrdf([sigma](const DirPair<double>& p) {
    const Vec3<double> h{p.wi.x + p.wo.x, p.wi.y + p.wo.y, p.wi.z + p.wo.z};
    const double norm = std::sqrt(h.x * h.x + h.y * h.y + h.z * h.z);
    const double theta_h = std::acos(std::clamp(h.z / norm, -1.0, 1.0));
    return 0.2 + 3 * std::exp(-theta_h * theta_h / (2 * sigma * sigma));
  });
}

std::vector<DesignProfile> family_profiles() {
  std::vector<DesignProfile> profiles;
  for (double sigma : {0.08, 0.1, 0.12, 0.15})
    profiles.push_back(
        design_profile(lobe(sigma), kKernelSpaces, {32, 32, 32}, ErrorSpace::linear));
  return profiles;
}

// F(lo) = lo, F(hi) = hi, strictly increasing, and F⁻¹(F(x)) = x.
void expect_bijection(const AxisWarp& w, const std::string& what) {
  EXPECT_DOUBLE_EQ(w.forward(w.lo()), w.lo()) << what;
  EXPECT_NEAR(w.forward(w.hi()), w.hi(), 1e-12 * w.hi()) << what;
  double last = w.forward(w.lo());
  for (int i = 1; i <= 1000; ++i) {
    const double x = w.lo() + (w.hi() - w.lo()) * i / 1000.0;
    const double u = w.forward(x);
    EXPECT_GT(u, last) << what << " at " << x;
    last = u;
    EXPECT_NEAR(w.inverse(u), x, 1e-9 * (w.hi() - w.lo())) << what << " at " << x;
    EXPECT_NEAR(w.forward(w.inverse(x)), x, 1e-9 * (w.hi() - w.lo())) << what << " at " << x;
  }
}

TEST(Design, EveryWarpIsAMonotoneBijectionOfItsAxis) {
  const std::vector<DesignProfile> profiles = family_profiles();
  const std::vector<LearnedWarps> learned = learn_warps(profiles, 0);
  ASSERT_EQ(learned.size(), kKernelSpaces.size());
  for (const LearnedWarps& l : learned)
    for (bool iso : {true, false}) {
      const GridSpec g = default_grid(l.space, iso ? GridKind::isotropic : GridKind::full, {4});
      for (Spacing s : kSpacings) {
        const std::vector<AxisWarp> warps = design_warps(g, s, &l);
        ASSERT_EQ(warps.size(), g.axes.size());
        for (std::size_t a = 0; a < warps.size(); ++a) {
          EXPECT_EQ(warps[a].lo(), g.axes[a].lo);
          EXPECT_EQ(warps[a].hi(), g.axes[a].hi);
          expect_bijection(warps[a], std::string(name_of(l.space)) + " " + std::string(name_of(s)) +
                                         " " + g.axes[a].name + (iso ? " 3D" : " 4D"));
        }
      }
    }
}

TEST(Design, AnalyticWarpsMatchTheirDefinitions) {
  using K = AxisWarp::Kind;
  // asin(1/2) / (π/2) = 1/3; MERL: (θ / (π/2))^½ (π/2), and asin first for a sine.
  EXPECT_NEAR(AxisWarp(K::arcsine, 0, 1).forward(0.5), 1.0 / 3, 1e-15);
  EXPECT_NEAR(AxisWarp(K::merl_angle, 0, kPi / 2).forward(kPi / 8), kPi / 4, 1e-15);
  EXPECT_NEAR(AxisWarp(K::merl_arcsine, 0, 1).forward(std::sin(kPi / 8)), 0.5, 1e-15);
  // Which axes each design warps: hybrid (‖h̄‖, ‖k‖, φk) and halfdiff (θh, θd, φd).
  const GridSpec hybrid = default_grid(space_of<Hybrid>, GridKind::isotropic, {4});
  const std::vector<AxisWarp> angle = design_warps(hybrid, Spacing::angle, nullptr);
  EXPECT_EQ(angle[0].kind(), K::arcsine);
  EXPECT_EQ(angle[1].kind(), K::arcsine);
  EXPECT_EQ(angle[2].kind(), K::identity);
  const std::vector<AxisWarp> merl = design_warps(hybrid, Spacing::merl, nullptr);
  EXPECT_EQ(merl[0].kind(), K::merl_arcsine);
  EXPECT_EQ(merl[1].kind(), K::arcsine);
  const GridSpec halfdiff = default_grid(space_of<HalfDiff>, GridKind::full, {4});
  const std::vector<AxisWarp> hd = design_warps(halfdiff, Spacing::merl, nullptr);
  EXPECT_EQ(hd[0].kind(), K::merl_angle);  // θh
  for (std::size_t a = 1; a < 4; ++a) EXPECT_EQ(hd[a].kind(), K::identity);
  EXPECT_TRUE(same_as_own(space_of<HalfDiff>, true, Spacing::angle));
  EXPECT_TRUE(same_as_own(space_of<Spherical>, false, Spacing::merl));
  EXPECT_FALSE(same_as_own(space_of<HalfDiff>, true, Spacing::merl));
  EXPECT_FALSE(same_as_own(space_of<Ortho>, true, Spacing::angle));
  EXPECT_FALSE(same_as_own(space_of<Spherical>, true, Spacing::learned));
}

TEST(Design, BadWarpsAndMissingLearnedWarpsAreRefused) {
  EXPECT_THROW(AxisWarp::from_cdf(0, 1, {0, 0.5, 0.5, 1}), std::invalid_argument);
  EXPECT_THROW(AxisWarp::from_cdf(0, 1, {0, 0.5, 0.9}), std::invalid_argument);
  EXPECT_THROW(AxisWarp(AxisWarp::Kind::arcsine, 0, kPi / 2), std::invalid_argument);
  EXPECT_THROW(AxisWarp(AxisWarp::Kind::identity, 1, 1), std::invalid_argument);
  const GridSpec g = default_grid(space_of<Hybrid>, GridKind::isotropic, {4});
  EXPECT_THROW(design_warps(g, Spacing::learned, nullptr), std::invalid_argument);
  LearnedWarps other;
  other.space = space_of<Ortho>;
  EXPECT_THROW(design_warps(g, Spacing::learned, &other), std::invalid_argument);
  EXPECT_EQ(parse_spacing("merl"), Spacing::merl);
  EXPECT_EQ(parse_spacing("uniform"), std::nullopt);
}

TEST(Design, LearnedWarpsPutTheSamplesWhereTheFamilyVariesAndBeatUniform) {
  // Learned on the family without its first member (σ = 0.08), tested on that member.
  const std::vector<DesignProfile> profiles = family_profiles();
  const std::vector<LearnedWarps> learned = learn_warps(profiles, 0);
  const auto halfdiff = std::find_if(learned.begin(), learned.end(), [](const LearnedWarps& w) {
    return w.space == space_of<HalfDiff>;
  });
  ASSERT_NE(halfdiff, learned.end());
  // The lobes live at θh < 0.3 rad, 19 % of θh's range: the learned θh axis gives them at least
  // half of its cells.
  const AxisWarp& theta_h = halfdiff->axes[0];
  EXPECT_GT(theta_h.forward(0.3) / (kPi / 2), 0.5);
  // The same budget, uniform in (θh, θd, φd) against the learned spacing.
  const test::FunctionBrdf held_out = lobe(0.08);
  const TestPairs test = draw_test_pairs(held_out, 40000, 5, ErrorSpace::linear, 85);
  GonioSetup setup;
  setup.space = space_of<HalfDiff>;
  setup.budget = 4000;
  setup.max_theta_deg = 85;
  const double uniform = reconstruction_error(GonioReconstruction(held_out, setup), test);
  setup.spacing = Spacing::learned;
  setup.learned = *halfdiff;
  const GonioReconstruction rec(held_out, setup);
  const double learned_error = reconstruction_error(rec, test);
  EXPECT_LT(learned_error, 0.6 * uniform) << "uniform " << uniform << ", learned " << learned_error;
  // Budgets stay comparable: the learned design takes about as many measurements.
  EXPECT_NEAR(double(rec.samples()) / 4000, 1.0, 0.2);
}

TEST(Design, LeaveOneOutNeverReadsTheHeldOutBrdf) {
  std::vector<DesignProfile> profiles = family_profiles();
  const std::vector<LearnedWarps> before = learn_warps(profiles, 1);
  const std::vector<LearnedWarps> others_before = learn_warps(profiles, 0);
  // Replace the held-out BRDF by a very different one (a lobe 5x wider).
  profiles[1] = design_profile(lobe(0.6), kKernelSpaces, {32, 32, 32}, ErrorSpace::linear);
  EXPECT_EQ(learn_warps(profiles, 1), before);
  // It does count when it is not held out (the check above could not pass by accident).
  EXPECT_NE(learn_warps(profiles, 0), others_before);
  // Nothing to learn from: no warps (the study then has no learned rows).
  EXPECT_TRUE(learn_warps(std::span(profiles).first(1), 0).empty());
}

}  // namespace
}  // namespace halfback::acquire
