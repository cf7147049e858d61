// SHA-256 (FIPS 180-4), written from the standard: identifies files (e.g. the published MERL
// materials) without a crypto library.
#pragma once

#include <cstddef>
#include <span>
#include <string>

namespace halfback {

// SHA-256 of bytes, lowercase hex.
std::string sha256_hex(std::span<const std::byte> bytes);

}  // namespace halfback
