// Writes the Python module's type stubs from their template at build time, with the lists the
// library holds put in (so that adding a parameterization, a loss, a renderer or a study metric
// needs no edit of the stubs):
//   @PARAMETERIZATION_NAMES@  the coordinate spaces ("dirs", then the parameterization list)
//   @LOSS_NAMES@              the fit's losses (fit::kLosses)
//   @EMIT_TARGETS@            the renderers of emit() (fit::kRenderers)
//   @SAMPLER_CHARTS@          the charts a Python parameterization may name (kSamplerCharts)
//   @STUDY_METRIC_SETTINGS@   StudySettings' keys of the study's metrics: no_NAME for each that
//                             can be turned off, and each option with its type and values
// Every key must be in the template, each once.
//   halfback_stubgen TEMPLATE OUTPUT
#include <fmt/format.h>

#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "halfback/core/params/charts.hpp"
#include "halfback/core/space.hpp"
#include "halfback/fit/emit.hpp"
#include "halfback/fit/fit.hpp"
#include "halfback/study/metric.hpp"
#include "metric_settings.hpp"

namespace {

using namespace halfback;

template <class Range, class Name>
std::string quoted(const Range& items, Name name) {
  std::string names;
  for (const auto& item : items)
    names += fmt::format("{}\"{}\"", names.empty() ? "" : ", ", std::string_view(name(item)));
  return names;
}

std::string quoted_space_names() {
  return "\"dirs\", " + quoted(parameterizations(), [](Space s) { return name_of(s); });
}

std::string study_metric_settings() {
  std::string lines;
  for (const study::Metric* m : study::study_metrics()) {
    if (m->switchable()) lines += fmt::format("    no_{}: bool\n", m->name());
    const std::vector<study::MetricOption> own = m->options();
    for (std::size_t i = 0; i < own.size(); ++i) {
      using Kind = study::MetricOption::Kind;
      const std::string_view type = own[i].kind == Kind::counts  ? "Sequence[int]"
                                    : own[i].kind == Kind::count ? "int"
                                                                 : "str";
      lines +=
          fmt::format("    {}: {}  # {}\n", own[i].key, type, python::python_option_values(*m, i));
    }
  }
  if (!lines.empty()) lines.pop_back();  // the template's line ends it
  return lines;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: halfback_stubgen TEMPLATE OUTPUT\n";
    return 2;
  }
  std::ifstream in(argv[1]);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) {
    std::cerr << "halfback_stubgen: " << argv[1] << " is unreadable\n";
    return 1;
  }
  std::string s = text.str();
  const std::vector<std::pair<std::string, std::string>> keys{
      {"@PARAMETERIZATION_NAMES@", quoted_space_names()},
      {"@LOSS_NAMES@", quoted(fit::kLosses, [](fit::Loss l) { return fit::name_of(l); })},
      {"@EMIT_TARGETS@", quoted(fit::kRenderers, [](fit::Renderer r) { return fit::name_of(r); })},
      {"@SAMPLER_CHARTS@", quoted(kSamplerCharts, [](const SamplerChart& c) { return c.name; })},
      {"@STUDY_METRIC_SETTINGS@", study_metric_settings()}};
  for (const auto& [key, value] : keys) {
    if (s.find(key) == std::string::npos) {
      std::cerr << "halfback_stubgen: " << argv[1] << " has no " << key << "\n";
      return 1;
    }
    for (auto at = s.find(key); at != std::string::npos; at = s.find(key, at + value.size()))
      s.replace(at, key.size(), value);
  }
  // A key left over is one this program does not know (decorators, "@property", are Python's).
  for (auto a = s.find('@'), b = s.find('@', a + 1); b != std::string::npos;
       a = b, b = s.find('@', a + 1)) {
    const std::string_view between(s.data() + a + 1, b - a - 1);
    if (!between.empty() &&
        between.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZ_") == std::string_view::npos) {
      std::cerr << "halfback_stubgen: " << argv[1] << " has an unknown key @" << between << "@\n";
      return 1;
    }
  }
  std::ofstream out(argv[2]);
  out << s;
  return out.good() ? 0 : 1;
}
