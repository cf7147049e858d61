// halfback_bench: batch conversion throughput (docs/performance.md).
//
// For every parameterization P, float and double, over kPairs (10^7 by default) SoA rows:
//   forward/P/T/threads:k   convert(dirs -> P), the engine, k = 1 or all hardware threads
//   inverse/P/T/threads:k   convert(P -> dirs)
//   scalar_forward/P/T      a straightforward per-pair loop through a virtual, parameterization-
//   scalar_inverse/P/T      generic interface with std math (the baseline of the speed-up)
//   plainstores/DIR/P/T     forward/inverse on one thread with the outputs' non-temporal stores
//   ntstores/DIR/P/T        forced off / on (by default: off)
//   packets/forward/spherical/T/k  the first 65536 rows in calls of k rows (16: the renderer's
//                           packets; 65536: one call)
//   stream/6to4/T/threads:k a plain triad moving the same bytes per pair as forward (6 columns
//   stream/4to6/T/threads:k in, 4 out) or inverse, over arrays of the same size: the memory bound
// plus, for one conversion, every instruction set (isa/...), and row-major (N, 6)/(N, 4) input and
// output against SoA columns, interleaved in one benchmark (layout/...: rows_over_soa).
// Timing: CPU time of the calling thread for one-thread runs (the machine is shared: wall time
// would count the other processes), wall time and the process's CPU time for threads:k > 1.
// Counters: s_per_pair (displayed with an SI prefix, e.g. 2.1n = 2.1 ns per pair),
// bytes_per_second (input + output bytes per pair); for the conversions also faults (page faults
// per iteration: none once the outputs are touched), sys_ms (system CPU time per iteration) and,
// on one thread, x_stream: the CPU time per pair over that of the triad of the same direction,
// timed right after the benchmark (the best of two passes), so that the ratio to the streaming
// bound holds under the same load. HALFBACK_BENCH_PAIRS overrides the size.
#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "core/batch_engine.hpp"
#include "core/row_kernels.hpp"
#include "halfback/core/batch.hpp"

namespace halfback {
namespace {

std::size_t pair_count() {
  if (const char* env = std::getenv("HALFBACK_BENCH_PAIRS")) return std::strtoull(env, nullptr, 10);
  return 10'000'000;
}

template <class T>
using Columns = std::vector<std::vector<T>>;

// The data of one precision: random valid pairs (uniform in solid angle), their coordinates in
// every parameterization (to time the inverse on valid input), and an output buffer.
template <class T>
struct Data {
  std::size_t n;
  Columns<T> dirs, out;
  std::vector<std::uint8_t> valid;
  std::vector<Columns<T>> coords;  // [space - 1]

  explicit Data(std::size_t rows) : n(rows), dirs(6, std::vector<T>(rows)), out(6), valid(rows) {
    for (auto& c : out) c.assign(rows, T(0));
    std::mt19937_64 rng(2024);
    std::uniform_real_distribution<double> u(0, 1);
    for (std::size_t r = 0; r < rows; ++r) {
      double w[6];
      for (int k = 0; k < 2; ++k) {
        const double z = u(rng), phi = 2 * std::numbers::pi * u(rng);
        const double s = std::sqrt((1 - z) * (1 + z));
        w[3 * k] = s * std::cos(phi);
        w[3 * k + 1] = s * std::sin(phi);
        w[3 * k + 2] = z;
      }
      for (int c = 0; c < 6; ++c) dirs[c][r] = static_cast<T>(w[c]);
    }
    for (Space s : kKernelSpaces) {
      Columns<T> q(4, std::vector<T>(rows));
      std::vector<ConstColumn<T>> ic;
      for (const auto& c : dirs) ic.push_back({c.data(), 1});
      std::vector<Column<T>> oc;
      for (auto& c : q) oc.push_back({c.data(), 1});
      convert<T>({Space::dirs, false}, {s, false}, ic, rows, {oc, {}, valid.data()});
      coords.push_back(std::move(q));
    }
  }

  static Data& get() {
    static Data data = [] {
      Data d(pair_count());
      d.warm_up();
      return d;
    }();
    return data;
  }

