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

#include <immintrin.h>

#include <array>
#include <cstdint>

#include "batch_kernels.hpp"
#include "batch_simd.hpp"

namespace halfback::detail {
namespace {

// Transposes between W rows of D values (D = 4 or 6: D registers) and D columns, in registers.
// The W rows are two groups of W/2 rows (D/2 registers each). For a pair of columns (c, c + 1), a
// group makes one "half" register [column c of its rows | column c + 1 of them] with two-source
// permutes (one for D = 4; two for D = 6, whose group spans three registers); the two groups'
// halves then make the two columns with one 128-bit-lane shuffle each, and back. GCC's
// vectorization of the plain loops (batch_kernels.hpp) took about twice as many instructions.
template <class S>
struct Zmm;
template <>
struct Zmm<float> {
  using V = __m512;
  using Index = std::int32_t;
  static constexpr int W = 16;
  static V load(const float* p) { return _mm512_loadu_ps(p); }
  static void store(float* p, V v) { _mm512_storeu_ps(p, v); }
  static V permute2(V a, __m512i idx, V b) { return _mm512_permutex2var_ps(a, idx, b); }
  static V low_halves(V a, V b) { return _mm512_shuffle_f32x4(a, b, 0x44); }
  static V high_halves(V a, V b) { return _mm512_shuffle_f32x4(a, b, 0xEE); }
};
template <>
struct Zmm<double> {
  using V = __m512d;
  using Index = std::int64_t;
  static constexpr int W = 8;
  static V load(const double* p) { return _mm512_loadu_pd(p); }
  static void store(double* p, V v) { _mm512_storeu_pd(p, v); }
  static V permute2(V a, __m512i idx, V b) { return _mm512_permutex2var_pd(a, idx, b); }
  static V low_halves(V a, V b) { return _mm512_shuffle_f64x2(a, b, 0x44); }
  static V high_halves(V a, V b) { return _mm512_shuffle_f64x2(a, b, 0xEE); }
};

// The permutes' indices (element e of a two-source permute: e < W from the first, else the
// second). Gather, half p of a group: value `pos` of the group's rows, first from its registers
// 0-1 (a), then 2 (b, D = 6). Scatter, register r of a group: from halves 0-1 (a), then 2 (b).
template <class I, int W, int D>
struct TransposeIndices {
  static constexpr int P = D / 2;
  std::array<std::array<I, W>, P> gather_a{}, gather_b{}, scatter_a{}, scatter_b{};
  constexpr TransposeIndices() {
    for (int p = 0; p < P; ++p)
      for (int e = 0; e < W; ++e) {
        const int pos = D * (e % (W / 2)) + 2 * p + e / (W / 2);
        gather_a[p][e] = static_cast<I>(pos < 2 * W ? pos : 0);
        gather_b[p][e] = static_cast<I>(pos < 2 * W ? e : W + pos - 2 * W);
      }
    for (int r = 0; r < P; ++r)
      for (int e = 0; e < W; ++e) {
        const int pos = r * W + e, row = pos / D, col = pos % D, half = col / 2;
        const int at = (col % 2) * (W / 2) + row;  // in the half
        scatter_a[r][e] = static_cast<I>(half < 2 ? half * W + at : 0);
        scatter_b[r][e] = static_cast<I>(half < 2 ? e : W + at);
      }
  }
};

// W rows of D values (D registers) <-> D column registers, by two-source permutes.
template <class S, int D>
struct PermuteRows {
  using Z = Zmm<S>;
  using V = typename Z::V;
  static constexpr int W = Z::W, P = D / 2;
  static constexpr TransposeIndices<typename Z::Index, W, D> idx{};

