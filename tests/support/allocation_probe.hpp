// Peak heap allocation through operator new, for the tests that a reader validates a file before
// allocating from the sizes it declares (docs/reliability/readers.md). Only the test
// binaries that compile tests/support/allocation_probe.cpp (which replaces the global operator
// new and delete) may include this header.
#pragma once

#include <cstddef>

namespace halfback::test {

// Bytes live through operator new now, and the largest such value since the last reset.
std::size_t allocated_bytes();
std::size_t peak_allocated_bytes();
void reset_peak_allocated_bytes();

// The peak growth of the heap during a scope: construct, do the work, read growth().
class AllocationProbe {
 public:
  AllocationProbe() : base_(allocated_bytes()) { reset_peak_allocated_bytes(); }
  std::size_t growth() const {
    const std::size_t peak = peak_allocated_bytes();
    return peak > base_ ? peak - base_ : 0;
  }

 private:
  std::size_t base_;
};

}  // namespace halfback::test
