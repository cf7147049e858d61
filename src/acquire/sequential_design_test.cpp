#include "halfback/acquire/sequential_design.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "halfback/acquire/design.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::acquire {
namespace {

GonioSetup sequential(Space space, std::size_t budget) {
  GonioSetup s;
  s.space = space;
  s.design = Design::sequential;
  s.budget = budget;
  s.max_theta_deg = 85;
  return s;
}

TEST(SequentialDesign, PilotSamplesAreTheGridsSamplesWhereMeasured) {
  // The pilot's values on its cells are sample_isotropic's on the same grid, wherever the
  // instrument reached (elsewhere: no weight).
  const auto brdf = load_brdf("lambert:albedo=0.2+ggx:alpha=0.2,f0=0.6");
  for (Space space : {space_of<HalfDiff>, space_of<Hybrid>, space_of<Spherical>}) {
    const GonioPlan pilot = gonio_plan(sequential_pilot(sequential(space, 4000)));
    std::vector<Rgb> values;
    for (const PlannedPoint& p : pilot.points) values.push_back(brdf->eval(p.pair));
    const IsoSamples s = pilot_samples(pilot, values, ErrorSpace::log);
    const auto& axes = pilot.cells.axes;
    const IsoSamples all = sample_isotropic(
        *brdf, space, {axes[0].count, axes[1].count, axes[2].count}, ErrorSpace::log);
    ASSERT_EQ(s.value.size(), all.value.size());
    std::size_t measured = 0;
    for (std::size_t p = 0; p < s.value.size(); ++p) {
      if (s.weight[p] == 0) continue;
      ++measured;
      EXPECT_NEAR(s.value[p], all.value[p], 1e-12 * (1 + all.value[p]));
      EXPECT_NEAR(s.weight[p], all.weight[p], 1e-12 * all.weight[p]);
    }
    EXPECT_EQ(measured, pilot.points.size());
    // About a quarter of the budget.
    EXPECT_NEAR(double(pilot.points.size()), 1000, 250);
  }
}

TEST(SequentialDesign, BudgetKeptAndWarpsFollowThePeak) {
  const auto glossy = load_brdf("lambert:albedo=0.05+ggx:alpha=0.05,f0=0.9");
  const SequentialAcquisition a =
      sequential_acquisition(*glossy, sequential(space_of<HalfDiff>, 10000), ErrorSpace::log);
  // Every measurement counts: the pilot's and the main grid's, near the budget.
  EXPECT_NEAR(double(a.samples), 10000, 1500);
  // The pilot found the specular peak at small θh: the warp puts more than the uniform share of
  // cells in the first tenth of θh.
  const AxisWarp& theta_h = a.warps.axes[0];
  const double tenth = theta_h.lo() + 0.1 * (theta_h.hi() - theta_h.lo());
  EXPECT_GT((theta_h.forward(tenth) - theta_h.lo()) / (theta_h.hi() - theta_h.lo()), 0.2);
}

TEST(SequentialDesign, BeatsTheRegularGridOnAGlossyBrdf) {
  const auto glossy = load_brdf("lambert:albedo=0.05+ggx:alpha=0.05,f0=0.9");
  const TestPairs test = draw_test_pairs(*glossy, 50000, 3, ErrorSpace::log, 85);
  GonioSetup regular = sequential(space_of<HalfDiff>, 10000);
  regular.design = Design::regular;
  const double grid = reconstruction_error(GonioReconstruction(*glossy, regular), test);
  const SequentialAcquisition a =
      sequential_acquisition(*glossy, sequential(space_of<HalfDiff>, 10000), ErrorSpace::log);
  EXPECT_LT(reconstruction_error(*a.reconstruction, test), 0.7 * grid);
}

TEST(SequentialDesign, RefusesWhatItIsNot) {
  GonioSetup s = sequential(space_of<HalfDiff>, 1000);
  s.isotropic = false;
  EXPECT_THROW(sequential_pilot(s), std::invalid_argument);
  s = sequential(space_of<HalfDiff>, 1000);
  EXPECT_THROW(sequential_pilot(s, {.pilot_share = 1.0}), std::invalid_argument);
  s.design = Design::regular;
  EXPECT_THROW(sequential_pilot(s), std::invalid_argument);
  // Not a grid: GonioReconstruction and the plans refuse it.
  s.design = Design::sequential;
  EXPECT_THROW(GonioReconstruction(*load_brdf("lambert"), s), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::acquire
