// `halfback compare A B`: the error of a BRDF B against a reference A, in every loss of `halfback
// fit` (fit.hpp's loss_value on fit()'s sample layout), in every error space of the study's
// reconstruction error (gonio.hpp's reconstruction_error on the study's test pairs), and as the
// difference of their directional albedos (albedo.hpp); a table on stdout, --json FILE, and with
// -o a figure (figure/compare.hpp). docs/fit.md, "Comparing a fit with its data".
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "command.hpp"
#include "halfback/acquire/gonio.hpp"
#include "halfback/acquire/samples.hpp"
#include "halfback/brdf/albedo.hpp"
#include "halfback/figure/compare.hpp"
#include "halfback/figure/render.hpp"
#include "halfback/fit/fit.hpp"
#include "halfback/fit/sample_limit.hpp"
#include "halfback/study/study.hpp"

namespace halfback::cli {

// A named namespace: the CLI is one unity translation unit, where file-local names would clash.
namespace compare_command {

struct Options {
  std::string reference, compared;  // A, B
  std::size_t samples = 20000;      // fit()'s default layout
  std::size_t test_pairs = study::StudyConfig{}.test_pairs;
  int albedo_samples = 128;
  int threads = 0;
  std::string json, figure;
};

// The study's reach of the test pairs and its seed (StudyConfig's defaults).
const double kMaxThetaDeg = study::StudyConfig{}.max_theta_deg;
const std::uint64_t kSeed = study::StudyConfig{}.seed;
constexpr double kAlbedoIncidencesDeg[] = {0, 30, 60, 80};

struct Loss {
  std::string name;
  double value = 0;
};
struct LossTable {
  std::string layout;
  std::size_t samples = 0, used = 0;  // the layout's pairs; those where A and B are finite
  std::vector<Loss> values;
};

struct SpaceError {
  std::string name;
  double value = 0;
  std::size_t used = 0;  // test pairs where A and B are finite
};

struct AlbedoRow {
  double theta_deg = 0;
  AlbedoEstimate reference, compared;
};

struct Comparison {
  LossTable losses;
  std::vector<SpaceError> study;
  std::vector<AlbedoRow> albedo;
};

bool finite(const Rgb& v) {
  return std::isfinite(v.r) && std::isfinite(v.g) && std::isfinite(v.b);
}

// Each of fit's losses of B against the values of A, on fit()'s layout (turned when either is
// anisotropic), over the pairs where both are finite (measured data leaves pairs unmeasured).
LossTable fit_losses(const Brdf& a, const Brdf& b, std::size_t n, int threads) {
  const bool turned = !a.isotropic() || !b.isotropic();
  const fit::Azimuths az = turned ? fit::Azimuths::turned : fit::Azimuths::canonical;
  const fit::Samples all = fit::halfdiff_samples(n, az);
  std::vector<Rgb> va(all.pairs.size()), vb(all.pairs.size());
  a.eval_batch(all.pairs, va);
  b.eval_batch(all.pairs, vb);
  fit::Samples kept;
  std::vector<Rgb> target;
  for (std::size_t i = 0; i < all.pairs.size(); ++i) {
    if (!finite(va[i]) || !finite(vb[i])) continue;
    kept.pairs.push_back(all.pairs[i]);
    kept.weight.push_back(all.weight[i]);
    kept.cos_i.push_back(all.cos_i[i]);
    target.push_back(va[i]);
  }
  if (kept.pairs.empty())
    throw std::runtime_error(
        fmt::format("A or B is not finite at every one of the {} pairs of the fit's layout", n));
  LossTable t;
  t.layout = fit::layout_name(az);
  t.samples = all.pairs.size();
  t.used = kept.pairs.size();
  for (fit::Loss loss : fit::kLosses)
    t.values.push_back(
        {std::string(fit::name_of(loss)), fit::loss_value(target, b, loss, kept, threads)});
  return t;
}

// The study's reconstruction error of B against A in each error space, on the study's test
// pairs (drawn from A where it is finite), those where B is not finite left out.
std::vector<SpaceError> study_errors(const Brdf& a, const Brdf& b, std::size_t n) {
  std::vector<SpaceError> out;
  for (acquire::ErrorSpace es : acquire::kErrorSpaces) {
    acquire::TestPairs test = acquire::draw_test_pairs(a, n, kSeed, es, kMaxThetaDeg);
    std::vector<Rgb> vb(test.pairs.size());
    b.eval_batch(test.pairs, vb);
    std::size_t kept = 0;
    for (std::size_t i = 0; i < test.pairs.size(); ++i) {
      if (!std::isfinite(vb[i].luminance())) continue;
      test.pairs[kept] = test.pairs[i];
      test.truth[kept++] = test.truth[i];
    }
    if (kept == 0)
      throw std::runtime_error(
          fmt::format("A or B is not finite at every one of the {} test pairs", n));
    test.pairs.resize(kept);
    test.truth.resize(kept);
    out.push_back(
        {std::string(acquire::name_of(es)), acquire::reconstruction_error(b, test), kept});
  }
  return out;
}

std::vector<AlbedoRow> albedo_rows(const Brdf& a, const Brdf& b, int n) {
  std::vector<AlbedoRow> rows;
  for (double deg : kAlbedoIncidencesDeg) {
    const double th = deg * std::numbers::pi / 180;
    const Vec3<double> wi{std::sin(th), 0, std::cos(th)};
    rows.push_back({deg, directional_albedo(a, wi, n), directional_albedo(b, wi, n)});
  }
  return rows;
}

Rgb difference(const AlbedoRow& r) {
  return {r.compared.mean.r - r.reference.mean.r, r.compared.mean.g - r.reference.mean.g,
          r.compared.mean.b - r.reference.mean.b};
}

std::string rgb_text(const Rgb& v) {
  if (!finite(v)) return "not measured";
  return fmt::format("{:.4g}, {:.4g}, {:.4g}", v.r, v.g, v.b);
}

// Notes on the albedos of measured data taken over part of the hemisphere only (albedo.hpp).
std::string coverage_notes(const std::vector<AlbedoRow>& rows) {
  std::string s;
  for (const AlbedoRow& r : rows)
    for (const auto& [name, a] : {std::pair{"A", &r.reference}, std::pair{"B", &r.compared}})
      if (a->measured > 0 && a->measured < 1)
        s += fmt::format(
            "  θi = {:g}°: {}'s albedo is the mean over the measured {:.3g} % of the "
            "cosine-weighted hemisphere\n",
            r.theta_deg, name, 100 * a->measured);
  return s;
}

std::string table_text(const Options& o, const Brdf& a, const Brdf& b, const Comparison& c) {
  std::string s = fmt::format("A (reference): {} ({})\nB (compared):  {} ({})\n\n", o.reference,
                              a.name(), o.compared, b.name());
  s += fmt::format(
      "Losses of `halfback fit` (docs/fit.md): mean r² over {} of the {} pairs of the {} layout "
      "and 3 channels\n",
      c.losses.used, c.losses.samples, c.losses.layout);
  for (const Loss& l : c.losses.values) s += fmt::format("  {:<12}{:.6g}\n", l.name, l.value);
  s += fmt::format(
      "\nStudy measures (docs/study.md): relative L² error of the luminance in each error space, "
      "over the study's test pairs ({} drawn, θ ≤ {:g}°, seed {})\n",
      o.test_pairs, kMaxThetaDeg, kSeed);
  for (const SpaceError& e : c.study)
    s += fmt::format("  {:<12}{:<14.6g}({} pairs)\n", e.name, e.value, e.used);
  s += fmt::format("\nDirectional albedo (r, g, b; {} × {} stratified samples)\n", o.albedo_samples,
                   o.albedo_samples);
  s += fmt::format("  {:<7}{:<28}{:<28}{}\n", "θi", "A", "B", "B − A");
  for (const AlbedoRow& r : c.albedo)
    s +=
        fmt::format("  {:<7}{:<28}{:<28}{}\n", fmt::format("{:g}°", r.theta_deg),
                    rgb_text(r.reference.mean), rgb_text(r.compared.mean), rgb_text(difference(r)));
  return s + coverage_notes(c.albedo);
}

nlohmann::json rgb_json(const Rgb& v) {
  return nlohmann::json::array({v.r, v.g, v.b});
}

std::string json_text(const Options& o, const Brdf& a, const Brdf& b, const Comparison& c) {
  nlohmann::json j;
  j["reference"] = {{"spec", o.reference}, {"name", a.name()}};
  j["compared"] = {{"spec", o.compared}, {"name", b.name()}};
  nlohmann::json losses = nlohmann::json::object();
  for (const Loss& l : c.losses.values) losses[l.name] = l.value;
  j["fit_losses"] = {{"layout", c.losses.layout},
                     {"samples", c.losses.samples},
                     {"used", c.losses.used},
                     {"values", losses}};
  nlohmann::json spaces = nlohmann::json::object(), used = nlohmann::json::object();
  for (const SpaceError& e : c.study) {
    spaces[e.name] = e.value;
    used[e.name] = e.used;
  }
  j["study_errors"] = {{"test_pairs", o.test_pairs},
                       {"max_theta_deg", kMaxThetaDeg},
                       {"seed", kSeed},
                       {"used", used},
                       {"values", spaces}};
  nlohmann::json rows = nlohmann::json::array();
  for (const AlbedoRow& r : c.albedo)
    rows.push_back({{"theta_i_deg", r.theta_deg},
                    {"reference", rgb_json(r.reference.mean)},
                    {"compared", rgb_json(r.compared.mean)},
                    {"difference", rgb_json(difference(r))},
                    {"reference_measured", r.reference.measured},
                    {"compared_measured", r.compared.measured}});
  j["albedo"] = {{"samples_per_axis", o.albedo_samples}, {"rows", rows}};
  return j.dump(2) + "\n";
}

void check_figure_path(const std::string& path) {
  if (!path.empty() && !figure::format_from_path(path))
    throw UsageError(fmt::format(
        "-o '{}': cannot tell the figure format: use a .png, .svg or .pdf file name", path));
}

int run(const Options& o) {
  check_figure_path(o.figure);
  if (!o.json.empty() && o.json == o.figure)
    throw UsageError(fmt::format("--json and -o name the same file '{}'", o.json));
  const BrdfPtr a = brdf_argument(o.reference, "A");
  const BrdfPtr b = brdf_argument(o.compared, "B");
  // Both outputs writable before any work; committed only once everything is made.
  std::optional<Output> json_out, figure_out;
  if (!o.json.empty()) json_out.emplace(o.json);
  if (!o.figure.empty()) figure_out.emplace(o.figure);

  Comparison c;
  c.losses = fit_losses(*a, *b, o.samples, o.threads);
  c.study = study_errors(*a, *b, o.test_pairs);
  c.albedo = albedo_rows(*a, *b, o.albedo_samples);
  if (json_out) json_out->write(json_text(o, *a, *b, c));
  if (figure_out) {
    figure::CompareFigureOptions fo;
    fo.reference = a;
    fo.compared = b;
    fo.threads = o.threads;
    const figure::Format format = *figure::format_from_path(o.figure);
    figure_out->write(figure::render(figure::compare_figure(fo).scene, format));
  }
  if (json_out) json_out->commit();
  if (figure_out) figure_out->commit();
  Output out("-");
  out.write(table_text(o, *a, *b, c));
  out.commit();
  return kExitOk;
}

}  // namespace compare_command

Command register_compare(CLI::App& parent) {
  auto o = std::make_shared<compare_command::Options>();
  CLI::App* app = parent.add_subcommand(
      "compare", "Compare a BRDF B with a reference A: fit losses, study errors, albedo, figure");
  app->add_option("A", o->reference, "Reference BRDF SPEC: a file or a model")->required();
  app->add_option("B", o->compared, "Compared BRDF SPEC (e.g. a fit of A)")->required();
  app->add_option("--samples", o->samples, "Pairs of the fit's layout for the losses")
      ->check(CLI::Range(std::size_t{1}, fit::kMaxFitSamples))
      ->capture_default_str();
  app->add_option("--test-pairs", o->test_pairs, "Test pairs of the study's errors")
      ->check(CLI::Range(std::size_t{100}, study::kMaxTestPairs))
      ->capture_default_str();
  app->add_option("--albedo-samples", o->albedo_samples,
                  "Stratified samples per axis of the albedo estimates (N x N)")
      ->check(CLI::Range(4, 4096))
      ->capture_default_str();
  app->add_option("--threads", o->threads, "worker threads (0: all cores)")
      ->check(non_negative_integer());
  app->add_option("--json", o->json, "Also write the numbers as JSON, replaced only on success")
      ->type_name("FILE");
  app->add_option("-o,--output,--out", o->figure,
                  "Figure: slices of A, B and log10(B/A), and both albedos (.png, .svg or .pdf; "
                  "--out is an alias)")
      ->type_name("FIG");
  app->footer(
      "Prints the error of B against A (the reference) in each loss of `halfback fit` and in\n"
      "each error space of the study, and their directional albedos (docs/fit.md, \"Comparing\n"
      "a fit with its data\").\n"
      "Example:\n"
      "  halfback fit --brdf gold-metallic-paint3.h5 --model lambert+ggx -o fit.json\n"
      "  halfback compare gold-metallic-paint3.h5 'SPEC printed by fit' -o compare.png");
  return {app, [o] { return compare_command::run(*o); }};
}

}  // namespace halfback::cli
