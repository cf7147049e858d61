// The batch conversion engine.
//
// Rows are processed in tiles of kTileBytes per column (512 float or 256 double rows). For each
// tile: input columns with stride 1 are read in place, others are gathered into SoA scratch; the
// stage kernels of batch_engine.hpp (check or decode, then encode) run on the tile; outputs with
// stride 1 are written in place, others scattered from scratch. A row-major (m, D) input or
// output (NumPy's C order) is read or written by the first or last stage itself, transposed in
// its vector loop, where the kernel table can (fused_rows), and else transposed in one pass. Tiles
// are grouped into chunks run by core's parallel_for on up to BatchOptions::threads threads. Every
// row is computed by the same vector code, in the same lane, whatever the chunking (tiles are whole
// multiples of every vector width), so the result does not depend on the thread count.
#include "halfback/core/batch.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>

#include "batch_engine.hpp"
#include "batch_registered.hpp"
#include "halfback/core/parallel.hpp"
#include "row_kernels.hpp"

namespace halfback {

// ---------------------------------------------------------------------------------------------
// Instruction-set dispatch
// ---------------------------------------------------------------------------------------------
namespace detail {

std::string_view isa_name(SimdIsa isa) {
  switch (isa) {
    case SimdIsa::scalar:
      return "scalar";
    case SimdIsa::sse2:
      return "sse2";
    case SimdIsa::avx2:
      return "avx2";
    case SimdIsa::avx512:
      return "avx512";
  }
  return "unknown";
}

std::optional<SimdIsa> isa_from_name(std::string_view name) {
  for (SimdIsa isa : kAllIsas)
    if (isa_name(isa) == name) return isa;
  return std::nullopt;
}

namespace {

#if defined(HALFBACK_X86_KERNELS)
bool cpu_supports(SimdIsa isa) {
  // __builtin_cpu_supports also checks that the OS saves the YMM/ZMM state (XGETBV).
  __builtin_cpu_init();
  switch (isa) {
    case SimdIsa::scalar:
    case SimdIsa::sse2:
      return true;  // x86-64 baseline
    case SimdIsa::avx2:
      return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    case SimdIsa::avx512:
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx2") &&
             __builtin_cpu_supports("fma");
  }
  return false;
}
#endif

const KernelSet* best_kernels() {
  for (auto it = std::rbegin(kAllIsas); it != std::rend(kAllIsas); ++it)
    if (const KernelSet* k = kernels_for(*it)) return k;
  return &kernels_scalar();
}

// The default table, and HALFBACK_ISA when it is set but not used (read once).
struct DefaultChoice {
  const KernelSet* kernels;
  std::string ignored_request;
};

const DefaultChoice& default_choice() {
  static const DefaultChoice chosen = []() -> DefaultChoice {
    const char* env = std::getenv("HALFBACK_ISA");
    if (!env) return {best_kernels(), {}};
    if (const auto isa = isa_from_name(env))
      if (const KernelSet* k = kernels_for(*isa)) return {k, {}};
    return {best_kernels(), env};
  }();
  return chosen;
}

const KernelSet& default_kernels() {
  return *default_choice().kernels;
}

std::atomic<const KernelSet*> g_override{nullptr};

}  // namespace

const KernelSet* kernels_for(SimdIsa isa) {
#if defined(HALFBACK_X86_KERNELS)
  if (!cpu_supports(isa)) return nullptr;
  switch (isa) {
    case SimdIsa::scalar:
      return &kernels_scalar();
    case SimdIsa::sse2:
      return &kernels_sse2();
    case SimdIsa::avx2:
      return &kernels_avx2();
    case SimdIsa::avx512:
      return &kernels_avx512();
  }
  return nullptr;
#else
  return isa == SimdIsa::scalar ? &kernels_scalar() : nullptr;
#endif
}

const KernelSet& active_kernels() {
  const KernelSet* k = g_override.load(std::memory_order_acquire);
  return k ? *k : default_kernels();
}

namespace {
std::atomic<bool> g_streaming{false};
}  // namespace

void set_streaming_stores(std::optional<bool> on) {
  g_streaming.store(on.value_or(false), std::memory_order_release);
}

// Whether convert() writes its outputs with non-temporal stores (off unless forced).
bool streaming_stores();
bool streaming_stores() {
  return g_streaming.load(std::memory_order_acquire);
}

bool set_batch_isa(std::optional<SimdIsa> isa) {
  if (!isa) {
    g_override.store(nullptr, std::memory_order_release);
    return true;
  }
  const KernelSet* k = kernels_for(*isa);
  if (!k) return false;
  g_override.store(k, std::memory_order_release);
  return true;
}

}  // namespace detail

SimdIsa simd_isa() {
  return detail::active_kernels().isa;
}

std::string_view simd_isa_name(SimdIsa isa) {
  return detail::isa_name(isa);
}

std::string_view simd_isa_request_ignored() {
  return detail::default_choice().ignored_request;
}

// ---------------------------------------------------------------------------------------------
// The tiled engine (the parameterizations of KernelParams; the others: batch_registered.cpp)
// ---------------------------------------------------------------------------------------------
namespace {

void check_shapes(Form from, Form to, std::size_t n_in, std::size_t n_out) {
  for (Form f : {from, to})
    if (!f.space.is_dirs()) (void)f.space.param();  // throws for an unknown space
  if (n_in != dimension(from))
    throw std::invalid_argument("convert: " + std::string(name_of(from.space)) + " needs " +
                                std::to_string(dimension(from)) + " input columns, got " +
                                std::to_string(n_in));
  if (n_out != dimension(to))
    throw std::invalid_argument("convert: " + std::string(name_of(to.space)) + " needs " +
                                std::to_string(dimension(to)) + " output columns, got " +
                                std::to_string(n_out));
  if ((from.space.is_dirs() && from.isotropic) || (to.space.is_dirs() && to.isotropic))
    throw std::invalid_argument("convert: dirs has no isotropic form");
}

using detail::kTileRows;
// A thread is worth starting only for this many tiles (~10^4 rows, tens of microseconds).
constexpr std::size_t kMinTilesPerThread = 32;

// The kernels and the column layout of one convert() call.
template <class T>
struct Plan {
  using Stages = detail::StageKernels<T>;
  Form from, to;
  std::size_t dim_in, dim_out;
  std::span<const ConstColumn<T>> in;
  const ConvertOutput<T>* out;
  bool want_jac;
  typename Stages::CheckFn check = nullptr;
  typename Stages::DecodeFn decode = nullptr;
  typename Stages::EncodeFn encode = nullptr;
  typename Stages::ValidFn valid_bytes;
  // The measure: of the output coordinates, or of the input ones when `to` is dirs; none (1 for a
  // valid row) when both are dirs.
  typename Stages::JacobianFn jacobian_in = nullptr, jacobian_out = nullptr;
  // Set when the input (output) columns are the fields of one row-major array of dimension(from)
  // (dimension(to)) values a row: moved by one vectorized transpose instead of per column.
  typename Stages::GatherFn gather = nullptr;
  typename Stages::ScatterFn scatter = nullptr;
  // Set instead when the stages read (write) those rows themselves: the Jacobian's stages read
  // columns, so a call that asks for it takes the transpose passes.
  bool rows_in = false, rows_out = false;

