// The block loops of the MERL lookups, each compiled three times (AVX-512, AVX2, the baseline) and
// chosen at load time by the CPU (GCC's target_clones). The loops are the formulas of
// merl_kernel.hpp applied row by row; the compiler vectorizes them across rows. Compiled without
// errno for sqrt, without trapping math and without contraction (src/formats/CMakeLists.txt): the
// roundings are those of the one-row path.
#include "merl_kernel.hpp"

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

HALFBACK_MERL_CLONES
void blend_rows(const merl::BinValues* table, const Cells& cells, std::size_t begin,
                std::size_t end, Rgb* out) {
  for (std::size_t i = begin; i < end; ++i) out[i] = blend(table, cells[i]);
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
