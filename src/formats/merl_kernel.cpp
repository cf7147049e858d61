// The block loops of the MERL lookups, each compiled for AVX-512, AVX2 and the baseline and run as
// simd_isa() says (isa_versions.hpp). The loops are the formulas of merl_kernel.hpp applied row
// by row; the compiler vectorizes them across rows. Compiled without errno for sqrt, without
// trapping math and without contraction (src/formats/CMakeLists.txt): the roundings are those of
// the one-row path, in every version. The blend and rows_apart also have hand-written AVX-512
// kernels (target attributes, run when avx512_kernels()), the same bits.
#include "merl_kernel.hpp"

#include <algorithm>
#include <cstdlib>

#include "formats/isa_versions.hpp"
#include "halfback/core/simd.hpp"

#if defined(__x86_64__) && defined(__GNUC__)
#define HALFBACK_MERL_AVX512 1
#include <immintrin.h>
#endif

namespace halfback::merl_kernel {

namespace {

[[gnu::always_inline]] inline void nearest_bins_body(const double* theta_h, const double* theta_d,
                                                     const double* phi_d, const std::uint8_t* apart,
                                                     std::size_t m, std::uint32_t apart_bin,
                                                     std::uint32_t* bin) {
  for (std::size_t i = 0; i < m; ++i) {
    const std::uint32_t k = nearest_bin(theta_h[i], theta_d[i], phi_d[i]);
    bin[i] = apart[i] ? apart_bin : k;
  }
}

// The axes in loops of their own: GCC 12 vectorizes each, not the three in one loop.
[[gnu::always_inline]] inline void cells_body(const double* theta_h, const double* theta_d,
                                              const double* phi_d, std::size_t m, Cells& out) {
  alignas(64) std::int32_t ih[kBlock], id[kBlock], ip[kBlock];
  for (std::size_t i = 0; i < m; ++i) {
    const Axis a = theta_h_axis(theta_h[i]);
    ih[i] = a.i;
    out.t[0][i] = a.t;
  }
  for (std::size_t i = 0; i < m; ++i) {
    const Axis a = theta_d_axis(theta_d[i]);
    id[i] = a.i;
    out.t[1][i] = a.t;
  }
  for (std::size_t i = 0; i < m; ++i) {
    const Axis a = phi_d_axis(phi_d[i]);
    ip[i] = a.i;
    out.t[2][i] = a.t;
  }
  for (std::size_t i = 0; i < m; ++i) {
    out.phi_step[i] = phi_step(ip[i]);
    out.base[i] = cell_base(ih[i], id[i], ip[i]);
  }
}

// Prefetches written in an always-inlined function: GCC takes a function whose only effects are
// prefetches for a pure one, and drops its calls.
[[gnu::always_inline]] inline void prefetch_corners(const merl::BinValues* table, const Cell& c) {
  const merl::BinValues* p = table + c.base;
  const merl::BinValues* q = p + c.phi_step;
  __builtin_prefetch(p);
  __builtin_prefetch(q);
  __builtin_prefetch(p + kThetaDStep);
  __builtin_prefetch(q + kThetaDStep);
  __builtin_prefetch(p + kThetaHStep);
  __builtin_prefetch(q + kThetaHStep);
  __builtin_prefetch(p + kThetaHStep + kThetaDStep);
  __builtin_prefetch(q + kThetaHStep + kThetaDStep);
}

// Steps of kRows rows: the corners of the next step are prefetched, this step's corner values
// copied into columns (a short loop of independent loads, so that many rows' cache misses are in
// flight), then blended across rows in vectors. Blended row by row, each row's arithmetic fills
// the out-of-order window and the misses of the next rows wait: three times the time of the table
// reads alone (docs/performance.md, "Measured lookups").
[[gnu::always_inline]] inline void blend_rows_portable_body(const merl::BinValues* table,
                                                            const Cells& cells, std::size_t begin,
                                                            std::size_t end, Rgb* out) {
  constexpr std::size_t kRows = 16;
  alignas(64) double x[8][3][kRows];
  alignas(64) double rgb[3][kRows];
  for (std::size_t i = begin; i < end; i += kRows) {
    const std::size_t n = end - i < kRows ? end - i : kRows;
    for (std::size_t r = i + n; r < i + n + kRows && r < end; ++r)
      prefetch_corners(table, cells[r]);
    for (std::size_t r = 0; r < n; ++r) {
      Corners v;
      load_corners(table, cells[i + r], v);
      for (int k = 0; k < 8; ++k)
        for (int ch = 0; ch < 3; ++ch) x[k][ch][r] = v.slot[k].rgb[ch];
    }
    for (std::size_t r = 0; r < n; ++r) {
      double one[3];
      blend_channels<3>([&](int k, int ch) { return x[k][ch][r]; }, cells.t[0][i + r],
                        cells.t[1][i + r], cells.t[2][i + r], one);
      rgb[0][r] = one[0];
      rgb[1][r] = one[1];
      rgb[2][r] = one[2];
    }
    for (std::size_t r = 0; r < n; ++r) out[i + r] = {rgb[0][r], rgb[1][r], rgb[2][r]};
  }
}

[[gnu::always_inline]] inline void rows_apart_portable_body(const double* rows,
                                                            const std::uint8_t* valid,
                                                            std::size_t m, std::uint8_t* apart) {
  for (std::size_t i = 0; i < m; ++i) {
    const double* p = rows + 6 * i;
    apart[i] =
        (valid[i] == 0) | (p[2] < 0) | (p[5] < 0) | ((p[0] + p[3] == 0) & (p[1] + p[4] == 0));
  }
}

}  // namespace

HALFBACK_ISA_VERSIONS(nearest_bins,
                      (const double* theta_h, const double* theta_d, const double* phi_d,
                       const std::uint8_t* apart, std::size_t m, std::uint32_t apart_bin,
                       std::uint32_t* bin),
                      (theta_h, theta_d, phi_d, apart, m, apart_bin, bin))
HALFBACK_ISA_VERSIONS(cells,
                      (const double* theta_h, const double* theta_d, const double* phi_d,
                       std::size_t m, Cells& out),
                      (theta_h, theta_d, phi_d, m, out))
HALFBACK_ISA_VERSIONS(blend_rows_portable,
                      (const merl::BinValues* table, const Cells& cells, std::size_t begin,
                       std::size_t end, Rgb* out),
                      (table, cells, begin, end, out))
HALFBACK_ISA_VERSIONS(rows_apart_portable,
                      (const double* rows, const std::uint8_t* valid, std::size_t m,
                       std::uint8_t* apart),
                      (rows, valid, m, apart))

#if defined(HALFBACK_MERL_AVX512)

// GCC 12's avx512fintrin.h self-initializes its "undefined" registers (GCC bug 105593), which
// -Wall reports at every inlined use (as in src/core/batch_kernels_avx512.cpp).
#pragma GCC diagnostic push
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ < 13
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

namespace {

#define HALFBACK_AVX512 __attribute__((target("avx512f")))

// Rows per lane group of the AVX-512 kernels (8 doubles a vector), and how far ahead (in rows) the
// blend prefetches its corners.
constexpr std::size_t kLanes = 8;
constexpr std::size_t kAhead = 16;

// A cell's 8 corner slots relative to its p = table + base and q = p + phi_step, in the order of
// blend_channels (θh, θd, φd): p, q, p + D, q + D, p + H, q + H, p + H + D, q + H + D.
constexpr std::uint32_t kCornerOffset[4] = {0, kThetaDStep, kThetaHStep, kThetaHStep + kThetaDStep};

// The R, G, B of one corner of 8 rows, one vector per channel: the 8 rows' 32-byte slots (R, G, B,
// pad) read as 4 + 4 halves of zmm registers and transposed by shuffles, instead of 24 scalar
// loads and stores through memory.
struct Channels {
  __m512d v[3];
};

HALFBACK_AVX512 inline Channels corner_channels(const merl::BinValues* const* row,
                                                std::uint32_t offset) {
  // z[r] = [slot of row r | slot of row r + 4]
  __m512d z[4];
  for (int r = 0; r < 4; ++r)
    z[r] = _mm512_insertf64x4(_mm512_castpd256_pd512(_mm256_load_pd(row[r][offset].rgb)),
                              _mm256_load_pd(row[r + 4][offset].rgb), 1);
  // [R0 R1 B0 B1 | R4 R5 B4 B5], [G0 G1 P0 P1 | G4 G5 P4 P5], and the same for rows 2, 3, 6, 7.
  const __m512d rb01 = _mm512_unpacklo_pd(z[0], z[1]), gp01 = _mm512_unpackhi_pd(z[0], z[1]);
  const __m512d rb23 = _mm512_unpacklo_pd(z[2], z[3]), gp23 = _mm512_unpackhi_pd(z[2], z[3]);
  const __m512i lo = _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13);
  const __m512i hi = _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15);
  // Lanes 0-1 and 4-5 from the first of each pair, 2-3 and 6-7 from the second: rows 0 to 7.
  return {{_mm512_permutex2var_pd(rb01, lo, rb23), _mm512_permutex2var_pd(gp01, lo, gp23),
           _mm512_permutex2var_pd(rb01, hi, rb23)}};
}