  // Outputs written with non-temporal stores (through scratch).
  bool stream;

  Plan(const Stages& k, Form f, Form t, std::span<const ConstColumn<T>> i,
       const ConvertOutput<T>& o, bool streaming_stores)
      : from(f),
        to(t),
        dim_in(dimension(f)),
        dim_out(dimension(t)),
        in(i),
        out(&o),
        valid_bytes(k.valid_bytes),
        stream(streaming_stores) {
    want_jac = o.jacobian.data != nullptr;
    const bool to_dirs = t.space.is_dirs();
    if (f.space.is_dirs()) {
      check = k.check;
    } else {
      decode = k.decode[f.space.kernel_index()][f.isotropic ? 1 : 0];
      if (want_jac && to_dirs)
        jacobian_in = k.jacobian[f.space.kernel_index()][f.isotropic ? 1 : 0];
    }
    if (!to_dirs) {
      encode = k.encode[t.space.kernel_index()][t.isotropic ? 1 : 0];
      if (want_jac) jacobian_out = k.jacobian[t.space.kernel_index()][t.isotropic ? 1 : 0];
    }
    const bool in_rows = interleaved(in);
    const bool out_rows = interleaved(std::span<const Column<T>>(o.columns));
    rows_in = in_rows && !want_jac && k.fused_rows[dim_in];
    rows_out = out_rows && !want_jac && k.fused_rows[dim_out];
    if (in_rows && !rows_in) gather = k.gather[dim_in];
    if (out_rows && !rows_out) scatter = k.scatter[dim_out];
  }

