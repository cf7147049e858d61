// `halfback fit`: an analytic model (or a sum of lobes) fitted to any BRDF (fit/fit.hpp,
// docs/fit.md); the fitted spec on stdout, the details in a JSON file.
#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "command.hpp"
#include "halfback/fit/emit.hpp"
#include "halfback/fit/fit.hpp"
#include "halfback/loader/load.hpp"
#include "view/fit_json.hpp"

namespace halfback::cli {

namespace {

struct FitCommandOptions {
  std::string brdf, model, loss = "ngan", output;
  std::vector<std::string> emits;  // TARGET:FILE
  std::size_t samples = 20000;
  int threads = 0;
};

// One --emit: the renderer's material, written to `path` (docs/fit.md, "Renderer-ready output").
struct Emit {
  fit::Renderer renderer;
  std::string path;
  std::unique_ptr<Output> out;
};

bool same_file(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ec;
  return fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec) && !ec;
}

// Each --emit TARGET:FILE (usage errors: no colon, an unknown target, stdout, a file that another
// output names), and whether the target has a material for the model's terms (usage error: the
// model and the target do not go together). No file is created here.
std::vector<Emit> parse_emits(const FitCommandOptions& o) {
  std::vector<Emit> emits;
  for (const std::string& item : o.emits) {
    const std::size_t colon = item.find(':');
    if (colon == std::string::npos || colon + 1 == item.size())
      throw UsageError(fmt::format("--emit '{}': expected TARGET:FILE, TARGET one of {}", item,
                                   fit::renderer_names()));
    const auto renderer = fit::parse_renderer(item.substr(0, colon));
    if (!renderer)
      throw UsageError(fmt::format("--emit '{}': unknown target '{}': expected {}", item,
                                   item.substr(0, colon), fit::renderer_names()));
    Emit e{*renderer, item.substr(colon + 1), nullptr};
    if (e.path == "-") throw UsageError(fmt::format("--emit '{}': writes to a file", item));
    if (same_file(e.path, o.output))
      throw UsageError(fmt::format("--emit '{}': the file of -o", item));
    for (const Emit& other : emits)
      if (same_file(e.path, other.path))
        throw UsageError(fmt::format("--emit '{}': the file of another --emit", item));
    try {
      fit::check_emittable(fit::parse_model(o.model), e.renderer);
    } catch (const std::invalid_argument& error) {
      throw UsageError(error.what());
    }
    emits.push_back(std::move(e));
  }
  return emits;
}

// The fitted model's text for each --emit, written to its Output (committed by the caller). A
// fitted value the renderer cannot take (docs/fit.md) fails the command with status 1.
void write_emits(std::vector<Emit>& emits, const fit::Model& model) {
  for (Emit& e : emits) {
    try {
      e.out->write(fit::emit_material(model, e.renderer));
    } catch (const std::invalid_argument& error) {
      throw std::runtime_error(fmt::format("the fitted model: {}", error.what()));
    }
  }
}

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
  std::vector<Emit> emits = parse_emits(o);
  // A bad --brdf SPEC is an error of status 1, as in every command that reads one.
  const BrdfPtr target = brdf_argument(o.brdf, "--brdf");
  Output out(o.output);  // an unwritable destination fails before the fit
  for (Emit& e : emits) e.out = std::make_unique<Output>(e.path);
  fit::FitResult r;
  try {
    r = fit::fit(*target, o.model, options);
  } catch (const std::invalid_argument& e) {  // a model with nothing to fit
    throw UsageError(fmt::format("--model: {}", e.what()));
  }
  view::JsonWriter j;
  view::write_fit(j, r, o.brdf, o.model);
  out.write(j.str() + "\n");
  write_emits(emits, r.model);  // every text made before any file is committed
  out.commit();
  for (Emit& e : emits) e.out->commit();
  fmt::print("{}\n", r.spec);
  fmt::print(stderr,
             "halfback fit: {} loss {:.6g} ({} samples, {} starts, {} iterations, {:.2f} s)\n",
             fit::name_of(r.loss), r.loss_value, r.samples, r.starts, r.iterations, r.seconds);
  for (const Emit& e : emits)
    fmt::print(stderr, "halfback fit: {} material 'halfback_fit' written to {}\n",
               fit::name_of(e.renderer), e.path);
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
  app->add_option("--loss", o->loss, fit::loss_names() + " (docs/fit.md)")
      ->capture_default_str();
  app->add_option("--samples", o->samples, "sample pairs (halfdiff Halton layout)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{10000000}))
      ->capture_default_str();
  app->add_option("--threads", o->threads, "worker threads (0: all cores)")
      ->check(CLI::NonNegativeNumber);
  app->add_option("-o,--output", o->output, "Output JSON file, replaced only on success")
      ->required()
      ->type_name("FILE");
  app->add_option("--emit", o->emits,
                  "TARGET:FILE: the fit as a renderer's material, replaced only on success; "
                  "mitsuba3 (lambert, ggx, beckmann, lambert + one of them) or pbrt-v4 (lambert, "
                  "ggx); repeatable (docs/fit.md)")
      ->type_name("TARGET:FILE")
      ->take_all();
  app->footer(
      "Prints the fitted model as a SPEC that every command reads (info, eval, render, ...).\n"
      "\n"
      "Example:\n"
      "  halfback fit --brdf embedded:gold-metallic-paint3 --model lambert+ggx -o fit.json\n"
      "  halfback fit --brdf merl.binary --model ggx -o fit.json --emit mitsuba3:bsdf.xml \\\n"
      "      --emit pbrt-v4:material.pbrt");
  return {app, [o] { return run_fit(*o); }};
}

}  // namespace halfback::cli
