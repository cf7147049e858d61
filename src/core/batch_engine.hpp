// Internals of the batch conversion engine (batch.cpp): the per-instruction-set kernel tables and
// the run-time choice between them. No xsimd here: the tables hold plain function pointers, and
// each instruction set's table is built in its own translation unit (batch_kernels_<isa>.cpp)
// compiled with that set's -m flags.
//
// A conversion runs in tiles of rows, in up to three stages on SoA columns, and a fourth when the
// measure is asked for:
//   check    (dirs input)   6 direction columns -> mask, accepted pair (NaN if invalid)
//   decode   (P input)      dim(P) columns -> 6 direction columns (NaN if invalid), mask
//   encode   (P output)     6 direction columns + mask -> dim(P) columns (NaN if invalid), mask;
//                           with a mask of kUnchecked (dirs input: a constant column) it does
//                           the check itself
//   jacobian (P in or out)  dim(P) columns -> J(q), not masked (the engine masks it)
// Masks are stored as T: 1 for a valid row, 0 otherwise. The Jacobian is a stage of its own rather
// than a variant of decode and encode so that those, the largest kernels, are compiled once.
//
// Row-major (NumPy C-order) inputs and outputs are transposed inside the stages' vector loops
// where the table says so (fused_rows): the first stage reads its D input values straight from
// the rows, the last one writes its D outputs as rows (StageRows). A transpose pass of its own
// over scratch (gather/scatter) cost as much as a third of a conversion at 10^7 pairs.

#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "halfback/core/parameterization.hpp"
#include "halfback/core/simd.hpp"

namespace halfback::detail {

using halfback::SimdIsa;

inline constexpr SimdIsa kAllIsas[] = {SimdIsa::scalar, SimdIsa::sse2, SimdIsa::avx2,
                                       SimdIsa::avx512};

// Rows per tile: a tile holds kTileBytes of each column (~20 columns stay in L1).
inline constexpr std::size_t kTileBytes = 2048;
template <class T>
inline constexpr std::size_t kTileRows = kTileBytes / sizeof(T);

// The mask value of a row of user-given directions that no stage has checked yet.
template <class T>
inline constexpr T kUnchecked = T(2);

// Where a stage reads its coordinates (or directions) and writes them, when not its column
// pointers: `in`, if set, holds the m rows of the stage's D input values (a row-major (m, D)
// array; the mask, if read, stays a column); `out`, if set, receives its D output values as rows.
template <class T>
struct StageRows {
  const T* in = nullptr;
  T* out = nullptr;
};

template <class T>
struct StageKernels {
  using CheckFn = void (*)(const T* const* in, T* const* copy, T* mask, std::size_t m,
                           StageRows<T> rows);
  using DecodeFn = void (*)(const T* const* in, T* const* dirs, T* mask, std::size_t m,
                            StageRows<T> rows);
  using EncodeFn = void (*)(const T* const* dirs, const T* mask_in, T* mask_out, T* const* out,
                            std::size_t m, StageRows<T> rows);
  using JacobianFn = void (*)(const T* const* coords, T* jac, std::size_t m);
  std::size_t width;  // lanes per vector
  CheckFn check;
  // [index in KernelParams][isotropic]
  DecodeFn decode[kKernelParamCount][2];
  EncodeFn encode[kKernelParamCount][2];
  JacobianFn jacobian[kKernelParamCount][2];
  // Transposes between m rows of D values (a row-major (m, D) array, such as a NumPy C-order
  // array) and D scratch columns spaced kTileRows<T> apart; [D] for D = 3, 4, 6, else null.
  using GatherFn = void (*)(const T* rows, T* columns, std::size_t m);
  using ScatterFn = void (*)(const T* columns, T* rows, std::size_t m);
  GatherFn gather[7];
  ScatterFn scatter[7];
  // Whether the check, decode and encode stages take rows of D values (StageRows) in their
  // vector loops, for D = 3, 4, 6; where not, the engine transposes with gather and scatter.
  bool fused_rows[7];
  // The mask column (1 or 0) as ConvertOutput::valid's bytes; here so that each table's compiler
  // flags vectorize it (built for the baseline, GCC compares one double at a time: 5 % of a
  // forward conversion in cache; docs/performance.md, "Conversions").
  using ValidFn = void (*)(const T* mask, std::uint8_t* valid, std::size_t m);
  ValidFn valid_bytes;
};

struct KernelSet {
  SimdIsa isa;
  std::string_view name;
  StageKernels<float> f32;
  StageKernels<double> f64;

  template <class T>
  const StageKernels<T>& stages() const {
    if constexpr (sizeof(T) == sizeof(float))
      return f32;
    else
      return f64;
  }
};

// One table per instruction set; the SIMD ones exist only in x86-64 builds.
const KernelSet& kernels_scalar();
const KernelSet& kernels_sse2();
const KernelSet& kernels_avx2();    // AVX2 + FMA
const KernelSet& kernels_avx512();  // AVX-512F (+ AVX2, FMA)

std::string_view isa_name(SimdIsa isa);
std::optional<SimdIsa> isa_from_name(std::string_view name);

// The table of `isa` when it is compiled in and this CPU (and OS) can run it, else nullptr.
const KernelSet* kernels_for(SimdIsa isa);

// The table convert() uses: the override if set, else HALFBACK_ISA from the environment (read
// once; scalar, sse2, avx2 or avx512; an unsupported one falls back to the best), else the best
// the CPU supports.
const KernelSet& active_kernels();

// For tests and benchmarks: forces an instruction set (nullopt: back to the default). Returns
// false, changing nothing, when `isa` is not available here. Not meant to race with convert().
bool set_batch_isa(std::optional<SimdIsa> isa);

// Outputs are written with plain stores by default. Non-temporal stores (outputs assembled in
// the tile's scratch, then copied past the caches) avoid the write-allocate reads of the output
// lines, but are slower on AMD Zen 5 and no faster on Intel (docs/performance.md, "Conversions"):
// the burst of copies at the end of each tile waits on the write-combining buffers, while plain
// stores overlap the kernels' arithmetic.
// For tests and benchmarks: forces non-temporal output stores on (true) or off (false);
// nullopt: the default (off). Not meant to race with convert().
void set_streaming_stores(std::optional<bool> on);

}  // namespace halfback::detail
