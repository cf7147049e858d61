// Metric 6 of the study (docs/study.md, "Fitting from measurements"): a model fitted to the
// measurements of each design of the isotropic gonio-reflectometer, against the same model fitted
// to the whole BRDF. Everything of the metric is here: its options, its table, its computation
// and its section of the report.
#include "fit_metric.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "halfback/core/batch.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/fit/fit.hpp"
#include "halfback/loader/load.hpp"
#include "report_internal.hpp"
#include "table_columns.hpp"

namespace halfback::study {

using acquire::Design;
using acquire::gonio_plan;
using acquire::GonioPlan;
using acquire::GonioSetup;
using acquire::kDesigns;
using acquire::kMaxSampleBudget;
using acquire::PlannedPoint;

// ---------------------------------------------------------------------------------------------
// The table
// ---------------------------------------------------------------------------------------------

std::string_view name_of(FitWeights w) {
  return w == FitWeights::uniform ? "uniform" : "solid-angle";
}

std::optional<FitWeights> parse_fit_weights(std::string_view name) {
  for (FitWeights w : kFitWeights)
    if (name_of(w) == name) return w;
  return std::nullopt;
}

MetricTable fit_table() {
  std::vector<std::string> weights;
  for (FitWeights w : kFitWeights) weights.emplace_back(name_of(w));
  return {"fit",
          {columns::parameterization(),
           columns::design(),
           columns::integer("budget"),
           columns::integer("samples"),
           {"weights", ColumnKind::text, weights},
           columns::text("model"),
           columns::text("loss"),
           columns::real("whole_loss"),
           columns::real("layout_loss"),
           columns::real("excess"),
           columns::real("shape_change"),
           columns::text("spec")},
          {}};
}

void add_fit(MetricTable& table, Space space, const FitPoint& p) {
  table.add({std::string(name_of(space)), std::string(name_of(p.design)), std::int64_t(p.budget),
             std::int64_t(p.samples), std::string(name_of(p.weights)), p.model, p.loss,
             p.whole_loss, p.layout_loss, p.layout_loss / p.whole_loss - 1, p.shape_change,
             p.spec});
}

std::vector<FitPoint> fit_points(const BrdfResult& result, Space space) {
  const MetricTable& t = result.table("fit");
  std::vector<FitPoint> points;
  for (const Row* row : rows_of(t, space))
    points.push_back({columns::design_of(t, *row), std::size_t(t.integer(*row, "budget")),
                      std::size_t(t.integer(*row, "samples")),
                      parse_fit_weights(t.text(*row, "weights")).value(), t.text(*row, "model"),
                      t.text(*row, "loss"), t.real(*row, "whole_loss"), t.real(*row, "layout_loss"),
                      t.real(*row, "shape_change"), t.text(*row, "spec")});
  return points;
}

namespace {

// The metric's options (StudyConfig::options), typed.
struct FitSettings {
  std::string model, loss;
  std::vector<std::size_t> budgets;
  std::size_t samples = 0;
};

FitSettings fit_settings(const StudyConfig& c) {
  return {c.option("fit_model"), c.option("fit_loss"), option_counts(c, "fit_budgets"),
          option_count(c, "fit_samples")};
}

// ---------------------------------------------------------------------------------------------
// The computation
// ---------------------------------------------------------------------------------------------

// The largest relative change of a fitted shape parameter (not a colour channel) from `whole`.
double shape_change(const fit::Model& layout, const fit::Model& whole) {
  double worst = 0;
  for (std::size_t i = 0; i < whole.params.size(); ++i) {
    const fit::Param& p = whole.params[i];
    if (!p.fitted || fit::channel_of(p) >= 0) continue;
    const double scale = std::max(std::abs(p.value), 1e-6 * (p.max - p.min));
    worst = std::max(worst, std::abs(layout.params[i].value - p.value) / scale);
  }
  return worst;
}

// The solid angle dωi dωo per unit volume of the isotropic coordinates of `space` at a pair:
// the weight of a measurement whose cell has the volume of every other (the own spacing's cells).
double solid_angle_density(Space space, const DirPair<double>& pair) {
  const Form iso{space, true}, dirs{Space::dirs, false};
  const double d[6] = {pair.wi.x, pair.wi.y, pair.wi.z, pair.wo.x, pair.wo.y, pair.wo.z};
  double q[3], back[6], jac = 0;
  if (!convert_one<double>(dirs, iso, d, q) || !convert_one<double>(iso, dirs, q, back, &jac))
    return 0;
  return std::isfinite(jac) && jac > 0 ? jac : 0;
}

// The measurements of a plan where the BRDF is finite, each weighted 1 or by its cell's solid
// angle, the weights' mean 1.
std::pair<fit::Samples, std::vector<Rgb>> measured(const Brdf& brdf, const GonioPlan& plan,
                                                   FitWeights weights) {
  fit::Samples s;
  std::vector<Rgb> values;
  double total = 0;
  for (const PlannedPoint& p : plan.points) {
    const Rgb v = brdf.eval(p.pair);
    if (!(std::isfinite(v.r) && std::isfinite(v.g) && std::isfinite(v.b))) continue;
    const double w =
        weights == FitWeights::uniform ? 1.0 : solid_angle_density(plan.setup.space, p.pair);
    if (!(w > 0)) continue;
    s.pairs.push_back(p.pair);
    s.weight.push_back(w);
    s.cos_i.push_back(p.pair.wi.z);
    values.push_back(v);
    total += w;
  }
  for (double& w : s.weight) w *= double(s.weight.size()) / total;
  return {std::move(s), std::move(values)};
}

struct Job {
  std::size_t param = 0;
  Design design = Design::regular;
  std::size_t budget = 0;
  FitWeights weights = FitWeights::uniform;
};

// The fit of the whole BRDF (whole_fit()).
std::optional<fit::FitResult> fit_whole(const BrdfStudy& study) {
  const FitSettings s = fit_settings(study.config);
  if (s.model.empty() || !study.brdf.isotropic()) return std::nullopt;
  const fit::FitOptions o{.loss = fit::parse_loss(s.loss).value(),  // validate() checked
                          .samples = s.samples};
  try {
    return fit::fit(study.brdf, s.model, o);
  } catch (const fit::FitDataError& e) {
    study.say(fmt::format("fit: skipped, {}", e.what()));
    return std::nullopt;
  }
}

// The rows of config.params (whose work is done in `work`: material_spaces), for each design
// (regular, stratified; own spacing) and each fit budget, against `whole_fit`. Nothing without a
// whole fit or budgets.
std::vector<std::pair<Space, FitPoint>> fit_rows(const Brdf& brdf, const StudyConfig& config,
                                                 std::span<const Space> work,
                                                 const std::optional<fit::FitResult>& whole_fit) {
  const FitSettings s = fit_settings(config);
  if (!whole_fit || s.budgets.empty()) return {};
  const fit::FitResult& whole = *whole_fit;
  const fit::Loss loss = fit::parse_loss(s.loss).value();
  fit::FitOptions o{.loss = loss, .samples = s.samples};
  const fit::Samples layout = fit::halfdiff_samples(s.samples);
  std::vector<Rgb> truth(layout.pairs.size());
  for (std::size_t i = 0; i < truth.size(); ++i) truth[i] = brdf.eval(layout.pairs[i]);

  std::vector<Job> jobs;
  for (std::size_t k = 0; k < work.size(); ++k)
    for (Design d : kDesigns)
      for (std::size_t budget : s.budgets)
        for (FitWeights w : kFitWeights) jobs.push_back({k, d, budget, w});
  std::vector<std::optional<FitPoint>> rows(jobs.size());
  o.threads = 1;  // one fit per job, the jobs on all cores
  parallel_for(jobs.size(), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      GonioSetup setup{.space = work[jobs[j].param],
                       .design = jobs[j].design,
                       .budget = jobs[j].budget,
                       .seed = config.seed,
                       .max_theta_deg = config.max_theta_deg};
      const auto [samples, values] = measured(brdf, gonio_plan(setup), jobs[j].weights);
      if (samples.pairs.empty()) continue;
      try {
        const fit::FitResult r = fit::fit_at(samples, values, s.model, o);
        const double on_whole = fit::loss_value(truth, *load_brdf(r.spec), loss, layout, 1);
        rows[j] = FitPoint{jobs[j].design,
                           jobs[j].budget,
                           samples.pairs.size(),
                           jobs[j].weights,
                           s.model,
                           s.loss,
                           whole.loss_value,
                           on_whole,
                           shape_change(r.model, whole.model),
                           r.spec};
      } catch (const fit::FitDataError&) {  // e.g. zero at every measurement: no row
      }
    }
  });
  std::vector<std::pair<Space, FitPoint>> out;
  for (std::size_t j = 0; j < jobs.size(); ++j)
    if (rows[j]) out.emplace_back(config.params[jobs[j].param], *rows[j]);
  return out;
}

