// `halfback study`: the quantitative comparison of the parameterizations on a set of BRDFs
// (include/halfback/study/, docs/study.md): options to a StudyConfig, progress, the files.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "command.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/study/metric.hpp"
#include "halfback/study/parts.hpp"
#include "halfback/study/report.hpp"
#include "halfback/study/study.hpp"
#include "halfback/util/atomic_file.hpp"
#include "halfback/util/csv.hpp"
#include "halfback/util/output_dir.hpp"

namespace halfback::cli {

namespace {

struct StudyOptions {
  std::vector<std::string> specs, merge;
  std::string out = "study";
  std::string budgets, budgets_4d, environments, params, metrics;
  std::map<std::string, std::string> metric_options;  // by MetricOption::key, as given
  std::vector<std::string> nielsen_database;  // Nielsen et al.'s database: files, folders, specs
  std::string nielsen_counts;
  double nielsen_eta = acquire::NielsenOptions{}.eta;
  std::string designs = "own,angle,merl,learned";
  study::StudySettings settings;
  bool resume = false;
  bool quiet = false, full_report = false;  // what goes to stdout (print_written)
};

// "(default X)", or "(default X; --quick Y)" when --quick changes it: the values the study
// uses (StudyConfig's and quick_config()'s), so that the help cannot drift from them.
template <class T>
std::string defaults(const T& plain, const T& quick) {
  const auto text = [](const T& v) {
    if constexpr (std::is_arithmetic_v<T>)
      return fmt::format("{}", v);
    else
      return fmt::format("{}", fmt::join(v, ","));
  };
  if (plain == quick) return "(default " + text(plain) + ")";
  return "(default " + text(plain) + "; --quick " + text(quick) + ")";
}

// The configuration of the options; a bad value is a usage error.
study::StudyConfig make_config(const StudyOptions& o) {
  study::StudySettings s = o.settings;
  if (!o.budgets.empty()) s.budgets = count_list(o.budgets, "--budgets", "sample budget");
  if (!o.budgets_4d.empty())
    s.budgets_4d = count_list(o.budgets_4d, "--budgets-4d", "sample budget");
  if (!o.environments.empty()) s.environments = split_list(o.environments, "--env", "environment");
  if (!o.metrics.empty()) s.metrics = split_list(o.metrics, "--metrics", "metric");
  for (const auto& [key, value] : o.metric_options)
    if (!value.empty()) s.options[key] = value;
  s.designs = split_list(o.designs, "--spacings", "spacing");
  if (!o.nielsen_counts.empty())
    s.nielsen_counts = count_list(o.nielsen_counts, "--nielsen-budgets", "measurement budget");
  if (!o.params.empty()) s.params = split_list(o.params, "--params", "parameterization");
  try {
    return study::make_config(s);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

// The specs of the BRDFs: files (every BRDF file of a directory, by content) and models. Files
// are read one at a time as they are studied (a MERL file is 33 MB); their format is checked
// here, models are created here, so that a bad spec stops the run before any work.
std::vector<std::string> expand_specs(const std::vector<std::string>& specs) {
  std::vector<std::string> out;
  for (const std::string& spec : specs) {
    std::error_code ec;
    if (std::filesystem::is_directory(spec, ec) &&
        detect_brdf_format(spec) == BrdfFileFormat::unknown) {
      const auto files = brdf_files_in(spec);
      if (files.empty())
        throw UsageError(
            fmt::format("'{}': no MERL, RGL, ALTA or neural BRDF file in this "
                        "directory",
                        spec));
      for (const auto& f : files) out.push_back(f.string());
    } else if (std::filesystem::exists(spec, ec)) {
      if (detect_brdf_format(spec) == BrdfFileFormat::unknown) brdf_argument(spec, "SPEC");
      out.push_back(spec);
    } else {
      brdf_argument(spec, "SPEC");
      out.push_back(spec);
    }
  }
  return out;
}

// The parts directory of a run: with --resume, the settings must be those of the run resumed;
// without, the parts of an earlier run are removed (its CSV files are replaced anyway).
std::filesystem::path prepare_parts(const StudyOptions& o, const study::StudyConfig& config) {
  const std::filesystem::path parts = study::parts_dir(o.out);
  create_output_directory(parts);
  const std::filesystem::path settings = parts / "settings.txt";
  const std::string described = study::describe_config(config);
  std::error_code ec;
  const bool earlier = std::filesystem::exists(settings, ec);
  if (o.resume && earlier && read_text_file(settings) != described)
    throw UsageError(fmt::format(
        "--resume: '{}' was run with other settings (its {}); run with the same options, or "
        "without --resume to start over",
        o.out, settings.string()));
  if (!o.resume) {
    std::size_t removed = 0;
    for (const auto& e : std::filesystem::directory_iterator(parts)) {
      const auto ext = e.path().extension();
      if (ext == ".part" || ext == ".exr") removed += std::filesystem::remove(e.path(), ec);
    }
    if (removed)
      warn("study", fmt::format("starting over: the results of an earlier run in '{}' are "
                                "replaced (--resume continues a run)",
                                parts.string()));
  }
  write_file_atomically(settings, described);
  return parts;
}

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

std::string duration_text(double s) {
  if (s < 90) return fmt::format("{:.0f} s", s);
  if (s < 5400) return fmt::format("{:.0f} min", s / 60);
  return fmt::format("{:.1f} h", s / 3600);
}

// Progress: a line per BRDF with the time it took and an estimate of the time left (the mean of
// the BRDFs studied in this run, times those left); on a terminal, also each task's stage.
class Progress {
 public:
  explicit Progress(std::size_t total) : total_(total), tty_(isatty(fileno(stderr))) {}

  std::function<void(std::string_view)> stage_callback() {
    if (!tty_) return {};
    return [this](std::string_view stage) {
      const std::lock_guard lock(mutex_);
      fmt::print(stderr, "\r\x1b[K{}: {} ({:.0f} s)", current_, stage, elapsed());
    };
  }
  void start(std::size_t k, const std::string& spec) {
    const std::lock_guard lock(mutex_);
    current_ = fmt::format("halfback study: [{}/{}] {}", k + 1, total_, spec);
    if (!tty_) fmt::print(stderr, "{}\n", current_);
  }
  void resumed(std::size_t k, const std::string& label) {
    ++done_;
    if (tty_ || k + 1 == total_ || done_ % 20 == 1)
      fmt::print(stderr, "{}halfback study: [{}/{}] {}: kept from the earlier run\n",
                 tty_ ? "\r\x1b[K" : "", k + 1, total_, label);
  }
  void finished(double seconds, double cpu) {
    ++done_;
    ++studied_;
    spent_ += seconds;
    const double left = spent_ / double(studied_) * double(total_ - done_);
    const std::lock_guard lock(mutex_);
    fmt::print(stderr, "{}{}: done in {:.1f} s ({:.1f} CPU s){}\n", tty_ ? "\r\x1b[K" : "",
               current_, seconds, cpu,
               done_ < total_ ? fmt::format("; about {} left", duration_text(left)) : "");
  }
  double elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
  }

 private:
  std::size_t total_, done_ = 0, studied_ = 0;
  double spent_ = 0;
  bool tty_;
  std::mutex mutex_;
  std::string current_;
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

// The report's head: the title, the header and the Summary section (what a terminal can show;
// the whole data's report is 2 000 lines).
std::string report_head(const std::string& markdown) {
  const std::size_t summary = markdown.find("\n## Summary");
  if (summary == std::string::npos) return markdown;
  const std::size_t next = markdown.find("\n## ", summary + 1);
  return next == std::string::npos ? markdown : markdown.substr(0, next + 1);
}

// On stdout: the report's head (or all of it with --full-report, nothing with --quiet) and
// where the files are.
void print_written(const study::StudyOutput& out, const std::string& dir, const StudyOptions& o) {
  if (o.quiet) return;
  std::string files;
  for (const std::string& f : out.files) files += (files.empty() ? "" : ", ") + f;
  const bool whole = o.full_report || report_head(out.markdown).size() == out.markdown.size();
  fmt::print("{}\n{}written in {}: {}\n", whole ? out.markdown : report_head(out.markdown),
             whole ? "" : fmt::format("(the whole report: {}/report.md)\n", dir), dir, files);
}

// The BRDF of a spec, studied, its part written; or the part of an earlier run (--resume).
study::BrdfResult study_one(const std::string& spec, std::size_t k,
                            const std::filesystem::path& parts, const study::StudyConfig& config,
                            bool resume, Progress& progress) {
  const std::string key = study::part_key(spec);
  std::error_code ec;
  if (resume && std::filesystem::exists(parts / (key + ".part"), ec)) {
    study::BrdfResult kept = study::read_part(parts, key, config.params);
    progress.resumed(k, kept.label);
    return kept;
  }
  progress.start(k, spec);
  const double cpu0 = cpu_seconds();
  const BrdfPtr brdf = load_brdf(spec);
  const std::string label = study::study_label(spec, *brdf);
  if (!brdf->isotropic())
    warn("study", label +
                      " is anisotropic: its isotropic metrics see its canonical pose, the 4D "
                      "metrics all of it");
  const study::BrdfResult result = study::study_brdf(*brdf, label, config);
  study::write_part(parts, key, result, k);
  progress.finished(result.seconds, cpu_seconds() - cpu0);
  // Read back, so that a run and its resumption write the report from the same numbers.
  return study::read_part(parts, key, config.params);
}

// The first pass of the learned design: every BRDF's profile (each file loaded once, one at a
// time per task), kept in OUT/profiles/SPACE-GRID/ so that --resume reuses them. A duplicate label
// stops the run here, before any work, as leave-one-out would not know which BRDF to leave out.
std::vector<study::LabeledProfile> profile_pass(const std::vector<std::string>& specs,
                                                const std::filesystem::path& out,
                                                const study::StudyConfig& config, bool resume) {
  // One directory per error space and grid: a profile depends on them, and --resume with other
  // settings (refused) must not leave profiles that a later --resume would take for these.
  const acquire::IsoGrid& g = config.profile_grid;
  const std::filesystem::path dir =
      study::profiles_dir(out) / fmt::format("{}-{}x{}x{}", name_of(config.space), g.a, g.b, g.phi);
  create_output_directory(dir);
  std::vector<study::LabeledProfile> profiles(specs.size());
  std::vector<char> reused(specs.size(), 0);
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = cpu_seconds();
  parallel_for(specs.size(), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::filesystem::path file = dir / (study::part_key(specs[k]) + ".profile");
      std::error_code ec;
      if (resume && std::filesystem::exists(file, ec)) {
        profiles[k] = study::profile_from_text(read_text_file(file), file.string());
        reused[k] = 1;
        continue;
      }
      const BrdfPtr brdf = load_brdf(specs[k]);
      profiles[k] = study::study_profile(*brdf, study::study_label(specs[k], *brdf), config);
      write_file_atomically(file, study::profile_text(profiles[k]));
    }
  });
  std::set<std::string> labels;
  for (std::size_t k = 0; k < specs.size(); ++k)
    if (!labels.insert(profiles[k].label).second)
      throw UsageError(fmt::format(
          "'{}': a second BRDF named '{}' (the tables would mix them); study it separately",
          specs[k], profiles[k].label));
  const auto kept = std::count(reused.begin(), reused.end(), 1);
  fmt::print(stderr,
             "halfback study: profiles of {} BRDF{} for the learned design in {:.1f} s ({:.1f} CPU "
             "s){}\n",
             specs.size(), specs.size() == 1 ? "" : "s",
             std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
             cpu_seconds() - cpu0, kept ? fmt::format("; {} kept from the earlier run", kept) : "");
  return profiles;
}

// Nielsen's database (--nielsen-database): its members loaded, their values at the candidate
// configurations and at the study's test pairs (the same for every BRDF) computed once.
void set_nielsen_database(study::StudyConfig& config, const std::vector<std::string>& specs,
                          double eta) {
  if (std::find(config.params.begin(), config.params.end(), space_of<HalfDiff>) ==
      config.params.end())
    throw UsageError("--nielsen-database: its rows are halfdiff's; add halfdiff to --params");
  if (config.budgets.empty())
    throw UsageError("--nielsen-database: needs the gonio-reflectometer (not --no-gonio)");
  const auto t0 = std::chrono::steady_clock::now();
  acquire::NielsenOptions options;
  options.max_theta_deg = config.max_theta_deg;
  options.seed = config.seed;
  options.eta = eta;  // (checked by check_nielsen_options)
  std::vector<BrdfPtr> members;
  for (const std::string& spec : expand_specs(specs)) {
    members.push_back(load_brdf(spec));
    if (!members.back()->isotropic())
      throw UsageError(fmt::format(
          "--nielsen-database '{}': {} is not isotropic (the basis is of isotropic BRDFs)", spec,
          members.back()->name()));
  }
  if (members.size() < 2)
    throw UsageError("--nielsen-database: at least two BRDFs are needed (repeat the option)");
  // What the database refuses now is in its members' values (one that is not finite): bad data.
  try {
    config.nielsen = std::make_shared<acquire::NielsenDatabase>(
        std::move(members), options,
        acquire::test_pair_directions(config.test_pairs, config.seed, config.max_theta_deg));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("--nielsen-database: ") + e.what());
  }
  const std::size_t candidates = config.nielsen->configurations().size();
  if (!config.nielsen_counts.empty() && config.nielsen_counts.back() > candidates)
    throw UsageError(
        fmt::format("--nielsen-budgets: {} measurements asked, Nielsen's database has {} candidate "
                    "configurations within --max-theta",
                    config.nielsen_counts.back(), candidates));
  config.nielsen_from = acquire::nielsen_fingerprint(*config.nielsen);
  fmt::print(stderr,
             "halfback study: Nielsen's database of {} BRDFs ({} configurations) in {:.1f} s\n",
             config.nielsen->members(), config.nielsen->configurations().size(),
             std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

// --nielsen-eta is checked whether or not a database is given (it was ignored without one).
void check_nielsen_options(const StudyOptions& o) {
  if (!(o.nielsen_eta >= 0))
    throw UsageError(fmt::format(
        "--nielsen-eta {}: the Tikhonov weight of Nielsen's reconstruction must be >= 0",
        o.nielsen_eta));
}

int run_study(StudyOptions& o) {
  if (o.specs.empty()) throw UsageError("no BRDF given (files, directories or model specs)");
  check_nielsen_options(o);
  study::StudyConfig config = make_config(o);
  const std::vector<std::string> specs = expand_specs(o.specs);
  create_output_directory(o.out);
  check_writable((std::filesystem::path(o.out) / "report.md").string());
  if (!o.nielsen_database.empty()) set_nielsen_database(config, o.nielsen_database, o.nielsen_eta);
  std::vector<study::LabeledProfile> profiles;
  if (study::wants_learned(config)) {
    profiles = profile_pass(specs, o.out, config, o.resume);
    config.learned_from = study::learned_fingerprint(profiles);
  }
  const std::filesystem::path parts = prepare_parts(o, config);

  Progress progress(specs.size());
  config.progress = progress.stage_callback();
  std::vector<study::BrdfResult> results;
  std::set<std::string> labels;
  for (std::size_t k = 0; k < specs.size(); ++k) {
    if (!profiles.empty()) study::set_learned(config, profiles, profiles[k].label);
    results.push_back(study_one(specs[k], k, parts, config, o.resume, progress));
    if (!labels.insert(results.back().label).second)
      throw UsageError(fmt::format(
          "'{}': a second BRDF named '{}' (the tables would mix them); study it separately",
          specs[k], results.back().label));
  }
  const study::StudyOutput out = study::write_study(o.out, results, config, progress.elapsed());
  print_written(out, o.out, o);
  return kExitOk;
}

// --merge: the report of the parts of several runs, as one run over all their BRDFs would write.
int run_merge(const StudyOptions& o) {
  if (!o.specs.empty())
    throw UsageError("--merge takes result directories, not BRDFs: run them, then merge");
  std::vector<std::filesystem::path> dirs(o.merge.begin(), o.merge.end());
  const study::MergedParts merged = study::read_parts(dirs);
  create_output_directory(o.out);
  check_writable((std::filesystem::path(o.out) / "report.md").string());
  double seconds = 0;
  for (const study::BrdfResult& b : merged.results) seconds += b.seconds;
  print_written(study::write_study(o.out, merged.results, merged.config, seconds), o.out, o);
  return kExitOk;
}

// The help of option `index` of `m`: what it sets, then its values as the settings resolve them
// (study::option_default), e.g. "... (default 1000,10000; --quick 1000)".
std::string metric_option_help(const study::Metric& m, std::size_t index) {
  const study::OptionDefault d = study::option_default(m, index);
  std::string values = "default " + d.value;
  if (d.quick != d.value) values += "; --quick " + d.quick;
  if (d.when_run) values += fmt::format("; the metric runs with --metrics {}", m.name());
  return fmt::format("{} ({})", m.options().at(index).help, values);
}

// --metrics, and per metric of the list (study::study_metrics()) that can be turned off, --no-NAME,
// and its options (--fit-model for the option fit_model).
void add_metric_options(CLI::App& app, StudyOptions& o) {
  std::string optional;
  for (const study::Metric* m : study::study_metrics())
    if (m->switchable())
      optional += fmt::format("{}{}{}", optional.empty() ? "" : ", ", m->name(),
                              m->on_by_default() ? "" : " (not by default)");
  app.add_option("--metrics", o.metrics,
                 "Metrics to run, comma-separated: " + optional +
                     " (default: those run by default; azimuthal and the other metrics without a "
                     "switch always run)");
  for (const study::Metric* m : study::study_metrics()) {
    if (m->switchable()) {
      const std::string name(m->name());
      app.add_flag_callback(
          "--no-" + name, [&o, name] { o.settings.off.push_back(name); },
          fmt::format("Not the {} metric{}", name,
                      m->description().empty() ? "" : fmt::format(" ({})", m->description())));
    }
    const std::vector<study::MetricOption> options = m->options();
    for (std::size_t i = 0; i < options.size(); ++i) {
      const study::MetricOption& option = options[i];
      std::string flag = "--" + option.key;
      std::replace(flag.begin(), flag.end(), '_', '-');
      using Kind = study::MetricOption::Kind;
      app.add_option(flag, o.metric_options[option.key], metric_option_help(*m, i))
          ->type_name(option.kind == Kind::count    ? "N"
                      : option.kind == Kind::counts ? "N,..."
                                                    : "TEXT");
    }
  }
}

// The parameterizations a study compares when --params is not given (default_studied()).
std::string default_studied_names() {
  std::string s;
  for (Space p : study::default_studied()) s += (s.empty() ? "" : ",") + std::string(name_of(p));
  return s;
}

}  // namespace

Command register_study(CLI::App& parent) {
  auto o = std::make_shared<StudyOptions>();
  const study::StudyConfig plain, quick = study::quick_config();
  CLI::App* app = parent.add_subcommand(
      "study",
      "Compare the parameterizations on BRDFs: azimuthal dependence, separability, a virtual "
      "gonio-reflectometer and the image-space error of its reconstructions (CSV, plots, "
      "Markdown and HTML reports)");
  app->add_option("specs", o->specs,
                  "BRDFs: files (MERL, RGL, ALTA, neural BRDF .h5), directories of files, or model "
                  "specs");
  app->add_option("-o,--output,--out", o->out,
                  "Output directory (created if missing; --out is an alias)")
      ->type_name("DIR")
      ->capture_default_str();
  app->add_option(
         "--params", o->params,
         "Parameterizations compared, comma-separated, in the order of the tables: " +
             parameterization_names(", ") +
             " (default: those studied without being asked, the spherical baseline last: " +
             default_studied_names() + ")")
      ->type_name("PARAM,...");
  app->add_option("--space,--error-space", o->settings.space,
                  "Error space: linear, log (ln(1 + Y)), cbrt (Y^(1/3)), nielsen (Nielsen et al. "
                  "2015's log-relative mapping) or low (Low et al. 2012's cosine-weighted log)")
      ->capture_default_str();
  app->add_option("--spacings,--designs", o->designs,
                  "Spacings of the gonio-reflectometer's cells, comma-separated: own (uniform in "
                  "the coordinates), angle (sine-like magnitudes through asin), merl (angle, and "
                  "sqrt of the half-vector angle), learned (warps fitted on the other BRDFs' "
                  "profiles, computed first and kept in OUT/profiles/); each is measured in the "
                  "regular and the stratified design (--designs is an alias)")
      ->capture_default_str();
  app->add_flag(
      "--quick", o->settings.quick,
      fmt::format("A small study: {} x {} x {} grids of the isotropic form ({} of the full "
                  "form) and each option's --quick value below",
                  quick.grid.a, quick.grid.b, quick.grid.phi, fmt::join(quick.full_grid, " x ")));
  app->add_option("--budgets", o->budgets,
                  "Gonio-reflectometer budgets, ascending, comma-separated " +
                      defaults(plain.budgets, quick.budgets))
      ->type_name("N,...");
  app->add_option("--budgets-4d", o->budgets_4d,
                  "Budgets of the 4D gonio-reflectometer of anisotropic BRDFs, comma-separated " +
                      defaults(plain.budgets_4d, quick.budgets_4d))
      ->type_name("N,...");
  app->add_option(
         "--test-pairs", o->settings.test_pairs,
         "Pairs the reconstructions are checked at " + defaults(plain.test_pairs, quick.test_pairs))
      ->check(CLI::Range(std::size_t(100), study::kMaxTestPairs));
  app->add_option("--env", o->environments,
                  "Environments of the image-space error, comma-separated: built-in names "
                  "(default, sky, studio, sunset) or .hdr/.exr files (default: the built-ins)");
  app->add_option("--image-budget", o->settings.image_budget,
                  fmt::format("The budget whose reconstructions are rendered: one of --budgets "
                              "(default {}, else the middle budget)",
                              plain.image_budget));
  app->add_option(
         "--image-size", o->settings.image_size,
         "Width and height of the renderings " + defaults(plain.image_size, quick.image_size))
      ->check(CLI::Range(8, 4096));
  app->add_option(
         "--image-spp", o->settings.image_spp,
         "Samples per pixel of the renderings " + defaults(plain.image_spp, quick.image_spp))
      ->check(CLI::Range(1, 1 << 16));
  app->add_option("--max-theta", o->settings.max_theta,
                  "The gonio-reflectometer's reach: no measurement where a direction is farther "
                  "from the normal (degrees)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 90.0));
  app->add_option("--seed", o->settings.seed,
                  "Seed of the test pairs, stratified designs and renderings")
      ->capture_default_str();
  add_metric_options(*app, *o);
  app->add_option("--nielsen-database", o->nielsen_database,
                  "Nielsen et al. 2015's minimal sampling: the database of its principal "
                  "components, an isotropic BRDF file, folder or spec (repeat the option for "
                  "more; e.g. the folder of the MERL networks); each BRDF of the study that is "
                  "one of them is left out of its own basis. Rows of halfdiff's gonio table, "
                  "design nielsen (docs/acquisition.md)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app->add_option("--nielsen-budgets,--nielsen-counts", o->nielsen_counts,
                  "Measurement budgets of Nielsen's design, ascending, comma-separated; "
                  "--nielsen-counts is an alias " +
                      defaults(plain.nielsen_counts, quick.nielsen_counts))
      ->type_name("N,...");
  app->add_option("--nielsen-eta", o->nielsen_eta,
                  "Tikhonov weight of Nielsen's reconstruction (their release's example: 40)")
      ->capture_default_str();
  app->add_flag("-q,--quiet", o->quiet, "Nothing on stdout (the report is in the output folder)");
  app->add_flag("--full-report", o->full_report,
                "The whole report on stdout (by default: its summary and where the files are)");
  app->add_flag("--resume", o->resume,
                "Continue an interrupted run in --output: the BRDFs whose results it holds "
                "(OUT/parts/) are not studied again (same options required)");
  app->add_option("--merge", o->merge,
                  "Write the report of the results of several runs (their --output directories, "
                  "with the same options) into --output, instead of studying BRDFs")
      ->expected(1, -1);
  app->footer(
      "Metrics (docs/study.md), under the measure cos(theta_i) cos(theta_o) dwi dwo:\n"
      "  azimuthal.csv     brdf,parameterization,error,dims: the error of dropping the relative\n"
      "                    azimuth (dims 3), or the second azimuth of the full form (dims 4)\n"
      "  separability.csv  brdf,parameterization,rank,error,dims: best rank-r approximations of\n"
      "                    the 2D projection (dims 2), the 3D table unfolded along the azimuth\n"
      "                    (3), the 4D table as (a, phi_a) x (b, phi_b) (4)\n"
      "  gonio.csv         brdf,parameterization,design,samples,error,dims,budget,spacing: the\n"
      "                    virtual gonio-reflectometer (regular and stratified layouts; the\n"
      "                    spacing of --spacings)\n"
      "  budget.csv        the samples each needs to reach errors of 0.05, 0.02, 0.01\n"
      "  image.csv         brdf,parameterization,design,samples,environment,relative_rmse,\n"
      "                    mean_delta_e2000,p95_delta_e2000,mae,rmse,ssim\n"
      "  parts/            each BRDF's results as soon as it is finished (--resume, --merge)\n"
      "  profiles/         each BRDF's profile for the learned design (--resume reuses them)\n"
      "Examples:\n"
      "  halfback study --output study ggx:alpha=0.2 ../shared/data/rgl\n"
      "  halfback study --output study --resume ggx:alpha=0.2 ../shared/data/rgl   (after "
      "Ctrl-C)\n"
      "  halfback study --merge run1 run2 --output all");
  return {app, [o] { return o->merge.empty() ? run_study(*o) : run_merge(*o); }};
}

}  // namespace halfback::cli
