// A metric registered at run time (metric.hpp) from this file alone is run, stored and reported
// like the built-in ones: its table has its rows, the settings (make_config's --metrics and
// options, describe_config and back) carry its option, a part file its table, the study's files
// its CSV file and its report section. (The registration lasts for the process: each test of this
// executable runs in a process of its own, gtest_discover_tests.)
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>

#include "halfback/loader/load.hpp"
#include "halfback/study/metric.hpp"
#include "halfback/study/parts.hpp"
#include "halfback/study/report.hpp"
#include "support/test_support.hpp"
#include "table_columns.hpp"

namespace halfback::study {
namespace {

// The mean luminance of ρ over the study's test pairs, times the option toy_scale: one row per
// parameterization (the same value in each), off unless asked for.
class ToyMetric final : public Metric {
 public:
  std::string_view name() const override { return "toy"; }
  bool on_by_default() const override { return false; }
  std::vector<MetricOption> options() const override {
    MetricOption scale;
    scale.key = "toy_scale";
    scale.kind = MetricOption::Kind::count;
    scale.default_value = "3";
    scale.help = "The toy metric's factor";
    return {scale};
  }
  static MetricTable table() {
    return {"toy", {columns::parameterization(), columns::real("scaled_mean")}, {}};
  }
  std::vector<TableDef> tables() const override { return {{table}}; }
  void measure_param(BrdfStudy& study, std::size_t k, MetricRows rows) const override {
    double sum = 0;
    for (const DirPair<double>& p : study.test.pairs) sum += study.brdf.eval(p).luminance();
    const double scale = double(option_count(study.config, "toy_scale"));
    rows.table("toy").add({std::string(name_of(study.config.params[k])),
                           scale * sum / double(study.test.pairs.size())});
  }
  std::string report_section(const std::vector<BrdfResult>& results, const StudyConfig&,
                             const report::ReportPlots&) const override {
    std::string md;
    for (const BrdfResult& b : results)
      for (const Row& row : b.table("toy").rows)
        md += "| " + b.label + " | " + std::get<std::string>(row[0]) + " | " +
              std::to_string(std::get<double>(row[1])) + " |\n";
    return md.empty() ? md
                      : "## Toy metric\n\n| BRDF | parameterization | value |\n|---|---|---|\n" +
                            md + "\n";
  }
};

std::string toy_file_text(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

StudySettings quick_settings() {
  StudySettings s;
  s.quick = true;
  s.params = {"halfdiff", "spherical"};
  s.off = {"gonio", "sampling", "fit"};
  s.options["toy_scale"] = "2";
  return s;
}

TEST(MetricPlugin, ARegisteredMetricIsRunStoredAndReported) {
  static const ToyMetric toy;
  register_metric(toy);
  EXPECT_EQ(find_metric("toy"), &toy);
  EXPECT_NE(metric_names().find(", toy"), std::string::npos);
  EXPECT_THROW(register_metric(toy), std::invalid_argument);  // its name is taken
  EXPECT_EQ(stored_tables().back().name, "toy");
  EXPECT_EQ(StudyConfig().option("toy_scale"), "");  // off by default

  // Asked for by --metrics: on, its option as given; its rows are ρ's mean luminance, 0.5/π.
  StudySettings asked = quick_settings();
  asked.metrics = {"toy"};
  const StudyConfig config = make_config(asked);
  EXPECT_EQ(config.option("toy_scale"), "2");
  EXPECT_TRUE(config.budgets.empty());  // --no-gonio
  const BrdfResult result = study_brdf(*load_brdf("lambert:albedo=0.5"), "lambert", config);
  const MetricTable& rows = result.table("toy");
  ASSERT_EQ(rows.rows.size(), 2u);
  EXPECT_EQ(rows.text(rows.rows[1], "parameterization"), "spherical");
  for (const Row& row : rows.rows)
    EXPECT_NEAR(rows.real(row, "scaled_mean"), 2 * 0.5 / std::numbers::pi, 1e-12);

  // The settings of the run carry its option, and read back.
  const std::string described = describe_config(config);
  EXPECT_NE(described.find("\ntoy_scale = 2\n"), std::string::npos) << described;
  EXPECT_EQ(config_from_description(described, "settings").option("toy_scale"), "2");

  // A part file holds its table and reads back the same rows; the study's files have toy.csv and
  // the report its section.
  const test::TempDir dir;
  write_part(dir.path(), "lambert", result, 0);
  EXPECT_NE(toy_file_text(dir / "lambert.part").find("[toy]\n"), std::string::npos);
  const BrdfResult back = read_part(dir.path(), "lambert", config.params);
  EXPECT_EQ(back.table("toy").rows, rows.rows);
  const StudyOutput out = write_study(dir.path(), {back}, config, 1.0);
  EXPECT_NE(std::find(out.files.begin(), out.files.end(), "toy.csv"), out.files.end());
  EXPECT_NE(toy_file_text(dir / "toy.csv").find("lambert,spherical,"), std::string::npos);
  EXPECT_NE(out.markdown.find("## Toy metric"), std::string::npos);

  // Not asked for: no rows, no file, no section, its option empty in the settings; --no-toy
  // turns it off when --metrics names it.
  const StudyConfig plain = make_config(quick_settings());
  EXPECT_NE(describe_config(plain).find("\ntoy_scale = \n"), std::string::npos);
  EXPECT_TRUE(study_brdf(*load_brdf("lambert"), "plain", plain).table("toy").rows.empty());
  asked.off.push_back("toy");
  EXPECT_EQ(make_config(asked).option("toy_scale"), "");
  asked.metrics = {"toy", "nosuchmetric"};
  EXPECT_THROW(make_config(asked), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::study
