// Measurement plans for a real instrument (acquisition.hpp): each configuration once, by isotropy
// and reciprocity; the value of every point of the plan is the value at its measured row; the
// serpentine order shortens the motors' travel; a reconstruction from the plan's rows is the
// virtual gonio-reflectometer's.
#include "halfback/study/acquisition.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "halfback/models/analytic.hpp"

namespace halfback::study {
namespace {

// An isotropic, reciprocal BRDF without the mirror symmetry about the plane of incidence would
// show a wrong turn; GGX plus a Lambert term has both symmetries, so the test also checks the
// rows' configurations directly.
const models::Sum& truth() {
  static const models::Sum sum({std::make_shared<models::Lambert>(Rgb{0.2, 0.3, 0.4}),
                                std::make_shared<models::Microfacet>(models::MicrofacetParams{})});
  return sum;
}

double cos_between(const DirPair<double>& p) {  // invariant under a turn about the normal
  return p.wi.x * p.wo.x + p.wi.y * p.wo.y + p.wi.z * p.wo.z;
}

TEST(AcquisitionPlan, EveryPointIsItsRowsConfiguration) {
  for (Space space : {space_of<HalfDiff>, space_of<Hybrid>, space_of<Spherical>}) {
    for (bool iso : {true, false}) {
      GonioSetup s;
      s.space = space;
      s.isotropic = iso;
      s.budget = iso ? 3000 : 6000;
      const AcquisitionPlan a = acquisition_plan(s);
      ASSERT_EQ(a.row_of_point.size(), a.plan.points.size());
      ASSERT_EQ(a.positions.size(), a.measured.size());
      for (std::size_t k = 0; k < a.plan.points.size(); ++k) {
        const DirPair<double>& p = a.plan.points[k].pair;
        const DirPair<double>& m = a.measured[a.row_of_point[k]];
        // The same zeniths (or swapped) and the same angle between the directions.
        const double ti = std::acos(std::clamp(p.wi.z, -1.0, 1.0)),
                     to = std::acos(std::clamp(p.wo.z, -1.0, 1.0));
        const double mi = a.positions[a.row_of_point[k]].light_theta,
                     mo = a.positions[a.row_of_point[k]].detector_theta;
        const bool same = std::abs(ti - mi) < 1e-7 && std::abs(to - mo) < 1e-7;
        const bool swapped = std::abs(ti - mo) < 1e-7 && std::abs(to - mi) < 1e-7;
        ASSERT_TRUE(same || swapped) << name_of(space) << " point " << k;
        ASSERT_NEAR(cos_between(p), cos_between(m), 1e-9) << name_of(space) << " point " << k;
        if (!iso) {  // no turn: the pair itself, or its swap
          const bool exact = std::abs(p.wi.x - m.wi.x) + std::abs(p.wi.y - m.wi.y) < 1e-9 ||
                             std::abs(p.wi.x - m.wo.x) + std::abs(p.wi.y - m.wo.y) < 1e-9;
          ASSERT_TRUE(exact) << name_of(space) << " point " << k;
        }
      }
      for (const GonioPosition& g : a.positions) {
        if (iso) {
          EXPECT_EQ(g.light_phi, 0.0);  // a three-axis instrument suffices
        }
        EXPECT_LE(g.light_theta, g.detector_theta + 1e-9);  // the swap nearer the normal
      }
    }
  }
}

// Reciprocity halves a halfdiff plan (φd and φd + π are each other's swap); the serpentine order
// travels less than the cells' order.
TEST(AcquisitionPlan, ReciprocityAndOrderSaveWork) {
  GonioSetup s;
  s.space = space_of<HalfDiff>;
  s.budget = 4000;
  const AcquisitionPlan a = acquisition_plan(s);
  EXPECT_LT(double(a.measured.size()), 0.6 * double(a.plan.points.size()));
  EXPECT_GT(double(a.measured.size()), 0.4 * double(a.plan.points.size()));
  EXPECT_LT(a.travel, 0.5 * a.cell_order_travel) << a.travel << " vs " << a.cell_order_travel;
  double sum = 0;
  for (std::size_t k = 1; k < a.positions.size(); ++k)
    sum += travel(a.positions[k - 1], a.positions[k]);
  EXPECT_NEAR(a.travel, sum, 1e-9 * sum);
}

// Values measured at the plan's rows, spread back to its points, give the reconstruction of the
// virtual instrument (the BRDF is isotropic and reciprocal); a missing row is filled, not zero.
TEST(AcquisitionPlan, ReconstructionFromTheRowsIsTheVirtualOne) {
  GonioSetup s;
  s.space = space_of<Hybrid>;
  s.design = Design::stratified;
  s.budget = 2000;
  const AcquisitionPlan a = acquisition_plan(s);
  std::vector<Rgb> rows(a.measured.size());
  truth().eval_batch(a.measured, rows);
  std::vector<Rgb> values(a.plan.points.size());
  for (std::size_t k = 0; k < values.size(); ++k) values[k] = rows[a.row_of_point[k]];
  const GonioReconstruction from_rows(a.plan, values, "lab");
  const GonioReconstruction virtual_one(truth(), s);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int k = 0; k < 200; ++k) {
    const double t1 = 1.4 * u(rng), t2 = 1.4 * u(rng), f = 6.28 * u(rng);
    const DirPair<double> p{{std::sin(t1), 0, std::cos(t1)},
                            {std::sin(t2) * std::cos(f), std::sin(t2) * std::sin(f), std::cos(t2)}};
    const Rgb x = from_rows.eval(p), y = virtual_one.eval(p);
    ASSERT_NEAR(x.g, y.g, 1e-9 * (1 + y.g)) << k;
  }
  values[0] = Rgb{NAN, NAN, NAN};
  const GonioReconstruction missing(a.plan, values, "lab");
  EXPECT_EQ(missing.samples(), virtual_one.samples() - 1);
  EXPECT_THROW(GonioReconstruction(a.plan, std::span(values).first(3), "lab"),
               std::invalid_argument);
}

}  // namespace
}  // namespace halfback::study