  // Whether column c is field c of one row-major array of columns.size() values a row.
  template <class C>
  static bool interleaved(std::span<const C> columns) {
    const auto d = static_cast<std::ptrdiff_t>(columns.size());
    for (std::ptrdiff_t c = 0; c < d; ++c)
      if (columns[c].stride != d || columns[c].data != columns[0].data + c) return false;
    return true;
  }
};

// The input mask of the encode stage for user-given directions: not yet checked (it checks them).
template <class T>
constexpr auto kUncheckedTile = [] {
  std::array<T, kTileRows<T>> column{};
  column.fill(detail::kUnchecked<T>);
  return column;
}();

// The measure where the mask is 1, NaN elsewhere; without a stage (dirs to dirs), 1.
template <class T>
void mask_jacobian(const T* mask, T* jac, std::size_t m, bool unit) {
  constexpr T nan = std::numeric_limits<T>::quiet_NaN();
  for (std::size_t i = 0; i < m; ++i) jac[i] = mask[i] > T(0) ? (unit ? T(1) : jac[i]) : nan;
}

// Scratch of one thread, reused by every call on it: allocating it per call would cost ~0.3 µs,
// which the renderer's and the RGL lookups' packets of 16 pairs would pay each time
// (docs/performance.md, "Conversions", "Small calls"). A call nested in another
// on the same thread (not done today: the tile loop calls nothing that could) gets its own.
class ScratchLease {
 public:
  static constexpr std::size_t kBytes = 20 * detail::kTileBytes;  // TileRunner's columns

  ScratchLease() {
    Slot& slot = this_thread();
    if (slot.busy) {
      spare_.reset(allocate());
      data_ = spare_.get();
      return;
    }
    if (!slot.buffer) slot.buffer.reset(allocate());
    slot.busy = true;
    held_ = &slot;
    data_ = slot.buffer.get();
  }
  ~ScratchLease() {
    if (held_) held_->busy = false;
  }
  ScratchLease(const ScratchLease&) = delete;
  ScratchLease& operator=(const ScratchLease&) = delete;

  std::byte* data() const { return data_; }

 private:
  struct Delete {
    void operator()(std::byte* p) const { ::operator delete[](p, std::align_val_t{64}); }
  };
  using Buffer = std::unique_ptr<std::byte[], Delete>;
  struct Slot {
    Buffer buffer;
    bool busy = false;
  };
  static std::byte* allocate() {
    return static_cast<std::byte*>(::operator new[](kBytes, std::align_val_t{64}));
  }
  static Slot& this_thread() {
    thread_local Slot slot;
    return slot;
  }

  Slot* held_ = nullptr;
  Buffer spare_;
  std::byte* data_ = nullptr;
};

// Copies n values with non-temporal stores where the destination's alignment allows (past the
// caches, without first reading the lines written); the caller fences (stream_fence) at the end.
template <class T>
void stream_copy(const T* src, T* dst, std::size_t n) {
  std::size_t i = 0;
#if defined(__SSE2__)
  constexpr std::size_t per = 16 / sizeof(T);
  if (reinterpret_cast<std::uintptr_t>(dst) % sizeof(T) == 0) {
    for (; i < n && reinterpret_cast<std::uintptr_t>(dst + i) % 16 != 0; ++i) dst[i] = src[i];
    for (; i + per <= n; i += per)
      _mm_stream_si128(reinterpret_cast<__m128i*>(dst + i),
                       _mm_loadu_si128(reinterpret_cast<const __m128i*>(src + i)));
  }
#endif
  if (i < n) std::memcpy(dst + i, src + i, (n - i) * sizeof(T));
}

void stream_fence() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

// The loop over the tiles of one chunk, on the thread's scratch.
template <class T>
class TileRunner {
 public:
  explicit TileRunner(const Plan<T>& plan)
      : plan_(plan), scratch_(reinterpret_cast<T*>(lease_.data())) {}

