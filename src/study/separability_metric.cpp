// Metric 2, separability (docs/study.md): the best rank-r approximations of the 2D projection,
// of the 3D table unfolded along its azimuth and, for an anisotropic BRDF, of the 4D table.
#include "grid_samples.hpp"
#include "halfback/study/metric.hpp"
#include "halfback/study/metrics.hpp"
#include "report_internal.hpp"

namespace halfback::study {

namespace {

class SeparabilityMetric final : public Metric {
 public:
  std::string_view name() const override { return "separability"; }
  std::vector<TableDef> tables() const override { return {{separability_table}}; }
  void measure_param(BrdfStudy& study, std::size_t k, MetricRows rows) const override {
    const GridSamples& g = grid_samples(study, k);
    const Space s = study.config.params[k];
    const std::vector<int>& ranks = study.config.ranks;
    MetricTable& table = rows.table("separability");
    add_separability(table, s, ranks, separability_2d(g.iso, ranks), 2);
    add_separability(table, s, ranks, separability_unfolded(g.iso, ranks), 3);
    if (g.full) add_separability(table, s, ranks, separability_4d(*g.full, ranks), 4);
  }
  std::string report_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                             const report::ReportPlots&) const override {
    return report::separability_section(results, config, report::contents_of(results).anisotropic);
  }
};

}  // namespace

const Metric& separability_metric() {
  static const SeparabilityMetric metric;
  return metric;
}

}  // namespace halfback::study
