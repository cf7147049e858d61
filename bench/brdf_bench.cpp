// Measured-BRDF evaluation throughput (docs/performance.md, "Measured lookups"):
//   MERL nearest-bin and trilinear lookups, per pair, and batched on one core, against a
//   straightforward per-pair implementation of the MERL reference lookup (acos-based half/diff
//   angles, Rodrigues rotations: src/formats/merl_reference.hpp) measured in the same run;
//   RGL evaluations (../shared/data/rgl, skipped when absent), against RGL's own loader when the
//   build is given a checkout of it (-DHALFBACK_RGL_REFERENCE_DIR=...); ALTA scattered data.
//   The *_Threads/1 and /2 benchmarks run eval_batch in an arena of 1 or 2 threads and report wall
//   time (and the process's CPU time, and their ratio: the threads kept busy), for the 2-thread
//   speed-up: only meaningful on an otherwise idle machine (--benchmark_filter='_Threads/').
//   The MerlFloor_* benchmarks time the parts of a MERL batch apart, on the same pairs: the SIMD
//   conversion alone, and the table reads alone (and the trilinear blends) at precomputed bins
//   and cells, on a table of the same layout and pages: what the batch cannot go below.
// Every benchmark processes the same 65536 random direction pairs (fixed seed); items/s counts
// pairs.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <sys/mman.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <numbers>
#include <random>
#include <span>
#include <vector>

#include "bench_brdfs.hpp"
#include "formats/merl_kernel.hpp"
#include "formats/merl_reference.hpp"
#include "halfback/brdf/albedo.hpp"
#include "halfback/core/batch.hpp"
#include "halfback/formats/alta.hpp"
#include "halfback/formats/merl.hpp"
#include "halfback/formats/rgl.hpp"
#include "halfback/loader/load.hpp"

#if defined(HALFBACK_RGL_REFERENCE)
#define POWITACQ_IMPLEMENTATION
#include <powitacq_rgb.h>
#endif

namespace {

using namespace halfback;

constexpr std::size_t kPairs = 1 << 16;

const std::vector<DirPair<double>>& pairs() {
  static const std::vector<DirPair<double>> v = [] {
    std::mt19937_64 rng(2015);
    std::uniform_real_distribution<double> u(0, 1);
    auto dir = [&] {
      const double z = u(rng), phi = 2 * std::numbers::pi * u(rng), s = std::sqrt(1 - z * z);
      return Vec3<double>{s * std::cos(phi), s * std::sin(phi), z};
    };
    std::vector<DirPair<double>> p(kPairs);
    for (auto& x : p) x = {dir(), dir()};
    return p;
  }();
  return v;
}

const MerlData& merl_data() {
  static const MerlData d = tabulate_merl(bench::Lobe{});
  return d;
}

void run_single(benchmark::State& state, const Brdf& brdf) {
  const auto& p = pairs();
  for (auto _ : state) {
    double sum = 0;
    for (const auto& x : p) sum += brdf.eval(x).g;
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * p.size()));
}

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// eval_batch in an arena of state.range(0) threads, for wall time (UseRealTime). The counter
// "busy_threads" is the process's CPU time over the wall time of the loop: about 2 when two
// threads share the work on an idle machine, less when the machine's load delays one of them.
void run_threads(benchmark::State& state, const Brdf& brdf) {
  const auto& p = pairs();
  std::vector<Rgb> out(p.size());
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  const double cpu0 = process_cpu_seconds();
  const auto wall0 = std::chrono::steady_clock::now();
  for (auto _ : state) {
    arena.execute([&] { brdf.eval_batch(p, out); });
    benchmark::DoNotOptimize(out.data());
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  state.counters["busy_threads"] = wall > 0 ? (process_cpu_seconds() - cpu0) / wall : 0;
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * p.size()));
}

