// The stage kernels of the batch engine, generic over a lane type B: a scalar (float, double) or
// an xsimd batch (include batch_simd.hpp first). They run the formulas of param.hpp through the
// row helpers of row_kernels.hpp, exactly as convert_one() does, one vector of rows at a time.
//
// Include this only from the batch_kernels_<isa>.cpp translation units. Everything here has
// internal linkage (anonymous namespace), and the param.hpp templates are instantiated only on
// the TU's own batch types, so code compiled with one TU's -m flags cannot be picked by the
// linker for another (one-definition-rule hazard of multi-ISA builds).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "batch_engine.hpp"
#include "row_kernels.hpp"

// Sanitizer builds (HALFBACK_NO_FLATTEN, set by CMake) keep the calls: flattening instrumented
// code takes the compiler minutes and gigabytes per kernel file, for no benefit to the checks.
#if defined(__GNUC__) && !defined(HALFBACK_NO_FLATTEN)
#define HALFBACK_FLATTEN [[gnu::flatten]]
#else
#define HALFBACK_FLATTEN
#endif

namespace halfback::detail {
namespace {

template <class B>
struct Lanes {
  using S = ScalarOf<B>;
  static constexpr std::size_t size = [] {
    if constexpr (std::is_floating_point_v<B>)
      return std::size_t{1};
    else
      return B::size;
  }();
  static B load(const S* p) {
    if constexpr (std::is_floating_point_v<B>)
      return *p;
    else
      return B::load_unaligned(p);
  }
  static void store(S* p, const B& v) {
    if constexpr (std::is_floating_point_v<B>)
      *p = v;
    else
      v.store_unaligned(p);
  }
};

// Moves W (lanes) rows of D values between memory and D lane vectors, for the stages' row-major
// inputs and outputs (StageRows). This generic one is for the scalar kernels (W = 1: a plain
// copy); the SIMD tables specialize it with their in-register transposes for rows of 4 and 6
// (batch_kernels_avx512.cpp; lane_transposes.hpp for SSE2 and AVX2) and leave rows of 3 off
// (fused = false: the engine transposes them with gather and scatter).
template <class B, int D>
struct RowTranspose {
  static constexpr bool fused = std::is_floating_point_v<B>;
  static void load(const ScalarOf<B>* rows, B* x) {
    for (int c = 0; c < D; ++c) x[c] = rows[c];
  }
  static void store(const B* y, ScalarOf<B>* rows) {
    for (int c = 0; c < D; ++c) rows[c] = y[c];
  }
};

// The specialization of a SIMD table, from its in-register transposes `Rows` (load and store
// between rows and D registers of type Rows::V, the native vectors that B wraps) for rows of 4
// and 6; rows of 3 (isotropic coordinates) keep the engine's transpose passes.
template <class Rows, class B, int D>
struct RegisterRowTranspose {
  using S = ScalarOf<B>;
  static constexpr bool fused = D == 4 || D == 6;
  static void load(const S* rows, B* x) {
    typename Rows::V c[D];
    Rows::load(rows, c);
    for (int k = 0; k < D; ++k) x[k] = B(c[k]);
  }
  static void store(const B* y, S* rows) {
    typename Rows::V c[D];
    for (int k = 0; k < D; ++k) c[k] = y[k];
    Rows::store(c, rows);
  }
};

// Software prefetch of the columns kPrefetchBytes ahead of each vector step, every line of it:
// the hardware prefetcher alone kept the 6 to 11 streams of a conversion too few lines ahead of
// the arithmetic (docs/performance.md, "Conversions"). Only where a vector step is whole lines
// (AVX-512). Outputs too for the decodes (the inverse conversions' last stage), where it is
// faster; the encodes gain nothing from it.
inline constexpr std::size_t kPrefetchBytes = 1024;
enum class Prefetch { inputs, inputs_and_outputs };

// The address is formed as an integer: it may lie past the end of a column (a prefetch never
// faults), and a column the stage reads or writes as rows is null.
template <class B, int N, int RW>
inline void prefetch_step(const ScalarOf<B>* const* columns, std::size_t i) {
  using S = ScalarOf<B>;
  constexpr std::size_t ahead = kPrefetchBytes / sizeof(S), line = 64 / sizeof(S);
  if constexpr (Lanes<B>::size % line == 0)
    for (int c = 0; c < N; ++c)
      if (columns[c])
        for (std::size_t k = 0; k < Lanes<B>::size; k += line)
          __builtin_prefetch(
              reinterpret_cast<const void*>(reinterpret_cast<std::uintptr_t>(columns[c]) +
                                            (i + ahead + k) * sizeof(S)),
              RW);
}

// f(x, y) on vectors [0, n) of rows: x[c] holds rows [i, i + W) of in[c], and y[c] is stored to
// out[c]; with rows.in (rows.out) set, x[0, DI) (y[0, DO)) come from (go to) rows of DI (DO)
// values instead (DI, DO = 0: never). The one flattened function of a stage: everything f calls,
// down to the xsimd intrinsics, is inlined into this loop (GCC otherwise keeps the larger
// param.hpp functions and sincos out of line, passing 512-bit vectors through memory,
// which costs 2-3x). It is not inlined itself, so that the full vectors and the padded last one
// share one copy of f's body: inlined twice, the kernel files took twice as long to compile. The
// layout is a branch per vector rather than a template parameter for the same reason; it is
// always predicted.
template <class B, int NI, int NO, int DI, int DO, Prefetch PF, class F>
[[gnu::noinline]] HALFBACK_FLATTEN void vector_loop(const ScalarOf<B>* const* in,
                                                    ScalarOf<B>* const* out, std::size_t n,
                                                    StageRows<ScalarOf<B>> rows, F f) {
  using L = Lanes<B>;
  constexpr bool rows_in = DI > 0 && RowTranspose<B, DI>::fused;
  constexpr bool rows_out = DO > 0 && RowTranspose<B, DO>::fused;
  B x[NI], y[NO];
  for (std::size_t i = 0; i < n; i += L::size) {
    prefetch_step<B, NI, 0>(in, i);
    if constexpr (PF == Prefetch::inputs_and_outputs) prefetch_step<B, NO, 1>(out, i);
    if (rows_in && rows.in) {
      if constexpr (rows_in) RowTranspose<B, DI>::load(rows.in + DI * i, x);
      for (int c = DI; c < NI; ++c) x[c] = L::load(in[c] + i);
    } else {
      for (int c = 0; c < NI; ++c) x[c] = L::load(in[c] + i);
    }
    f(x, y);
    if (rows_out && rows.out) {
      if constexpr (rows_out) RowTranspose<B, DO>::store(y, rows.out + DO * i);
      for (int c = DO; c < NO; ++c) L::store(out[c] + i, y[c]);
    } else {
      for (int c = 0; c < NO; ++c) L::store(out[c] + i, y[c]);
    }
  }
}

// Runs f on every row. The last m % W rows go through a zero-padded buffer (as columns, also
// those of row-major inputs and outputs); lanes are independent, so the padding never changes a
// real row's result.
template <class B, int NI, int NO, int DI = 0, int DO = 0, Prefetch PF = Prefetch::inputs, class F>
inline void for_rows(const ScalarOf<B>* const* in, ScalarOf<B>* const* out, std::size_t m,
                     StageRows<ScalarOf<B>> rows, F f) {
  using S = ScalarOf<B>;
  constexpr std::size_t W = Lanes<B>::size;
  const std::size_t full = m - m % W;
  vector_loop<B, NI, NO, DI, DO, PF>(in, out, full, rows, f);
  if (full == m) return;
  const std::size_t r = m - full;
  alignas(64) S buf[NI > NO ? NI : NO][W];
  const S* buf_in[NI];
  S* buf_out[NO];
  for (int c = 0; c < NI; ++c) {
    const bool from_rows = rows.in && c < DI;
    for (std::size_t k = 0; k < W; ++k)
      buf[c][k] = k >= r ? S(0) : from_rows ? rows.in[DI * (full + k) + c] : in[c][full + k];
    buf_in[c] = buf[c];
  }
  for (int c = 0; c < NO; ++c) buf_out[c] = buf[c];
  vector_loop<B, NI, NO, DI, DO, PF>(buf_in, buf_out, W, {}, f);
  for (int c = 0; c < NO; ++c) {
    const bool to_rows = rows.out && c < DO;
    for (std::size_t k = 0; k < r; ++k)
      (to_rows ? rows.out[DO * (full + k) + c] : out[c][full + k]) = buf[c][k];
  }
}

template <class B>
inline B nan_lanes() {
  return B(std::numeric_limits<ScalarOf<B>>::quiet_NaN());
}

template <class B>
inline B mask_to_lanes(const MaskOf<B>& m) {
  using S = ScalarOf<B>;
  return LaneOps<B>::select(m, B(S(1)), B(S(0)));
}

// dirs input: the pair_is_valid() mask and the accepted pair, onto the unit upper hemisphere
// (accepted_pair(); NaN where invalid), which the encode stage reads.
template <class B>
void check_stage(const ScalarOf<B>* const* in, ScalarOf<B>* const* copy, ScalarOf<B>* mask,
                 std::size_t m, StageRows<ScalarOf<B>> rows) {
  using S = ScalarOf<B>;
  using L = LaneOps<B>;
  S* outs[7] = {copy[0], copy[1], copy[2], copy[3], copy[4], copy[5], mask};
  for_rows<B, 6, 7, 6, 6>(in, outs, m, rows, [](const B* x, B* y) {
    const DirPair<B> raw{{x[0], x[1], x[2]}, {x[3], x[4], x[5]}};
    const auto ok = pair_is_valid(raw);
    const DirPair<B> p = accepted_pair(raw);
    const B v[6] = {p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z};
    for (int c = 0; c < 6; ++c) y[c] = L::select(ok, v[c], nan_lanes<B>());
    y[6] = mask_to_lanes<B>(ok);
  });
}

// P input: the pair (NaN where invalid) and the domain mask.
template <class B, class P, bool Iso>
void decode_stage(const ScalarOf<B>* const* in, ScalarOf<B>* const* dirs, ScalarOf<B>* mask,
                  std::size_t m, StageRows<ScalarOf<B>> rows) {
  using S = ScalarOf<B>;
  constexpr int NI = Iso ? 3 : 4;
  constexpr int NO = 6 + 1;
  S* outs[NO];
  for (int c = 0; c < 6; ++c) outs[c] = dirs[c];
  outs[6] = mask;
  for_rows<B, NI, NO, NI, 6, Prefetch::inputs_and_outputs>(in, outs, m, rows, [](const B* q, B* y) {
    const Solved<B> s = decode_param<P, B>(Iso, q);
    y[0] = s.pair.wi.x;
    y[1] = s.pair.wi.y;
    y[2] = s.pair.wi.z;
    y[3] = s.pair.wo.x;
    y[4] = s.pair.wo.y;
    y[5] = s.pair.wo.z;
    y[6] = mask_to_lanes<B>(s.in_domain);
  });
}

// P output: the coordinates of the pair (NaN where the mask is 0), onto the unit hemisphere first
// as convert_row() does: a decoded pair is unit only to rounding. Rows whose mask is kUnchecked
// are the user's directions (dirs input): checked here, in the loop that computes, so that their
// loads from memory overlap the arithmetic (a check pass of its own over the input waits on
// memory at 10^7 pairs; docs/performance.md, "Conversions", "One pass over the input"), and put
// on the hemisphere twice, as the check stage followed by this one would (convert_row's accepted
// pair, then its unit pair): the same bits. The mask is rewritten, 1 or 0.
template <class B, class P, bool Iso>
void encode_stage(const ScalarOf<B>* const* dirs, const ScalarOf<B>* mask_in, ScalarOf<B>* mask_out,
                  ScalarOf<B>* const* out, std::size_t m, StageRows<ScalarOf<B>> rows) {
  using S = ScalarOf<B>;
  using L = LaneOps<B>;
  constexpr int kDim = Iso ? 3 : 4;
  const S* ins[7] = {dirs[0], dirs[1], dirs[2], dirs[3], dirs[4], dirs[5], mask_in};
  S* outs[kDim + 1];
  for (int c = 0; c < kDim; ++c) outs[c] = out[c];
  outs[kDim] = mask_out;
  for_rows<B, 7, kDim + 1, 6, kDim>(ins, outs, m, rows, [](const B* x, B* y) {
    const DirPair<B> raw{{x[0], x[1], x[2]}, {x[3], x[4], x[5]}};
    const auto unchecked = x[6] == B(kUnchecked<S>), checked_valid = x[6] == B(S(1));
    // Almost always every direction is unit to rounding and kept as it is, twice: one test. Such
    // a pair is valid too (on_unit_hemisphere's tolerances are within pair_is_valid's).
    static_assert(S(4) * std::numeric_limits<S>::epsilon() < static_cast<S>(kUnitTolerance));
    const auto kept = L::mask_and(on_unit_hemisphere(raw.wi), on_unit_hemisphere(raw.wo));
    auto ok = L::mask_or(checked_valid, L::mask_and(unchecked, kept));
    DirPair<B> pair = raw;
    if (!all_lanes(kept)) [[unlikely]] {
      ok = L::mask_or(checked_valid, L::mask_and(unchecked, pair_is_valid(raw)));
      const DirPair<B> once = accepted_pair(raw), twice = accepted_pair(once);
      auto pick = [&](const Vec3<B>& a, const Vec3<B>& b) {
        return Vec3<B>{L::select(unchecked, a.x, b.x), L::select(unchecked, a.y, b.y),
                       L::select(unchecked, a.z, b.z)};
      };
      pair = {pick(twice.wi, once.wi), pick(twice.wo, once.wo)};
    }
    encode_param<P, B>(Iso, pair, y);
    if (!all_lanes(ok)) [[unlikely]]
      for (int c = 0; c < kDim; ++c) y[c] = L::select(ok, y[c], nan_lanes<B>());
    y[kDim] = mask_to_lanes<B>(ok);
  });
}

// The measure J(q) of coordinates of P at every row, not masked: the engine puts NaN where the
// row is invalid. A stage of its own, from the same q in the same lanes as decode and encode see
// it, so the bits are those of convert_one.
template <class B, class P, bool Iso>
void jacobian_stage(const ScalarOf<B>* const* coords, ScalarOf<B>* jac, std::size_t m) {
  using S = ScalarOf<B>;
  constexpr int NI = Iso ? 3 : 4;
  S* outs[1] = {jac};
  for_rows<B, NI, 1>(coords, outs, m, {},
                     [](const B* q, B* y) { y[0] = jacobian_of<P, B>(Iso, q); });
}

template <class S>
void valid_bytes(const S* __restrict mask, std::uint8_t* __restrict valid, std::size_t m) {
  for (std::size_t i = 0; i < m; ++i) valid[i] = mask[i] > S(0);
}

template <class S, int D, std::size_t Pitch>
inline void gather_rows_spaced(const S* __restrict rows, S* __restrict columns, std::size_t m) {
  for (std::size_t i = 0; i < m; ++i)
    for (int c = 0; c < D; ++c) columns[c * Pitch + i] = rows[D * i + c];
}

template <class S, int D, std::size_t Pitch>
inline void scatter_rows_spaced(const S* __restrict columns, S* __restrict rows, std::size_t m) {
  for (std::size_t i = 0; i < m; ++i)
    for (int c = 0; c < D; ++c) rows[D * i + c] = columns[c * Pitch + i];
}

// Row-major (m, D) <-> D columns kTileRows apart, for the rows a table does not transpose in
// registers (rows of 3; every D of the scalar table). Plain loops with compile-time D and spacing,
// which GCC vectorizes with this translation unit's permutes (a runtime spacing defeats it, and so
// does a group of 6: rows of 6 go as 2m rows of 3 and an even/odd split, both vectorized).
template <class S, int D>
void gather_rows(const S* __restrict rows, S* __restrict columns, std::size_t m) {
  constexpr std::size_t pitch = kTileRows<S>;
  if constexpr (D == 6) {
    alignas(64) S half[3 * 2 * pitch];  // 3 columns of the 2m half-rows (ωi, ωo, ωi, ...)
    gather_rows_spaced<S, 3, 2 * pitch>(rows, half, 2 * m);
    for (int c = 0; c < 3; ++c) {
      const S* __restrict h = half + c * 2 * pitch;
      S* __restrict wi = columns + c * pitch;
      S* __restrict wo = columns + (c + 3) * pitch;
      for (std::size_t i = 0; i < m; ++i) {
        wi[i] = h[2 * i];
        wo[i] = h[2 * i + 1];
      }
    }
  } else {
    gather_rows_spaced<S, D, pitch>(rows, columns, m);
  }
}

template <class S, int D>
void scatter_rows(const S* __restrict columns, S* __restrict rows, std::size_t m) {
  constexpr std::size_t pitch = kTileRows<S>;
  if constexpr (D == 6) {
    alignas(64) S half[3 * 2 * pitch];
    for (int c = 0; c < 3; ++c) {
      S* __restrict h = half + c * 2 * pitch;
      const S* __restrict wi = columns + c * pitch;
      const S* __restrict wo = columns + (c + 3) * pitch;
      for (std::size_t i = 0; i < m; ++i) {
        h[2 * i] = wi[i];
        h[2 * i + 1] = wo[i];
      }
    }
    scatter_rows_spaced<S, 3, 2 * pitch>(half, rows, 2 * m);
  } else {
    scatter_rows_spaced<S, D, pitch>(columns, rows, m);
  }
}

// The same passes through a SIMD table's in-register transposes (RowTranspose), where it has them.
template <class B, int D>
void gather_transposed(const ScalarOf<B>* __restrict rows, ScalarOf<B>* __restrict columns,
                       std::size_t m) {
  using L = Lanes<B>;
  constexpr std::size_t pitch = kTileRows<ScalarOf<B>>;
  std::size_t i = 0;
  for (; i + L::size <= m; i += L::size) {
    B x[D];
    RowTranspose<B, D>::load(rows + D * i, x);
    for (int c = 0; c < D; ++c) L::store(columns + c * pitch + i, x[c]);
  }
  for (; i < m; ++i)
    for (int c = 0; c < D; ++c) columns[c * pitch + i] = rows[D * i + c];
}

template <class B, int D>
void scatter_transposed(const ScalarOf<B>* __restrict columns, ScalarOf<B>* __restrict rows,
                        std::size_t m) {
  using L = Lanes<B>;
  constexpr std::size_t pitch = kTileRows<ScalarOf<B>>;
  std::size_t i = 0;
  for (; i + L::size <= m; i += L::size) {
    B y[D];
    for (int c = 0; c < D; ++c) y[c] = L::load(columns + c * pitch + i);
    RowTranspose<B, D>::store(y, rows + D * i);
  }
  for (; i < m; ++i)
    for (int c = 0; c < D; ++c) rows[D * i + c] = columns[c * pitch + i];
}

// The transpose passes of rows of D (the calls whose stages do not read or write the rows).
template <class B, int D>
constexpr void fill_transposes(StageKernels<ScalarOf<B>>& k) {
  using S = ScalarOf<B>;
  if constexpr (RowTranspose<B, D>::fused && !std::is_floating_point_v<B>) {
    k.gather[D] = &gather_transposed<B, D>;
    k.scatter[D] = &scatter_transposed<B, D>;
  } else {
    k.gather[D] = &gather_rows<S, D>;
    k.scatter[D] = &scatter_rows<S, D>;
  }
}

// The stages of parameterization P, at its index I in KernelParams; the decodes on vectors W.
template <class B, class W, class P, std::size_t I>
constexpr void fill_param_stages(StageKernels<ScalarOf<B>>& k) {
  k.decode[I][0] = &decode_stage<W, P, false>;
  k.decode[I][1] = &decode_stage<W, P, true>;
  k.encode[I][0] = &encode_stage<B, P, false>;
  k.encode[I][1] = &encode_stage<B, P, true>;
  k.jacobian[I][0] = &jacobian_stage<B, P, false>;
  k.jacobian[I][1] = &jacobian_stage<B, P, true>;
}

// B: the vector type of the stages; W: that of the decodes, which may be two vectors per step
// (Twin, batch_kernels_avx512.cpp).
template <class B, class W = B>
constexpr StageKernels<ScalarOf<B>> make_stages() {
  StageKernels<ScalarOf<B>> k{};
  k.width = Lanes<B>::size;
  k.check = &check_stage<B>;
  k.valid_bytes = &valid_bytes<ScalarOf<B>>;
  fill_transposes<B, 3>(k);
  fill_transposes<B, 4>(k);
  fill_transposes<B, 6>(k);
  k.fused_rows[3] = RowTranspose<B, 3>::fused;
  k.fused_rows[4] = RowTranspose<B, 4>::fused;
  k.fused_rows[6] = RowTranspose<B, 6>::fused;
  // The plan reads fused_rows for the whole table: the Twin stages must fuse the same widths.
  static_assert(RowTranspose<W, 4>::fused == RowTranspose<B, 4>::fused &&
                RowTranspose<W, 6>::fused == RowTranspose<B, 6>::fused);
  for_each_param(KernelParams{},
                 [&]<class P, std::size_t I>() { fill_param_stages<B, W, P, I>(k); });
  return k;
}

template <class BF, class BD, class WF = BF, class WD = BD>
constexpr KernelSet make_kernel_set(SimdIsa isa, std::string_view name) {
  return KernelSet{isa, name, make_stages<BF, WF>(), make_stages<BD, WD>()};
}

}  // namespace
}  // namespace halfback::detail
