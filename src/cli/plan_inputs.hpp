// What `halfback plan` and `halfback reconstruct` read besides a plan and its measurements: the
// BRDFs a design learns from (docs/acquisition.md): Nielsen's database, and the profiles of the
// learned spacing (a study's profile files, or BRDFs whose profiles are taken here as a study
// takes them).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "halfback/acquire/design.hpp"
#include "halfback/acquire/nielsen.hpp"
#include "halfback/core/space.hpp"

namespace halfback::cli {

// The database of BRDF specs (files, folders of BRDF files, models) given as `option`, built with
// `options` as the study builds it (without the study's test pairs: the values are the same).
// UsageError for fewer than two BRDFs, an anisotropic one or a spec that names nothing; a file
// that cannot be read is a data error (status 1).
std::shared_ptr<const acquire::NielsenDatabase> nielsen_database(
    const std::vector<std::string>& specs, const acquire::NielsenOptions& options,
    const char* option);

// The learned spacing's warps of `space`: learn_warps() over profiles (the study's rule), each
// `profiles` entry a .profile file of a study or a folder of them (OUT/profiles/SPACE-GRID/), or
// with `brdfs` the profiles of those BRDFs taken as a study takes them (its default grid and error
// space). `leave_out`, when not empty, is the label of a profile left out, as the study leaves out
// the BRDF it studies. UsageError when there are no profiles besides the one left out, the label
// is not among them, or they hold no profile of `space`.
acquire::LearnedWarps learned_warps(const std::vector<std::string>& profiles,
                                    const std::vector<std::string>& brdfs,
                                    const std::string& leave_out, Space space);

}  // namespace halfback::cli
