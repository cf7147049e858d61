// Kernel table for AVX-512F, compiled with -mavx512f -mavx2 -mfma (src/core/CMakeLists.txt).
// Selected at run time by batch.cpp only when the CPU supports it.
// One-definition-rule guard: xsimd 8.1 defines two non-template inline functions (the range
// reduction of huge sin/cos arguments). Compiled here with avx512 flags, they would be link-time
// duplicates of the SSE2 translation unit's copies, and the linker could keep this copy for all
// callers, including the SSE2 kernels on a CPU without avx512. Give this TU's copies their own
// names. (The test halfback_isa_symbols checks that no other symbol is shared.)
#define __ieee754_rem_pio2 halfback_avx512_ieee754_rem_pio2
#define __kernel_rem_pio2 halfback_avx512_kernel_rem_pio2

#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ < 13
// GCC 12's avx512fintrin.h self-initializes its "undefined" registers (GCC bug 105593), which
// -Wall reports at every inlined use. The same kernel code is warning-checked in the other TUs.
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

#include "batch_kernels.hpp"
#include "batch_simd.hpp"

namespace halfback::detail {

const KernelSet& kernels_avx512() {
  using A = xsimd::avx512f;
  static constexpr KernelSet k =
      make_kernel_set<xsimd::batch<float, A>, xsimd::batch<double, A>>(SimdIsa::avx512, "avx512");
  return k;
}

}  // namespace halfback::detail
