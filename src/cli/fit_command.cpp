// `halfback fit`: an analytic model (or a sum of lobes) fitted to any BRDF (fit/fit.hpp,
// docs/fit.md); the fitted spec on stdout, the details in a JSON file.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "command.hpp"
#include "fit/fit_json.hpp"
#include "halfback/acquire/acquisition.hpp"
#include "halfback/fit/emit.hpp"
#include "halfback/fit/fit.hpp"
#include "halfback/fit/sample_limit.hpp"
#include "halfback/loader/load.hpp"
#include "measurements.hpp"

namespace halfback::cli {

namespace {

struct FitCommandOptions {
  std::string brdf, model, loss = "ngan", output;
  std::string plan, measurements;  // a lab's values at a plan's rows, instead of --brdf
  double max_theta_deg = 90;
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

// A file (or folder) that exists, or an embedded material: what load_brdf reads as data.
bool is_brdf_not_model(const std::string& text) {
  std::error_code ec;
  return text.starts_with("embedded:") || (!text.empty() && std::filesystem::exists(text, ec));
}

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

// UsageError for a --model that names a BRDF (a file, an embedded material) rather than a
// model: the registry's "neither an existing file nor a known BRDF model" was wrong for a file.
void check_model_terms(const std::string& model) {
  if (is_brdf_not_model(model))
    throw UsageError(
        fmt::format("--model '{}': a BRDF, not a model: --model takes models of `halfback models` "
                    "(MODEL[+MODEL...]); give the BRDF to fit them to as --brdf",
                    model));
  std::size_t start = 0;
  while (start <= model.size()) {
    const std::size_t plus = std::min(model.find('+', start), model.size());
    const std::string term = model.substr(start, plus - start);
    if (is_brdf_not_model(term))
      throw UsageError(fmt::format(
          "--model '{}': '{}' is a BRDF, not a model: --model takes models of `halfback "
          "models` (MODEL[+MODEL...]); give the BRDF to fit them to as --brdf",
          model, term));
    start = plus + 1;
  }
}

// The source of the values to fit: --brdf SPEC, or --plan with --measurements (usage errors
// for neither, both, or half of the pair).
void check_source(const FitCommandOptions& o) {
  if (!o.brdf.empty() && !o.plan.empty())
    throw UsageError(
        "--brdf and --plan: give the BRDF to fit, or a plan and its measurements, "
        "not both");
  if (o.brdf.empty() && o.plan.empty())
    throw UsageError("give --brdf SPEC, or --plan PLAN.json with --measurements VALUES.csv");
  if (!o.plan.empty() && o.measurements.empty())
    throw UsageError("--plan needs --measurements VALUES.csv (the lab's values at its rows)");
  if (o.plan.empty() && !o.measurements.empty())
    throw UsageError("--measurements goes with --plan PLAN.json (the rows they were measured at)");
}

// The values a lab measured at a plan's rows as fit samples (docs/fit.md, "Fitting a lab's
// measurements"): one sample per row, weighted by the number of the design's points it stands
// for (a row measures a point and, by reciprocity, its swap), scaled to mean 1; NaN where a row
// was not measured (fit_at leaves it out). `measured` is the count of measured rows.
struct PlanSamples {
  fit::Samples samples;
  std::vector<Rgb> values;
  std::size_t measured = 0;
};

// What was fitted, for the JSON's "brdf": the spec, or the plan and its measurements.
std::string source_of(const FitCommandOptions& o) {
  return o.brdf.empty() ? fmt::format("plan {} measurements {}", o.plan, o.measurements) : o.brdf;
}

PlanSamples plan_samples(const FitCommandOptions& o) {
  const acquire::AcquisitionPlan plan = acquire::read_plan_sidecar(o.plan);
  PlanSamples p;
  p.values = read_measurements(o.measurements, plan.measured.size(), p.measured);
  std::vector<double> points(plan.measured.size(), 0.0);
  for (const std::size_t row : plan.row_of_point) points[row] += 1;
  const double mean = double(plan.row_of_point.size()) / double(plan.measured.size());
  for (std::size_t r = 0; r < plan.measured.size(); ++r) {
    p.samples.pairs.push_back(plan.measured[r]);
    p.samples.weight.push_back(points[r] / mean);
    p.samples.cos_i.push_back(plan.measured[r].wi.z);
  }
  return p;
}

// A warning on stderr for each dead lobe of the fit (fit::kDeadLobeShare, docs/fit.md).
void warn_dead_lobes(const fit::FitResult& r) {
  for (std::size_t t = 0; t < r.dead.size(); ++t)
    if (r.dead[t])
      fmt::print(stderr,
                 "halfback fit: warning: term {} of {} ({}) is a dead lobe: {:.3g} of the fitted "
                 "sum's albedo, loss {:.6g} without it (docs/fit.md, \"Dead lobes\"); the model "
                 "fits as well without it\n",
                 t + 1, r.model.terms.size(), r.model.terms[t], r.albedo_share[t],
                 r.loss_without[t]);
}

// A warning on stderr when the fitted model reflects more light than it receives.
void warn_energy(const fit::FitEnergy& e) {
  if (e.creates_energy())
    fmt::print(stderr,
               "halfback fit: warning: the fitted model reflects more light than it receives: "
               "directional albedo {:.3f} (± {:.3f}) at θi = {}° (docs/fit.md, \"Energy\"); a "
               "renderer gains energy from it\n",
               e.max_albedo, e.standard_error, e.theta_deg);
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
  options.max_theta = o.max_theta_deg * std::numbers::pi / 180;
  check_source(o);
  check_model_terms(o.model);
  try {
    (void)fit::parse_model(o.model);
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("--model: {}", e.what()));
  }
  std::vector<Emit> emits = parse_emits(o);
  // A bad --brdf SPEC, plan or measurements file is an error of status 1.
  const BrdfPtr target = o.brdf.empty() ? nullptr : brdf_argument(o.brdf, "--brdf");
  const PlanSamples lab = o.plan.empty() ? PlanSamples{} : plan_samples(o);
  Output out(o.output);  // an unwritable destination fails before the fit
  for (Emit& e : emits) e.out = std::make_unique<Output>(e.path);
  fit::FitResult r;
  try {
    r = target ? fit::fit(*target, o.model, options)
               : fit::fit_at(lab.samples, lab.values, o.model, options);
  } catch (const std::invalid_argument& e) {  // a model with nothing to fit
    throw UsageError(fmt::format("--model: {}", e.what()));
  }
  const fit::FitEnergy energy = fit::fitted_energy(r.spec);
  out.write(fit::fit_json(r, source_of(o), o.model, energy).dump() + "\n");
  write_emits(emits, r.model);  // every text made before any file is committed
  out.commit();
  for (Emit& e : emits) e.out->commit();
  fmt::print("{}\n", r.spec);
  fmt::print(stderr,
             "halfback fit: {} loss {:.6g} ({} samples, {} starts, {} iterations, {:.2f} s)\n",
             fit::name_of(r.loss), r.loss_value, r.samples, r.starts, r.iterations, r.seconds);
  if (r.missing || r.out_of_reach)
    fmt::print(stderr,
               "halfback fit: left out: {} samples missing (NaN: not measured), {} out of reach "
               "(theta above {:g} deg)\n",
               r.missing, r.out_of_reach, o.max_theta_deg);
  for (const Emit& e : emits)
    fmt::print(stderr, "halfback fit: {} material 'halfback_fit' written to {}\n",
               fit::name_of(e.renderer), e.path);
  warn_dead_lobes(r);
  warn_energy(energy);
  return kExitOk;
}

}  // namespace

Command register_fit(CLI::App& parent) {
  auto o = std::make_shared<FitCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "fit", "Fit an analytic model or a sum of lobes to a BRDF; print the fitted spec");
  app->add_option("--brdf", o->brdf, "BRDF SPEC to fit: a file or a model");
  app->add_option("--plan", o->plan,
                  "PLAN.json of `halfback plan`: fit the values measured at its rows (with "
                  "--measurements) instead of a --brdf")
      ->type_name("FILE");
  app->add_option("--measurements", o->measurements,
                  "CSV of a lab's values at the plan's rows: row and r, g, b (or row and value); "
                  "rows missing are left out")
      ->type_name("FILE");
  app->add_option("--max-theta", o->max_theta_deg,
                  "the instrument's reach: samples with theta_i or theta_o above it (degrees) are "
                  "left out")
      ->check(CLI::Range(1.0, 90.0))
      ->capture_default_str();
  app->add_option("--model", o->model,
                  "MODEL[+MODEL...] of `halfback models`; values given (ggx:f0=0.9) are held")
      ->required();
  app->add_option("--loss", o->loss, fit::loss_names() + " (docs/fit.md)")->capture_default_str();
  app->add_option("--samples", o->samples,
                  "sample pairs (halfdiff Halton layout; turned about the normal for a model "
                  "that can be anisotropic; the bbm-* losses use BBM's grid instead)")
      ->check(CLI::Range(std::size_t{1}, fit::kMaxFitSamples))
      ->capture_default_str();
  app->add_option("--threads", o->threads, "worker threads (0: all cores)")
      ->check(CLI::NonNegativeNumber);
  app->add_option("-o,--output", o->output, "Output JSON file, replaced only on success")
      ->required()
      ->type_name("FILE");
  app->add_option("--emit", o->emits,
                  "TARGET:FILE: the fit as a renderer's material, replaced only on success; "
                  "mitsuba3 (lambert, ggx, beckmann, lambert + one of them), pbrt-v4 (lambert, "
                  "ggx), blender (a Python script for Cycles: sums of lambert, oren-nayar, ggx, "
                  "disney) or materialx (a MaterialX document: sums of lambert, oren-nayar, ggx; "
                  "disney alone); repeatable (docs/fit.md)")
      ->type_name("TARGET:FILE")
      ->take_all();
  app->footer(
      "Prints the fitted model as a SPEC that every command reads (info, eval, render, ...).\n"
      "\n"
      "Example:\n"
      "  halfback fit --brdf embedded:gold-metallic-paint3 --model lambert+ggx -o fit.json\n"
      "  halfback fit --brdf merl.binary --model ggx -o fit.json --emit mitsuba3:bsdf.xml \\\n"
      "      --emit pbrt-v4:material.pbrt\n"
      "  halfback fit --plan plan.json --measurements lab.csv --model lambert+ggx -o fit.json\n"
      "\n"
      "Samples whose value is NaN (unmeasured bins, rows not measured) or beyond --max-theta are\n"
      "left out and counted on stderr (docs/fit.md).");
  return {app, [o] { return run_fit(*o); }};
}

}  // namespace halfback::cli
