// Little-endian decoding/encoding and whole-file reading, shared by the binary readers and writers
// in src/io (private header).
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <system_error>

#include "halfback/util/format_error.hpp"

namespace halfback::io_detail {

template <class T>
T byteswap_value(T v) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  std::memcpy(&v, b, sizeof(T));
  return v;
}

// Reads a little-endian T at p (no alignment needed).
template <class T>
T load_le(const std::byte* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) v = byteswap_value(v);
  return v;
}

template <class T>
void store_le(std::byte* p, T v) {
  if constexpr (std::endian::native == std::endian::big) v = byteswap_value(v);
  std::memcpy(p, &v, sizeof(T));
}

// Reads a whole file; `max_bytes` guards against reading something huge by mistake (the file's
// size is checked before anything is allocated). Throws FormatError.
inline std::string read_file_bytes(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw FormatError(name, "file", ec ? ec.message() : "not a regular file");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw FormatError(name, "file", "cannot get its size: " + ec.message());
  if (size > max_bytes)
    throw FormatError(name, "file size",
                      std::to_string(size) + " bytes is more than this format allows (" +
                          std::to_string(max_bytes) + " bytes)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FormatError(name, "file", "cannot open for reading");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  if (size > 0 && !in.read(bytes.data(), static_cast<std::streamsize>(size)))
    throw FormatError(name, "file",
                      "read error after " + std::to_string(in.gcount()) + " of " +
                          std::to_string(size) + " bytes");
  return bytes;
}

inline std::span<const std::byte> as_bytes(const std::string& s) {
  return {reinterpret_cast<const std::byte*>(s.data()), s.size()};
}

}  // namespace halfback::io_detail
