// `halfback study`: the quantitative comparison of the parameterizations on a set of BRDFs
// (include/halfback/study/, docs/study.md): options to a StudyConfig, progress, the files.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <future>
#include <iterator>
#include <mutex>
#include <string>
#include <vector>

#include "command.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/figure/material.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/study/report.hpp"
#include "halfback/study/study.hpp"

namespace halfback::cli {

namespace {

struct StudyOptions {
  std::vector<std::string> specs;
  std::string out = "study";
  std::string space = "log";
  std::string budgets, budgets_4d, environments;
  std::string designs = "own,angle,merl,learned";  // issue 14: designs and error spaces
  std::size_t test_pairs = 0, image_budget = 0;
  int image_size = 0, image_spp = 0;
  double max_theta = 85;
  std::uint64_t seed = 1;
  bool quick = false, no_gonio = false, no_images = false;
};

// The BRDFs of the specs: files, every BRDF file of a directory (by content), or models.
std::vector<std::pair<std::string, BrdfPtr>> load_all(const std::vector<std::string>& specs) {
  std::vector<std::pair<std::string, BrdfPtr>> brdfs;
  for (const std::string& spec : specs) {
    std::error_code ec;
    if (std::filesystem::is_directory(spec, ec)) {
      const auto files = brdf_files_in(spec);
      if (files.empty())
        throw UsageError(fmt::format("'{}': no MERL, RGL or ALTA file in this directory", spec));
      for (const auto& f : files) brdfs.emplace_back(f.string(), load_brdf(f.string()));
    } else {
      brdfs.emplace_back(spec, load_brdf(spec));
    }
  }
  return brdfs;
}

study::StudyConfig make_config(const StudyOptions& o) {
  study::StudyConfig c;
  const auto space = study::parse_error_space(o.space);
  if (!space)
    throw UsageError(fmt::format(
        "--error-space '{}': expected linear, log, cbrt, nielsen or low (docs/study.md)", o.space));
  c.space = *space;
  c.spacings.clear();
  for (const std::string& name : split_list(o.designs, "--designs", "design")) {
    const auto spacing = study::parse_spacing(name);
    if (!spacing)
      throw UsageError(
          fmt::format("--designs: '{}' is not a design (own, angle, merl or learned)", name));
    c.spacings.push_back(*spacing);
  }
  if (o.quick) {
    c.grid = {24, 24, 32};
    c.full_grid = {8, 16, 8, 16};
    c.budgets = {1000, 10000};
    c.budgets_4d = {1000, 10000};
    c.test_pairs = 20000;
    c.image_size = 48;
    c.image_spp = 8;
  }
  auto ascending = [](std::vector<std::size_t> v, const char* option) {
    for (std::size_t i = 1; i < v.size(); ++i)
      if (v[i] <= v[i - 1]) throw UsageError(fmt::format("{}: budgets must be ascending", option));
    return v;
  };
  if (!o.budgets.empty())
    c.budgets = ascending(count_list(o.budgets, "--budgets", "sample budget"), "--budgets");
  if (!o.budgets_4d.empty())
    c.budgets_4d =
        ascending(count_list(o.budgets_4d, "--budgets-4d", "sample budget"), "--budgets-4d");
  if (o.test_pairs) c.test_pairs = o.test_pairs;
  if (o.image_size) c.image_size = o.image_size;
  if (o.image_spp) c.image_spp = o.image_spp;
  c.seed = o.seed;
  c.max_theta_deg = o.max_theta;
  // The image budget: as asked, else 10^4 if it is a budget, else the middle budget.
  if (o.image_budget) {
    c.image_budget = o.image_budget;
  } else if (std::find(c.budgets.begin(), c.budgets.end(), c.image_budget) == c.budgets.end()) {
    c.image_budget = c.budgets[c.budgets.size() / 2];
  }
  if (o.no_gonio) c.budgets.clear();
  if (!o.no_gonio && !o.no_images) {
    if (o.environments.empty()) {
      c.environments = render::default_environments();
    } else {
      for (const std::string& spec : split_list(o.environments, "--env", "environment")) {
        c.environments.push_back(render::load_environment(spec));
      }
    }
  }
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  return c;
}

int run_study(const StudyOptions& o) {
  if (o.specs.empty()) throw UsageError("no BRDF given (files, directories or model specs)");
  study::StudyConfig config = make_config(o);
  const auto brdfs = load_all(o.specs);
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  if (ec || !std::filesystem::is_directory(o.out))
    throw std::runtime_error(fmt::format("cannot create the output directory '{}': {}", o.out,
                                         ec ? ec.message() : "a file of that name exists"));
  check_writable((std::filesystem::path(o.out) / "report.md").string());

  // Progress: a line per BRDF; on a terminal, also the stage each task has reached.
  const bool tty = isatty(fileno(stderr));
  std::mutex progress_mutex;
  std::string current;
  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  if (tty)
    config.progress = [&](std::string_view stage) {
      const std::lock_guard lock(progress_mutex);
      fmt::print(stderr, "\r\x1b[K{}: {} ({:.0f} s)", current, stage, elapsed());
    };
  // The learned design: each BRDF's profile first, then per BRDF the warps of all the others.
  std::vector<study::DesignProfile> profiles;
  const bool learned = std::find(config.spacings.begin(), config.spacings.end(),
                                 study::Spacing::learned) != config.spacings.end();
  if (learned && !config.budgets.empty() && brdfs.size() > 1) {
    fmt::print(stderr, "halfback study: profiles of {} BRDFs for the learned design\n",
               brdfs.size());
    profiles.resize(brdfs.size());
    parallel_for(brdfs.size(), 1, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k)
        profiles[k] = study::design_profile(*brdfs[k].second, study::kStudied, config.profile_grid,
                                            config.space);
    });
  }
  std::vector<study::BrdfResult> results;
  for (std::size_t k = 0; k < brdfs.size(); ++k) {
    if (!profiles.empty()) config.learned = study::learn_warps(profiles, k);
    const auto& [spec, brdf] = brdfs[k];
    // Files by their BRDF's name (merl:..., rgl:...), models by their spec, which holds their
    // parameters (two GGX of different roughness are both named "ggx").
    const std::string label = std::filesystem::exists(spec, ec) ? brdf->name() : spec;
    {
      const std::lock_guard lock(progress_mutex);
      current = fmt::format("halfback study: [{}/{}] {}", k + 1, brdfs.size(), label);
    }
    if (!tty) fmt::print(stderr, "{}\n", current);
    if (!brdf->isotropic())
      warn("study", label +
                        " is anisotropic: its isotropic metrics see its canonical pose, the "
                        "4D metrics all of it");
    results.push_back(study::study_brdf(*brdf, label, config));
    if (tty) fmt::print(stderr, "\r\x1b[K{}: done in {:.1f} s\n", current, results.back().seconds);
  }
  const study::StudyOutput out = study::write_study(o.out, results, config, elapsed());
  std::string files;
  for (const std::string& f : out.files) files += (files.empty() ? "" : ", ") + f;
  fmt::print("{}\nwritten in {}: {}\n", out.markdown, o.out, files);
  return kExitOk;
}

}  // namespace

