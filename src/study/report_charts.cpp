// The figures of the report (report_internal.hpp): bar charts of metrics 1, 2 and 4, the
// gonio-reflectometer's curves, the designs and the summary, and the example renderings. A series
// (a colour) per parameterization, in the order of the results'.
#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <optional>

#include "halfback/figure/chart.hpp"
#include "halfback/figure/material.hpp"
#include "halfback/figure/plot.hpp"
#include "halfback/figure/render.hpp"
#include "halfback/study/metric.hpp"
#include "report_internal.hpp"

namespace halfback::study::report {

using acquire::Design;
using acquire::Spacing;

namespace {

std::vector<std::string> param_names(const std::vector<Space>& params) {
  std::vector<std::string> names;
  for (Space s : params) names.emplace_back(name_of(s));
  return names;
}

// A bar chart with a row per BRDF and a bar per parameterization: value(b, s) for each BRDF of
// results that `shown` accepts.
template <class Value, class Shown>
figure::BarChart per_brdf_chart(const std::vector<BrdfResult>& results, Value value, Shown shown) {
  figure::BarChart c;
  c.series = param_names(params_of(results));
  for (const BrdfResult& b : results) {
    if (!shown(b)) continue;
    c.rows.push_back(b.label);
    c.values.emplace_back();
    for (Space s : b.params) c.values.back().push_back(value(b, s));
  }
  return c;
}

figure::BarChart azimuthal_chart(const std::vector<BrdfResult>& results,
                                 const StudyConfig& config) {
  figure::BarChart c = per_brdf_chart(
      results, [](const BrdfResult& b, Space s) { return azimuthal_error(b, s, 3); },
      [](const BrdfResult&) { return true; });
  c.title = fmt::format("Azimuthal dependence ({} error space)", name_of(config.space));
  c.x_label = "relative error of dropping the relative azimuth";
  return c;
}

figure::BarChart separability_chart(const std::vector<BrdfResult>& results,
                                    const StudyConfig& config) {
  figure::BarChart c = per_brdf_chart(
      results,
      [](const BrdfResult& b, Space s) {
        const std::vector<double> e = separability_errors(b, s, 2);
        return e.empty() ? 0.0 : e[0];
      },
      [](const BrdfResult&) { return true; });
  c.title = fmt::format("Separability of the 2D projection, rank 1 ({} error space)",
                        name_of(config.space));
  c.x_label = "relative error of the best rank-1 approximation";
  return c;
}

// The regular design's relative RMSE of the BRDFs that were rendered (0 where not finite).
figure::BarChart image_chart(const std::vector<BrdfResult>& results, const StudyConfig& config) {
  figure::BarChart c = per_brdf_chart(
      results,
      [](const BrdfResult& b, Space s) {
        const MeanImageError m = mean_image_error(image_points(b, s), Design::regular);
        return m.count && std::isfinite(m.relative_rmse) ? m.relative_rmse : 0.0;
      },
      [](const BrdfResult& b) { return has_images(b); });
  c.title = fmt::format("Image-space error of the reconstructions from {} measurements",
                        config.image_budget);
  c.x_label = "relative RMSE of the sphere renderings (regular design, mean over maps)";
  return c;
}

// The gonio curves as small multiples: one panel per BRDF, a colour per parameterization, the
// regular design solid and the stratified one dashed.
figure::Scene gonio_chart(const std::vector<BrdfResult>& results, bool four_d,
                          const StudyConfig& config) {
  figure::LogLogChart c;
  c.title = fmt::format("Virtual gonio-reflectometer{}: relative error ({} space) against samples",
                        four_d ? " (4D, full form)" : "", name_of(config.space));
  c.x_label = "measurements";
  c.y_label = "relative error";
  for (const BrdfResult& b : results) {
    if (four_d && b.isotropic) continue;
    figure::LogLogPanel panel{b.label, {}};
    for (std::size_t i = 0; i < b.params.size(); ++i) {
      const std::vector<GonioPoint> points = gonio_points(b, b.params[i], four_d ? 4 : 3);
      for (Design d : {Design::regular, Design::stratified, Design::nielsen}) {
        GonioCurve curve = gonio_curve(points, d);
        bool positive = !curve.samples.empty(), exact = true;
        for (double v : curve.errors) {
          positive &= v > 0 && std::isfinite(v);
          exact &= v < 1e-12;
        }
        if (!positive || exact) continue;  // an exact reconstruction has no place on a log axis
        // Nielsen's curve (halfdiff's, a database's components) in a colour of its own.
        const int colour = d == Design::nielsen ? int(b.params.size()) : int(i);
        panel.series.push_back({fmt::format("{} {}", name_of(b.params[i]), name_of(d)), colour,
                                d == Design::stratified, std::move(curve.samples),
                                std::move(curve.errors)});
      }
    }
    if (!panel.series.empty()) c.panels.push_back(std::move(panel));
  }
  if (c.panels.empty()) return {};
  c.columns = int(std::min<std::size_t>(4, c.panels.size()));
  return figure::loglog_chart(c);
}

namespace {

// One strategy's curve over a set of BRDFs: per budget, the median measurements and the median
// error of those that have the row (none: nothing to draw).
std::optional<figure::LineSeries> median_curve(const std::vector<BrdfResult>& results,
                                               const std::vector<std::size_t>& members, Space s,
                                               Design d) {
  std::map<std::size_t, std::pair<std::vector<double>, std::vector<double>>> at;  // by budget
  for (const std::size_t j : members)
    for (const GonioPoint& p : gonio_points(results[j], s, 3))
      if (p.design == d && p.spacing == Spacing::own && p.error > 0 && std::isfinite(p.error)) {
        at[p.budget].first.push_back(double(p.samples));
        at[p.budget].second.push_back(p.error);
      }
  if (at.empty()) return std::nullopt;
  figure::LineSeries line;
  for (auto& [budget, v] : at) {
    line.x.push_back(median(v.first));
    line.y.push_back(median(v.second));
  }
  return line;
}

}  // namespace

// Every acquisition strategy of the study, one panel per kind of BRDF: the median error against
// the median measurements of each parameterization's regular (solid) and sequential (dashed)
// designs, Dupuy & Jakob's layout and Nielsen et al.'s minimal sampling (colours of their own).
// Empty without a sequential, Dupuy & Jakob or Nielsen row.
figure::Scene strategies_chart(const std::vector<BrdfResult>& results) {
  const std::vector<Space>& params = params_of(results);
  figure::LogLogChart c;
  c.title = "Acquisition strategies: median relative error against measurements, by kind";
  c.x_label = "measurements";
  c.y_label = "median relative error";
  bool beyond_grids = false;
  for (const auto& [kind, members] : kinds_of(results)) {
    figure::LogLogPanel panel{fmt::format("{} ({})", kind, members.size()), {}};
    for (std::size_t i = 0; i < params.size(); ++i)
      for (Design d : {Design::regular, Design::sequential})
        if (auto line = median_curve(results, members, params[i], d)) {
          line->name = fmt::format("{} {}", name_of(params[i]), name_of(d));
          line->colour = int(i);
          line->dashed = d == Design::sequential;
          beyond_grids |= d == Design::sequential;
          panel.series.push_back(std::move(*line));
        }
    const std::pair<Design, const char*> literature[] = {{Design::dupuy_jakob, "Dupuy & Jakob"},
                                                         {Design::nielsen, "Nielsen et al."}};
    for (std::size_t k = 0; k < 2; ++k)
      for (Space s : params)
        if (auto line = median_curve(results, members, s, literature[k].first)) {
          line->name = literature[k].second;
          line->colour = int(params.size() + k);
          beyond_grids = true;
          panel.series.push_back(std::move(*line));
        }
    if (!panel.series.empty()) c.panels.push_back(std::move(panel));
  }
  if (c.panels.empty() || !beyond_grids) return {};
  c.columns = int(std::min<std::size_t>(3, c.panels.size()));
  return figure::loglog_chart(c);
}

// Metric 5: each sampler's efficiency against the cosine, one panel per table size and measure
// (the albedo estimator, the pixels with MIS). One curve per sampler chart (parameterizations
// that share a chart share its sampler and its curve, named by all of them) and per sampler
// (tabulated solid, factored dashed): its efficiencies over the BRDFs sorted, against the
// fraction of the BRDFs, so that a curve above another is the better sampler over the database;
// the cosine's 1 in a colour of its own.
figure::Scene sampling_chart(const std::vector<BrdfResult>& results, const StudyConfig& config) {
  const std::vector<Space>& params = params_of(results);
  std::vector<const BrdfResult*> sampled;
  for (const BrdfResult& b : results)
    if (!b.table("sampling").rows.empty()) sampled.push_back(&b);
  if (sampled.empty() || params.empty()) return {};
  // The charts in the order of their first parameterization, each with its parameterizations.
  std::vector<std::pair<std::string, std::vector<Space>>> charts;
  for (Space s : params) {
    std::string chart;
    for (const BrdfResult* b : sampled)
      if (const auto points = sampling_points(*b, s, "tabulated"); !points.empty()) {
        chart = points.front().chart;
        break;
      }
    if (chart.empty()) continue;
    auto it =
        std::find_if(charts.begin(), charts.end(), [&](const auto& c) { return c.first == chart; });
    if (it == charts.end()) it = charts.insert(charts.end(), {chart, {}});
    it->second.push_back(s);
  }
  constexpr int kCosineColour = 7;  // the palette's grey, for no chart
  constexpr double kEfficiencyFloor = 1e-3;
  figure::LogLogChart c;
  c.title = fmt::format(
      "Importance sampling: each chart's efficiency against cosine sampling over "
      "the {}, sorted",
      brdf_count(sampled.size()));
  c.x_label = "fraction of the BRDFs, each curve sorted (below 0.001: drawn at 0.001)";
  c.y_label = "efficiency vs cosine";
  c.linear_x = true;
  for (const std::size_t kib : option_counts(config, "sampler_kib"))
    for (const bool pixels : {false, true}) {
      figure::LogLogPanel panel{
          fmt::format("{} KiB, {}", kib, pixels ? "pixels (MIS)" : "directional albedo"), {}};
      for (std::size_t k = 0; k < charts.size(); ++k) {
        std::string names;
        for (Space s : charts[k].second)
          names += (names.empty() ? "" : " / ") + std::string(name_of(s));
        for (const char* sampler : {"tabulated", "factored"}) {
          std::vector<double> e;
          for (const BrdfResult* b : sampled)
            for (const SamplingPoint& p : sampling_points(*b, charts[k].second.front(), sampler))
              if (p.kib == kib) {
                const double v = pixels ? p.pixel_efficiency_vs_cosine_mis : p.efficiency_vs_cosine;
                // A BRDF that the cosine samples exactly (a Lambertian: no variance) has an
                // efficiency of ~0 against it; drawn at the floor, it does not stretch the axis
                // over twenty decades.
                if (std::isfinite(v)) e.push_back(std::max(v, kEfficiencyFloor));
              }
          if (e.empty()) continue;
          std::sort(e.begin(), e.end());
          figure::LineSeries line{fmt::format("{} {}", names, sampler),
                                  int(k % kCosineColour),
                                  std::string_view(sampler) == "factored",
                                  {},
                                  std::move(e)};
          for (std::size_t i = 0; i < line.y.size(); ++i)
            line.x.push_back((double(i) + 0.5) / double(line.y.size()));
          panel.series.push_back(std::move(line));
        }
      }
      if (panel.series.empty()) continue;
      panel.series.push_back({"cosine", kCosineColour, false, {1e-3, 1}, {1, 1}});
      c.panels.push_back(std::move(panel));
    }
  if (c.panels.empty()) return {};
  c.columns = 2;
  c.panel_width = 320;
  c.panel_height = 200;
  return figure::loglog_chart(c);
}

// Each parameterization's median error per design (section 3b).
figure::Scene designs_chart(const std::vector<BrdfResult>& results, const StudyConfig& config) {
  const std::size_t ref = reference_budget(config);
  const DesignComparison c = compare_designs(results, ref);
  if (c.brdfs.empty() || c.keys.size() < 2) return {};
  figure::BarChart chart;
  chart.title = fmt::format("Designs: median relative error ({} space) at N = {}",
                            name_of(config.space), ref);
  chart.x_label = fmt::format("median over {} of the reconstruction's relative error",
                              brdf_count(c.brdfs.size()));
  for (const DesignKey& k : c.keys) chart.series.push_back(design_name(k));
  chart.rows = param_names(c.params);
  chart.values = c.median;
  figure::BarChartLayout layout;
  layout.label_width = 110;  // the rows are parameterization names
  return figure::bar_chart(chart, layout);
}

// The gonio-reflectometer's median per kind, in the own regular design and in the best ones.
figure::Scene summary_chart(const std::vector<BrdfResult>& results,
                            const std::vector<SummaryMetric>& metrics, const StudyConfig& config,
                            const Contents& has) {
  if (!has.gonio) return {};
  figure::BarChart chart;
  chart.title = fmt::format("Gonio-reflectometer at N = {}: median relative error per kind",
                            reference_budget(config));
  chart.x_label = "median over the BRDFs of the kind (own regular design; each in its best design)";
  chart.series = param_names(params_of(results));
  for (const auto& [kind, rows] : kinds_of(results))
    for (const SummaryMetric& m : metrics) {
      if (m.chart_row.empty()) continue;
      const auto [med, n] = medians(m, rows);
      if (n == 0) continue;
      chart.rows.push_back(fmt::format("{} ({}), {}", kind, n, m.chart_row));
      chart.values.push_back(med);
    }
  if (chart.rows.empty()) return {};
  figure::BarChartLayout layout;
  layout.label_width = 200;
  return figure::bar_chart(chart, layout);
}

void save_plot(const figure::Scene& sc, const std::filesystem::path& dir, const std::string& stem,
               std::vector<std::string>& files) {
  if (sc.items.empty()) return;
  for (const char* ext : {".png", ".svg"}) {
    figure::save(sc, dir / (stem + ext));
    files.push_back(stem + ext);
  }
}

}  // namespace

namespace {

// The luminance of a rendering's pixels.
std::vector<double> luminance(const render::Image& im) {
  std::vector<double> y(std::size_t(im.width) * std::size_t(im.height));
  for (std::size_t p = 0; p < y.size(); ++p)
    y[p] = 0.2126 * im.rgb[3 * p] + 0.7152 * im.rgb[3 * p + 1] + 0.0722 * im.rgb[3 * p + 2];
  return y;
}

// The difference of a reconstruction's rendering from the BRDF's, |Y − Y_ref| over the mean of
// Y_ref over the pixels it lights, as a "hot" ramp: black 0, red, yellow, white at kFullScale and
// above. The two are rendered with the same random numbers, so their common noise cancels.
constexpr double kDifferenceFullScale = 0.5;
figure::ImageItem difference_item(const render::Image& test, const render::Image& reference,
                                  double x, double y, double size) {
  const std::vector<double> t = luminance(test), r = luminance(reference);
  double sum = 0;
  std::size_t lit = 0;
  for (double v : r)
    if (v > 0 && std::isfinite(v)) sum += v, ++lit;
  const double mean = lit ? sum / double(lit) : 1;
  figure::ImageItem item;
  item.x = x;
  item.y = y;
  item.width = item.height = size;
  item.px_width = std::size_t(reference.width);
  item.px_height = std::size_t(reference.height);
  item.rgba.resize(4 * r.size());
  for (std::size_t p = 0; p < r.size(); ++p) {
    const double d = std::abs(t[p] - r[p]) / mean;
    const double u = std::isfinite(d) ? std::clamp(3 * d / kDifferenceFullScale, 0.0, 3.0) : 3.0;
    const double rgb[3] = {std::min(u, 1.0), std::clamp(u - 1, 0.0, 1.0),
                           std::clamp(u - 2, 0.0, 1.0)};
    for (int c = 0; c < 3; ++c) item.rgba[4 * p + c] = std::uint8_t(std::lround(255 * rgb[c]));
    item.rgba[4 * p + 3] = 255;
  }
  item.smooth = true;
  return item;
}

}  // namespace

// At most kMaxExampleRows of `all`, spread evenly over its order (the first and the last kept).
std::vector<const BrdfResult*> spread_rows(const std::vector<const BrdfResult*>& all) {
  if (all.size() <= kMaxExampleRows) return all;
  std::vector<const BrdfResult*> some;
  for (std::size_t i = 0; i < kMaxExampleRows; ++i)
    some.push_back(all[(i * (all.size() - 1) + (kMaxExampleRows - 1) / 2) / (kMaxExampleRows - 1)]);
  return some;
}

// The renderings of the BRDFs and of their regular-design reconstructions under the first
// environment, side by side (the same tone mapping for a row), for the eye; under each
// reconstruction its difference from the BRDF's rendering (difference_item), which shows the
// reconstruction's error where the renderings alone show mostly their common noise.
figure::Scene examples_chart(const std::vector<BrdfResult>& results, const StudyConfig& config) {
  const std::vector<Space>& params = params_of(results);
  const double cell = 66, gap = 4, label_w = 250, top = 92;
  const std::size_t columns = params.size() + 1;  // the BRDF, then its reconstructions
  std::vector<const BrdfResult*> rendered;        // the BRDFs with every rendering
  for (const BrdfResult& b : results)
    if (b.example_images.size() == columns) rendered.push_back(&b);
  const std::vector<const BrdfResult*> shown = spread_rows(rendered);
  const std::size_t rows = shown.size();
  if (rows == 0 || config.environments.empty()) return {};
  figure::Scene sc;
  sc.title = "Renderings of the reconstructions";
  const std::string title = fmt::format(
      "The BRDF and its reconstructions from {} measurements (regular design), under {}",
      config.image_budget, config.environments.front().label);
  const std::string note = fmt::format(
      "{} environment samples per pixel, the same in every image: the noise is common to a "
      "row.{}",
      config.image_spp,
      rows < rendered.size()
          ? fmt::format(" {} of the {} BRDFs, spread evenly over the list.", rows, rendered.size())
          : "");
  const std::string note2 = fmt::format(
      "Under each reconstruction: |its luminance − the BRDF's| over the BRDF's mean luminance, "
      "black 0, red, yellow, white ≥ {:g} %.",
      100 * kDifferenceFullScale);
  std::vector<std::string> heads{"BRDF"};
  for (const std::string& name : param_names(params)) heads.push_back(figure::escape_markup(name));
  // The columns' pitch: a cell, or the widest head (a parameterization's name is wider than a
  // cell: "rectified-hybrid", "dupuy-jakob:per-material").
  double pitch = cell + gap;
  for (const std::string& head : heads)
    pitch = std::max(pitch, figure::snap(figure::approx_text_width(head, 9) + 8));
  const double row_h = 2 * (cell + gap) + 6;
  sc.width = figure::snap(
      std::max({label_w + double(columns) * pitch + 10, 24 + 13 * 0.62 * double(title.size()),
                24 + 9.5 * 0.55 * double(note2.size())}));
  sc.height = figure::snap(top + 14 + double(rows) * row_h + 10);
  sc.text({12, 24}, figure::escape_markup(title), 13, figure::HAlign::left,
          figure::VAlign::baseline, figure::kBlack, 0, true);
  sc.text({12, 42}, figure::escape_markup(note), 9.5);
  sc.text({12, 56}, figure::escape_markup(note2), 9.5);
  for (std::size_t k = 0; k < heads.size(); ++k)
    sc.text({label_w + double(k) * pitch + cell / 2, top - 8}, heads[k], 9, figure::HAlign::centre);
  double y = top;
  for (const BrdfResult* row : shown) {
    const BrdfResult& b = *row;
    sc.text({label_w - 8, y + cell / 2}, figure::escape_markup(b.label), 8.5, figure::HAlign::right,
            figure::VAlign::middle);
    sc.text({label_w - 8, y + cell + gap + cell / 2}, "difference", 8, figure::HAlign::right,
            figure::VAlign::middle);
    for (std::size_t k = 0; k < b.example_images.size(); ++k) {
      sc.add(figure::rendering_item(b.example_images[k], label_w + double(k) * pitch, y, cell));
      if (k > 0)
        sc.add(difference_item(b.example_images[k], b.example_images[0],
                               label_w + double(k) * pitch, y + cell + gap, cell));
    }
    y += row_h;
  }
  return sc;
}

ReportPlots report_plots(const std::vector<BrdfResult>& results, const StudyConfig& config,
                         const Contents& has, const std::vector<SummaryMetric>& summary) {
  ReportPlots p;
  p.summary = summary_chart(results, summary, config, has);
  p.azimuthal = figure::bar_chart(azimuthal_chart(results, config));
  p.separability = figure::bar_chart(separability_chart(results, config));
  if (has.gonio) p.gonio = gonio_chart(results, false, config);
  if (has.gonio && has.anisotropic) p.gonio4d = gonio_chart(results, true, config);
  if (has.gonio) p.designs = designs_chart(results, config);
  if (has.gonio) p.strategies = strategies_chart(results);
  if (has.sampling) p.sampling = sampling_chart(results, config);
  if (has.images) {
    p.image = figure::bar_chart(image_chart(results, config));
    p.renderings = examples_chart(results, config);
  }
  return p;
}

void save_plots(const ReportPlots& p, const std::filesystem::path& dir,
                std::vector<std::string>& files) {
  save_plot(p.summary, dir, "summary", files);
  save_plot(p.azimuthal, dir, "azimuthal", files);
  save_plot(p.separability, dir, "separability", files);
  save_plot(p.gonio, dir, "gonio", files);
  save_plot(p.gonio4d, dir, "gonio4d", files);
  save_plot(p.designs, dir, "designs", files);
  save_plot(p.strategies, dir, "strategies", files);
  save_plot(p.image, dir, "image", files);
  save_plot(p.sampling, dir, "sampling", files);
  save_plot(p.renderings, dir, "renderings", files);
}

std::string plot_link(const figure::Scene& sc, const char* alt, const char* stem) {
  return sc.items.empty() ? std::string() : fmt::format("![{}]({}.png)\n\n", alt, stem);
}

}  // namespace halfback::study::report
