// The study's metric options as the Python API writes them (study_brdf's docstring and the type
// stubs' StudySettings, src/python/stubgen.cpp): their values from the list of metrics
// (study::option_default), never written by hand.
#pragma once

#include <fmt/format.h>

#include <cstddef>
#include <string>

#include "halfback/study/metric.hpp"

namespace halfback::python {

// An option's value as Python writes it: a list for Kind::counts ("[1000, 10000]"), a string for
// text ("'ngan'"), else the number.
inline std::string python_value(const study::MetricOption& o, const std::string& text) {
  using Kind = study::MetricOption::Kind;
  if (o.kind == Kind::count) return text;
  if (o.kind == Kind::text) return "'" + text + "'";
  std::string list = text;
  for (std::size_t at = list.find(','); at != std::string::npos; at = list.find(',', at + 2))
    list.insert(at + 1, " ");
  return "[" + list + "]";
}

// The values of option `index` of `m` when the settings do not give it: "default [1000, 10000];
// quick: [1000]" ("... when metrics names neural" for the option that turns a metric on).
inline std::string python_option_values(const study::Metric& m, std::size_t index) {
  const study::MetricOption o = m.options().at(index);
  const study::OptionDefault d = study::option_default(m, index);
  std::string values = "default " + python_value(o, d.value);
  if (d.when_run) values += fmt::format(" when metrics names {}", m.name());
  if (d.quick != d.value) values += "; quick: " + python_value(o, d.quick);
  return values;
}

}  // namespace halfback::python