Command register_study(CLI::App& parent) {
  auto o = std::make_shared<StudyOptions>();
  CLI::App* app = parent.add_subcommand(
      "study",
      "Compare the parameterizations on BRDFs: azimuthal dependence, separability, a virtual "
      "gonio-reflectometer and the image-space error of its reconstructions (CSV, plots, "
      "Markdown and HTML reports)");
  app->add_option("specs", o->specs, "BRDFs: files, directories of files, or model specs")
      ->required();
  app->add_option("-o,--out", o->out, "Output directory (created if missing)")
      ->capture_default_str();
  app->add_option("--space,--error-space", o->space,
                  "Error space: linear, log (ln(1 + Y)), cbrt (Y^(1/3)), nielsen (Nielsen et al. "
                  "2015's log-relative mapping) or low (Low et al. 2012's cosine-weighted log)")
      ->capture_default_str();
  app->add_option("--designs", o->designs,
                  "Designs of the gonio-reflectometer, comma-separated: own (uniform in the "
                  "coordinates), angle (sine-like magnitudes through asin), merl (angle, and sqrt "
                  "of the half-vector angle), learned (warps fitted on the other BRDFs)")
      ->capture_default_str();
  app->add_flag("--quick", o->quick,
                "A small study: 24 x 24 x 32 grids, budgets 1000,10000, 20000 test pairs, "
                "48^2 images");
  app->add_option("--budgets", o->budgets,
                  "Gonio-reflectometer budgets, ascending (default 1000,3000,10000,30000,100000)");
  app->add_option("--budgets-4d", o->budgets_4d,
                  "Budgets of the 4D gonio-reflectometer of anisotropic BRDFs "
                  "(default 1000,10000,100000,1000000)");
  app->add_option("--test-pairs", o->test_pairs,
                  "Pairs the reconstructions are checked at (default 200000)")
      ->check(CLI::Range(std::size_t(100), study::kMaxTestPairs));
  app->add_option("--env", o->environments,
                  "Environments of the image-space error, comma-separated: built-in names "
                  "(default, sky, studio, sunset) or .hdr/.exr files (default: the built-ins)");
  app->add_option("--image-budget", o->image_budget,
                  "The budget whose reconstructions are rendered (one of --budgets; default "
                  "10000)");
  app->add_option("--image-size", o->image_size, "Width and height of the renderings (default 96)")
      ->check(CLI::Range(8, 4096));
  app->add_option("--image-spp", o->image_spp, "Samples per pixel of the renderings (default 16)")
      ->check(CLI::Range(1, 1 << 16));
  app->add_option("--max-theta", o->max_theta,
                  "The gonio-reflectometer's reach: no measurement where a direction is farther "
                  "from the normal (degrees)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 90.0));
  app->add_option("--seed", o->seed, "Seed of the test pairs, stratified designs and renderings")
      ->capture_default_str();
  app->add_flag("--no-gonio", o->no_gonio, "Metrics 1-2 only (no gonio-reflectometer, no images)");
  app->add_flag("--no-images", o->no_images, "No image-space error");
  app->footer(
      "Metrics (docs/study.md), under the measure cos(theta_i) cos(theta_o) dwi dwo:\n"
      "  azimuthal.csv     brdf,parameterization,error,dims: the error of dropping the relative\n"
      "                    azimuth (dims 3), or the second azimuth of the full form (dims 4)\n"
      "  separability.csv  brdf,parameterization,rank,error,dims: best rank-r approximations of\n"
      "                    the 2D projection (dims 2), the 3D table unfolded along the azimuth\n"
      "                    (3), the 4D table as (a, phi_a) x (b, phi_b) (4)\n"
      "  gonio.csv         brdf,parameterization,design,samples,error,dims,budget,spacing: the\n"
      "                    virtual gonio-reflectometer (regular and stratified layouts; the\n"
      "                    spacing of --designs)\n"
      "  budget.csv        the samples each needs to reach errors of 0.05, 0.02, 0.01\n"
      "  image.csv         brdf,parameterization,design,samples,environment,relative_rmse,\n"
      "                    mean_delta_e2000,p95_delta_e2000,mae,rmse,ssim\n"
      "Example:\n"
      "  halfback study --out study ggx:alpha=0.2 ../shared/data/rgl");
  return {app, [o] { return run_study(*o); }};
}

}  // namespace halfback::cli
