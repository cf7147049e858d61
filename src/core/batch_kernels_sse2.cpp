// Kernel table for SSE2 (the x86-64 baseline), compiled with the default flags.
// Selected at run time by batch.cpp only when the CPU supports it.
#include "batch_kernels.hpp"
#include "batch_simd.hpp"

namespace halfback::detail {

const KernelSet& kernels_sse2() {
  using A = xsimd::sse2;
  static constexpr KernelSet k =
      make_kernel_set<xsimd::batch<float, A>, xsimd::batch<double, A>>(SimdIsa::sse2, "sse2");
  return k;
}

}  // namespace halfback::detail