  // One untimed pass writing the outputs: the first benchmark of a process otherwise ran its
  // first iteration 5-10x slower (seen on the AMD VM, with no page faults counted), and with one
  // iteration in its time budget reported that alone.
  void warm_up() {
    std::vector<ConstColumn<T>> ic;
    for (const auto& c : dirs) ic.push_back({c.data(), 1});
    std::vector<Column<T>> oc;
    for (std::size_t c = 0; c < 4; ++c) oc.push_back({out[c].data(), 1});
    convert<T>({Space::dirs, false}, {space_of<Ortho>, false}, ic, n, {oc, {}, valid.data()});
  }
};

std::string type_name(float) {
  return "float";
}
std::string type_name(double) {
  return "double";
}

unsigned all_threads() {
  return static_cast<unsigned>(tbb::info::default_concurrency());
}

template <class T>
void set_counters(benchmark::State& state, std::size_t n, std::size_t columns) {
  const double pairs = static_cast<double>(n) * static_cast<double>(state.iterations());
  state.counters["s_per_pair"] =
      benchmark::Counter(pairs, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.SetBytesProcessed(static_cast<std::int64_t>(pairs * columns * sizeof(T)));
}

// CPU time of the calling thread, in seconds.
double thread_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Page faults and system time of the process, sampled around a benchmark's loop.
struct Usage {
  double faults, sys_s;
  static Usage now() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return {
        static_cast<double>(u.ru_minflt + u.ru_majflt),
        static_cast<double>(u.ru_stime.tv_sec) + 1e-6 * static_cast<double>(u.ru_stime.tv_usec)};
  }
};

template <class T>
double stream_seconds_per_pair(bool forward);

// --- the engine ---------------------------------------------------------------------------

template <class T>
void bm_convert(benchmark::State& state, Space space, bool forward, unsigned threads) {
  Data<T>& d = Data<T>::get();
  const Form dirs{Space::dirs, false}, param{space, false};
  const Columns<T>& src = forward ? d.dirs : d.coords[space.kernel_index()];
  std::vector<ConstColumn<T>> ic;
  for (const auto& c : src) ic.push_back({c.data(), 1});
  std::vector<Column<T>> oc;
  for (std::size_t c = 0; c < (forward ? 4u : 6u); ++c) oc.push_back({d.out[c].data(), 1});
  const ConvertOutput<T> out{oc, {}, d.valid.data()};
  const Usage u0 = Usage::now();
  const double t0 = thread_seconds();
  for (auto _ : state) {
    convert<T>(forward ? dirs : param, forward ? param : dirs, ic, d.n, out, {int(threads)});
    benchmark::ClobberMemory();
  }
  const double cpu = thread_seconds() - t0;
  const Usage u1 = Usage::now();
  set_counters<T>(state, d.n, 10);
  const auto iterations = static_cast<double>(state.iterations());
  state.counters["faults"] = (u1.faults - u0.faults) / iterations;
  state.counters["sys_ms"] = 1e3 * (u1.sys_s - u0.sys_s) / iterations;
  if (threads == 1)
    state.counters["x_stream"] =
        cpu / (iterations * static_cast<double>(d.n)) / stream_seconds_per_pair<T>(forward);
}

// The same conversion with the input and the output as row-major arrays ((N, 6) and (N, 4),
// NumPy's default C order) and as structure-of-arrays columns, interleaved: each iteration
// converts once in each layout (in alternating order), timed apart by the thread's CPU time, so
// that both see the same state of a shared host (on the AMD VM its memory bandwidth moved by up
// to 1.5x between runs, and medians of separate benchmarks compared different states of it).
// Counters: soa and rows (the least time a pair of either), rows_over_soa (their ratio) and
// rows_over_soa_med (the median of the iterations' own ratios).
template <class T>
void bm_layout(benchmark::State& state, Space space, bool forward) {
  Data<T>& d = Data<T>::get();
  const Columns<T>& src = forward ? d.dirs : d.coords[space.kernel_index()];
  const std::size_t nin = forward ? 6 : 4, nout = forward ? 4 : 6;
  std::vector<T> in_rows(nin * d.n), out_rows(nout * d.n, T(0));
  for (std::size_t r = 0; r < d.n; ++r)
    for (std::size_t c = 0; c < nin; ++c) in_rows[nin * r + c] = src[c][r];
  std::vector<ConstColumn<T>> rows_in, soa_in;
  std::vector<Column<T>> rows_out, soa_out;
  for (std::size_t c = 0; c < nin; ++c) {
    rows_in.push_back({in_rows.data() + c, static_cast<std::ptrdiff_t>(nin)});
    soa_in.push_back({src[c].data(), 1});
  }
  for (std::size_t c = 0; c < nout; ++c) {
    rows_out.push_back({out_rows.data() + c, static_cast<std::ptrdiff_t>(nout)});
    soa_out.push_back({d.out[c].data(), 1});
  }
  const Form dirs{Space::dirs, false}, param{space, false};
  auto seconds = [&](bool rows) {
    const double t0 = thread_seconds();
    convert<T>(forward ? dirs : param, forward ? param : dirs, rows ? rows_in : soa_in, d.n,
               {rows ? rows_out : soa_out, {}, d.valid.data()}, {1});
    benchmark::ClobberMemory();
    return thread_seconds() - t0;
  };
  std::vector<double> soa, rows;
  for (auto _ : state) {
    const bool rows_first = soa.size() % 2 == 1;
    const double first = seconds(rows_first), second = seconds(!rows_first);
    soa.push_back(rows_first ? second : first);
    rows.push_back(rows_first ? first : second);
    state.SetIterationTime(first + second);
  }
  if (soa.empty()) return;
  std::vector<double> ratio(soa.size());
  for (std::size_t i = 0; i < soa.size(); ++i) ratio[i] = rows[i] / soa[i];
  const auto n = static_cast<double>(d.n);
  const double soa_min = *std::min_element(soa.begin(), soa.end());
  const double rows_min = *std::min_element(rows.begin(), rows.end());
  std::sort(ratio.begin(), ratio.end());
  state.counters["soa"] = soa_min / n;
  state.counters["rows"] = rows_min / n;
  state.counters["rows_over_soa"] = rows_min / soa_min;
  state.counters["rows_over_soa_med"] = ratio[ratio.size() / 2];
}

// The same with the outputs' non-temporal stores forced off (on): what they change, measured in
// the same run (by default they are off).
template <class T>
void bm_stores(benchmark::State& state, Space space, bool forward, bool streaming) {
  detail::set_streaming_stores(streaming);
  bm_convert<T>(state, space, forward, 1);
  detail::set_streaming_stores(std::nullopt);
}

// The first 65536 rows (SoA, forward) converted in calls of `packet` rows, as the renderer and the
// RGL lookups do with 16: the per-call cost against one call over all of them (packet = 65536).
template <class T>
void bm_packets(benchmark::State& state, Space space, std::size_t packet) {
  Data<T>& d = Data<T>::get();
  const std::size_t n = std::min<std::size_t>(d.n, 65536);
  const Form dirs{Space::dirs, false}, param{space, false};
  for (auto _ : state) {
    for (std::size_t r0 = 0; r0 < n; r0 += packet) {
      const std::size_t m = std::min(packet, n - r0);
      ConstColumn<T> ic[6];
      for (int c = 0; c < 6; ++c) ic[c] = {d.dirs[c].data() + r0, 1};
      Column<T> oc[4];
      for (int c = 0; c < 4; ++c) oc[c] = {d.out[c].data() + r0, 1};
      convert<T>(dirs, param, ic, m, {oc, {}, d.valid.data() + r0}, {1});
    }
    benchmark::ClobberMemory();
  }
  set_counters<T>(state, n, 10);
}

template <class T>
void bm_isa(benchmark::State& state, detail::SimdIsa isa, Space space, bool forward) {
  if (!detail::set_batch_isa(isa)) {
    state.SkipWithError("instruction set not available");
    return;
  }
  bm_convert<T>(state, space, forward, 1);
  detail::set_batch_isa(std::nullopt);
}

// --- the scalar baseline: per pair, virtual, std math ------------------------------------------

template <class T>
class VirtualParam {
 public:
  virtual ~VirtualParam() = default;
  // Coordinates of a pair (NaN and false when the pair is not a valid one).
  virtual bool forward(const DirPair<T>& p, T* q) const = 0;
  // The pair with coordinates q (NaN and false outside the domain).
  virtual bool inverse(const T* q, DirPair<T>& p) const = 0;
};

template <class P, class T>
class VirtualParamOf final : public VirtualParam<T> {
 public:
  bool forward(const DirPair<T>& p, T* q) const override {
    if (!detail::pair_is_valid(p)) {
      for (int i = 0; i < 4; ++i) q[i] = std::numeric_limits<T>::quiet_NaN();
      return false;
    }
    const Tuple4<T> t = P::forward(p);
    for (int i = 0; i < 4; ++i) q[i] = t[i];
    return true;
  }
  bool inverse(const T* q, DirPair<T>& p) const override {
    const Solved<T> s = halfback::inverse<P>(Tuple4<T>{q[0], q[1], q[2], q[3]});
    p = s.pair;
    return s.in_domain;
  }
};

template <class T>
std::unique_ptr<VirtualParam<T>> make_parameterization(Space space) {
  return visit_kernel_param(space.kernel_index(), [](auto p) -> std::unique_ptr<VirtualParam<T>> {
    return std::make_unique<VirtualParamOf<decltype(p), T>>();
  });
}

template <class T>
void bm_scalar(benchmark::State& state, Space space, bool forward) {
  Data<T>& d = Data<T>::get();
  std::unique_ptr<VirtualParam<T>> param = make_parameterization<T>(space);
  const VirtualParam<T>* pp = param.get();
  benchmark::DoNotOptimize(pp);  // keep the call virtual
  const Columns<T>& q = d.coords[space.kernel_index()];
  for (auto _ : state) {
    for (std::size_t i = 0; i < d.n; ++i) {
      if (forward) {
        const DirPair<T> p{{d.dirs[0][i], d.dirs[1][i], d.dirs[2][i]},
                           {d.dirs[3][i], d.dirs[4][i], d.dirs[5][i]}};
        T r[4];
        d.valid[i] = pp->forward(p, r);
        for (int c = 0; c < 4; ++c) d.out[c][i] = r[c];
      } else {
        const T in[4] = {q[0][i], q[1][i], q[2][i], q[3][i]};
        DirPair<T> p;
        d.valid[i] = pp->inverse(in, p);
        d.out[0][i] = p.wi.x;
        d.out[1][i] = p.wi.y;
        d.out[2][i] = p.wi.z;
        d.out[3][i] = p.wo.x;
        d.out[4][i] = p.wo.y;
        d.out[5][i] = p.wo.z;
      }
    }
    benchmark::ClobberMemory();
  }
  set_counters<T>(state, d.n, 10);
}

// --- the streaming bound ------------------------------------------------------------------

// A triad that reads the `in` columns and writes the `out` columns once per pair, like convert():
// 6 -> 4 (forward) or 4 -> 6 (inverse).
template <class T>
void stream_rows(const Columns<T>& a, Columns<T>& o, std::size_t nin, std::size_t nout,
                 std::size_t begin, std::size_t end) {
  const T s = T(0.5);
  if (nin == 6) {
    const T *a0 = a[0].data(), *a1 = a[1].data(), *a2 = a[2].data(), *a3 = a[3].data(),
            *a4 = a[4].data(), *a5 = a[5].data();
    T *o0 = o[0].data(), *o1 = o[1].data(), *o2 = o[2].data(), *o3 = o[3].data();
    for (std::size_t i = begin; i < end; ++i) {
      o0[i] = a0[i] + s * a4[i];
      o1[i] = a1[i] + s * a5[i];
      o2[i] = a2[i] * s;
      o3[i] = a3[i] * s;
    }
  } else {
    const T *a0 = a[0].data(), *a1 = a[1].data(), *a2 = a[2].data(), *a3 = a[3].data();
    T *o0 = o[0].data(), *o1 = o[1].data(), *o2 = o[2].data(), *o3 = o[3].data(), *o4 = o[4].data(),
      *o5 = o[5].data();
    for (std::size_t i = begin; i < end; ++i) {
      o0[i] = a0[i] * s;
      o1[i] = a1[i] * s;
      o2[i] = a2[i] * s;
      o3[i] = a3[i] * s;
      o4[i] = a0[i] + a1[i];
      o5[i] = a2[i] + a3[i];
    }
  }
  (void)nout;
}

// One thread's CPU time per pair of the triad, the best of two passes.
template <class T>
double stream_seconds_per_pair(bool forward) {
  Data<T>& d = Data<T>::get();
  const Columns<T>& src = forward ? d.dirs : d.coords[0];
  double best = 0;
  for (int pass = 0; pass < 2; ++pass) {
    const double t0 = thread_seconds();
    stream_rows(src, d.out, forward ? 6 : 4, forward ? 4 : 6, 0, d.n);
    benchmark::ClobberMemory();
    const double t = thread_seconds() - t0;
    best = pass == 0 ? t : std::min(best, t);
  }
  return best / static_cast<double>(d.n);
}

template <class T>
void bm_stream(benchmark::State& state, bool forward, unsigned threads) {
  Data<T>& d = Data<T>::get();
  const Columns<T>& src = forward ? d.dirs : d.coords[0];
  const std::size_t nin = forward ? 6 : 4, nout = forward ? 4 : 6;
  tbb::task_arena arena(static_cast<int>(threads));
  for (auto _ : state) {
    if (threads == 1) {
      stream_rows(src, d.out, nin, nout, 0, d.n);
    } else {
      arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, d.n, 1 << 16),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                            stream_rows(src, d.out, nin, nout, r.begin(), r.end());
                          });
      });
    }
    benchmark::ClobberMemory();
  }
  set_counters<T>(state, d.n, 10);
}

