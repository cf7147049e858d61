// The study's neural metric (docs/study.md, "Neural networks"): the paper's question asked of the
// models the field uses for measured materials. For each parameterization studied, networks of
// Sztrajman et al. 2021's form (two hidden ReLU layers, ρ = e^y − 1, their loss, sampling and
// Adam; docs/neural.md) whose input is the parameterization's three isotropic coordinates are
// trained on the BRDF at each hidden width with one training budget, and their error is the
// study's reconstruction error on the study's test pairs; halfdiff's row adds Sztrajman et al.'s
// own input (the half and difference vectors). Off by default: it trains networks.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "halfback/neural/train.hpp"
#include "halfback/study/metric.hpp"
#include "report_internal.hpp"
#include "table_columns.hpp"

namespace halfback::study {

namespace {

// What the table's `input` column holds.
constexpr const char* kCoordinates = "coordinates";  // the parameterization's (a, b, φ)
constexpr const char* kVectors = "vectors";          // Sztrajman et al.'s (h with φh = 0, d)

MetricTable neural_table() {
  return {"neural",
          {columns::parameterization(),
           {"input", ColumnKind::text, {kCoordinates, kVectors}},
           columns::integer("width"),
           columns::integer("parameters"),
           columns::integer("bytes"),
           columns::real("loss"),
           columns::real("error"),
           columns::real("seconds")},
          {}};
}

// The metric's options (StudyConfig::options), typed.
struct NeuralSettings {
  std::vector<std::size_t> widths;
  std::size_t samples = 0, epochs = 0;
  double learning_rate = 0;
};

double parse_rate(const std::string& text) {
  std::size_t used = 0;
  double v = NAN;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !(v > 0 && v <= 1))
    throw std::invalid_argument(
        fmt::format("study: neural_learning_rate '{}': expected a number in (0, 1]", text));
  return v;
}

NeuralSettings neural_settings(const StudyConfig& c) {
  return {option_counts(c, "neural_widths"), option_count(c, "neural_samples"),
          option_count(c, "neural_epochs"), parse_rate(c.option("neural_learning_rate"))};
}

NbrdfTrainOptions train_options(const NeuralSettings& s, std::size_t width, std::uint64_t seed) {
  NbrdfTrainOptions o;
  o.hidden = {width, width};
  o.samples = s.samples;
  o.epochs = s.epochs;
  o.learning_rate = s.learning_rate;
  o.final_learning_rate = s.learning_rate / 100;  // falling geometrically over the epochs
  o.seed = seed;
  o.threads = 1;  // one network per parameterization's task, the tasks on all cores
  return o;
}

std::int64_t parameter_count(const NbrdfNetwork& n) {
  std::int64_t count = 0;
  for (const NbrdfLayer& l : n.layers) count += std::int64_t(l.kernel.size() + l.bias.size());
  return count;
}

void add_row(MetricTable& table, Space row_space, const char* input, std::size_t width,
             const NbrdfTrainResult& r, const acquire::TestPairs& test,
             std::optional<Space> input_space, double seconds) {
  const BrdfPtr net = trained_nbrdf_brdf(r.network, input_space, "network");
  const std::int64_t params = parameter_count(r.network);
  table.add({std::string(name_of(row_space)), std::string(input), std::int64_t(width), params,
             4 * params, r.loss, acquire::reconstruction_error(*net, test), seconds});
}

double since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The rows of the median error of each width, per parameterization (and halfdiff's vectors).
std::string neural_section(const std::vector<BrdfResult>& results, const NeuralSettings& s,
                           const StudyConfig& config) {
  const std::vector<Space>& params = report::params_of(results);
  std::string md = fmt::format(
      "## Neural networks\n\nNetworks of Sztrajman et al. 2021's form (docs/neural.md: two hidden "
      "ReLU layers of the width below, ρ = e^y − 1, their loss and pair sampling, Adam) trained on "
      "each BRDF with the same budget for every input — {} pairs drawn, {} epochs of batches of "
      "512, a learning rate of {} falling geometrically to a hundredth of it, seed {} — whose "
      "input is each parameterization's three isotropic "
      "coordinates, and for halfdiff also Sztrajman et al.'s vectors (the half vector with φh = 0 "
      "and the difference vector; the row `vectors`). Each cell: the median over the BRDFs of the "
      "network's error against the BRDF, the study's reconstruction error in the `{}` space on "
      "its test pairs; lower is better. A network of width w has w² + 8w + 3 parameters (4 bytes "
      "each, float32) on coordinates, w² + 11w + 3 on vectors. neural.csv has every network's "
      "training loss and time.\n\n",
      s.samples, s.epochs, s.learning_rate, config.seed, acquire::name_of(config.space));
  md += report::table_header("input | width", params);
  std::string wins_text;
  for (const char* input : {kCoordinates, kVectors})
    for (const std::size_t width : s.widths) {
      std::vector<std::vector<double>> errors(params.size());
      report::Wins wins(params);
      bool any = false;
      for (const BrdfResult& b : results) {
        const MetricTable& t = b.table("neural");
        std::vector<double> row(params.size(), NAN);
        for (std::size_t k = 0; k < params.size(); ++k)
          for (const Row* r : rows_of(t, params[k]))
            if (t.text(*r, "input") == input && std::size_t(t.integer(*r, "width")) == width) {
              row[k] = t.real(*r, "error");
              errors[k].push_back(row[k]);
              any = true;
            }
        wins.add(row);
      }
      if (!any) continue;
      md += fmt::format("| {} | {} |", input, width);
      for (std::size_t k = 0; k < params.size(); ++k)
        md += errors[k].empty() ? std::string(" – |")
                                : fmt::format(" {:.4g} |", report::median(errors[k]));
      md += "\n";
      if (input == std::string(kCoordinates))
        wins_text += fmt::format("- width {}: {}\n", width, wins.text());
    }
  return md + "\nLowest error on coordinates (BRDFs):\n\n" + wins_text + "\n";
}

class NeuralMetric final : public Metric {
 public:
  std::string_view name() const override { return "neural"; }
  std::string_view description() const override {
    return "neural BRDFs trained on each parameterization's coordinates";
  }
  bool on_by_default() const override { return false; }
  std::vector<MetricOption> options() const override {
    MetricOption widths, samples, epochs, rate;
    widths.key = "neural_widths";
    widths.kind = MetricOption::Kind::counts;
    widths.default_value = "8,16,21,32,64";
    widths.quick_value = "8,21";
    widths.noun = "hidden width";
    widths.help = fmt::format(
        "Hidden widths of the neural metric's networks (two layers each), ascending, 1 to {}",
        nbrdf::kMaxWidth);
    samples.key = "neural_samples";
    samples.kind = MetricOption::Kind::count;
    samples.default_value = "100000";
    samples.quick_value = "20000";
    samples.noun = "pair count";
    samples.help = "Pairs drawn to train each network of the neural metric";
    epochs.key = "neural_epochs";
    epochs.kind = MetricOption::Kind::count;
    epochs.default_value = "20";
    epochs.quick_value = "5";
    epochs.noun = "epoch count";
    epochs.help = "Epochs of each network of the neural metric";
    rate.key = "neural_learning_rate";
    rate.default_value = "0.001";
    rate.help =
        "Adam's first learning rate of the neural metric, falling to a hundredth at the last "
        "epoch";
    return {widths, samples, epochs, rate};
  }
  void validate(const StudyConfig& config) const override {
    const NeuralSettings s = neural_settings(config);
    for (std::size_t i = 0; i < s.widths.size(); ++i)
      if (s.widths[i] > nbrdf::kMaxWidth || (i && s.widths[i] <= s.widths[i - 1]))
        throw std::invalid_argument(
            fmt::format("study: neural widths must be ascending, from 1 to {}", nbrdf::kMaxWidth));
    check_nbrdf_train_options(train_options(s, s.widths.front(), config.seed));
  }
  std::vector<TableDef> tables() const override { return {{neural_table}}; }
  void measure_param(BrdfStudy& study, std::size_t k, MetricRows rows) const override {
    if (!study.brdf.isotropic()) return;  // the networks are isotropic
    const NeuralSettings s = neural_settings(study.config);
    const Space row_space = study.config.params[k], work = study.work[k];
    MetricTable& table = rows.table("neural");
    try {
      for (const std::size_t width : s.widths) {
        const NbrdfTrainOptions o = train_options(s, width, study.config.seed);
        auto start = std::chrono::steady_clock::now();
        const NbrdfTrainResult r = train_nbrdf_on(study.brdf, o, work);
        add_row(table, row_space, kCoordinates, width, r, study.test, work, since(start));
        if (name_of(row_space) == "halfdiff") {
          start = std::chrono::steady_clock::now();
          const NbrdfTrainResult v = train_nbrdf(study.brdf, o);
          add_row(table, row_space, kVectors, width, v, study.test, std::nullopt, since(start));
        }
      }
      study.say(fmt::format("neural ({})", name_of(row_space)));
    } catch (const std::domain_error& e) {  // values it cannot train on: no rows
      table.rows.clear();
      study.say(fmt::format("neural ({}): skipped, {}", name_of(row_space), e.what()));
    }
  }
  std::string report_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                             const report::ReportPlots&) const override {
    if (std::all_of(results.begin(), results.end(),
                    [](const BrdfResult& b) { return b.table("neural").rows.empty(); }))
      return {};
    return neural_section(results, neural_settings(config), config);
  }
};

}  // namespace

const Metric& neural_metric() {
  static const NeuralMetric metric;
  return metric;
}

}  // namespace halfback::study
