// Metric 5, importance sampling (docs/render.md, "Comparing samplers"; docs/study.md): the
// tabulated and factored samplers of the BRDF in each parameterization's chart at each table
// size, against the cosine, the BRDF's own sampler, Dupuy & Jakob's warps and the fitted mixture
// (the fit metric's whole fit, fit_metric.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <mutex>
#include <optional>

#include "fit_metric.hpp"
#include "halfback/formats/rgl.hpp"
#include "halfback/formats/rgl_writer.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/render/brdf_sampler.hpp"
#include "halfback/render/factored_sampler.hpp"
#include "halfback/render/renderer.hpp"
#include "halfback/render/sampling_metric.hpp"
#include "halfback/study/image_metrics.hpp"
#include "halfback/study/metric.hpp"
#include "report_internal.hpp"

namespace halfback::study {

namespace {

// Metric 5: the tabulated sampler in each parameterization's chart at each table size, measured
// once per chart (parameterizations that share a chart share the sampler: their rows copy it),
// against the cosine and the BRDF's own sampler.
// `work`: the spaces the samplers are built in (material_spaces), the rows named by config.params.
// The bytes of the sampling fields of an RGL export (NDF, σ, VNDF, luminance and their warps; not
// the RGB tables, which only evaluate) at these resolutions: they depend on the options only, so
// they are measured once per ladder step, on a Lambertian.
std::size_t sampling_bytes(const RglExportOptions& o) {
  static std::mutex mutex;
  static std::map<std::pair<int, int>, std::size_t> known;
  const std::lock_guard lock(mutex);
  const auto key = std::pair{o.resolution, o.vndf_resolution};
  if (const auto it = known.find(key); it != known.end()) return it->second;
  std::size_t bytes = 0;
  for (const TensorFieldData& f : rgl_fields(*load_brdf("lambert"), o))
    if (f.name != "rgb" && f.name != "spectra") bytes += f.data.size();
  return known[key] = bytes;
}

// Dupuy & Jakob 2018's sampler of `brdf` in at most `kib` KiB: the RGL export's VNDF and
// luminance warps (8 incidence slices) at the largest of a ladder of resolutions whose sampling
// fields fit. With the KiB taken; nullptr (and 0) where the BRDF is anisotropic, the export
// refuses it, or nothing fits.
std::pair<std::shared_ptr<const Brdf>, double> vndf_warp_sampler(const Brdf& brdf,
                                                                 std::size_t kib) {
  if (!brdf.isotropic()) return {nullptr, 0.0};
  constexpr std::pair<int, int> kLadder[] = {{64, 256}, {48, 192}, {32, 128}, {24, 96},
                                             {16, 64},  {12, 48},  {8, 32}};
  for (const auto& [resolution, vndf] : kLadder) {
    RglExportOptions o;
    o.theta_i = 8, o.resolution = resolution, o.vndf_resolution = vndf, o.threads = 1;
    o.incidences = RglIncidences::sigma;  // the published layout, sampled at its nodes
    o.tabulation = RglTabulation::point;
    const std::size_t bytes = sampling_bytes(o);
    if (bytes > kib * 1024) continue;
    try {
      TensorFile file = parse_tensor_file(serialize_tensor_file(rgl_fields(brdf, o)), "vndf-warp");
      return {std::make_shared<RglBrdf>(file, "vndf-warp"), double(bytes) / 1024};
    } catch (const std::invalid_argument&) {
      return {nullptr, 0.0};  // the export refuses this BRDF
    }
  }
  return {nullptr, 0.0};
}

// The sphere's pixels as estimators (the study's image protocol, under the first environment of
// the study, the sky without one): `sampler` (a BRDF with the sampling to measure) rendered with
// the BRDF's samples alone or with MIS. As a SamplingMeasure, so that render::relative_efficiency
// compares two: relative_variance is the image's relative variance per pixel sample over the
// sphere (render::relative_pixel_variance); seconds_per_sample the rendering's time per pixel
// sample; per_wo is empty.
render::SamplingMeasure measure_pixels(const Brdf& sampler, const StudyConfig& config,
                                       render::Strategy strategy) {
  render::RenderSettings settings = image_settings(config);
  settings.strategy = strategy;
  settings.variance = true;
  const render::EnvMap& env = config.environments.empty()
                                  ? *render::default_environments().front().map
                                  : *config.environments.front().map;
  const render::RenderResult r = render::render_sampled(sampler, env, settings);
  render::SamplingMeasure m;
  m.relative_variance =
      render::relative_pixel_variance(r, sphere_mask(settings.width, settings.height));
  m.seconds_per_sample = r.seconds / (double(settings.width) * settings.height * r.spp);
  return m;
}

// What metric 5 compares each sampler with, measured once per BRDF.
struct SamplingReferences {
  render::SamplingMeasure cosine, cosine_pixels_brdf, cosine_pixels_mis;
  std::optional<render::SamplingMeasure> own, mixture;
  std::string own_description = "none";
  std::map<std::size_t, std::pair<render::SamplingMeasure, double>> vndf_warp;  // by KiB asked
};

SamplingReferences sampling_references(const Brdf& brdf, const StudyConfig& config,
                                       const render::SamplingMetricOptions& o,
                                       const std::optional<fit::FitResult>& fitted) {
  SamplingReferences r;
  const auto cosine_sampler = render::with_cosine_sampling(brdf);
  r.cosine = render::measure_sampling(brdf, *cosine_sampler, o);
  r.cosine_pixels_brdf = measure_pixels(*cosine_sampler, config, render::Strategy::brdf);
  r.cosine_pixels_mis = measure_pixels(*cosine_sampler, config, render::Strategy::mis);
  if (brdf.has_importance_sampling()) {
    r.own = render::measure_sampling(brdf, brdf, o);
    r.own_description = brdf.describe_sampling();
  }
  if (fitted) r.mixture = render::measure_sampling(brdf, *load_brdf(fitted->spec), o);
  for (const std::size_t kib : option_counts(config, "sampler_kib")) {
    const auto [sampler, kib_taken] = vndf_warp_sampler(brdf, kib);
    if (sampler) r.vndf_warp[kib] = {render::measure_sampling(brdf, *sampler, o), kib_taken};
  }
  return r;
}

// A row of metric 5: `sampler` (of `kind`, in `chart`, taking `kib_taken` of the `kib` asked)
// measured on the albedo and the pixels, against the references.
SamplingPoint measure_sampler(const Brdf& brdf, const Brdf& sampler, const SamplingReferences& ref,
                              const StudyConfig& config, const render::SamplingMetricOptions& o,
                              std::string kind, std::size_t kib, double kib_taken,
                              std::string chart) {
  const render::SamplingMeasure m = render::measure_sampling(brdf, sampler, o);
  SamplingPoint p;
  p.kib = kib;
  p.sampler = std::move(kind);
  p.sampler_kib = kib_taken;
  p.chart = std::move(chart);
  p.relative_variance = m.relative_variance;
  p.relative_variance_error = m.relative_variance_error;
  p.ns_per_sample = 1e9 * m.seconds_per_sample;
  p.efficiency_vs_cosine = render::relative_efficiency(m, ref.cosine);
  p.own_sampler = ref.own_description;
  p.efficiency_vs_own = ref.own ? render::relative_efficiency(m, *ref.own) : 0;
  if (const auto w = ref.vndf_warp.find(kib); w != ref.vndf_warp.end()) {
    p.vndf_warp_kib = w->second.second;
    p.efficiency_vs_vndf_warp = render::relative_efficiency(m, w->second.first);
  }
  p.efficiency_vs_fitted_mixture = ref.mixture ? render::relative_efficiency(m, *ref.mixture) : 0;
  const render::SamplingMeasure alone = measure_pixels(sampler, config, render::Strategy::brdf);
  const render::SamplingMeasure mis = measure_pixels(sampler, config, render::Strategy::mis);
  p.pixel_relative_variance_brdf = alone.relative_variance;
  p.pixel_relative_variance_mis = mis.relative_variance;
  p.pixel_efficiency_vs_cosine_brdf = render::relative_efficiency(alone, ref.cosine_pixels_brdf);
  p.pixel_efficiency_vs_cosine_mis = render::relative_efficiency(mis, ref.cosine_pixels_mis);
  return p;
}

// The factored sampler's tables are capped at this many radial cells (2·256² cells a term): its
// build factors views × cells, which grows past what a study of many BRDFs can afford.
constexpr int kMaxFactoredRadial = 256;

// Metric 5's rows of one chart at one table size: the tabulated sampler and the factored one.
std::vector<SamplingPoint> chart_samplers(const Brdf& brdf, Space space, std::size_t kib,
                                          const SamplingReferences& ref, const StudyConfig& config,
                                          const render::SamplingMetricOptions& o) {
  const std::string chart(space.param().sampler_chart().name);
  const render::TabulatedSampler table(brdf, render::tabulation_for_memory(space, kib * 1024));
  render::FactorOptions fo = render::factoring_for_memory(space, kib * 1024, kFactoredTerms);
  fo.radial = std::min(fo.radial, kMaxFactoredRadial);
  fo.azimuthal = 2 * fo.radial;
  const render::FactoredSampler factored(brdf, fo);
  return {measure_sampler(brdf, table, ref, config, o, "tabulated", kib,
                          double(table.cells()) * 20 / 1024, chart),
          measure_sampler(brdf, factored, ref, config, o, "factored", kib,
                          double(factored.bytes()) / 1024, chart)};
}

std::vector<std::pair<Space, SamplingPoint>> sampling_rows(
    const Brdf& brdf, const StudyConfig& config, std::span<const Space> work,
    const std::optional<fit::FitResult>& fitted) {
  const render::SamplingMetricOptions o{.samples = option_count(config, "sampler_samples"),
                                        .seed = config.seed};
  const SamplingReferences ref = sampling_references(brdf, config, o, fitted);
  // Parameterizations that share a chart share its samplers: measured once.
  std::map<std::pair<std::string, std::size_t>, std::vector<SamplingPoint>> by_chart;
  std::vector<std::pair<Space, SamplingPoint>> rows;
  for (std::size_t k = 0; k < work.size(); ++k)
    for (const std::size_t kib : option_counts(config, "sampler_kib")) {
      const std::string chart(work[k].param().sampler_chart().name);
      auto it = by_chart.find({chart, kib});
      if (it == by_chart.end())
        it = by_chart
                 .emplace(std::pair{chart, kib}, chart_samplers(brdf, work[k], kib, ref, config, o))
                 .first;
      for (const SamplingPoint& p : it->second) rows.emplace_back(config.params[k], p);
    }
  return rows;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The report (its figures, sampling.png and strategies.png, are drawn with the others:
// report_charts.cpp)
// ---------------------------------------------------------------------------------------------

namespace report {
namespace {

// Per parameterization at one table size: the tabulated and the factored sampler's median
// efficiencies against the cosine, on the albedo and on the pixels with MIS, and for how many
// BRDFs the factored one is the more efficient on the albedo.
std::string sampler_comparison(const std::vector<BrdfResult>& results,
                               const std::vector<Space>& params, std::size_t kib) {
  std::string md = fmt::format(
      "Tabulated and factored ({} terms) samplers in {} KiB, median efficiency against "
      "the cosine on the albedo and on the pixels (MIS):\n\n| parameterization | "
      "albedo, tabulated | albedo, factored | pixels, tabulated | pixels, factored | "
      "factored more efficient (BRDFs) |\n|---|---|---|---|---|---|\n",
      kFactoredTerms, kib);
  for (Space s : params) {
    std::vector<double> albedo[2], pixels[2];
    int wins = 0, compared = 0;
    for (const BrdfResult& b : results) {
      const SamplingPoint* found[2] = {nullptr, nullptr};
      const std::vector<SamplingPoint> kinds[2] = {sampling_points(b, s, "tabulated"),
                                                   sampling_points(b, s, "factored")};
      for (int k = 0; k < 2; ++k)
        for (const SamplingPoint& p : kinds[k])
          if (p.kib == kib) found[k] = &p;
      if (!found[0] || !found[1]) continue;
      for (int k = 0; k < 2; ++k) {
        albedo[k].push_back(found[k]->efficiency_vs_cosine);
        pixels[k].push_back(found[k]->pixel_efficiency_vs_cosine_mis);
      }
      ++compared;
      wins += found[1]->efficiency_vs_cosine > found[0]->efficiency_vs_cosine;
    }
    if (compared == 0) continue;
    md += fmt::format("| {} | {:.3g} | {:.3g} | {:.3g} | {:.3g} | {} of {} |\n", name_of(s),
                      median(albedo[0]), median(albedo[1]), median(pixels[0]), median(pixels[1]),
                      wins, compared);
  }
  return md + "\n";
}

std::string sampling_tables(const std::vector<BrdfResult>& results, const StudyConfig& config) {
  const std::vector<Space>& params = params_of(results);
  std::string md;
  for (const std::size_t kib : option_counts(config, "sampler_kib")) {
    std::string rows;
    Wins wins(params);
    int beats_own = 0, with_own = 0, beats_warp = 0, with_warp = 0, beats_mix = 0, with_mix = 0;
    for (const BrdfResult& b : results) {
      if (b.table("sampling").rows.empty()) continue;
      std::vector<double> variance;
      rows += row_start(b.label);
      bool better_than_own = false, has_own = false, better_than_warp = false, has_warp = false,
           better_than_mix = false, has_mix = false;
      for (Space s : params) {
        double v = NAN;
        for (const SamplingPoint& p : sampling_points(b, s))
          if (p.kib == kib) {
            v = p.relative_variance;
            has_own = p.own_sampler != "none";
            better_than_own |= has_own && p.efficiency_vs_own > 1;
            has_warp |= p.vndf_warp_kib > 0;
            better_than_warp |= p.efficiency_vs_vndf_warp > 1;
            has_mix |= p.efficiency_vs_fitted_mixture > 0;
            better_than_mix |= p.efficiency_vs_fitted_mixture > 1;
          }
        variance.push_back(v);
        rows += std::isfinite(v) ? fmt::format(" {:.3g} |", v) : " – |";
      }
      rows += "\n";
      wins.add(variance);
      with_own += has_own;
      beats_own += better_than_own;
      with_warp += has_warp;
      beats_warp += better_than_warp;
      with_mix += has_mix;
      beats_mix += better_than_mix;
    }
    md += fmt::format("Tables of {} KiB:\n\n", kib) + table_header("BRDF", params) + rows +
          fmt::format(
              "\nLowest variance (BRDFs): {}. BRDFs with a sampler of their own: {}, of "
              "which some table here is more efficient than it for {}. BRDFs with Dupuy & "
              "Jakob's warp in at most {} KiB: {}, of which some table here is more efficient "
              "than it for {}. BRDFs with a fitted mixture ({} sampled through its lobes' "
              "samplers): {}, of which some table here is more efficient than it for {}.\n\n",
              wins.text(), with_own, beats_own, kib, with_warp, beats_warp,
              config.option("fit_model").empty() ? "no model" : config.option("fit_model"),
              with_mix, beats_mix) +
          sampler_comparison(results, params, kib);
  }
  return md;
}

// Importance sampling (metric 5; docs/render.md, "Comparing samplers"): the tabulated and factored
// samplers of each parameterization's chart.
std::string sampling_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                             const ReportPlots& plots) {
  std::string md = fmt::format(
      "## Importance sampling\n\nThe BRDF sampled by a table of ρ cos θi in each "
      "parameterization's sampler chart (the renderer's tabulated sampler, docs/render.md), "
      "tables of equal memory: the relative variance of the one-sample estimator of the "
      "directional albedo, mean over 8 outgoing directions from the normal to 89° ({} samples "
      "each; lower is better; sampling.csv has its standard error, the time per sample and the "
      "efficiency against the cosine and the BRDF's own sampler). Parameterizations that share "
      "a chart share the sampler. Below each table, the factored sampler (Lawrence et al. 2004's "
      "manner: {} terms shared by every view, finer cells at the same memory) beside the "
      "tabulated one.\n\n",
      option_count(config, "sampler_samples"), kFactoredTerms);
  return md + plot_link(plots.sampling, "Importance sampling", "sampling") +
         sampling_tables(results, config);
}

}  // namespace
}  // namespace report

namespace {

class SamplingMetric final : public Metric {
 public:
  std::string_view name() const override { return "sampling"; }
  std::string_view description() const override { return "the importance samplers of each chart"; }
  std::vector<MetricOption> options() const override {
    MetricOption kib;
    kib.key = "sampler_kib";
    kib.kind = MetricOption::Kind::counts;
    kib.default_value = "64,1024";
    kib.quick_value = "64";
    kib.noun = "table size";
    kib.help =
        "Sizes of the samplers' tables (tabulated and factored) compared by the sampling metric, "
        "KiB, comma-separated";
    MetricOption samples;
    samples.key = "sampler_samples";
    samples.kind = MetricOption::Kind::count;
    samples.default_value = "4096";
    samples.quick_value = "1024";
    samples.noun = "sample count";
    samples.help = "Samples per outgoing direction of the sampling metric";
    return {kib, samples};
  }
  void validate(const StudyConfig& config) const override {
    for (const std::size_t kib : option_counts(config, "sampler_kib"))
      if (kib < 1 || kib > kMaxSamplerKib)
        throw std::invalid_argument(
            fmt::format("study: sampler tables of {} KiB: expected 1 to {}", kib, kMaxSamplerKib));
    const std::size_t samples = option_count(config, "sampler_samples");
    if (samples < 2 || samples > kMaxSamplerSamples)
      throw std::invalid_argument(
          fmt::format("study: {} samples per direction for the sampling "
                      "metric: expected 2 to {}",
                      samples, kMaxSamplerSamples));
  }
  std::vector<TableDef> tables() const override { return {{sampling_table}}; }
  void measure_brdf(BrdfStudy& study, MetricRows rows) const override {
    for (const auto& [space, point] :
         sampling_rows(study.brdf, study.config, study.work, whole_fit(study)))
      add_sampling(rows.table("sampling"), space, point);
    study.say("sampling");
  }
  std::string report_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                             const report::ReportPlots& plots) const override {
    if (!report::contents_of(results).sampling) return {};
    return report::sampling_section(results, config, plots);
  }
};

}  // namespace

const Metric& sampling_metric() {
  static const SamplingMetric metric;
  return metric;
}

}  // namespace halfback::study
