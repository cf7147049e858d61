// Helpers for the file-format tests (not part of the library).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "halfback/core/param.hpp"
#include "halfback/util/format_error.hpp"

#ifndef HALFBACK_SOURCE_DIR
#define HALFBACK_SOURCE_DIR "."  // the tests' CMake targets define it; CTest sets the variable
#endif

namespace halfback::test {

// ../shared/data/SUB (from HALFBACK_SHARED_DIR, set by CTest), or "" when absent.
inline std::filesystem::path shared_data(const std::string& sub) {
  const char* dir = std::getenv("HALFBACK_SHARED_DIR");
  std::filesystem::path p =
      std::filesystem::path(dir && *dir ? dir : HALFBACK_SOURCE_DIR "/../shared") / "data" / sub;
  std::error_code ec;
  return std::filesystem::exists(p, ec) ? p : std::filesystem::path{};
}

inline bool in_ci() {
  const char* ci = std::getenv("CI");
  return ci && std::string(ci) == "true";
}

// Skips the test when the shared data is missing, or fails under CI=true.
#define HALFBACK_REQUIRE_SHARED(var, sub)                                                  \
  const std::filesystem::path var = ::halfback::test::shared_data(sub);                    \
  if (var.empty()) {                                                                       \
    if (::halfback::test::in_ci()) FAIL() << "../shared/data/" sub " is missing under CI"; \
    GTEST_SKIP() << "../shared/data/" sub " not found (set HALFBACK_SHARED_DIR)";          \
  }

// A fresh directory under the system temporary directory, removed at destruction.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("halfback-test-" + std::to_string(rd()) + "-" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

inline void write_bytes(const std::filesystem::path& path, const void* data, std::size_t n) {
  std::ofstream out(path, std::ios::binary);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(n));
  ASSERT_TRUE(out.good()) << path;
}

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline Vec3<double> direction(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// Uniform on the upper hemisphere.
inline Vec3<double> uniform_hemisphere(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  const double z = u(rng), phi = 2 * std::numbers::pi * u(rng);
  const double s = std::sqrt(std::max(0.0, 1 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

// Expects `statement` to throw FormatError whose message contains every string of `parts`.
#define EXPECT_FORMAT_ERROR(statement, ...)                                  \
  do {                                                                       \
    try {                                                                    \
      statement;                                                             \
      ADD_FAILURE() << "no FormatError from " #statement;                    \
    } catch (const ::halfback::FormatError& e) {                             \
      for (const std::string part : {__VA_ARGS__})                           \
        EXPECT_NE(std::string(e.what()).find(part), std::string::npos)       \
            << "message: " << e.what() << "\nexpected to contain: " << part; \
    }                                                                        \
  } while (0)

}  // namespace halfback::test
