// Runs a check under every instruction set this CPU runs, as HALFBACK_ISA would choose it:
// simd_isa() returns each in turn (detail::set_batch_isa), so the batch engine's kernel tables and
// the formats' block loops (src/formats/isa_versions.hpp) run their version for it. Back to the
// default afterwards. Returns how many instruction sets ran the check.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <optional>
#include <string>

#include "core/batch_engine.hpp"
#include "halfback/core/simd.hpp"

namespace halfback::test {

template <class Check>
std::size_t under_every_isa(Check&& check) {
  std::size_t ran = 0;
  for (SimdIsa isa : detail::kAllIsas) {
    if (!detail::set_batch_isa(isa)) continue;
    SCOPED_TRACE("simd_isa() = " + std::string(simd_isa_name(isa)));
    check(isa);
    ++ran;
  }
  detail::set_batch_isa(std::nullopt);
  return ran;
}

}  // namespace halfback::test
