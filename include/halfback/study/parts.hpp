// The study as independent per-BRDF parts (docs/study.md, "Running on whole databases"
// and "Scaling out"): the settings of a run as typed options (the CLI's and Python's), one BRDF's
// result as tables of CSV text that round-trip exactly, the part files a run writes one BRDF at a
// time (so that --resume continues an interrupted run) and their merge into one report.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/acquire/design.hpp"
#include "halfback/study/report.hpp"
#include "halfback/study/study.hpp"

namespace halfback::study {

// The options of `halfback study` that decide the results (the Python settings dict has the same
// keys, '-' spelled '_'). Zero or empty: the default (or --quick's).
struct StudySettings {
  // --params: names of parameterizations (space_from_name); empty: default_studied().
  std::vector<std::string> params;
  std::string space = "log";  // --error-space: parse_error_space()
  // --spacings: parse_spacing() names. `learned` needs the profiles of the study's BRDFs (below).
  std::vector<std::string> designs{"own", "angle", "merl", "learned"};
  bool quick = false;
  // --metrics: the metrics to run (metric.hpp's names); empty: those on by default. Metrics that
  // cannot be turned off (azimuthal, separability) run whether listed or not.
  std::vector<std::string> metrics;
  // --no-NAME: metrics not to run (of those --metrics or the defaults name).
  std::vector<std::string> off;
  // The metrics' options given (MetricOption::key -> text, e.g. fit_budgets -> "1000,3000");
  // those not given take their default (or --quick's).
  std::map<std::string, std::string> options;
  // --nielsen-budgets (empty: the default); the database itself is StudyConfig::nielsen.
  std::vector<std::size_t> nielsen_counts;
  std::vector<std::size_t> budgets, budgets_4d;
  std::size_t test_pairs = 0, image_budget = 0;
  int image_size = 0, image_spp = 0;
  double max_theta = 85;
  std::uint64_t seed = 1;
  std::vector<std::string> environments;  // built-in names or .hdr/.exr files; empty: built-ins
};

// The configuration of the settings (environments loaded). Throws std::invalid_argument naming
// the option (--error-space, --spacings, --budgets, ...) and what it accepts.
StudyConfig make_config(const StudySettings& settings);

// The settings --quick gives before the options given apply (smaller grids, budgets, test pairs and
// images; each metric's quick values): what `study --help` states beside each default.
StudyConfig quick_config();

// Whether `config` asks for the learned design (then each BRDF needs the others' profiles).
bool wants_learned(const StudyConfig& config);

// The learned design (design.hpp) makes a BRDF's study depend on the other BRDFs, through their
// profiles only: the warps of held-out BRDF k are learn_warps(profiles, k), a deterministic
// function of the profiles in their order. A run computes every profile first (each BRDF loaded
// once), keeps them as text (exact round trip) and gives each BRDF's study the warps and the
// fingerprint of the whole list, which describe_config() records.
struct LabeledProfile {
  std::string label;  // study_label() of the BRDF
  acquire::DesignProfile profile;
};
LabeledProfile study_profile(const Brdf& brdf, const std::string& label, const StudyConfig& config);
std::string profile_text(const LabeledProfile& profile);
// Throws std::runtime_error naming `source` on text that profile_text() did not write.
LabeledProfile profile_from_text(std::string_view text, const std::string& source);
// A hash of the profiles' texts in order (their count, too).
std::string learned_fingerprint(std::span<const LabeledProfile> profiles);
// Sets config.learned and config.learned_from for the BRDF labeled `label`, which must be one of
// `profiles` (std::invalid_argument otherwise: leave-one-out needs to know which to leave out).
// Fewer than two profiles: no learned warps (the learned design then has no rows), as one BRDF
// has no other to learn from.
void set_learned(StudyConfig& config, std::span<const LabeledProfile> profiles,
                 const std::string& label);

// Every setting of `config` that the results depend on, as "key = value" lines in a fixed order,
// the parameterizations first: two runs whose descriptions are equal give the same tables for
// the same BRDF.
std::string describe_config(const StudyConfig& config);

// The configuration a description was made from, for writing a report: environments by label
// only (no map; they are not rendered again). Throws std::runtime_error naming `source` and the
// line for text that describe_config() did not write, or for a parameterization that is not
// known in this process (one registered at run time by the program that wrote it).
StudyConfig config_from_description(std::string_view text, const std::string& source);

// The label of a BRDF in the tables: a file by its BRDF's name (merl:..., rgl:..., nbrdf:...), a
// model by its spec, which holds its parameters (two GGX of different roughness are both "ggx").
std::string study_label(std::string_view spec, const Brdf& brdf);

// One BRDF's result as tables of CSV text, keyed "brdf" (its label, whether it is isotropic and
// its seconds) and by the name of each stored table (metric_tables.hpp: "azimuthal",
// "separability", "gonio", "image"): the rows of the study's CSV files (budget.csv is derived from
// gonio), the numbers written in shortest round-trip form so that reading them back gives the
// same doubles. The example renderings are not tables (see BrdfPart).
using StudyTables = std::map<std::string, std::string>;
StudyTables to_tables(const BrdfResult& result);
// The result of tables that to_tables() wrote for a study of `params` (the run's settings say
// which). Throws std::runtime_error naming `source`, the table and the line on a malformed table,
// or a row of a parameterization that is not one of `params`.
BrdfResult from_tables(const StudyTables& tables, std::span<const Space> params,
                       const std::string& source);

// A run's directory of parts: DIR/parts/settings.txt (describe_config) and, per BRDF, KEY.part (its
// tables and its position `order` in the run) and KEY.exr (its example renderings side by side),
// the .exr written first and each file atomically, so that a .part file means a finished BRDF.
std::filesystem::path parts_dir(const std::filesystem::path& out);
// The file stem of a BRDF spec: readable, and distinct for distinct specs (a hash of the spec).
std::string part_key(std::string_view spec);
// A run's profiles: DIR/profiles/SPACE-GRID/KEY.profile (the CLI's), written atomically so that
// --resume reuses them.
std::filesystem::path profiles_dir(const std::filesystem::path& out);
void write_part(const std::filesystem::path& parts, const std::string& key,
                const BrdfResult& result, std::size_t order);
// The part of `key` (with its example renderings when their file is there), of a run of
// `params`. Throws std::runtime_error naming the file when it is missing or malformed.
BrdfResult read_part(const std::filesystem::path& parts, const std::string& key,
                     std::span<const Space> params, std::size_t* order = nullptr);

// Results gathered from several runs (directories of parts, or Python's tables) for one report.
struct MergedParts {
  StudyConfig config;
  std::string settings;  // describe_config() of the first run added; empty before
  std::vector<BrdfResult> results;
  std::map<std::string, std::string> source_of;  // label -> the run it came from
};

// Appends the results of one run (`settings` its describe_config(), `source` its name for errors)
// to `into`. Throws std::runtime_error when the settings differ from those of the runs added
// before, or when a BRDF is already there.
void merge_into(MergedParts& into, const std::string& settings, const std::string& source,
                std::vector<BrdfResult> results);

// The results of the parts of `dirs` (each a study output directory or its parts directory), in
// the order of the directories and, within one, in the order of its run. Throws
// std::runtime_error naming the directory when it has no parts, and as merge_into().
MergedParts read_parts(const std::vector<std::filesystem::path>& dirs);

}  // namespace halfback::study
