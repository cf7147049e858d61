#include "halfback/study/study.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <any>
#include <chrono>
#include <initializer_list>
#include <map>
#include <stdexcept>

#include "halfback/core/parallel.hpp"
#include "halfback/render/renderer.hpp"
#include "halfback/study/image_metrics.hpp"
#include "halfback/study/metric.hpp"
#include "halfback/study/metric_tables.hpp"
#include "material_spaces.hpp"

namespace halfback::study {

using acquire::draw_test_pairs;
using acquire::kMaxSampleBudget;

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
  for (const Metric* m : study_metrics()) {
    for (const MetricOption& o : m->options()) {
      const auto it = options.find(o.key);
      if (it == options.end())
        throw std::invalid_argument(fmt::format("study: no value of the option {}", o.key));
      if (!it->second.empty()) check_option_text(o, it->second, "study: " + o.key);
    }
    if (m->is_on(*this)) m->validate(*this);
  }
}

render::RenderSettings image_settings(const StudyConfig& c) {
  render::RenderSettings s;
  s.width = s.height = c.image_size;
  s.spp = c.image_spp;
  s.seed = c.seed;
  s.strategy = render::Strategy::env;  // the same light directions for every BRDF
  s.threads = 0;
  return s;
}

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
  std::vector<const Metric*> on;
  for (const Metric* m : study_metrics())
    if (m->is_on(config)) on.push_back(m);
  // The reconstructions are checked where the instrument reaches (docs/study.md says why).
  BrdfStudy study(
      brdf, label, config, material_spaces(brdf, label, config.params),
      draw_test_pairs(brdf, config.test_pairs, config.seed, config.space, config.max_theta_deg));
  // One task per parameterization, with tables of its own rows, then the metrics of the whole
  // BRDF (their renderings and fits use all cores).
  std::vector<std::vector<MetricTable>> done(config.params.size());
  parallel_for(config.params.size(), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      done[k] = stored_tables();
      for (const Metric* m : on) m->measure_param(study, k, MetricRows{done[k]});
      study.task[k].clear();
      study.say(fmt::format("metrics {}", name_of(config.params[k])));
    }
  });
  BrdfResult result;
  result.label = label;
  result.isotropic = brdf.isotropic();
  result.params = config.params;
  result.tables = stored_tables();
  for (const std::vector<MetricTable>& tables : done)
    for (std::size_t t = 0; t < result.tables.size(); ++t)
      for (const Row& row : tables[t].rows) result.tables[t].rows.push_back(row);
  for (const Metric* m : on) m->measure_brdf(study, MetricRows{result.tables});
  // Each table: the rows of the parameterizations one after the other, each in its order.
  for (MetricTable& table : result.tables) {
    auto index = [&](const Row& row) {
      const std::string& name = table.text(row, "parameterization");
      return std::find_if(config.params.begin(), config.params.end(),
                          [&](Space s) { return name_of(s) == name; }) -
             config.params.begin();
    };
    std::stable_sort(table.rows.begin(), table.rows.end(),
                     [&](const Row& a, const Row& b) { return index(a) < index(b); });
  }
  result.example_images = std::move(study.example_images);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace halfback::study