  static __m512i index(const std::array<typename Z::Index, W>& i) {
    return _mm512_loadu_si512(i.data());
  }
  static void load(const S* rows, V* columns) {
    V half[2][P];
    for (int g = 0; g < 2; ++g) {
      const S* src = rows + g * P * W;
      V r[P];
      for (int k = 0; k < P; ++k) r[k] = Z::load(src + k * W);
      for (int p = 0; p < P; ++p) {
        half[g][p] = Z::permute2(r[0], index(idx.gather_a[p]), r[1]);
        if constexpr (D == 6) half[g][p] = Z::permute2(half[g][p], index(idx.gather_b[p]), r[2]);
      }
    }
    for (int p = 0; p < P; ++p) {
      columns[2 * p] = Z::low_halves(half[0][p], half[1][p]);
      columns[2 * p + 1] = Z::high_halves(half[0][p], half[1][p]);
    }
  }
  static void store(const V* columns, S* rows) {
    V half[2][P];
    for (int p = 0; p < P; ++p) {
      half[0][p] = Z::low_halves(columns[2 * p], columns[2 * p + 1]);
      half[1][p] = Z::high_halves(columns[2 * p], columns[2 * p + 1]);
    }
    for (int g = 0; g < 2; ++g) {
      S* dst = rows + g * P * W;
      for (int r = 0; r < P; ++r) {
        V v = Z::permute2(half[g][0], index(idx.scatter_a[r]), half[g][1]);
        if constexpr (D == 6) v = Z::permute2(v, index(idx.scatter_b[r]), half[g][2]);
        Z::store(dst + r * W, v);
      }
    }
  }
};

template <class S, int D>
struct ZmmRows : PermuteRows<S, D> {};

// 8 rows of 6 doubles to columns without two-source permutes, which on Zen 5 issue to the FMA
// pipes the conversions need (docs/performance.md, "Array layouts", "Zen 5's pipes"). A 128-bit
// piece is two values of a row (piece p: columns 2p, 2p + 1). r[k] = [chunk k of rows 0-3 | of
// rows 4-7] (chunk: four values, pieces 2k and 2k + 1) comes from a 256-bit load and a broadcast
// one, blended; swapping the two pieces of each 256-bit half (an in-half permute) and blending
// gathers piece p of the even rows (even[p]) and of the odd rows (odd[p]) in row order, and
// unpacklo and unpackhi of those are columns 2p and 2p + 1: 12 loads, 6 permutes, 12 blends and
// 6 unpacks for 6 loads, 18 permutes and 12 index loads. The stores keep the permutes, and so
// do floats: this order is no faster there.
template <>
struct ZmmRows<double, 6> : PermuteRows<double, 6> {
  using V = __m512d;
  static V swap_pieces(V v) { return _mm512_permutex_pd(v, 0x4E); }
  // Pieces 0 and 2 of a, 1 and 3 of b.
  static V interleave(V a, V b) { return _mm512_mask_blend_pd(0xCC, a, b); }
  static void load(const double* rows, V* columns) {
    V r[6];
    for (int k = 0; k < 6; ++k)
      r[k] = _mm512_mask_blend_pd(0xF0, _mm512_castpd256_pd512(_mm256_loadu_pd(rows + 4 * k)),
                                  _mm512_broadcast_f64x4(_mm256_loadu_pd(rows + 24 + 4 * k)));
    // Row j's piece p is piece 3j + p of its half: in r[(3j + p) / 2], at (3j + p) % 2.
    const V even[3] = {interleave(r[0], swap_pieces(r[3])), interleave(swap_pieces(r[0]), r[3]),
                       interleave(r[1], swap_pieces(r[4]))};
    const V odd[3] = {interleave(swap_pieces(r[1]), r[4]), interleave(r[2], swap_pieces(r[5])),
                      interleave(swap_pieces(r[2]), r[5])};
    for (int p = 0; p < 3; ++p) {
      columns[2 * p] = _mm512_unpacklo_pd(even[p], odd[p]);
      columns[2 * p + 1] = _mm512_unpackhi_pd(even[p], odd[p]);
    }
  }
};

template <class S, int D>
struct RowTranspose<xsimd::batch<S, xsimd::avx512f>, D>
    : RegisterRowTranspose<ZmmRows<S, D>, xsimd::batch<S, xsimd::avx512f>, D> {};

// Two vectors per step (the decodes, halfdiff's encode): the rows of each half in turn. Without
// it the Twin stages would not read the rows the plan hands them (fused_rows is per table).
template <class S, int D>
struct RowTranspose<Twin<xsimd::batch<S, xsimd::avx512f>>, D> {
  using B = xsimd::batch<S, xsimd::avx512f>;
  using Half = RowTranspose<B, D>;
  static constexpr bool fused = Half::fused;
  static void load(const S* rows, Twin<B>* x) {
    B lo[D], hi[D];
    Half::load(rows, lo);
    Half::load(rows + D * B::size, hi);
    for (int k = 0; k < D; ++k) x[k] = Twin<B>(lo[k], hi[k]);
  }
  static void store(const Twin<B>* y, S* rows) {
    B lo[D], hi[D];
    for (int k = 0; k < D; ++k) {
      lo[k] = y[k].lo;
      hi[k] = y[k].hi;
    }
    Half::store(lo, rows);
    Half::store(hi, rows + D * B::size);
  }
};

constexpr KernelSet make_avx512_set() {
  using A = xsimd::avx512f;
  using F = xsimd::batch<float, A>;
  using D = xsimd::batch<double, A>;
  // Two vectors per step (Twin, batch_simd.hpp) for every decode (the inverses), whose latency
  // stalls the second vector hides. The encodes keep one vector: with two, more of their
  // registers spill, which costs more than it hides (docs/performance.md, "Conversions": the
  // measurements of both choices).
  return make_kernel_set<F, D, Twin<F>, Twin<D>>(SimdIsa::avx512, "avx512");
}

}  // namespace

const KernelSet& kernels_avx512() {
  static constexpr KernelSet k = make_avx512_set();
  return k;
}

}  // namespace halfback::detail
