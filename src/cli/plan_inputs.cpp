#include "plan_inputs.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "command.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/study/parts.hpp"
#include "halfback/study/study.hpp"
#include "halfback/util/csv.hpp"

namespace halfback::cli {

namespace {

// Each spec's BRDFs: a folder (not itself a BRDF file) by its BRDF files, sorted.
std::vector<std::string> database_specs(const std::vector<std::string>& specs, const char* option) {
  std::vector<std::string> out;
  for (const std::string& spec : specs) {
    std::error_code ec;
    if (std::filesystem::is_directory(spec, ec) &&
        detect_brdf_format(spec) == BrdfFileFormat::unknown) {
      const auto files = brdf_files_in(spec);
      if (files.empty())
        throw UsageError(fmt::format(
            "{} '{}': no MERL, RGL, ALTA or neural BRDF file in this directory", option, spec));
      for (const auto& f : files) out.push_back(f.string());
    } else {
      out.push_back(spec);
    }
  }
  return out;
}

// The .profile files of a path: the file, or a folder's, sorted.
std::vector<std::filesystem::path> profile_files_at(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_directory(path, ec)) return {path};
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(path))
    if (e.path().extension() == ".profile") files.push_back(e.path());
  if (files.empty())
    throw UsageError(
        fmt::format("--profiles '{}': no .profile file in this folder (a study's are in "
                    "OUT/profiles/SPACE-GRID/)",
                    path));
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

std::shared_ptr<const acquire::NielsenDatabase> nielsen_database(
    const std::vector<std::string>& specs, const acquire::NielsenOptions& options,
    const char* option) {
  std::vector<BrdfPtr> members;
  for (const std::string& spec : database_specs(specs, option)) {
    members.push_back(brdf_argument(spec, option));
    if (!members.back()->isotropic())
      throw UsageError(fmt::format("{} '{}': {} is not isotropic (the basis is of isotropic BRDFs)",
                                   option, spec, members.back()->name()));
  }
  if (members.size() < 2)
    throw UsageError(fmt::format("{}: at least two BRDFs are needed (repeat the option)", option));
  try {
    options.validate();
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  try {  // what the database refuses now is in its members' values: bad data
    return std::make_shared<const acquire::NielsenDatabase>(std::move(members), options);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(fmt::format("{}: {}", option, e.what()));
  }
}

acquire::LearnedWarps learned_warps(const std::vector<std::string>& profiles,
                                    const std::vector<std::string>& brdfs,
                                    const std::string& leave_out, Space space) {
  std::vector<study::LabeledProfile> labeled;
  for (const std::string& path : profiles)
    for (const std::filesystem::path& file : profile_files_at(path))
      labeled.push_back(study::profile_from_text(read_text_file(file), file.string()));
  study::StudyConfig config;  // the study's grid and error space
  config.params = {space};
  for (const std::string& spec : database_specs(brdfs, "--database")) {
    const BrdfPtr brdf = brdf_argument(spec, "--database");
    labeled.push_back(study::study_profile(*brdf, study::study_label(spec, *brdf), config));
  }
  std::size_t held_out = labeled.size();  // none
  if (!leave_out.empty()) {
    const auto it = std::find_if(labeled.begin(), labeled.end(),
                                 [&](const auto& p) { return p.label == leave_out; });
    if (it == labeled.end())
      throw UsageError(
          fmt::format("--leave-out '{}': no profile of that label among those given", leave_out));
    held_out = std::size_t(it - labeled.begin());
  }
  std::vector<acquire::DesignProfile> plain;
  for (const study::LabeledProfile& p : labeled) plain.push_back(p.profile);
  std::vector<acquire::LearnedWarps> learned;
  try {
    learned = acquire::learn_warps(plain, held_out);
  } catch (const std::invalid_argument& e) {  // profiles of different grids
    throw UsageError(fmt::format("--profiles: {}", e.what()));
  }
  if (learned.empty())
    throw UsageError(
        "the learned spacing needs the profiles of other BRDFs: --profiles (a study's) or "
        "--database (BRDFs to learn from), besides any left out");
  for (const acquire::LearnedWarps& w : learned)
    if (w.space == space) return w;
  throw UsageError(
      fmt::format("--profiles: no profile of {} (the study did not study it)", name_of(space)));
}

}  // namespace halfback::cli
