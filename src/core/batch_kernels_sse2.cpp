// Kernel table for SSE2 (the x86-64 baseline), compiled with the default flags.
// Selected at run time by batch.cpp only when the CPU supports it.
#include <emmintrin.h>

#include <cstddef>

#include "batch_kernels.hpp"
#include "batch_simd.hpp"
#include "lane_transposes.hpp"

namespace halfback::detail {
namespace {

// SSE2's one 128-bit lane for the row transposes (lane_transposes.hpp): 2 double or 4 float rows
// a vector, plain loads and stores.
struct SseLanes {
  using F = __m128;
  using Dv = __m128d;
  static F load(const float* p, std::ptrdiff_t) { return _mm_loadu_ps(p); }
  static Dv load(const double* p, std::ptrdiff_t) { return _mm_loadu_pd(p); }
  static void store(const F* v, int n, float* lo, float*) {
    for (int k = 0; k < n; ++k) _mm_storeu_ps(lo + 4 * k, v[k]);
  }
  static void store(const Dv* v, int n, double* lo, double*) {
    for (int k = 0; k < n; ++k) _mm_storeu_pd(lo + 2 * k, v[k]);
  }
  static F unpacklo(F a, F b) { return _mm_unpacklo_ps(a, b); }
  static F unpackhi(F a, F b) { return _mm_unpackhi_ps(a, b); }
  static Dv unpacklo(Dv a, Dv b) { return _mm_unpacklo_pd(a, b); }
  static Dv unpackhi(Dv a, Dv b) { return _mm_unpackhi_pd(a, b); }
  template <int Imm>
  static F shuffle(F a, F b) {
    return _mm_shuffle_ps(a, b, Imm);
  }
  template <int Imm>
  static Dv shuffle(Dv a, Dv b) {
    return _mm_shuffle_pd(a, b, Imm);
  }
  static Dv as_d(F v) { return _mm_castps_pd(v); }
  static F as_f(Dv v) { return _mm_castpd_ps(v); }
};

template <class S, int D>
struct RowTranspose<xsimd::batch<S, xsimd::sse2>, D>
    : RegisterRowTranspose<LaneRows<SseLanes, S, D>, xsimd::batch<S, xsimd::sse2>, D> {};

}  // namespace

const KernelSet& kernels_sse2() {
  using A = xsimd::sse2;
  static constexpr KernelSet k =
      make_kernel_set<xsimd::batch<float, A>, xsimd::batch<double, A>>(SimdIsa::sse2, "sse2");
  return k;
}

}  // namespace halfback::detail
