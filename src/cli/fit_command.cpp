// `halfback fit`: an analytic model (or a sum of lobes) fitted to any BRDF (fit/fit.hpp,
// docs/fit.md); the fitted spec on stdout, the details in a JSON file.
#include <fmt/format.h>

#include <string>

#include "command.hpp"
#include "halfback/fit/fit.hpp"
#include "halfback/loader/load.hpp"
#include "view/fit_json.hpp"

namespace halfback::cli {

namespace {

struct FitCommandOptions {
  std::string brdf, model, loss = "ngan", output;
  std::size_t samples = 20000;
  int threads = 0;
};

int run_fit(const FitCommandOptions& o) {
  if (o.output == "-")
    throw UsageError("-o: fit writes its JSON to a file (the spec goes to stdout)");
  fit::FitOptions options;
  const auto loss = fit::parse_loss(o.loss);
  if (!loss) throw UsageError(fmt::format("--loss '{}': expected {}", o.loss, fit::loss_names()));
  options.loss = *loss;
  options.samples = o.samples;
  options.threads = o.threads;
  try {
    (void)fit::parse_model(o.model);
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("--model: {}", e.what()));
  }
  // A bad --brdf SPEC is an error of status 1, as in every command that reads one.
  const BrdfPtr target = brdf_argument(o.brdf, "--brdf");
  Output out(o.output);  // an unwritable destination fails before the fit
  fit::FitResult r;
  try {
    r = fit::fit(*target, o.model, options);
  } catch (const std::invalid_argument& e) {  // a model with nothing to fit
    throw UsageError(fmt::format("--model: {}", e.what()));
  }
  view::JsonWriter j;
  view::write_fit(j, r, o.brdf, o.model);
  out.write(j.str() + "\n");
  out.commit();
  fmt::print("{}\n", r.spec);
  fmt::print(stderr,
             "halfback fit: {} loss {:.6g} ({} samples, {} starts, {} iterations, {:.2f} s)\n",
             fit::name_of(r.loss), r.loss_value, r.samples, r.starts, r.iterations, r.seconds);
  return kExitOk;
}

}  // namespace

Command register_fit(CLI::App& parent) {
  auto o = std::make_shared<FitCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "fit", "Fit an analytic model or a sum of lobes to a BRDF; print the fitted spec");
  app->add_option("--brdf", o->brdf, "BRDF SPEC to fit: a file or a model")->required();
  app->add_option("--model", o->model,
                  "MODEL[+MODEL...] of `halfback models`; values given (ggx:f0=0.9) are held")
      ->required();
  app->add_option("--loss", o->loss, "ngan, low-e1, low-e2, cube-root or log (docs/fit.md)")
      ->capture_default_str();
  app->add_option("--samples", o->samples, "sample pairs (halfdiff Halton layout)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{10000000}))
      ->capture_default_str();
  app->add_option("--threads", o->threads, "worker threads (0: all cores)")
      ->check(CLI::NonNegativeNumber);
  app->add_option("-o,--output", o->output, "Output JSON file, replaced only on success")
      ->required()
      ->type_name("FILE");
  app->footer(
      "Prints the fitted model as a SPEC that every command reads (info, eval, render, ...).\n"
      "\n"
      "Example:\n"
      "  halfback fit --brdf embedded:gold-metallic-paint3 --model lambert+ggx -o fit.json");
  return {app, [o] { return run_fit(*o); }};
}

}  // namespace halfback::cli
