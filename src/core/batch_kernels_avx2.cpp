// Kernel table for AVX2 + FMA, compiled with -mavx2 -mfma (src/core/CMakeLists.txt).
// Selected at run time by batch.cpp only when the CPU supports it.
// One-definition-rule guard: xsimd 8.1 defines two non-template inline functions (the range
// reduction of huge sin/cos arguments). Compiled here with avx2 flags, they would be link-time
// duplicates of the SSE2 translation unit's copies, and the linker could keep this copy for all
// callers, including the SSE2 kernels on a CPU without avx2. Give this TU's copies their own
// names. (The test halfback_isa_symbols checks that no other symbol is shared.)
#define __ieee754_rem_pio2 halfback_avx2_ieee754_rem_pio2
#define __kernel_rem_pio2 halfback_avx2_kernel_rem_pio2

#include "batch_kernels.hpp"
#include "batch_simd.hpp"

namespace halfback::detail {

const KernelSet& kernels_avx2() {
  using A = xsimd::fma3<xsimd::avx2>;
  static constexpr KernelSet k =
      make_kernel_set<xsimd::batch<float, A>, xsimd::batch<double, A>>(SimdIsa::avx2, "avx2");
  return k;
}

}  // namespace halfback::detail
