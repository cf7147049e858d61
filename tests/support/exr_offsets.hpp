// The scan-line offset table of a single-part scan-line OpenEXR file, read from its bytes (for the
// tests of halfback's EXR writers: a writer that takes the stream's bytes before the OpenEXR
// writer is destroyed leaves the table zero, which readers paper over by scanning the file).
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace halfback::test {

inline std::vector<std::uint64_t> exr_scanline_offsets(const std::string& bytes) {
  auto need = [&](std::size_t end) {
    if (end > bytes.size()) throw std::runtime_error("EXR: truncated header");
  };
  need(8);
  if (std::memcmp(bytes.data(), "\x76\x2f\x31\x01", 4) != 0)
    throw std::runtime_error("EXR: bad magic number");
  std::size_t at = 8;
  auto c_string = [&] {
    const std::size_t end = bytes.find('\0', at);
    if (end == std::string::npos) throw std::runtime_error("EXR: unterminated name");
    std::string s = bytes.substr(at, end - at);
    at = end + 1;
    return s;
  };
  while (!c_string().empty()) {  // attribute: name, type, size, value; an empty name ends them
    c_string();
    need(at + 4);
    std::uint32_t size = 0;
    std::memcpy(&size, bytes.data() + at, 4);  // little-endian, as the machines that run tests
    at += 4 + size;
  }
  need(at + 8);
  std::uint64_t first = 0;
  std::memcpy(&first, bytes.data() + at, 8);
  // The first chunk starts right after the table: its offset gives the table's length.
  if (first <= at || (first - at) % 8 != 0 || first > bytes.size()) return {first};
  std::vector<std::uint64_t> offsets((first - at) / 8);
  std::memcpy(offsets.data(), bytes.data() + at, 8 * offsets.size());
  return offsets;
}

}  // namespace halfback::test
