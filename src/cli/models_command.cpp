// `halfback models`: the analytic models of the registry, their parameters, defaults and ranges.
#include <fmt/format.h>

#include <string>

#include "command.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::cli {

namespace {

std::string describe_models() {
  const ModelRegistry& registry = model_registry();
  std::string s;
  for (const std::string& name : registry.names()) {
    const ModelInfo* m = registry.find(name);
    s += fmt::format("{}\n  {}\n", m->name, m->description);
    for (const ModelParam& p : m->params) {
      std::string range;
      if (!p.choices.empty()) {
        for (const auto& c : p.choices) range += (range.empty() ? "" : " | ") + c;
        range =
            fmt::format("one of {}, default {}", range, p.choices.at(std::size_t(p.default_value)));
      } else if (!p.default_from.empty()) {
        range = fmt::format("default: {}, in [{:g}, {:g}]", p.default_from, p.min, p.max);
      } else {
        range = fmt::format("default {:g}, in [{:g}, {:g}]", p.default_value, p.min, p.max);
      }
      s += fmt::format("  {:<12} {} ({})\n", p.name, p.description, range);
    }
    s += '\n';
  }
  s += "A model is named by a SPEC: NAME or NAME:KEY=VALUE,KEY=VALUE (a first value without a key\n"
       "sets the first parameter), and models add with '+', e.g. "
       "'lambert:albedo=0.3+ggx:alpha=0.1'.\n";
  return s;
}

}  // namespace

Command register_models(CLI::App& parent) {
  CLI::App* app = parent.add_subcommand(
      "models", "List the analytic BRDF models, their parameters, defaults and ranges");
  app->footer("Example:\n  halfback eval --brdf ggx:alpha=0.2,f0=0.9 -i pairs.csv");
  return {app, [] {
            Output out("-");
            out.write(describe_models());
            out.commit();
            return kExitOk;
          }};
}

}  // namespace halfback::cli