// ---------------------------------------------------------------------------------------------
// The report
// ---------------------------------------------------------------------------------------------

// Per design and budget, each parameterization's median excess of the fit from its measurements
// over the whole fit and median shape change, and which has the lowest excess per BRDF.
// A BRDF that the model fits exactly (e.g. a GGX model fitted by lambert+ggx) has its whole fit's
// loss at round-off; a ratio of two losses there is noise ("5.6e+08 %", "-23 %"). Such BRDFs are
// left out of the medians and compared in absolute terms below the table.
bool whole_fit_exact(const BrdfResult& b, const std::vector<Space>& params) {
  for (Space s : params)
    for (const FitPoint& p : fit_points(b, s)) return p.whole_loss < kRoundOffLoss;
  return false;
}

// The BRDFs fitted exactly, and per parameterization the largest loss on the whole BRDF of their
// fits from measurements: how far from exact the measurements' fits are, in absolute terms.
std::string exact_fits_text(const std::vector<BrdfResult>& results,
                            const std::vector<Space>& params) {
  std::string labels;
  std::vector<double> worst(params.size(), -1);
  for (const BrdfResult& b : results) {
    if (!whole_fit_exact(b, params)) continue;
    labels += (labels.empty() ? "" : ", ") + b.label;
    for (std::size_t k = 0; k < params.size(); ++k)
      for (const FitPoint& p : fit_points(b, params[k]))
        worst[k] = std::max(worst[k], p.layout_loss);
  }
  if (labels.empty()) return {};
  std::string losses;
  for (std::size_t k = 0; k < params.size(); ++k)
    if (worst[k] >= 0)
      losses += fmt::format("{}{} {:.2g}{}", losses.empty() ? "" : ", ", name_of(params[k]),
                            worst[k], worst[k] < kRoundOffLoss ? " (exact too)" : "");
  return fmt::format(
      "\nFitted exactly by the model (the whole fit's loss below {:.0e}, round-off, where a "
      "ratio of losses means nothing), left out of the medians and counts above: {}. The "
      "largest loss on the whole BRDF of their fits from measurements: {}.\n",
      kRoundOffLoss, labels, losses);
}

