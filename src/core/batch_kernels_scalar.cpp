// Scalar kernel table (one row per "vector"): the fallback on non-x86 builds, and a cross-check
// of the tiled engine in the tests. Same stage code as the SIMD tables, on float/double lanes.
#include "batch_kernels.hpp"

namespace halfback::detail {

const KernelSet& kernels_scalar() {
  static constexpr KernelSet k = make_kernel_set<float, double>(SimdIsa::scalar, "scalar");
  return k;
}

}  // namespace halfback::detail