// One thread: its CPU time. Several: wall time (the rate), and the process's CPU time beside it.
void (*timing(unsigned threads))(benchmark::internal::Benchmark*) {
  if (threads == 1)
    return [](benchmark::internal::Benchmark* b) { b->Unit(benchmark::kMillisecond); };
  return [](benchmark::internal::Benchmark* b) {
    b->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();
  };
}

template <class T>
void register_all() {
  const std::string t = type_name(T{});
  const unsigned all = all_threads();
  std::vector<unsigned> thread_counts{1};
  if (all > 1) thread_counts.push_back(all);
  for (bool forward : {true, false}) {
    const std::string dir = forward ? "forward" : "inverse";
    for (Space s : kKernelSpaces) {
      const std::string p(name_of(s));
      for (unsigned k : thread_counts)
        benchmark::RegisterBenchmark(
            (dir + "/" + p + "/" + t + "/threads:" + std::to_string(k)).c_str(),
            [=](benchmark::State& st) { bm_convert<T>(st, s, forward, k); })
            ->Apply(timing(k));
      for (bool streaming : {false, true})
        benchmark::RegisterBenchmark(
            ((streaming ? "ntstores/" : "plainstores/") + dir + "/" + p + "/" + t).c_str(),
            [=](benchmark::State& st) { bm_stores<T>(st, s, forward, streaming); })
            ->Apply(timing(1));
      benchmark::RegisterBenchmark(("scalar_" + dir + "/" + p + "/" + t).c_str(),
                                   [=](benchmark::State& st) { bm_scalar<T>(st, s, forward); })
          ->Unit(benchmark::kMillisecond);
    }
    for (unsigned k : thread_counts)
      benchmark::RegisterBenchmark(
          ((forward ? "stream/6to4/" : "stream/4to6/") + t + "/threads:" + std::to_string(k))
              .c_str(),
          [=](benchmark::State& st) { bm_stream<T>(st, forward, k); })
          ->Apply(timing(k));
  }
  for (detail::SimdIsa isa : detail::kAllIsas)
    for (bool forward : {true, false})
      benchmark::RegisterBenchmark(
          (std::string("isa/") + (forward ? "forward" : "inverse") + "/halfdiff/" + t + "/" +
           std::string(detail::isa_name(isa)))
              .c_str(),
          [=](benchmark::State& st) { bm_isa<T>(st, isa, space_of<HalfDiff>, forward); })
          ->Unit(benchmark::kMillisecond);
  for (std::size_t packet : {std::size_t{16}, std::size_t{65536}})
    benchmark::RegisterBenchmark(
        ("packets/forward/spherical/" + t + "/" + std::to_string(packet)).c_str(),
        [=](benchmark::State& st) { bm_packets<T>(st, space_of<Spherical>, packet); })
        ->Apply(timing(1));
  for (Space s : {space_of<Spherical>, space_of<HalfDiff>, space_of<Ortho>, space_of<Hybrid>})
    for (bool forward : {true, false})
      benchmark::RegisterBenchmark((std::string("layout/") + (forward ? "forward/" : "inverse/") +
                                    std::string(name_of(s)) + "/" + t)
                                       .c_str(),
                                   [=](benchmark::State& st) { bm_layout<T>(st, s, forward); })
          ->UseManualTime()
          ->MinTime(1.0)
          ->Unit(benchmark::kMillisecond);
}

}  // namespace
}  // namespace halfback

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  halfback::register_all<float>();
  halfback::register_all<double>();
  benchmark::AddCustomContext("halfback_isa", std::string(halfback::detail::active_kernels().name));
  benchmark::AddCustomContext("pairs", std::to_string(halfback::pair_count()));
  benchmark::AddCustomContext("threads_all", std::to_string(halfback::all_threads()));
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