std::string fit_tables(const std::vector<BrdfResult>& results, const FitSettings& fit) {
  const std::vector<Space>& params = report::params_of(results);
  std::string md = report::table_header("weights | design | budget", params);
  std::string wins_text;
  for (FitWeights w : kFitWeights)
    for (Design d : kDesigns)
      for (const std::size_t budget : fit.budgets) {
        std::vector<std::vector<double>> excess(params.size()), change(params.size());
        report::Wins wins(params);
        for (const BrdfResult& b : results) {
          if (whole_fit_exact(b, params)) continue;
          std::vector<double> row(params.size(), NAN);
          for (std::size_t k = 0; k < params.size(); ++k)
            for (const FitPoint& p : fit_points(b, params[k]))
              if (p.weights == w && p.design == d && p.budget == budget) {
                row[k] = p.layout_loss / p.whole_loss - 1;
                excess[k].push_back(row[k]);
                change[k].push_back(p.shape_change);
              }
          wins.add(row);
        }
        md += fmt::format("| {} | {} | {} |", name_of(w), name_of(d), budget);
        for (std::size_t k = 0; k < params.size(); ++k)
          md += excess[k].empty()
                    ? std::string(" – |")
                    : fmt::format(" {:.3g} % / {:.2g} % |", 100 * report::median(excess[k]),
                                  100 * report::median(change[k]));
        md += "\n";
        wins_text +=
            fmt::format("- {}, {} at {}: {}\n", name_of(w), name_of(d), budget, wins.text());
      }
  return md + exact_fits_text(results, params) + "\nLowest excess (BRDFs):\n\n" + wins_text + "\n";
}