  void run(std::size_t r0, std::size_t m) {
    const Plan<T>& p = plan_;
    const auto base = static_cast<std::ptrdiff_t>(r0);
    const T* in[detail::kMaxDim] = {};
    detail::StageRows<T> rows;
    if (p.rows_in) rows.in = p.in[0].data + base * static_cast<std::ptrdiff_t>(p.dim_in);
    if (p.gather)
      p.gather(p.in[0].data + base * static_cast<std::ptrdiff_t>(p.dim_in), column(kInput), m);
    for (std::size_t c = 0; c < p.dim_in && !p.rows_in; ++c) {  // else the first stage reads rows
      const ConstColumn<T>& col = p.in[c];
      if (p.gather) {
        in[c] = column(kInput + c);
      } else if (col.stride == 1) {
        in[c] = col.data + base;
      } else {
        T* s = column(kInput + c);
        const T* src = col.data + base * col.stride;
        for (std::size_t i = 0; i < m; ++i) s[i] = src[static_cast<std::ptrdiff_t>(i) * col.stride];
        in[c] = s;
      }
    }
    // With non-temporal stores, every output is assembled in scratch first.
    const bool direct = !p.stream;
    T* out[detail::kMaxDim] = {};
    if (p.rows_out) rows.out = direct ? out_rows(r0) : column(kOutput);
    for (std::size_t c = 0; c < p.dim_out && !p.rows_out; ++c) {
      const Column<T>& col = p.out->columns[c];
      out[c] = col.stride == 1 && direct ? col.data + base : column(kOutput + c);
    }
    const Column<T>& jcol = p.out->jacobian;
    T* jac = nullptr;
    if (p.want_jac) jac = jcol.stride == 1 && direct ? jcol.data + base : column(kJacobian);
    T* mask = column(kMask);

    run_stages(in, out, jac, mask, m, rows);
    write_outputs(out, jac, mask, r0, m);
  }

 private:
  // Columns: 6 gathered inputs (also the staging of non-temporal row stores, once the stages have
  // read them), 6 outputs to scatter (or the staged rows the last stage writes, with non-temporal
  // stores), 6 directions, mask, jacobian.
  static constexpr std::size_t kInput = 0, kOutput = 6, kDirs = 12, kMask = 18, kJacobian = 19,
                               kColumns = 20;
  static_assert(kColumns * detail::kTileBytes <= ScratchLease::kBytes);
  T* column(std::size_t c) { return scratch_ + c * kTileRows<T>; }
  // The output rows of the tile at row r0 (a row-major output).
  T* out_rows(std::size_t r0) const {
    return plan_.out->columns[0].data + static_cast<std::ptrdiff_t>(r0 * plan_.dim_out);
  }

  // `rows`: the row-major input the first stage reads, the output rows the last one writes.
  void run_stages(const T* const* in, T* const* out, T* jac, T* mask, std::size_t m,
                  detail::StageRows<T> rows) {
    const Plan<T>& p = plan_;
    // The input's measure before decoding: `out` may share memory with `in`.
    if (jac && p.jacobian_in) p.jacobian_in(in, jac, m);
    if (p.check && !p.encode) {
      p.check(in, out, mask, m, rows);
    } else if (p.check) {
      p.encode(in, kUncheckedTile<T>.data(), mask, out, m, rows);  // it checks them itself
    } else if (!p.encode) {
      p.decode(in, out, mask, m, rows);
    } else {
      T* dirs[6];
      for (int c = 0; c < 6; ++c) dirs[c] = column(kDirs + c);
      p.decode(in, dirs, mask, m, {rows.in, nullptr});
      p.encode(dirs, mask, mask, out, m, {nullptr, rows.out});
    }
    if (jac && p.jacobian_out) p.jacobian_out(out, jac, m);
    if (jac) mask_jacobian(mask, jac, m, !p.jacobian_in && !p.jacobian_out);
  }

  void write_outputs(T* const* out, const T* jac, const T* mask, std::size_t r0, std::size_t m) {
    const Plan<T>& p = plan_;
    const auto base = static_cast<std::ptrdiff_t>(r0);
    if (p.rows_out) {
      if (p.stream) stream_copy(column(kOutput), out_rows(r0), m * p.dim_out);  // staged rows
    } else if (p.scatter) {
      T* rows = out_rows(r0);
      if (p.stream) {
        p.scatter(column(kOutput), column(kInput), m);
        stream_copy(column(kInput), rows, m * p.dim_out);
      } else {
        p.scatter(column(kOutput), rows, m);
      }
    } else {
      for (std::size_t c = 0; c < p.dim_out; ++c) write_column(p.out->columns[c], out[c], base, m);
    }
    if (jac) write_column(p.out->jacobian, jac, base, m);
    if (std::uint8_t* valid = p.out->valid) p.valid_bytes(mask, valid + r0, m);
  }

  // A column computed in scratch to its place (nothing to do when it was computed in place).
  void write_column(const Column<T>& col, const T* values, std::ptrdiff_t base, std::size_t m) {
    T* dst = col.data + base * col.stride;
    if (dst == values) return;
    if (col.stride == 1) {
      stream_copy(values, dst, m);
      return;
    }
    for (std::size_t i = 0; i < m; ++i)
      dst[static_cast<std::ptrdiff_t>(i) * col.stride] = values[i];
  }

