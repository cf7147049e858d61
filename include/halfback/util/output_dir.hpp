// A folder that a command writes several outputs into (study results, the paper's figures).
#pragma once

#include <filesystem>

namespace halfback {

// Creates `dir` and its parents if needed. Throws std::runtime_error naming the folder and the
// reason when it cannot be created, or when a file (not a folder) has that name.
void create_output_directory(const std::filesystem::path& dir);

}  // namespace halfback