// Fitting from measurements (metric 6; docs/study.md): does the parameterization of a design change
// the fit?
std::string fit_section(const std::vector<BrdfResult>& results, const FitSettings& fit) {
  std::string md = fmt::format(
      "## Fitting from measurements\n\n`{}` fitted under the `{}` loss (docs/fit.md) to the "
      "measurements of each design of the isotropic gonio-reflectometer (own spacing, within "
      "the reach), each measurement weighted 1 as a laboratory fits its data (uniform: the "
      "design's density weights the loss) or by its cell's solid angle (so that the loss "
      "estimates the whole fit's integral), and to the whole BRDF (fit()'s layout of {} pairs). "
      "Each cell: the median over the BRDFs of the excess of "
      "the measurements' fit over the whole fit, both measured on the whole BRDF (0 %: as good "
      "as fitting the whole BRDF), then the median largest relative change of a shape "
      "parameter (e.g. α) between the two fits; lower is better. fit.csv has every fit's spec.\n\n",
      fit.model, fit.loss, fit.samples);
  return md + fit_tables(results, fit);
}

class FitMetric final : public Metric {
 public:
  std::string_view name() const override { return "fit"; }
  std::string_view description() const override {
    return "a model fitted to each design's measurements";
  }
  std::vector<MetricOption> options() const override {
    MetricOption model, loss, budgets, samples;
    model.key = "fit_model";
    model.default_value = "lambert+ggx";
    model.help =
        "Model of the fit metric (docs/study.md), fitted to each design's measurements and to the "
        "whole BRDF";
    loss.key = "fit_loss";
    loss.default_value = "ngan";
    loss.help = "Loss of the fit metric (`halfback fit --loss`), one of " + fit::loss_names();
    budgets.key = "fit_budgets";
    budgets.kind = MetricOption::Kind::counts;
    budgets.default_value = "1000,10000";
    budgets.quick_value = "1000";
    budgets.noun = "sample budget";
    budgets.help = "Measurement budgets of the fit metric, ascending, comma-separated";
    samples.key = "fit_samples";
    samples.kind = MetricOption::Kind::count;
    samples.default_value = "20000";
    samples.quick_value = "5000";
    samples.noun = "sample count";
    samples.help = "Pairs of the whole BRDF's fit of the fit metric";
    return {model, loss, budgets, samples};
  }
  void validate(const StudyConfig& config) const override {
    const FitSettings s = fit_settings(config);
    if (!fit::parse_loss(s.loss))
      throw std::invalid_argument(
          fmt::format("study: the fit loss '{}': expected {}", s.loss, fit::loss_names()));
    (void)fit::parse_model(s.model);  // std::invalid_argument naming the model's problem
    for (std::size_t i = 0; i < s.budgets.size(); ++i)
      if (s.budgets[i] > kMaxSampleBudget || (i && s.budgets[i] <= s.budgets[i - 1]))
        throw std::invalid_argument(
            fmt::format("study: fit budgets must be ascending, from 1 to {}", kMaxSampleBudget));
    if (s.samples < 100 || s.samples > kMaxTestPairs)
      throw std::invalid_argument(fmt::format(
          "study: {} samples for the whole fit: expected 100 to {}", s.samples, kMaxTestPairs));
  }
  std::vector<TableDef> tables() const override { return {{fit_table}}; }
  void measure_brdf(BrdfStudy& study, MetricRows rows) const override {
    const auto points = fit_rows(study.brdf, study.config, study.work, whole_fit(study));
    for (const auto& [space, point] : points) add_fit(rows.table("fit"), space, point);
    if (!points.empty()) study.say("fit");
  }
  std::string report_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                             const report::ReportPlots&) const override {
    if (std::all_of(results.begin(), results.end(),
                    [](const BrdfResult& b) { return b.table("fit").rows.empty(); }))
      return {};
    return fit_section(results, fit_settings(config));
  }
};

}  // namespace

const std::optional<fit::FitResult>& whole_fit(BrdfStudy& study) {
  return study.memo<std::optional<fit::FitResult>>("whole_fit",
                                                   [&study] { return fit_whole(study); });
}

const Metric& fit_metric() {
  static const FitMetric metric;
  return metric;
}

}  // namespace halfback::study
