// The study as independent per-BRDF parts (issue 14; docs/study.md, "Running on whole databases"
// and "Scaling out"): the settings of a run as typed options (the CLI's and Python's), one BRDF's
// result as tables of CSV text that round-trip exactly, the part files a run writes one BRDF at a
// time (so that --resume continues an interrupted run) and their merge into one report.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/study/report.hpp"
#include "halfback/study/study.hpp"

namespace halfback::study {

// The options of `halfback study` that decide the results (the Python settings dict has the same
// keys, '-' spelled '_'). Zero or empty: the default (or --quick's).
struct StudySettings {
  std::string space = "log";
  bool quick = false, no_gonio = false, no_images = false;
  std::vector<std::size_t> budgets, budgets_4d;
  std::size_t test_pairs = 0, image_budget = 0;
  int image_size = 0, image_spp = 0;
  double max_theta = 85;
  std::uint64_t seed = 1;
  std::vector<std::string> environments;  // built-in names or .hdr/.exr files; empty: built-ins
};

// The configuration of the settings (environments loaded). Throws std::invalid_argument naming
// the option (--space, --budgets, ...) and what it accepts.
StudyConfig make_config(const StudySettings& settings);

// Every setting of `config` that the results depend on, as "key = value" lines in a fixed order:
// two runs whose descriptions are equal give the same tables for the same BRDF.
std::string describe_config(const StudyConfig& config);

// The configuration a description was made from, for writing a report: environments by label
// only (no map; they are not rendered again). Throws std::runtime_error naming `source` and the
// line for text that describe_config() did not write.
StudyConfig config_from_description(std::string_view text, const std::string& source);

// The label of a BRDF in the tables: a file by its BRDF's name (merl:..., rgl:..., nbrdf:...), a
// model by its spec, which holds its parameters (two GGX of different roughness are both "ggx").
std::string study_label(std::string_view spec, const Brdf& brdf);

// One BRDF's result as tables of CSV text, keyed "brdf", "azimuthal", "separability", "gonio" and
// "image": the rows of the study's CSV files (budget.csv is derived from gonio), the numbers
// written in shortest round-trip form so that reading them back gives the same doubles. The
// example renderings are not tables (see BrdfPart).
using StudyTables = std::map<std::string, std::string>;
StudyTables to_tables(const BrdfResult& result);
// Throws std::runtime_error naming `source`, the table and the line on a malformed table.
BrdfResult from_tables(const StudyTables& tables, const std::string& source);

// A run's directory of parts: DIR/parts/settings.txt (describe_config) and, per BRDF, KEY.part (its
// tables and its position `order` in the run) and KEY.exr (its example renderings side by side),
// the .exr written first and each file atomically, so that a .part file means a finished BRDF.
std::filesystem::path parts_dir(const std::filesystem::path& out);
// The file stem of a BRDF spec: readable, and distinct for distinct specs (a hash of the spec).
std::string part_key(std::string_view spec);
void write_part(const std::filesystem::path& parts, const std::string& key,
                const BrdfResult& result, std::size_t order);
// The part of `key` (with its example renderings when their file is there). Throws
// std::runtime_error naming the file when it is missing or malformed.
BrdfResult read_part(const std::filesystem::path& parts, const std::string& key,
                     std::size_t* order = nullptr);

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
