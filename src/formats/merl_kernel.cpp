// The block loops of the MERL lookups, each compiled three times (AVX-512, AVX2, the baseline) and
// chosen at load time by the CPU (GCC's target_clones). The loops are the formulas of
// merl_kernel.hpp applied row by row; the compiler vectorizes them across rows. Compiled without
// errno for sqrt, without trapping math and without contraction (src/formats/CMakeLists.txt): the
// roundings are those of the one-row path.
#include "merl_kernel.hpp"
#include <algorithm>
#include <cstdlib>

namespace halfback::merl_kernel {

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(__SANITIZE_ADDRESS__)
#define HALFBACK_MERL_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define HALFBACK_MERL_CLONES
#endif

HALFBACK_MERL_CLONES
void nearest_bins(const double* theta_h, const double* theta_d, const double* phi_d,
                  const std::uint8_t* apart, std::size_t m, std::uint32_t apart_bin,
                  std::uint32_t* bin) {
  for (std::size_t i = 0; i < m; ++i) {
    const std::uint32_t k = nearest_bin(theta_h[i], theta_d[i], phi_d[i]);
    bin[i] = apart[i] ? apart_bin : k;
  }
}

// The axes in loops of their own: GCC 12 vectorizes each, not the three in one loop.
HALFBACK_MERL_CLONES
void cells(const double* theta_h, const double* theta_d, const double* phi_d, std::size_t m,
           Cells& out) {
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
// flight), then blended across rows in vectors. Blending row by row, each row's arithmetic filled
// the out-of-order window (3.1-3.3 against 1.0-1.1 ms per 65536 rows for the table reads alone;
// docs/performance.md).
HALFBACK_MERL_CLONES
void blend_rows(const merl::BinValues* table, const Cells& cells, std::size_t begin,
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

HALFBACK_MERL_CLONES
void rows_apart(const double* rows, const std::uint8_t* valid, std::size_t m, std::uint8_t* apart) {
  for (std::size_t i = 0; i < m; ++i) {
    const double* p = rows + 6 * i;
    apart[i] =
        (valid[i] == 0) | (p[2] < 0) | (p[5] < 0) | ((p[0] + p[3] == 0) & (p[1] + p[4] == 0));
  }
}

}  // namespace halfback::merl_kernel