  const Plan<T>& plan_;
  ScratchLease lease_;
  T* scratch_;
};

// Rows before the first tile, so that the other tiles start on a 64-byte line in every unit-stride
// column, when they all have the same offset in a line (arrays allocated alike: malloc's large
// blocks start 16 bytes into a page). Every whole-line vector then loads and stores one line
// instead of two: 3-4 % of a forward conversion at 10^7 pairs (docs/performance.md,
// "Conversions", "The aligning head"). 0 for a small batch (one more partial tile would cost more),
// for columns that disagree, and for row-major data (its rows are not lines).
template <class T>
std::size_t aligning_head(std::span<const ConstColumn<T>> in, const ConvertOutput<T>& out,
                          std::size_t n) {
  if (n < 16 * kTileRows<T>) return 0;
  constexpr std::uintptr_t kLine = 64, kNone = kLine;
  std::uintptr_t offset = kNone;
  bool agree = true;
  auto see = [&](const void* data, std::ptrdiff_t stride) {
    if (data == nullptr || stride != 1) return;
    const std::uintptr_t o = reinterpret_cast<std::uintptr_t>(data) % kLine;
    agree = agree && (offset == kNone || offset == o);
    offset = o;
  };
  for (const ConstColumn<T>& c : in) see(c.data, c.stride);
  for (const Column<T>& c : out.columns) see(c.data, c.stride);
  see(out.jacobian.data, out.jacobian.stride);
  if (!agree || offset == kNone || offset % sizeof(T) != 0) return 0;
  return (kLine - offset) % kLine / sizeof(T);
}

}  // namespace

template <class T>
void convert(Form from, Form to, std::span<const ConstColumn<T>> in, std::size_t n,
             const ConvertOutput<T>& out, const BatchOptions& options) {
  check_shapes(from, to, in.size(), out.columns.size());
  if (n == 0) return;
  const auto tabled = [](Form f) { return f.space.is_dirs() || f.space.has_kernels(); };
  if (!tabled(from) || !tabled(to))
    return detail::convert_registered(from, to, in, n, out, options);
  const Plan<T> plan(detail::active_kernels().stages<T>(), from, to, in, out,
                     detail::streaming_stores());

  // Tile t holds rows [t tile - shift, (t + 1) tile - shift) of [0, n): the first one is the
  // aligning head, if any.
  constexpr std::size_t tile = kTileRows<T>;
  const std::size_t head = aligning_head(in, out, n);
  const std::size_t shift = head == 0 ? 0 : tile - head;
  const std::size_t tiles = (n + shift + tile - 1) / tile;
  auto run_tiles = [&](std::size_t t0, std::size_t t1) {
    TileRunner<T> runner(plan);
    for (std::size_t t = t0; t < t1; ++t) {
      const std::size_t begin = std::max(t * tile, shift) - shift;
      runner.run(begin, std::min((t + 1) * tile - shift, n) - begin);
    }
    if (plan.stream) stream_fence();  // this thread's non-temporal stores, before it returns
  };

  // A small batch (the renderer's packets) stays on this thread without asking oneTBB.
  const std::size_t requested = tiles < 2 * kMinTilesPerThread && options.threads >= 0
                                    ? 1
                                    : static_cast<std::size_t>(thread_count(options.threads));
  const std::size_t threads = std::min(requested, tiles / kMinTilesPerThread);
  if (threads <= 1) {
    run_tiles(0, tiles);
    return;
  }
  // Several chunks per thread, so that a thread slowed down by other work is compensated.
  const std::size_t grain = std::max<std::size_t>(tiles / (threads * 8), 4);
  parallel_for(tiles, grain, run_tiles, static_cast<int>(threads));
}

template <class T>
bool convert_one(Form from, Form to, std::span<const T> in, std::span<T> out, T* jacobian) {
  check_shapes(from, to, in.size(), out.size());
  return detail::convert_row(from, to, in.data(), out.data(), jacobian);
}

template void convert<float>(Form, Form, std::span<const ConstColumn<float>>, std::size_t,
                             const ConvertOutput<float>&, const BatchOptions&);
template void convert<double>(Form, Form, std::span<const ConstColumn<double>>, std::size_t,
                              const ConvertOutput<double>&, const BatchOptions&);
template bool convert_one<float>(Form, Form, std::span<const float>, std::span<float>, float*);
template bool convert_one<double>(Form, Form, std::span<const double>, std::span<double>, double*);

}  // namespace halfback
