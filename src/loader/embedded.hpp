// Files embedded in the library at build time (cmake/embed_files.cmake): the CC0 measured
// materials of data/ that the default figures show, so that they need no file.
#pragma once

#include <span>
#include <string_view>

namespace halfback::detail {

struct EmbeddedFile {
  std::string_view name;
  std::span<const unsigned char> bytes;
};

std::span<const EmbeddedFile> embedded_files();

}  // namespace halfback::detail