// eval_batch in a one-thread arena: one core (CPU time = wall time of that thread).
void run_batch_one_core(benchmark::State& state, const Brdf& brdf) {
  const auto& p = pairs();
  std::vector<Rgb> out(p.size());
  tbb::task_arena one_core(1);
  for (auto _ : state) {
    one_core.execute([&] { brdf.eval_batch(p, out); });
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * p.size()));
}

// docs/reliability/numerics.md, "Directional albedo: bounded memory, and multiple importance
// sampling": the directional albedo of GGX α = 0.05 at θi = 75°, n = 64, by cosine sampling (the
// baseline) and with MIS. Counters: the standard error and SE² × seconds (the variance at equal
// time: the ratio of the two rows is MIS's gain; the target is ≥ 100, i.e. an SE 10× lower at equal
// time). The estimate is kept in a struct (GCC 12 + Benchmark 1.7's DoNotOptimize(double) was seen
// to corrupt a value).
void albedo_at_75(benchmark::State& state, AlbedoSampling sampling) {
  const BrdfPtr ggx = load_brdf("ggx:alpha=0.05,f0=0.9");
  const double t = 75 * std::numbers::pi / 180;
  AlbedoEstimate a;
  std::uint64_t seed = 1;
  for (auto _ : state) {
    a = directional_albedo(*ggx, {std::sin(t), 0, std::cos(t)}, 64, seed++, sampling);
    benchmark::DoNotOptimize(a);
  }
  state.counters["standard_error"] = a.standard_error.g;
  state.counters["mean"] = a.mean.g;
}
void BM_AlbedoGgx75_Cosine(benchmark::State& state) {
  albedo_at_75(state, AlbedoSampling::cosine);
}
void BM_AlbedoGgx75_Mis(benchmark::State& state) {
  albedo_at_75(state, AlbedoSampling::mis);
}
BENCHMARK(BM_AlbedoGgx75_Cosine)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_AlbedoGgx75_Mis)->Unit(benchmark::kMicrosecond);

void BM_MerlReference_OneThread(benchmark::State& state) {
  const auto& p = pairs();
  const double* values = merl_data().values.data();
  for (auto _ : state) {
    double sum = 0;
    for (const auto& x : p) {
      double r, g, b;
      merl_reference::lookup(values, {x.wi.x, x.wi.y, x.wi.z}, {x.wo.x, x.wo.y, x.wo.z}, r, g, b);
      sum += g;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * p.size()));
}
BENCHMARK(BM_MerlReference_OneThread)->Unit(benchmark::kMillisecond);

void BM_MerlNearest_OneThread(benchmark::State& state) {
  static const MerlBrdf brdf(merl_data(), {MerlLookup::nearest});
  run_single(state, brdf);
}
BENCHMARK(BM_MerlNearest_OneThread)->Unit(benchmark::kMillisecond);

void BM_MerlNearest_BatchOneCore(benchmark::State& state) {
  static const MerlBrdf brdf(merl_data(), {MerlLookup::nearest});
  run_batch_one_core(state, brdf);
}
BENCHMARK(BM_MerlNearest_BatchOneCore)->Unit(benchmark::kMillisecond);

void BM_MerlNearest_Threads(benchmark::State& state) {
  static const MerlBrdf brdf(merl_data(), {MerlLookup::nearest});
  run_threads(state, brdf);
}
BENCHMARK(BM_MerlNearest_Threads)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();

void BM_MerlTrilinear_OneThread(benchmark::State& state) {
  static const MerlBrdf brdf(merl_data(), {MerlLookup::trilinear});
  run_single(state, brdf);
}
BENCHMARK(BM_MerlTrilinear_OneThread)->Unit(benchmark::kMillisecond);

void BM_MerlTrilinear_BatchOneCore(benchmark::State& state) {
  static const MerlBrdf brdf(merl_data(), {MerlLookup::trilinear});
  run_batch_one_core(state, brdf);
}
BENCHMARK(BM_MerlTrilinear_BatchOneCore)->Unit(benchmark::kMillisecond);