// blend_channels<3> on 8 rows, operation for operation: the same weights (products in the order
// θh, θd, φd), the same sums in the same order, an unmeasured corner skipped by a mask.
HALFBACK_AVX512 inline void blend_group(const merl::BinValues* table, const Cells& cells,
                                        std::size_t i, double* rgb) {
  const merl::BinValues* p[kLanes];
  const merl::BinValues* q[kLanes];
  for (std::size_t r = 0; r < kLanes; ++r) {
    p[r] = table + cells.base[i + r];
    q[r] = p[r] + cells.phi_step[i + r];
  }
  const __m512d one = _mm512_set1_pd(1.0), zero = _mm512_setzero_pd();
  const __m512d t[3] = {_mm512_loadu_pd(cells.t[0] + i), _mm512_loadu_pd(cells.t[1] + i),
                        _mm512_loadu_pd(cells.t[2] + i)};
  __m512d sum[3] = {zero, zero, zero}, wsum[3] = {zero, zero, zero};
  for (int a = 0; a < 2; ++a) {
    const __m512d wa = a ? t[0] : _mm512_sub_pd(one, t[0]);
    for (int b = 0; b < 2; ++b) {
      const __m512d wb = _mm512_mul_pd(wa, b ? t[1] : _mm512_sub_pd(one, t[1]));
      for (int k = 0; k < 2; ++k) {
        const __m512d w = _mm512_mul_pd(wb, k ? t[2] : _mm512_sub_pd(one, t[2]));
        const Channels x = corner_channels(k ? q : p, kCornerOffset[2 * a + b]);
        for (int ch = 0; ch < 3; ++ch) {
          const __mmask8 measured = _mm512_cmp_pd_mask(x.v[ch], zero, _CMP_GE_OQ);
          sum[ch] = _mm512_add_pd(sum[ch], _mm512_maskz_mul_pd(measured, w, x.v[ch]));
          wsum[ch] = _mm512_add_pd(wsum[ch], _mm512_maskz_mov_pd(measured, w));
        }
      }
    }
  }
  __m512d c[3];
  for (int ch = 0; ch < 3; ++ch) {
    const __mmask8 any = _mm512_cmp_pd_mask(wsum[ch], zero, _CMP_GT_OQ);
    c[ch] = _mm512_mask_mul_pd(_mm512_set1_pd(kNaN), any, _mm512_div_pd(sum[ch], wsum[ch]),
                               _mm512_set1_pd(merl::kScale[ch]));
  }
  // R, G, B of 8 rows to 24 consecutive doubles (Rgb).
  const __m512i rg0 = _mm512_setr_epi64(0, 8, 0, 1, 9, 1, 2, 10);
  const __m512i b0 = _mm512_setr_epi64(0, 1, 8, 3, 4, 9, 6, 7);
  const __m512i rg1 = _mm512_setr_epi64(0, 3, 11, 0, 4, 12, 0, 5);
  const __m512i b1 = _mm512_setr_epi64(10, 1, 2, 11, 4, 5, 12, 7);
  const __m512i rg2 = _mm512_setr_epi64(13, 0, 6, 14, 0, 7, 15, 0);
  const __m512i b2 = _mm512_setr_epi64(0, 13, 2, 3, 14, 5, 6, 15);
  _mm512_storeu_pd(rgb, _mm512_permutex2var_pd(_mm512_permutex2var_pd(c[0], rg0, c[1]), b0, c[2]));
  _mm512_storeu_pd(rgb + 8,
                   _mm512_permutex2var_pd(_mm512_permutex2var_pd(c[0], rg1, c[1]), b1, c[2]));
  _mm512_storeu_pd(rgb + 16,
                   _mm512_permutex2var_pd(_mm512_permutex2var_pd(c[0], rg2, c[1]), b2, c[2]));
}

}  // namespace

