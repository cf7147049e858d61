// Metric 4, the image-space error (docs/study.md): the gonio metric's reconstructions at the
// image budget rendered on a sphere under each environment, against the BRDF's rendering.
#include <fmt/format.h>

#include "gonio_reconstructions.hpp"
#include "halfback/render/renderer.hpp"
#include "halfback/study/image_metrics.hpp"
#include "halfback/study/metric.hpp"
#include "report_internal.hpp"

namespace halfback::study {

using acquire::Design;

namespace {

class ImageMetric final : public Metric {
 public:
  std::string_view name() const override { return "images"; }
  std::string_view description() const override {
    return "the image-space error of the reconstructions";
  }
  // Its settings are the study's (environments, image budget and size): on with environments.
  bool switchable() const override { return true; }
  bool is_on(const StudyConfig& config) const override { return !config.environments.empty(); }
  void switch_off(StudyConfig& config) const override { config.environments.clear(); }
  std::vector<TableDef> tables() const override { return {{image_table}}; }
  void measure_brdf(BrdfStudy& study, MetricRows rows) const override {
    const StudyConfig& config = study.config;
    if (config.budgets.empty() || study.test.pairs.empty() || config.environments.empty()) return;
    const render::RenderSettings settings = image_settings(config);
    const std::vector<std::uint8_t> mask = sphere_mask(settings.width, settings.height);
    for (const render::Environment& env : config.environments) {
      const render::RenderResult truth_result =
          render::render_sampled(study.brdf, *env.map, settings);
      // A BRDF without data somewhere (an ALTA file's few incidence angles) has no ground-truth
      // image to compare with: its reconstructions extrapolate where it has nothing.
      if (truth_result.nonfinite > 0) {
        study.say(fmt::format("images {}: skipped, the BRDF has no value somewhere", env.label));
        continue;
      }
      const render::Image& truth = truth_result.image;
      const bool first = &env == &config.environments.front();
      if (first) study.example_images.push_back(truth);
      for (std::size_t k = 0; k < config.params.size(); ++k) {
        const auto kept = study.per_param[k].find(kImageReconstructions);
        if (kept == study.per_param[k].end()) continue;
        for (const auto& rec :
             *std::any_cast<std::shared_ptr<const GonioReconstructions>>(kept->second)) {
          const render::Image img = render::render_sampled(*rec, *env.map, settings).image;
          if (first && rec->setup().design == Design::regular) study.example_images.push_back(img);
          const ImageError e = compare_images(img, truth, mask);
          add_image(rows.table("image"), config.params[k],
                    {rec->setup().design, rec->samples(), env.label, e.relative_rmse,
                     e.mean_delta_e, e.p95_delta_e, e.mae, e.rmse, e.ssim});
        }
      }
      study.say(fmt::format("images {}", env.label));
    }
  }
  std::string report_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                             const report::ReportPlots& plots) const override {
    if (!report::contents_of(results).images) return {};
    return report::image_section(results, config, plots);
  }
};

}  // namespace

const Metric& image_metric() {
  static const ImageMetric metric;
  return metric;
}

}  // namespace halfback::study