void BM_MerlTrilinear_Threads(benchmark::State& state) {
  static const MerlBrdf brdf(merl_data(), {MerlLookup::trilinear});
  run_threads(state, brdf);
}
BENCHMARK(BM_MerlTrilinear_Threads)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();

// --- The floors of the MERL batch: its parts timed apart ---

// The batch's table layout (one 32-byte slot a bin, on 2 MB pages when the kernel gives them),
// filled from the same data.
const merl::BinValues* floor_table() {
  static const merl::BinValues* t = [] {
    constexpr std::size_t kPage = std::size_t(2) << 20;
    const std::size_t bytes = (merl::kBins * sizeof(merl::BinValues) + kPage - 1) / kPage * kPage;
    auto* p = static_cast<merl::BinValues*>(std::aligned_alloc(kPage, bytes));
    madvise(p, bytes, MADV_HUGEPAGE);
    const auto& v = merl_data().values;
    for (std::size_t i = 0; i < merl::kBins; ++i)
      p[i] = {{v[i], v[i + merl::kBins], v[i + 2 * merl::kBins], 0.0}};
    return p;  // kept for the whole run
  }();
  return t;
}

// The bins and cells of the pairs, as eval() finds them.
const std::vector<std::uint32_t>& floor_bins() {
  static const std::vector<std::uint32_t> b = [] {
    std::vector<std::uint32_t> b;
    for (const auto& x : pairs()) {
      const Tuple4<double> q = HalfDiff::forward(x);
      b.push_back(merl_kernel::nearest_bin(q[0], q[2], q[3]));
    }
    return b;
  }();
  return b;
}

const std::vector<merl_kernel::Cells>& floor_cells() {
  static const std::vector<merl_kernel::Cells> c = [] {
    std::vector<merl_kernel::Cells> c(kPairs / merl_kernel::kBlock);
    for (std::size_t i = 0; i < kPairs; ++i) {
      const Tuple4<double> q = HalfDiff::forward(pairs()[i]);
      const merl_kernel::Cell cell = merl_kernel::cell_of(q[0], q[2], q[3]);
      auto& block = c[i / merl_kernel::kBlock];
      const std::size_t k = i % merl_kernel::kBlock;
      block.base[k] = cell.base;
      block.phi_step[k] = cell.phi_step;
      for (int a = 0; a < 3; ++a) block.t[a][k] = cell.t[a];
    }
    return c;
  }();
  return c;
}

// The conversion alone, as eval_batch calls it: blocks of state.range(0) rows (256: the batch's
// blocks; 32: the cost of smaller calls, for a pipeline that would interleave them with the table
// reads) read in place, to (θh, θd, φd).
void BM_MerlFloor_Conversion(benchmark::State& state) {
  const auto& p = pairs();
  const std::size_t block = static_cast<std::size_t>(state.range(0));
  alignas(64) static double q[3][merl_kernel::kBlock];
  alignas(64) static std::uint8_t valid[merl_kernel::kBlock];
  const Column<double> cols[3] = {{q[0], 1}, {q[1], 1}, {q[2], 1}};
  for (auto _ : state) {
    for (std::size_t f = 0; f < p.size(); f += block) {
      const double* rows = &p[f].wi.x;
      const ConstColumn<double> in[6] = {{rows, 6},     {rows + 1, 6}, {rows + 2, 6},
                                         {rows + 3, 6}, {rows + 4, 6}, {rows + 5, 6}};
      convert<double>(Form{Space::dirs}, Form{space_of<HalfDiff>, true}, in, block,
                      ConvertOutput<double>{cols, {}, valid}, BatchOptions{1});
      benchmark::DoNotOptimize(q[0][0]);
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * p.size()));
}
BENCHMARK(BM_MerlFloor_Conversion)->Arg(256)->Arg(32)->Unit(benchmark::kMillisecond);

