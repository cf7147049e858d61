#include "halfback/study/study.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <initializer_list>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>

#include "fit_metric.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/fit/fit.hpp"
#include "halfback/formats/adaptive_param.hpp"
#include "halfback/formats/rgl.hpp"
#include "halfback/formats/rgl_writer.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/render/brdf_sampler.hpp"
#include "halfback/render/factored_sampler.hpp"
#include "halfback/render/renderer.hpp"
#include "halfback/render/sampling_metric.hpp"
#include "halfback/study/dupuy_jakob_design.hpp"
#include "halfback/study/image_metrics.hpp"
#include "halfback/study/metric_tables.hpp"
#include "halfback/study/sequential_design.hpp"
#include "material_spaces.hpp"

namespace halfback::study {

namespace {

// a × b × ... cells, or an error naming the grid when it is empty or above kMaxGridCells.
void check_grid(std::initializer_list<std::size_t> axes, const char* which) {
  std::size_t cells = 1;
  for (std::size_t n : axes) {
    if (n == 0)
      throw std::invalid_argument(
          fmt::format("study: the {} needs at least one cell per axis", which));
    if (n > kMaxGridCells || cells > kMaxGridCells / n)
      cells = kMaxGridCells + 1;
    else
      cells *= n;
  }
  if (cells > kMaxGridCells)
    throw std::invalid_argument(
        fmt::format("study: the {} has more than the maximum of {} cells", which, kMaxGridCells));
}

}  // namespace

std::vector<Space> default_studied() {
  std::vector<Space> params = parameterizations();
  std::erase_if(params, [](Space s) { return !s.param().studied_by_default(); });
  // The baseline last, so that the tables read from the half-vector parameterizations to it.
  std::stable_partition(params.begin(), params.end(),
                        [](Space s) { return s != space_of<Spherical>; });
  return params;
}

const MetricTable& BrdfResult::table(std::string_view name) const {
  for (const MetricTable& t : tables)
    if (t.name == name) return t;
  throw std::invalid_argument(
      fmt::format("study: the result of '{}' has no table '{}'", label, name));
}

void StudyConfig::validate() const {
  if (params.empty()) throw std::invalid_argument("study: at least one parameterization");
  for (std::size_t i = 0; i < params.size(); ++i) {
    if (params[i].is_dirs())
      throw std::invalid_argument("study: 'dirs' is not a parameterization to study");
    if (std::find(params.begin(), params.begin() + std::ptrdiff_t(i), params[i]) !=
        params.begin() + std::ptrdiff_t(i))
      throw std::invalid_argument(
          fmt::format("study: the parameterization '{}' is given twice", name_of(params[i])));
  }
  check_grid({grid.a, grid.b, grid.phi}, "isotropic grid");
  check_grid({full_grid[0], full_grid[1], full_grid[2], full_grid[3]}, "4D grid");
  for (const auto* b : {&budgets, &budgets_4d}) {
    for (std::size_t i = 0; i < b->size(); ++i) {
      if ((*b)[i] == 0 || (i > 0 && (*b)[i] <= (*b)[i - 1]))
        throw std::invalid_argument("study: sample budgets must be >= 1 and ascending");
      if ((*b)[i] > kMaxSampleBudget)
        throw std::invalid_argument(fmt::format(
            "study: the sample budget {} is above the maximum of {}", (*b)[i], kMaxSampleBudget));
    }
  }
  if (spacings.empty()) throw std::invalid_argument("study: at least one design (spacing)");
  for (std::size_t i = 0; i < spacings.size(); ++i)
    if (std::find(spacings.begin(), spacings.begin() + std::ptrdiff_t(i), spacings[i]) !=
        spacings.begin() + std::ptrdiff_t(i))
      throw std::invalid_argument(
          fmt::format("study: the design '{}' is given twice", name_of(spacings[i])));
  if (test_pairs < 100) throw std::invalid_argument("study: at least 100 test pairs");
  if (test_pairs > kMaxTestPairs)
    throw std::invalid_argument(
        fmt::format("study: {} test pairs is above the maximum of {}", test_pairs, kMaxTestPairs));
  if (!(max_theta_deg > 0 && max_theta_deg <= 90))
    throw std::invalid_argument(
        "study: the gonio-reflectometer's reach must be in (0, 90] degrees");
  for (const std::size_t kib : sampler_kib)
    if (kib < 1 || kib > kMaxSamplerKib)
      throw std::invalid_argument(
          fmt::format("study: sampler tables of {} KiB: expected 1 to {}", kib, kMaxSamplerKib));
  if (!sampler_kib.empty() && (sampler_samples < 2 || sampler_samples > kMaxSamplerSamples))
    throw std::invalid_argument(
        fmt::format("study: {} samples per direction for the sampling "
                    "metric: expected 2 to {}",
                    sampler_samples, kMaxSamplerSamples));
  if (!fit_model.empty()) {
    if (!fit::parse_loss(fit_loss))
      throw std::invalid_argument(
          fmt::format("study: the fit loss '{}': expected {}", fit_loss, fit::loss_names()));
    (void)fit::parse_model(fit_model);  // std::invalid_argument naming the model's problem
    for (std::size_t i = 0; i < fit_budgets.size(); ++i)
      if (fit_budgets[i] < 1 || fit_budgets[i] > kMaxSampleBudget ||
          (i && fit_budgets[i] <= fit_budgets[i - 1]))
        throw std::invalid_argument(
            fmt::format("study: fit budgets must be ascending, from 1 to {}", kMaxSampleBudget));
    if (fit_samples < 100 || fit_samples > kMaxTestPairs)
      throw std::invalid_argument(fmt::format(
          "study: {} samples for the whole fit: expected 100 to {}", fit_samples, kMaxTestPairs));
  }
  for (std::size_t i = 0; i < nielsen_counts.size(); ++i)
    if (nielsen_counts[i] < 1 || (i && nielsen_counts[i] <= nielsen_counts[i - 1]))
      throw std::invalid_argument("study: Nielsen's measurement counts must be ascending, >= 1");
  if (!environments.empty() && !budgets.empty()) {
    if (std::find(budgets.begin(), budgets.end(), image_budget) == budgets.end())
      throw std::invalid_argument(
          fmt::format("study: the image budget {} is not one of the sample budgets", image_budget));
    if (image_size < 8 || image_spp < 1)
      throw std::invalid_argument("study: images need >= 8 pixels and >= 1 sample per pixel");
    if (std::size_t(image_size) > kMaxImageSize || image_spp > render::kMaxRenderSpp)
      throw std::invalid_argument(
          fmt::format("study: images of at most {} pixels a side and {} samples per pixel",
                      kMaxImageSize, render::kMaxRenderSpp));
    for (const render::Environment& e : environments)
      if (!e.map) throw std::invalid_argument("study: environment '" + e.label + "' is empty");
  }
}

namespace {

render::RenderSettings image_settings(const StudyConfig& c) {
  render::RenderSettings s;
  s.width = s.height = c.image_size;
  s.spp = c.image_spp;
  s.seed = c.seed;
  s.strategy = render::Strategy::env;  // the same light directions for every BRDF
  s.threads = 0;
  return s;
}

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
  for (const std::size_t kib : config.sampler_kib) {
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

std::vector<std::pair<Space, SamplingPoint>> sampling_metric(
    const Brdf& brdf, const StudyConfig& config, std::span<const Space> work,
    const std::optional<fit::FitResult>& fitted) {
  const render::SamplingMetricOptions o{.samples = config.sampler_samples, .seed = config.seed};
  const SamplingReferences ref = sampling_references(brdf, config, o, fitted);
  // Parameterizations that share a chart share its samplers: measured once.
  std::map<std::pair<std::string, std::size_t>, std::vector<SamplingPoint>> by_chart;
  std::vector<std::pair<Space, SamplingPoint>> rows;
  for (std::size_t k = 0; k < work.size(); ++k)
    for (const std::size_t kib : config.sampler_kib) {
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

ImageError image_error(const Brdf& test, const Brdf& reference, const render::EnvMap& env,
                       const StudyConfig& config) {
  const render::RenderSettings settings = image_settings(config);
  const render::RenderResult truth = render::render_sampled(reference, env, settings);
  if (truth.nonfinite > 0)
    throw std::invalid_argument(
        fmt::format("image error: the reference {} gave {} values that are not finite in its "
                    "rendering",
                    reference.name(), truth.nonfinite));
  const render::Image img = render::render_sampled(test, env, settings).image;
  return compare_images(img, truth.image, sphere_mask(settings.width, settings.height));
}

BrdfResult study_brdf(const Brdf& brdf, const std::string& label, const StudyConfig& config) {
  config.validate();
  const auto t0 = std::chrono::steady_clock::now();
  auto say = [&](const std::string& stage) {
    if (config.progress) config.progress(stage);
  };
  BrdfResult result;
  result.label = label;
  result.isotropic = brdf.isotropic();
  // The reconstructions are checked where the instrument reaches (docs/study.md says why).
  const TestPairs test =
      draw_test_pairs(brdf, config.test_pairs, config.seed, config.space, config.max_theta_deg);
  const bool gonio = !config.budgets.empty() && !test.pairs.empty();  // empty: metrics 1-2 only

  // One task per parameterization, with tables of its own rows; the reconstructions at the image
  // budget are kept for the renderings.
  struct Task {
    Space space;
    std::vector<MetricTable> tables = stored_tables();
    std::vector<std::unique_ptr<GonioReconstruction>> for_images;  // one per design
    MetricTable& table(std::string_view name) {
      for (MetricTable& t : tables)
        if (t.name == name) return t;
      throw std::logic_error("study: no table " + std::string(name));
    }
  };
  // Rows are named by s, the work done in w (s but for the per-material warp: material_spaces).
  auto study_in = [&](Space s, Space w) {
    Task t;
    t.space = s;
    const IsoSamples x = sample_isotropic(brdf, w, config.grid, config.space);
    const bool iso = brdf.isotropic();
    std::optional<FullSamples> f;
    if (!iso) f = sample_full(brdf, w, config.full_grid, config.space);
    add_azimuthal(t.table("azimuthal"), s, azimuthal_error(x), 3);
    if (f) add_azimuthal(t.table("azimuthal"), s, azimuthal_error(*f), 4);
    MetricTable& separability = t.table("separability");
    add_separability(separability, s, config.ranks, separability_2d(x, config.ranks), 2);
    add_separability(separability, s, config.ranks, separability_unfolded(x, config.ranks), 3);
    if (f) add_separability(separability, s, config.ranks, separability_4d(*f, config.ranks), 4);
    if (gonio) {
      std::vector<GonioPoint> points;
      for (const GonioRun& run : gonio_runs(s, w, iso, config)) {
        if (run.copy_of_own) {  // the same cells as own: the same numbers
          for (std::size_t k = 0, own = points.size(); k < own; ++k)
            if (points[k].spacing == Spacing::own && points[k].design == run.setup.design)
              points.push_back({points[k].design, points[k].budget, points[k].samples,
                                points[k].error, run.setup.spacing});
          continue;
        }
        if (run.setup.design == Design::sequential) {
          const SequentialAcquisition a = sequential_acquisition(brdf, run.setup, config.space);
          points.push_back({Design::sequential, run.setup.budget, a.samples,
                            reconstruction_error(*a.reconstruction, test), Spacing::own});
          continue;
        }
        if (run.setup.design == Design::dupuy_jakob) {
          if (const auto p = dupuy_jakob_point(brdf, run.setup.budget, test)) points.push_back(*p);
          continue;
        }
        auto rec = std::make_unique<GonioReconstruction>(brdf, run.setup);
        points.push_back({run.setup.design, run.setup.budget, rec->samples(),
                          reconstruction_error(*rec, test), run.setup.spacing});
        if (run.setup.spacing == Spacing::own && run.setup.budget == config.image_budget &&
            !config.environments.empty())
          t.for_images.push_back(std::move(rec));
      }
      if (config.nielsen && iso && s == space_of<HalfDiff>)
        for (const GonioPoint& p : nielsen_points(brdf, test, config)) points.push_back(p);
      for (const GonioPoint& p : points) add_gonio(t.table("gonio"), s, p, iso ? 3 : 4);
    }
    say(fmt::format("{} {}", gonio ? "gonio" : "metrics", name_of(s)));
    return t;
  };
  const std::vector<Space> work = material_spaces(brdf, label, config.params);
  std::vector<Task> done(config.params.size());
  parallel_for(config.params.size(), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) done[k] = study_in(config.params[k], work[k]);
  });

  if (gonio && !config.environments.empty()) {
    const render::RenderSettings settings = image_settings(config);
    const std::vector<std::uint8_t> mask = sphere_mask(settings.width, settings.height);
    for (const render::Environment& env : config.environments) {
      const render::RenderResult truth_result = render::render_sampled(brdf, *env.map, settings);
      // A BRDF without data somewhere (an ALTA file's few incidence angles) has no ground-truth
      // image to compare with: its reconstructions extrapolate where it has nothing.
      if (truth_result.nonfinite > 0) {
        say(fmt::format("images {}: skipped, the BRDF has no value somewhere", env.label));
        continue;
      }
      const render::Image& truth = truth_result.image;
      const bool first = &env == &config.environments.front();
      if (first) result.example_images.push_back(truth);
      for (Task& t : done)
        for (const auto& rec : t.for_images) {
          const render::Image img = render::render_sampled(*rec, *env.map, settings).image;
          if (first && rec->setup().design == Design::regular) result.example_images.push_back(img);
          const ImageError e = compare_images(img, truth, mask);
          add_image(t.table("image"), t.space,
                    {rec->setup().design, rec->samples(), env.label, e.relative_rmse,
                     e.mean_delta_e, e.p95_delta_e, e.mae, e.rmse, e.ssim});
        }
      say(fmt::format("images {}", env.label));
    }
  }
  // One fit of the whole BRDF serves metric 5's fitted-mixture sampler and metric 6.
  const std::optional<fit::FitResult> fitted =
      config.sampler_kib.empty() && config.fit_budgets.empty() ? std::nullopt
                                                               : whole_fit(brdf, config, say);
  if (!config.sampler_kib.empty()) {
    for (const auto& [space, point] : sampling_metric(brdf, config, work, fitted))
      for (Task& t : done)
        if (t.space == space) add_sampling(t.table("sampling"), space, point);
    say("sampling");
  }
  const auto fit_rows = fit_metric(brdf, config, work, fitted);
  for (const auto& [space, point] : fit_rows)
    for (Task& t : done)
      if (t.space == space) add_fit(t.table("fit"), space, point);
  if (!fit_rows.empty()) say("fit");
  // Each table: the rows of the parameterizations one after the other.
  result.params = config.params;
  result.tables = stored_tables();
  for (const Task& t : done)
    for (std::size_t k = 0; k < result.tables.size(); ++k)
      for (const Row& row : t.tables[k].rows) result.tables[k].rows.push_back(row);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace halfback::study
