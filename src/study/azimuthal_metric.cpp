// Metric 1, the azimuthal dependence (docs/study.md): the error of dropping the relative azimuth
// of each parameterization's isotropic form, and the second azimuth of an anisotropic BRDF's
// full form.
#include "grid_samples.hpp"
#include "halfback/study/metric.hpp"
#include "halfback/study/metrics.hpp"
#include "report_internal.hpp"

namespace halfback::study {

namespace {

class AzimuthalMetric final : public Metric {
 public:
  std::string_view name() const override { return "azimuthal"; }
  std::vector<TableDef> tables() const override { return {{azimuthal_table}}; }
  void measure_param(BrdfStudy& study, std::size_t k, MetricRows rows) const override {
    const GridSamples& g = grid_samples(study, k);
    const Space s = study.config.params[k];
    add_azimuthal(rows.table("azimuthal"), s, azimuthal_error(g.iso), 3);
    if (g.full) add_azimuthal(rows.table("azimuthal"), s, azimuthal_error(*g.full), 4);
  }
  std::string report_section(const std::vector<BrdfResult>& results, const StudyConfig&,
                             const report::ReportPlots&) const override {
    return report::azimuthal_section(results, report::contents_of(results).anisotropic);
  }
};

}  // namespace

const Metric& azimuthal_metric() {
  static const AzimuthalMetric metric;
  return metric;
}

}  // namespace halfback::study