// The table reads alone: the slot of each row's bin, prefetched 16 rows ahead, summed.
void BM_MerlFloor_NearestReads(benchmark::State& state) {
  const merl::BinValues* t = floor_table();
  const auto& b = floor_bins();
  const std::size_t n = b.size();
  for (auto _ : state) {
    double sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (i + 16 < n) __builtin_prefetch(t + b[i + 16]);
      const double* v = t[b[i]].rgb;
      sum += v[0] + v[1] + v[2];
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
}
BENCHMARK(BM_MerlFloor_NearestReads)->Unit(benchmark::kMillisecond);

// The table reads alone: one value of each of a row's 8 corners (4 to 8 cache lines), prefetched
// 16 rows ahead, summed; on the batch's table (32-byte slots of doubles), or on a float32 copy
// (16-byte slots: 2 to 8 lines a row, fewer on average), for the record: the lookups keep the
// doubles (a float table would change their tested 1e-12 agreement with the stored values).
template <class Slot>
void trilinear_reads(benchmark::State& state, const Slot* t) {
  using merl_kernel::kThetaDStep, merl_kernel::kThetaHStep, merl_kernel::kBlock;
  const auto& c = floor_cells();
  auto corners = [&](std::size_t i) {
    const auto& block = c[i / kBlock];
    const Slot* p = t + block.base[i % kBlock];
    return std::pair{p, p + block.phi_step[i % kBlock]};
  };
  for (auto _ : state) {
    double sum = 0;
    for (std::size_t i = 0; i < kPairs; ++i) {
      if (i + 16 < kPairs) {
        const auto [p, q] = corners(i + 16);
        for (const Slot* x :
             {p, q, p + kThetaDStep, q + kThetaDStep, p + kThetaHStep, q + kThetaHStep,
              p + kThetaHStep + kThetaDStep, q + kThetaHStep + kThetaDStep})
          __builtin_prefetch(x);
      }
      const auto [p, q] = corners(i);
      sum += p->rgb[0] + q->rgb[0] + p[kThetaDStep].rgb[1] + q[kThetaDStep].rgb[1] +
             p[kThetaHStep].rgb[2] + q[kThetaHStep].rgb[2] + p[kThetaHStep + kThetaDStep].rgb[0] +
             q[kThetaHStep + kThetaDStep].rgb[0];
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kPairs));
}

void BM_MerlFloor_TrilinearReads(benchmark::State& state) {
  trilinear_reads(state, floor_table());
}
BENCHMARK(BM_MerlFloor_TrilinearReads)->Unit(benchmark::kMillisecond);

struct alignas(16) FloatSlot {
  float rgb[4];
};

void BM_MerlFloor_TrilinearReadsFloat32(benchmark::State& state) {
  static const FloatSlot* t = [] {
    constexpr std::size_t kPage = std::size_t(2) << 20;
    const std::size_t bytes = (merl::kBins * sizeof(FloatSlot) + kPage - 1) / kPage * kPage;
    auto* p = static_cast<FloatSlot*>(std::aligned_alloc(kPage, bytes));
    madvise(p, bytes, MADV_HUGEPAGE);
    const merl::BinValues* d = floor_table();
    for (std::size_t i = 0; i < merl::kBins; ++i)
      p[i] = {{float(d[i].rgb[0]), float(d[i].rgb[1]), float(d[i].rgb[2]), 0.0f}};
    return p;  // kept for the whole run
  }();
  trilinear_reads(state, t);
}
BENCHMARK(BM_MerlFloor_TrilinearReadsFloat32)->Unit(benchmark::kMillisecond);

// The reads and the blends of the batch (the kernel it calls), at precomputed cells: the trilinear
// batch without its conversion.
void BM_MerlFloor_TrilinearBlends(benchmark::State& state) {
  const merl::BinValues* t = floor_table();
  const auto& c = floor_cells();
  std::vector<Rgb> out(kPairs);
  for (auto _ : state) {
    for (std::size_t b = 0; b < c.size(); ++b)
      merl_kernel::blend_rows(t, c[b], 0, merl_kernel::kBlock,
                              out.data() + b * merl_kernel::kBlock);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kPairs));
}
BENCHMARK(BM_MerlFloor_TrilinearBlends)->Unit(benchmark::kMillisecond);

