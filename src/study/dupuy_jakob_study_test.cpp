// Dupuy & Jakob's layout as a design of the study (acquire/dupuy_jakob_design.hpp): the rows of the
// per-material parameterization, the report, and the plan that refuses it.
#include <gtest/gtest.h>

#include "halfback/acquire/acquisition.hpp"
#include "halfback/acquire/dupuy_jakob_design.hpp"
#include "halfback/acquire/gonio.hpp"
#include "halfback/core/parameterization.hpp"
#include "halfback/formats/adaptive_param.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/study/metric.hpp"
#include "halfback/study/metric_tables.hpp"
#include "halfback/study/report.hpp"
#include "halfback/study/study.hpp"
#include "support/test_support.hpp"

namespace halfback::study {
namespace {

using acquire::Design;
using acquire::draw_test_pairs;
using acquire::dupuy_jakob_acquisition;
using acquire::dupuy_jakob_layout;
using acquire::DupuyJakobLayout;
using acquire::plan_setup;
using acquire::PlanSettings;
using acquire::reconstruction_error;
using acquire::Spacing;
using acquire::TestPairs;

// In the study, the layout is a design of the per-material parameterization: its rows are the
// acquisition's own error on the study's test pairs (the file export-rgl writes), with every
// measurement counted; other parameterizations have none; the report sets it beside the grids;
// an instrument's plan refuses it.
TEST(DupuyJakobLayout, IsADesignOfThePerMaterialParameterizationInTheStudy) {
  register_brdf_parameterization_families();
  StudyConfig c;
  c.params = {space_of<HalfDiff>, *space_from_name(kPerMaterialWarp)};
  c.grid = {8, 8, 8};
  c.budgets = {1000, 10000};
  c.image_budget = 10000;
  c.test_pairs = 5000;
  c.environments.clear();
  find_metric("sampling")->switch_off(c);
  c.options["fit_budgets"].clear();  // the whole fit only (for nothing)
  c.spacings = {Spacing::own};
  const BrdfPtr brdf = load_brdf("lambert:albedo=0.2+ggx:alpha=0.15,f0=0.8");
  const BrdfResult r = study_brdf(*brdf, "glossy", c);
  const TestPairs test = draw_test_pairs(*brdf, c.test_pairs, c.seed, c.space, c.max_theta_deg);
  for (const GonioPoint& p : gonio_points(r, c.params[0], 3))
    EXPECT_NE(p.design, Design::dupuy_jakob);
  int rows = 0;
  for (const GonioPoint& p : gonio_points(r, c.params[1], 3)) {
    if (p.design != Design::dupuy_jakob) continue;
    ++rows;
    const DupuyJakobLayout layout = dupuy_jakob_layout(p.budget);
    EXPECT_EQ(p.samples, layout.measurements());
    EXPECT_EQ(p.error, reconstruction_error(*dupuy_jakob_acquisition(*brdf, layout), test));
  }
  EXPECT_EQ(rows, 2);
  const test::TempDir dir;
  const StudyOutput out = write_study(dir.path(), {r}, c, 1.0);
  EXPECT_NE(out.markdown.find("Dupuy & Jakob's acquisition (`dupuy-jakob`"), std::string::npos);
  PlanSettings plan;
  plan.design = "dupuy-jakob";
  EXPECT_THROW(plan_setup(plan), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::study