HALFBACK_AVX512 void blend_rows_avx512(const merl::BinValues* table, const Cells& cells,
                                       std::size_t begin, std::size_t end, Rgb* out) {
  static_assert(sizeof(Rgb) == 3 * sizeof(double), "Rgb is 3 packed doubles");
  for (std::size_t i = begin; i < end; i += kLanes) {
    for (std::size_t r = i + kAhead; r < i + kAhead + kLanes && r < end; ++r)
      prefetch_corners(table, cells[r]);
    if (end - i >= kLanes) {
      blend_group(table, cells, i, &out[i].r);
      continue;
    }
    // The tail: its rows in a group of their own, padded with a cell inside the table.
    Cells tail;
    for (std::size_t r = 0; r < kLanes; ++r) {
      const bool row = i + r < end;
      tail.base[r] = row ? cells.base[i + r] : 0;
      tail.phi_step[r] = row ? cells.phi_step[i + r] : 1;
      for (int a = 0; a < 3; ++a) tail.t[a][r] = row ? cells.t[a][i + r] : 0.0;
    }
    alignas(64) double rgb[3 * kLanes];
    blend_group(table, tail, 0, rgb);
    for (std::size_t r = 0; i + r < end; ++r)
      out[i + r] = {rgb[3 * r], rgb[3 * r + 1], rgb[3 * r + 2]};
  }
}