std::filesystem::path shared_file(const char* sub) {
  const char* dir = std::getenv("HALFBACK_SHARED_DIR");
  const std::filesystem::path p =
      std::filesystem::path(dir && *dir ? dir : HALFBACK_SOURCE_DIR "/../shared") / "data" / sub;
  return std::filesystem::exists(p) ? p : std::filesystem::path{};
}

const RglBrdf* rgl() {
  static const std::shared_ptr<const RglBrdf> b = [] {
    const auto p = shared_file("rgl/ilm_l3_37_metallic_rgb.bsdf");
    return p.empty() ? nullptr : load_rgl(p);
  }();
  return b.get();
}

#if defined(HALFBACK_RGL_REFERENCE)
// RGL's own loader on the same file and pairs (it returns fr·cos θo, in float).
void BM_RglReference_OneThread(benchmark::State& state) {
  if (!rgl()) return state.SkipWithError("../shared/data/rgl not found");
  static const powitacq_rgb::BRDF reference(
      shared_file("rgl/ilm_l3_37_metallic_rgb.bsdf").string());
  const auto& p = pairs();
  for (auto _ : state) {
    float sum = 0;
    for (const auto& x : p) {
      const powitacq_rgb::Vector3f wi(float(x.wi.x), float(x.wi.y), float(x.wi.z)),
          wo(float(x.wo.x), float(x.wo.y), float(x.wo.z));
      sum += reference.eval(wi, wo)[1];
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * p.size()));
}
BENCHMARK(BM_RglReference_OneThread)->Unit(benchmark::kMillisecond);
#endif

void BM_Rgl_OneThread(benchmark::State& state) {
  if (!rgl()) return state.SkipWithError("../shared/data/rgl not found");
  run_single(state, *rgl());
}
BENCHMARK(BM_Rgl_OneThread)->Unit(benchmark::kMillisecond);

void BM_Rgl_Threads(benchmark::State& state) {
  if (!rgl()) return state.SkipWithError("../shared/data/rgl not found");
  run_threads(state, *rgl());
}
BENCHMARK(BM_Rgl_Threads)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();

void BM_Rgl_BatchOneCore(benchmark::State& state) {
  if (!rgl()) return state.SkipWithError("../shared/data/rgl not found");
  run_batch_one_core(state, *rgl());
}
BENCHMARK(BM_Rgl_BatchOneCore)->Unit(benchmark::kMillisecond);

// eval_batch on 16 pairs at a time, as the renderer calls it (one core).
void BM_Rgl_BatchOf16(benchmark::State& state) {
  if (!rgl()) return state.SkipWithError("../shared/data/rgl not found");
  const std::span<const DirPair<double>> p(pairs());
  std::vector<Rgb> out(p.size());
  for (auto _ : state) {
    for (std::size_t i = 0; i < p.size(); i += 16)
      rgl()->eval_batch(p.subspan(i, 16), std::span(out).subspan(i, 16));
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * p.size()));
}
BENCHMARK(BM_Rgl_BatchOf16)->Unit(benchmark::kMillisecond);

const AltaBrdf* alta() {
  static const std::shared_ptr<const AltaBrdf> b = [] {
    const auto p = shared_file("alta/retro-3M-jaune.dat");
    return p.empty() ? nullptr : load_alta(p, AltaOptions{8, true});
  }();
  return b.get();
}

void BM_Alta_OneThread(benchmark::State& state) {
  if (!alta()) return state.SkipWithError("../shared/data/alta not found");
  run_single(state, *alta());
}
BENCHMARK(BM_Alta_OneThread)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
