// A metric of the study as a plug-in (docs/study.md, "Adding a metric"): its settings (name,
// whether it runs by default, its options), its tables, its computation on one BRDF (per
// parameterization and/or per BRDF) and its section of the report. The study's one list of
// metrics (study_metrics()) is what study_brdf, the part files, the settings (the CLI's
// --metrics, --no-NAME and option flags, Python's settings dict, describe_config) and the report
// follow. A metric is one file (src/study/NAME_metric.cpp) and one line of the list in
// src/study/metric_list.cpp, or, outside the library, a register_metric() call.
#pragma once

#include <any>
#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "halfback/acquire/gonio.hpp"
#include "halfback/brdf/brdf.hpp"
#include "halfback/core/space.hpp"
#include "halfback/render/image.hpp"
#include "halfback/study/metric_tables.hpp"
#include "halfback/study/study.hpp"
#include "halfback/study/table.hpp"

namespace halfback::study {

namespace report {
struct ReportPlots;  // report_internal.hpp
}

// An option of a metric, kept as text in StudyConfig::options under `key` ("fit_model"), which
// is also the CLI's flag (--fit-model), Python's settings key and the line of describe_config.
struct MetricOption {
  // text: any string; count: an integer >= 1; counts: ascending integers >= 1, comma-separated.
  enum class Kind { text, count, counts };
  std::string key;
  Kind kind = Kind::text;
  std::string default_value;  // as text ("1000,10000")
  std::string quick_value;    // under --quick; empty: the default
  // What it sets, for the CLI's help and Python's docstring, without its values: they follow from
  // default_value and quick_value (option_default()), never written here.
  std::string help;
  std::string noun = "value";  // what one number is, for errors ("sample budget")
};

// What one BRDF's metrics share while it is studied (study_brdf): the BRDF, the settings, the
// spaces worked in, the test pairs of the reconstructions, and values one metric computes for
// another (memo(): e.g. the whole fit that the fit and sampling metrics use).
struct BrdfStudy {
  BrdfStudy(const Brdf& brdf, const std::string& label, const StudyConfig& config,
            std::vector<Space> work, acquire::TestPairs test)
      : brdf(brdf),
        label(label),
        config(config),
        work(std::move(work)),
        test(std::move(test)),
        task(config.params.size()),
        per_param(config.params.size()) {}
  BrdfStudy(const BrdfStudy&) = delete;
  BrdfStudy& operator=(const BrdfStudy&) = delete;

  const Brdf& brdf;
  const std::string& label;
  const StudyConfig& config;
  // The spaces the work is done in (material_spaces), one per config.params, which name the rows.
  std::vector<Space> work;
  acquire::TestPairs test;
  // Per parameterization, what its per-parameterization steps share (a metric's own keys):
  // `task` is dropped when the parameterization's task ends, `per_param` kept for the per-BRDF
  // steps.
  std::vector<std::map<std::string, std::any>> task, per_param;
  // Renderings for the report (BrdfResult::example_images).
  std::vector<render::Image> example_images;
  // Progress (StudyConfig::progress).
  void say(const std::string& stage) const {
    if (config.progress) config.progress(stage);
  }
  // The value under `key`, made by `make` on its first use (from any thread; once).
  template <class T>
  const T& memo(const std::string& key, const std::function<T()>& make) {
    std::unique_lock lock(memo_mutex_);
    auto& slot = memos_[key];
    if (!slot) slot = std::make_shared<Memo>();
    const std::shared_ptr<Memo> m = slot;
    lock.unlock();
    std::call_once(m->once, [&] { m->value = make(); });
    return std::any_cast<const T&>(m->value);
  }

 private:
  struct Memo {
    std::once_flag once;
    std::any value;
  };
  std::mutex memo_mutex_;
  std::map<std::string, std::shared_ptr<Memo>> memos_;
};

// Where a metric writes its rows: the tables of stored_tables(), by name.
struct MetricRows {
  std::vector<MetricTable>& tables;
  MetricTable& table(std::string_view name) const;
};

class Metric {
 public:
  virtual ~Metric() = default;
  // Its name in --metrics and --no-NAME ("fit").
  virtual std::string_view name() const = 0;
  // What it measures, in a few words (the CLI's help of --no-NAME).
  virtual std::string_view description() const { return {}; }
  virtual bool on_by_default() const { return true; }
  // Its options (StudyConfig::options). By default the metric is off when its first option is
  // empty ("fit_model = " in a run's settings), so that a run's description says which ran.
  virtual std::vector<MetricOption> options() const { return {}; }
  // Whether it can be turned off; whether it is on in `config`; turning it off.
  virtual bool switchable() const { return !options().empty(); }
  virtual bool is_on(const StudyConfig& config) const;
  virtual void switch_off(StudyConfig& config) const;
  // Throws std::invalid_argument naming a bad option (called by StudyConfig::validate when on).
  virtual void validate(const StudyConfig&) const {}
  // Its tables (columns; derived ones with their derivation), in the order of the CSV files.
  virtual std::vector<TableDef> tables() const = 0;
  // Its rows for parameterization config.params[k] (worked in study.work[k]), run in parallel
  // over k: `rows` holds that parameterization's tables. Then, after every parameterization, its
  // rows of the whole BRDF (any parameterization's), in the order of the list.
  virtual void measure_param(BrdfStudy&, std::size_t /*k*/, MetricRows /*rows*/) const {}
  virtual void measure_brdf(BrdfStudy&, MetricRows /*rows*/) const {}
  // Its section of report.md (empty: none, e.g. no rows).
  virtual std::string report_section(const std::vector<BrdfResult>& results,
                                     const StudyConfig& config,
                                     const report::ReportPlots& plots) const = 0;
};

// Every metric, the built-in ones (metric_list.cpp) then those registered, in that order.
std::span<const Metric* const> study_metrics();
// Adds a metric to the list (e.g. from a static initializer, before any study is configured);
// std::invalid_argument when its name, a table's or an option's key is taken.
void register_metric(const Metric& metric);
// The metric of that name, or nullptr.
const Metric* find_metric(std::string_view name);
// "azimuthal, separability, ...".
std::string metric_names();

// What option `index` of `metric` is worth when it is not given, as the settings resolve it
// (default_metric_options(), make_config()) and as the CLI's help and Python's docstring say it:
// `value` without --quick, `quick` with it (equal when the option has no quick value);
// `when_run`: the first option of a metric off by default, empty (the metric off) unless the
// metric is asked for (--metrics), then `value` (`quick`).
struct OptionDefault {
  std::string value, quick;
  bool when_run = false;
};
OptionDefault option_default(const Metric& metric, std::size_t index);

// A metric option's value as numbers (MetricOption::Kind count/counts), read from `config`.
// std::invalid_argument naming the option when the text is not of its kind.
std::size_t option_count(const StudyConfig& config, const std::string& key);
std::vector<std::size_t> option_counts(const StudyConfig& config, const std::string& key);
// Checks that `value` is of the option's kind; std::invalid_argument naming `where` otherwise.
void check_option_text(const MetricOption& option, const std::string& value,
                       const std::string& where);

}  // namespace halfback::study
