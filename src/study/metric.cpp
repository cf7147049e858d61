// The list of the study's metrics and what every metric shares (metric.hpp).
#include "halfback/study/metric.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <stdexcept>

namespace halfback::study {

std::span<const Metric* const> builtin_metrics();  // metric_list.cpp

namespace {

std::vector<const Metric*>& registered() {
  static std::vector<const Metric*> metrics = [] {
    const auto builtin = builtin_metrics();
    return std::vector<const Metric*>(builtin.begin(), builtin.end());
  }();
  return metrics;
}

// The number of `text` (digits only), or 0 when it is not one.
std::size_t count_of(std::string_view text) {
  std::size_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  return ec == std::errc() && end == text.data() + text.size() ? v : 0;
}

std::vector<std::string_view> split_commas(std::string_view text) {
  std::vector<std::string_view> parts;
  if (text.empty()) return parts;
  for (std::size_t start = 0;;) {
    const std::size_t comma = text.find(',', start);
    parts.push_back(text.substr(start, comma - start));
    if (comma == std::string_view::npos) return parts;
    start = comma + 1;
  }
}

}  // namespace

MetricTable& MetricRows::table(std::string_view name) const {
  for (MetricTable& t : tables)
    if (t.name == name) return t;
  throw std::logic_error("study: no table " + std::string(name));
}

bool Metric::is_on(const StudyConfig& config) const {
  const std::vector<MetricOption> o = options();
  return o.empty() || !config.option(o.front().key).empty();
}

void Metric::switch_off(StudyConfig& config) const {
  const std::vector<MetricOption> o = options();
  if (o.empty())
    throw std::logic_error(fmt::format("study: the metric {} cannot be turned off", name()));
  config.options[o.front().key].clear();
}

std::span<const Metric* const> study_metrics() {
  return registered();
}

void register_metric(const Metric& metric) {
  for (const Metric* m : registered()) {
    if (m->name() == metric.name())
      throw std::invalid_argument(fmt::format("study: a metric named '{}' is listed", m->name()));
    for (const TableDef& mine : metric.tables())
      for (const TableDef& theirs : m->tables())
        if (mine.columns().name == theirs.columns().name)
          throw std::invalid_argument(fmt::format("study: the metric {} has a table '{}' already",
                                                  m->name(), theirs.columns().name));
    for (const MetricOption& mine : metric.options())
      for (const MetricOption& theirs : m->options())
        if (mine.key == theirs.key)
          throw std::invalid_argument(fmt::format("study: the metric {} has an option '{}' already",
                                                  m->name(), theirs.key));
  }
  registered().push_back(&metric);
}

const Metric* find_metric(std::string_view name) {
  for (const Metric* m : study_metrics())
    if (m->name() == name) return m;
  return nullptr;
}

std::string metric_names() {
  std::string names;
  for (const Metric* m : study_metrics())
    names += fmt::format("{}{}", names.empty() ? "" : ", ", m->name());
  return names;
}

void check_option_text(const MetricOption& option, const std::string& value,
                       const std::string& where) {
  if (option.kind == MetricOption::Kind::text) return;
  if (option.kind == MetricOption::Kind::count) {
    if (count_of(value) == 0)
      throw std::invalid_argument(
          fmt::format("{}: '{}' is not a {} (an integer >= 1)", where, value, option.noun));
    return;
  }
  std::size_t last = 0;
  for (const std::string_view part : split_commas(value)) {
    const std::size_t v = count_of(part);
    if (v == 0)
      throw std::invalid_argument(
          fmt::format("{}: '{}' is not a {} (an integer >= 1)", where, part, option.noun));
    if (v <= last)
      throw std::invalid_argument(fmt::format("{}: the values must be ascending", where));
    last = v;
  }
}

std::size_t option_count(const StudyConfig& config, const std::string& key) {
  const std::string& text = config.option(key);
  const std::size_t v = count_of(text);
  if (v == 0)
    throw std::invalid_argument(fmt::format("study: {} '{}' is not an integer >= 1", key, text));
  return v;
}

std::vector<std::size_t> option_counts(const StudyConfig& config, const std::string& key) {
  std::vector<std::size_t> values;
  for (const std::string_view part : split_commas(config.option(key))) {
    const std::size_t v = count_of(part);
    if (v == 0)
      throw std::invalid_argument(fmt::format("study: {} '{}': '{}' is not an integer >= 1", key,
                                              config.option(key), part));
    values.push_back(v);
  }
  return values;
}

OptionDefault option_default(const Metric& metric, std::size_t index) {
  const MetricOption o = metric.options().at(index);
  return {o.default_value, o.quick_value.empty() ? o.default_value : o.quick_value,
          index == 0 && !metric.on_by_default()};
}

std::map<std::string, std::string> default_metric_options() {
  std::map<std::string, std::string> options;
  for (const Metric* m : study_metrics()) {
    const std::vector<MetricOption> own = m->options();
    for (std::size_t i = 0; i < own.size(); ++i) {
      const OptionDefault d = option_default(*m, i);
      options[own[i].key] = d.when_run ? std::string() : d.value;
    }
  }
  return options;
}

const std::string& StudyConfig::option(const std::string& key) const {
  const auto it = options.find(key);
  if (it == options.end()) throw std::logic_error("study: no metric has the option " + key);
  return it->second;
}

}  // namespace halfback::study
