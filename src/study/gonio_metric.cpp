// Metric 3, the virtual gonio-reflectometer (docs/study.md): each parameterization's
// reconstructions at each budget in each design, checked on the study's test pairs; gonio.csv and
// the budgets derived from it (budget.csv). The reconstructions at the image budget are kept for
// the image metric (image_metric.cpp).
#include <fmt/format.h>

#include <algorithm>
#include <optional>

#include "gonio_reconstructions.hpp"
#include "halfback/acquire/dupuy_jakob_design.hpp"
#include "halfback/acquire/sequential_design.hpp"
#include "halfback/study/metric.hpp"
#include "material_spaces.hpp"
#include "report_internal.hpp"

namespace halfback::study {

using acquire::Design;
using acquire::dupuy_jakob_acquisition;
using acquire::dupuy_jakob_layout;
using acquire::DupuyJakobLayout;
using acquire::GonioReconstruction;
using acquire::GonioSetup;
using acquire::kDesigns;
using acquire::LearnedWarps;
using acquire::nielsen_acquisition;
using acquire::NielsenAcquisition;
using acquire::reconstruction_error;
using acquire::same_as_own;
using acquire::sequential_acquisition;
using acquire::SequentialAcquisition;
using acquire::Spacing;
using acquire::TestPairs;

namespace {

// One reconstruction of the gonio-reflectometer: the own spacing in every layout, then the other
// spacings in the regular layout, each at every budget (designs that are the own one for this
// parameterization copy its rows; the learned one only where warps were learned).
struct GonioRun {
  GonioSetup setup;
  bool copy_of_own = false;
};

// s names the parameterization (config.params), w is the space worked in (material_spaces).
std::vector<GonioRun> gonio_runs(Space s, Space w, bool iso, const StudyConfig& config) {
  const auto& budgets = iso ? config.budgets : config.budgets_4d;
  const auto learned = std::find_if(config.learned.begin(), config.learned.end(),
                                    [&](const LearnedWarps& l) { return l.space == s; });
  const bool own = std::find(config.spacings.begin(), config.spacings.end(), Spacing::own) !=
                   config.spacings.end();
  std::vector<GonioRun> runs;
  auto add = [&](Spacing spacing, Design d) {
    if (spacing == Spacing::learned && learned == config.learned.end()) return;
    const bool copy = own && spacing != Spacing::own && same_as_own(w, iso, spacing);
    for (std::size_t budget : budgets) {
      GonioRun run;
      run.copy_of_own = copy;
      run.setup.space = w;
      run.setup.isotropic = iso;
      run.setup.design = d;
      run.setup.budget = budget;
      run.setup.seed = config.seed;
      run.setup.max_theta_deg = config.max_theta_deg;
      run.setup.spacing = spacing;
      if (spacing == Spacing::learned) {
        run.setup.learned = *learned;
        run.setup.learned->space = w;  // learned under the name, applied in the BRDF's own space
      }
      runs.push_back(std::move(run));
      if (copy) break;  // one marker copies every budget
    }
  };
  if (own)
    for (Design d : kDesigns) add(Spacing::own, d);
  if (own && iso) add(Spacing::own, Design::sequential);
  for (Spacing spacing : config.spacings)
    if (spacing != Spacing::own) add(spacing, Design::regular);
  // Dupuy & Jakob's own acquisition, in their parameterization (isotropic BRDFs: the export's).
  if (own && iso && is_per_material_placeholder(s.param())) add(Spacing::own, Design::dupuy_jakob);
  return runs;
}

// Dupuy & Jakob's acquisition of `brdf` at `budget` (dupuy_jakob_design.hpp) as a row of the
// gonio table: the measurements it takes, the retro-reflection included. None when the budget is
// below its smallest layout or the export refuses the BRDF (a value the format cannot hold).
std::optional<GonioPoint> dupuy_jakob_point(const Brdf& brdf, std::size_t budget,
                                            const TestPairs& test) {
  try {
    const DupuyJakobLayout layout = dupuy_jakob_layout(budget);
    const double error = reconstruction_error(*dupuy_jakob_acquisition(brdf, layout, 1), test);
    return GonioPoint{Design::dupuy_jakob, budget, layout.measurements(), error, Spacing::own};
  } catch (const std::invalid_argument&) {
    return std::nullopt;
  }
}

// Nielsen et al.'s acquisition of `brdf` (nielsen.hpp) as rows of halfdiff's gonio table, one per
// measurement count (the budget and the samples), on the study's test pairs (the database keeps
// its members' values there: combinations are read, not evaluated).
std::vector<GonioPoint> nielsen_points(const Brdf& brdf, const TestPairs& test,
                                       const StudyConfig& config) {
  const NielsenAcquisition a = nielsen_acquisition(config.nielsen, brdf, config.nielsen_counts);
  std::vector<GonioPoint> points;
  for (const auto& rec : a.reconstructions)
    points.push_back(GonioPoint{Design::nielsen, rec->measurements(), rec->measurements(),
                                reconstruction_error(*rec, test), Spacing::own});
  return points;
}

class GonioMetric final : public Metric {
 public:
  std::string_view name() const override { return "gonio"; }
  std::string_view description() const override {
    return "the virtual gonio-reflectometer, and with it the images: metrics 1-2 only";
  }
  // Its settings are the study's (budgets, designs, test pairs): on when there are budgets.
  bool switchable() const override { return true; }
  bool is_on(const StudyConfig& config) const override { return !config.budgets.empty(); }
  void switch_off(StudyConfig& config) const override {
    config.budgets.clear();
    config.environments.clear();  // no reconstructions to render
  }
  std::vector<TableDef> tables() const override {
    return {{gonio_table}, {budget_table, derive_budget}};
  }
  void measure_param(BrdfStudy& study, std::size_t k, MetricRows rows) const override {
    const StudyConfig& config = study.config;
    if (config.budgets.empty() || study.test.pairs.empty()) return;
    const Brdf& brdf = study.brdf;
    const Space s = config.params[k];
    const bool iso = brdf.isotropic();
    auto kept = std::make_shared<GonioReconstructions>();
    std::vector<GonioPoint> points;
    for (const GonioRun& run : gonio_runs(s, study.work[k], iso, config)) {
      if (run.copy_of_own) {  // the same cells as own: the same numbers
        for (std::size_t j = 0, own = points.size(); j < own; ++j)
          if (points[j].spacing == Spacing::own && points[j].design == run.setup.design)
            points.push_back({points[j].design, points[j].budget, points[j].samples,
                              points[j].error, run.setup.spacing});
        continue;
      }
      if (run.setup.design == Design::sequential) {
        const SequentialAcquisition a = sequential_acquisition(brdf, run.setup, config.space);
        points.push_back({Design::sequential, run.setup.budget, a.samples,
                          reconstruction_error(*a.reconstruction, study.test), Spacing::own});
        continue;
      }
      if (run.setup.design == Design::dupuy_jakob) {
        if (const auto p = dupuy_jakob_point(brdf, run.setup.budget, study.test))
          points.push_back(*p);
        continue;
      }
      auto rec = std::make_unique<GonioReconstruction>(brdf, run.setup);
      points.push_back({run.setup.design, run.setup.budget, rec->samples(),
                        reconstruction_error(*rec, study.test), run.setup.spacing});
      if (run.setup.spacing == Spacing::own && run.setup.budget == config.image_budget &&
          !config.environments.empty())
        kept->push_back(std::move(rec));
    }
    if (config.nielsen && iso && s == space_of<HalfDiff>)
      for (const GonioPoint& p : nielsen_points(brdf, study.test, config)) points.push_back(p);
    for (const GonioPoint& p : points) add_gonio(rows.table("gonio"), s, p, iso ? 3 : 4);
    study.per_param[k][kImageReconstructions] =
        std::shared_ptr<const GonioReconstructions>(std::move(kept));
  }
  std::string report_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                             const report::ReportPlots& plots) const override {
    const report::Contents has = report::contents_of(results);
    if (!has.gonio) return {};
    return report::gonio_section(results, config, has.anisotropic, plots) +
           report::designs_section(results, config, plots);
  }
};

}  // namespace

const Metric& gonio_metric() {
  static const GonioMetric metric;
  return metric;
}

}  // namespace halfback::study
