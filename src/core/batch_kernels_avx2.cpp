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

#include "batch_kernels.hpp"
#include "batch_simd.hpp"

namespace halfback::detail {
namespace {

// Transposes between W rows of D values (D = 4 or 6) and D column registers, in registers. The
// 128-bit lane 0 of a column holds the first W/2 rows, lane 1 the others, so that the transpose
// is one small transpose per lane, of in-lane unpacks and shuffles: the loads put 128-bit pieces
// of the rows into their lanes (a load and an insert), and the stores pair two registers' lanes
// with one cross-lane permute per 256-bit store (measured faster than storing the 128-bit lanes
// one by one; docs/performance.md, "Array layouts"). Against GCC's vectorization of the plain
// loops in a pass of their own, rows / SoA went from 1.2-1.45 to 1.03-1.27 in cache.
template <class S, int D>
struct YmmRows;

// Registers v[0, n) (n even) to memory as their 128-bit lanes: the lanes 0 in order from lo, the
// lanes 1 from hi, two lanes a store.
inline void store_lanes(const __m256d* v, int n, double* lo, double* hi) {
  for (int k = 0; k < n; k += 2) {
    _mm256_storeu_pd(lo + 2 * k, _mm256_permute2f128_pd(v[k], v[k + 1], 0x20));
    _mm256_storeu_pd(hi + 2 * k, _mm256_permute2f128_pd(v[k], v[k + 1], 0x31));
  }
}
inline void store_lanes(const __m256* v, int n, float* lo, float* hi) {
  for (int k = 0; k < n; k += 2) {
    _mm256_storeu_ps(lo + 4 * k, _mm256_permute2f128_ps(v[k], v[k + 1], 0x20));
    _mm256_storeu_ps(hi + 4 * k, _mm256_permute2f128_ps(v[k], v[k + 1], 0x31));
  }
}

// 4 rows of doubles; piece p of a row is its columns 2p and 2p + 1.
template <int D>
struct YmmRows<double, D> {
  static void load(const double* rows, __m256d* columns) {
    for (int p = 0; p < D / 2; ++p) {
      const __m256d even = _mm256_loadu2_m128d(rows + 2 * D + 2 * p, rows + 2 * p);     // rows 0, 2
      const __m256d odd = _mm256_loadu2_m128d(rows + 3 * D + 2 * p, rows + D + 2 * p);  // 1, 3
      columns[2 * p] = _mm256_unpacklo_pd(even, odd);
      columns[2 * p + 1] = _mm256_unpackhi_pd(even, odd);
    }
  }
  static void store(const __m256d* columns, double* rows) {
    __m256d piece[D];  // rows 0 and 1 in lane 0, 2 and 3 in lane 1, piece by piece
    for (int p = 0; p < D / 2; ++p) {
      piece[p] = _mm256_unpacklo_pd(columns[2 * p], columns[2 * p + 1]);
      piece[D / 2 + p] = _mm256_unpackhi_pd(columns[2 * p], columns[2 * p + 1]);
    }
    store_lanes(piece, D, rows, rows + 2 * D);
  }
};

// The 64-bit pieces 0 of a and b (lane by lane), pieces 1, and [piece Imm & 1 of a, piece
// Imm >> 1 of b] (in both lanes).
inline __m256 pieces_lo(__m256 a, __m256 b) {
  return _mm256_castpd_ps(_mm256_unpacklo_pd(_mm256_castps_pd(a), _mm256_castps_pd(b)));
}
inline __m256 pieces_hi(__m256 a, __m256 b) {
  return _mm256_castpd_ps(_mm256_unpackhi_pd(_mm256_castps_pd(a), _mm256_castps_pd(b)));
}
template <int Imm>
inline __m256 pieces(__m256 a, __m256 b) {
  return _mm256_castpd_ps(
      _mm256_shuffle_pd(_mm256_castps_pd(a), _mm256_castps_pd(b), Imm | Imm << 2));
}

// 8 rows of 4 floats: rows 0-3 in lane 0, rows 4-7 in lane 1, a 4 x 4 transpose in each lane.
template <>
struct YmmRows<float, 4> {
  static void load(const float* rows, __m256* columns) {
    __m256 r[4];  // row j in lane 0, row j + 4 in lane 1
    for (int j = 0; j < 4; ++j) r[j] = _mm256_loadu2_m128(rows + 4 * (j + 4), rows + 4 * j);
    const __m256 r01lo = _mm256_unpacklo_ps(r[0], r[1]);  // r0c0 r1c0 r0c1 r1c1
    const __m256 r01hi = _mm256_unpackhi_ps(r[0], r[1]);  // r0c2 r1c2 r0c3 r1c3
    const __m256 r23lo = _mm256_unpacklo_ps(r[2], r[3]);
    const __m256 r23hi = _mm256_unpackhi_ps(r[2], r[3]);
    columns[0] = pieces_lo(r01lo, r23lo);
    columns[1] = pieces_hi(r01lo, r23lo);
    columns[2] = pieces_lo(r01hi, r23hi);
    columns[3] = pieces_hi(r01hi, r23hi);
  }
  static void store(const __m256* columns, float* rows) {
    const __m256 c01lo = _mm256_unpacklo_ps(columns[0], columns[1]);  // r0c0 r0c1 r1c0 r1c1
    const __m256 c01hi = _mm256_unpackhi_ps(columns[0], columns[1]);  // r2c0 r2c1 r3c0 r3c1
    const __m256 c23lo = _mm256_unpacklo_ps(columns[2], columns[3]);
    const __m256 c23hi = _mm256_unpackhi_ps(columns[2], columns[3]);
    const __m256 r[4] = {pieces_lo(c01lo, c23lo), pieces_hi(c01lo, c23lo), pieces_lo(c01hi, c23hi),
                         pieces_hi(c01hi, c23hi)};
    store_lanes(r, 4, rows, rows + 16);
  }
};

// 8 rows of 6 floats as 64-bit pieces (piece k: columns 2k, 2k + 1). Two rows are three 128-bit
// quarters, x = [piece 0, 1 of the first], y = [piece 2 of the first, 0 of the second],
// z = [piece 1, 2 of the second]; each register holds rows (0, 1), (2, 3) in lane 0 and
// (4, 5), (6, 7) in lane 1. In-lane shuffles of the pieces give, for each piece k, the pieces of
// two rows, and one more the columns.
template <>
struct YmmRows<float, 6> {
  // The quarters q (0: x, 1: y, 2: z) of rows (2i, 2i + 1) in lane 0 and (2i + 4, 2i + 5) in
  // lane 1.
  static __m256 quarter(const float* rows, int i, int q) {
    return _mm256_loadu2_m128(rows + 6 * (2 * i + 4) + 4 * q, rows + 6 * (2 * i) + 4 * q);
  }
  static void load(const float* rows, __m256* columns) {
    __m256 piece[2][3];  // [row pair i][k]: piece k of rows 2i, 2i + 1 (and + 4)
    for (int i = 0; i < 2; ++i) {
      const __m256 x = quarter(rows, i, 0), y = quarter(rows, i, 1), z = quarter(rows, i, 2);
      piece[i][0] = pieces<0b10>(x, y);
      piece[i][1] = pieces<0b01>(x, z);
      piece[i][2] = pieces<0b10>(y, z);
    }
    for (int k = 0; k < 3; ++k) {
      columns[2 * k] = _mm256_shuffle_ps(piece[0][k], piece[1][k], _MM_SHUFFLE(2, 0, 2, 0));
      columns[2 * k + 1] = _mm256_shuffle_ps(piece[0][k], piece[1][k], _MM_SHUFFLE(3, 1, 3, 1));
    }
  }
  static void store(const __m256* columns, float* rows) {
    __m256 piece[2][3];
    for (int k = 0; k < 3; ++k) {
      piece[0][k] = _mm256_unpacklo_ps(columns[2 * k], columns[2 * k + 1]);  // rows 0, 1 (4, 5)
      piece[1][k] = _mm256_unpackhi_ps(columns[2 * k], columns[2 * k + 1]);  // rows 2, 3 (6, 7)
    }
    __m256 q[6];
    for (int i = 0; i < 2; ++i) {
      q[3 * i] = pieces_lo(piece[i][0], piece[i][1]);
      q[3 * i + 1] = pieces<0b10>(piece[i][2], piece[i][0]);
      q[3 * i + 2] = pieces_hi(piece[i][1], piece[i][2]);
    }
    store_lanes(q, 6, rows, rows + 24);
  }
};

template <class S>
struct Ymm;
template <>
struct Ymm<float> {
  using V = __m256;
};
template <>
struct Ymm<double> {
  using V = __m256d;
};

// The rows of the stages' vector loops (batch_kernels.hpp), transposed in registers; rows of 3
// (isotropic coordinates) keep the engine's transpose passes.
template <class S, int D>
struct RowTranspose<xsimd::batch<S, xsimd::fma3<xsimd::avx2>>, D> {
  using B = xsimd::batch<S, xsimd::fma3<xsimd::avx2>>;
  static constexpr bool fused = D == 4 || D == 6;
  static void load(const S* rows, B* x) {
    typename Ymm<S>::V c[D];
    YmmRows<S, D>::load(rows, c);
    for (int k = 0; k < D; ++k) x[k] = B(c[k]);
  }
  static void store(const B* y, S* rows) {
    typename Ymm<S>::V c[D];
    for (int k = 0; k < D; ++k) c[k] = y[k];
    YmmRows<S, D>::store(c, rows);
  }
};

}  // namespace

const KernelSet& kernels_avx2() {
  using A = xsimd::fma3<xsimd::avx2>;
  static constexpr KernelSet k =
      make_kernel_set<xsimd::batch<float, A>, xsimd::batch<double, A>>(SimdIsa::avx2, "avx2");
  return k;
}

}  // namespace halfback::detail
