#include "halfback/util/output_dir.hpp"

#include <fmt/format.h>

#include <stdexcept>
#include <system_error>

namespace halfback {

void create_output_directory(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw std::runtime_error(fmt::format("cannot create the output directory '{}': {}",
                                         dir.string(),
                                         ec ? ec.message() : "a file of that name exists"));
}

}  // namespace halfback