// rows_apart on 8 rows at a time: the 6 components of 8 row-major pairs by gathers (from L1: the
// conversion has just read them).
HALFBACK_AVX512 void rows_apart_avx512(const double* rows, const std::uint8_t* valid, std::size_t m,
                                       std::uint8_t* apart) {
  const __m256i stride = _mm256_setr_epi32(0, 6, 12, 18, 24, 30, 36, 42);
  const __m512d zero = _mm512_setzero_pd();
  std::size_t i = 0;
  for (; i + kLanes <= m; i += kLanes) {
    const double* p = rows + 6 * i;
    __m512d x[6];
    for (int c = 0; c < 6; ++c) x[c] = _mm512_i32gather_pd(stride, p + c, 8);
    const __mmask8 rejected = _mm512_cmpeq_epi64_mask(
        _mm512_cvtepu8_epi64(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(valid + i))),
        _mm512_setzero_si512());
    const __mmask8 below =
        _mm512_cmp_pd_mask(x[2], zero, _CMP_LT_OQ) | _mm512_cmp_pd_mask(x[5], zero, _CMP_LT_OQ);
    const __mmask8 normal = _mm512_cmp_pd_mask(_mm512_add_pd(x[0], x[3]), zero, _CMP_EQ_OQ) &
                            _mm512_cmp_pd_mask(_mm512_add_pd(x[1], x[4]), zero, _CMP_EQ_OQ);
    const __m128i bytes =
        _mm512_cvtepi64_epi8(_mm512_maskz_set1_epi64(rejected | below | normal, 1));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(apart + i), bytes);
  }
  rows_apart_portable(rows + 6 * i, valid + i, m - i, apart + i);
}

#pragma GCC diagnostic pop

bool avx512_kernels() {
  // The library's one choice (core/simd.hpp): the CPU and OS support AVX-512F, and HALFBACK_ISA
  // does not ask for less.
  return simd_isa() == SimdIsa::avx512;
}

#else

void blend_rows_avx512(const merl::BinValues* table, const Cells& cells, std::size_t begin,
                       std::size_t end, Rgb* out) {
  blend_rows_portable(table, cells, begin, end, out);
}
void rows_apart_avx512(const double* rows, const std::uint8_t* valid, std::size_t m,
                       std::uint8_t* apart) {
  rows_apart_portable(rows, valid, m, apart);
}
bool avx512_kernels() {
  return false;
}

#endif

void blend_rows(const merl::BinValues* table, const Cells& cells, std::size_t begin,
                std::size_t end, Rgb* out) {
  if (avx512_kernels())
    blend_rows_avx512(table, cells, begin, end, out);
  else
    blend_rows_portable(table, cells, begin, end, out);
}

void rows_apart(const double* rows, const std::uint8_t* valid, std::size_t m, std::uint8_t* apart) {
  if (avx512_kernels())
    rows_apart_avx512(rows, valid, m, apart);
  else
    rows_apart_portable(rows, valid, m, apart);
}

}  // namespace halfback::merl_kernel
