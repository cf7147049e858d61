// Kernel table for AVX2 + FMA, compiled with -mavx2 -mfma (src/core/CMakeLists.txt).
// Selected at run time by batch.cpp only when the CPU supports it.
// One-definition-rule guard: xsimd 8.1 defines two non-template inline functions (the range
// reduction of huge sin/cos arguments). Compiled here with avx2 flags, they would be link-time
// duplicates of the SSE2 translation unit's copies, and the linker could keep this copy for all
// callers, including the SSE2 kernels on a CPU without avx2. Give this TU's copies their own
// names. (The test halfback_isa_symbols checks that no other symbol is shared.)
#define __ieee754_rem_pio2 halfback_avx2_ieee754_rem_pio2
#define __kernel_rem_pio2 halfback_avx2_kernel_rem_pio2

#include <immintrin.h>

#include <cstddef>

#include "batch_kernels.hpp"
#include "batch_simd.hpp"
#include "lane_transposes.hpp"

namespace halfback::detail {
namespace {

// AVX2's two 128-bit lanes for the row transposes (lane_transposes.hpp). The loads are a 128-bit
// load and an insert; the stores pair two registers' lanes with one cross-lane permute per
// 256-bit store, which is faster than storing the lanes one by one. Transposed in registers
// because transpose passes over scratch cost row-major data about twice the time of SoA at 10^7
// pairs (docs/performance.md, "Array layouts", "AVX2 transposes in registers").
struct AvxLanes {
  using F = __m256;
  using Dv = __m256d;
  static F load(const float* p, std::ptrdiff_t lane_stride) {
    return _mm256_loadu2_m128(p + lane_stride, p);
  }
  static Dv load(const double* p, std::ptrdiff_t lane_stride) {
    return _mm256_loadu2_m128d(p + lane_stride, p);
  }
  static void store(const F* v, int n, float* lo, float* hi) {
    for (int k = 0; k < n; k += 2) {
      _mm256_storeu_ps(lo + 4 * k, _mm256_permute2f128_ps(v[k], v[k + 1], 0x20));
      _mm256_storeu_ps(hi + 4 * k, _mm256_permute2f128_ps(v[k], v[k + 1], 0x31));
    }
  }
  static void store(const Dv* v, int n, double* lo, double* hi) {
    for (int k = 0; k < n; k += 2) {
      _mm256_storeu_pd(lo + 2 * k, _mm256_permute2f128_pd(v[k], v[k + 1], 0x20));
      _mm256_storeu_pd(hi + 2 * k, _mm256_permute2f128_pd(v[k], v[k + 1], 0x31));
    }
  }
  static F unpacklo(F a, F b) { return _mm256_unpacklo_ps(a, b); }
  static F unpackhi(F a, F b) { return _mm256_unpackhi_ps(a, b); }
  static Dv unpacklo(Dv a, Dv b) { return _mm256_unpacklo_pd(a, b); }
  static Dv unpackhi(Dv a, Dv b) { return _mm256_unpackhi_pd(a, b); }
  template <int Imm>
  static F shuffle(F a, F b) {
    return _mm256_shuffle_ps(a, b, Imm);
  }
  template <int Imm>
  static Dv shuffle(Dv a, Dv b) {
    return _mm256_shuffle_pd(a, b, Imm | Imm << 2);  // the same two bits for each lane
  }
  static Dv as_d(F v) { return _mm256_castps_pd(v); }
  static F as_f(Dv v) { return _mm256_castpd_ps(v); }
};

template <class S, int D>
struct RowTranspose<xsimd::batch<S, xsimd::fma3<xsimd::avx2>>, D>
    : RegisterRowTranspose<LaneRows<AvxLanes, S, D>, xsimd::batch<S, xsimd::fma3<xsimd::avx2>>, D> {
};

}  // namespace

const KernelSet& kernels_avx2() {
  using A = xsimd::fma3<xsimd::avx2>;
  static constexpr KernelSet k =
      make_kernel_set<xsimd::batch<float, A>, xsimd::batch<double, A>>(SimdIsa::avx2, "avx2");
  return k;
}

}  // namespace halfback::detail
