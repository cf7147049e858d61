// The study's neural metric: off by default; a row per parameterization, width and input (halfdiff
// with Sztrajman et al.'s vectors too), each with its network's size and the study's error of the
// network against the BRDF; no rows for an anisotropic BRDF.
#include <gtest/gtest.h>

#include "halfback/loader/load.hpp"
#include "halfback/study/metric.hpp"
#include "halfback/study/metric_tables.hpp"
#include "halfback/study/study.hpp"

namespace halfback::study {
namespace {

StudyConfig neural_only() {
  StudyConfig c;
  c.params = {space_of<HalfDiff>, space_of<Hybrid>, space_of<Spherical>};
  c.grid = {8, 8, 8};
  c.budgets.clear();  // no gonio-reflectometer error, no images
  find_metric("sampling")->switch_off(c);
  find_metric("fit")->switch_off(c);
  c.test_pairs = 20000;
  c.options["neural_widths"] = "2,16";
  c.options["neural_samples"] = "6000";
  c.options["neural_epochs"] = "30";
  c.options["neural_learning_rate"] = "0.01";
  return c;
}

TEST(NeuralMetric, OffByDefault) {
  const StudyConfig c;
  EXPECT_FALSE(find_metric("neural")->is_on(c));
  EXPECT_FALSE(find_metric("neural")->on_by_default());
}

// A Lambertian is a constant, which a network represents with its last bias alone: every input
// reaches it closely. A glossy lobe needs the units: the wider network is the better one.
TEST(NeuralMetric, ARowPerWidthAndInputWithItsSizeAndError) {
  const StudyConfig c = neural_only();
  const BrdfResult lambert = study_brdf(*load_brdf("lambert:albedo=0.5"), "lambert", c);
  const MetricTable& t = lambert.table("neural");
  ASSERT_EQ(t.rows.size(), 2u * (3 + 1));  // halfdiff twice (coordinates and vectors)
  for (const Row& r : t.rows) {
    const std::int64_t w = t.integer(r, "width");
    const bool vectors = t.text(r, "input") == "vectors";
    EXPECT_TRUE(!vectors || t.text(r, "parameterization") == "halfdiff");
    EXPECT_EQ(t.integer(r, "parameters"), w * w + (vectors ? 11 : 8) * w + 3);
    EXPECT_EQ(t.integer(r, "bytes"), 4 * t.integer(r, "parameters"));
    EXPECT_LT(t.real(r, "error"), 0.02) << t.text(r, "parameterization") << " " << w;
  }
  const BrdfResult ggx =
      study_brdf(*load_brdf("lambert:albedo=0.1+ggx:alpha=0.3,f0=0.8"), "ggx", c);
  const MetricTable& g = ggx.table("neural");
  for (Space s : c.params) {
    double narrow = 0, wide = 0;
    for (const Row* r : rows_of(g, s))
      if (g.text(*r, "input") == "coordinates")
        (g.integer(*r, "width") == 2 ? narrow : wide) = g.real(*r, "error");
    EXPECT_GT(narrow, 0) << name_of(s);
    EXPECT_LT(wide, narrow) << name_of(s);
  }
}

TEST(NeuralMetric, NoRowsForAnAnisotropicBrdf) {
  StudyConfig c = neural_only();
  c.full_grid = {4, 8, 4, 8};  // the 4D tables of metrics 1-2, small
  c.budgets_4d.clear();
  const BrdfResult r = study_brdf(*load_brdf("ggx:alpha_x=0.1,alpha_y=0.4"), "aniso", c);
  EXPECT_TRUE(r.table("neural").rows.empty());
}

}  // namespace
}  // namespace halfback::study
