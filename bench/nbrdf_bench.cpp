// Neural BRDF evaluation throughput (docs/performance.md, "Neural BRDFs"): batches of 10^6 random
// pairs through eval_batch (blocks of pairs × layer widths in float) on one core and on all
// cores, against the straightforward per-pair loop (eval() on each pair, the renderer's path)
// in the same run. The network is ../shared/data/nbrdf/merl_nbrdf/blue-acrylic.h5 when present,
// else the embedded gold-metallic-paint3 (same 6-21-21-3 shape). items/s counts pairs.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <random>
#include <vector>

#include "bench_brdfs.hpp"
#include "halfback/formats/nbrdf.hpp"
#include "halfback/loader/load.hpp"

namespace {

using namespace halfback;

constexpr std::size_t kPairs = 1'000'000;

const std::vector<DirPair<double>>& pairs() {
  static const std::vector<DirPair<double>> v = [] {
    std::mt19937_64 rng(2021);
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

const Brdf& network() {
  return bench::neural_brdf(HALFBACK_SOURCE_DIR);
}

void BM_NbrdfBatchOneCore(benchmark::State& state) {
  const Brdf& brdf = network();
  pairs();  // generated before the timing
  std::vector<Rgb> out(kPairs);
  tbb::task_arena one_core(1);
  for (auto _ : state) {
    one_core.execute([&] { brdf.eval_batch(pairs(), out); });
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(std::int64_t(state.iterations() * kPairs));
}
BENCHMARK(BM_NbrdfBatchOneCore)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_NbrdfBatchAllCores(benchmark::State& state) {
  const Brdf& brdf = network();
  pairs();  // generated before the timing
  std::vector<Rgb> out(kPairs);
  for (auto _ : state) {
    brdf.eval_batch(pairs(), out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(std::int64_t(state.iterations() * kPairs));
}
BENCHMARK(BM_NbrdfBatchAllCores)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_NbrdfPerPairLoop(benchmark::State& state) {
  const Brdf& brdf = network();
  pairs();  // generated before the timing
  std::vector<Rgb> out(kPairs);
  for (auto _ : state) {
    for (std::size_t i = 0; i < kPairs; ++i) out[i] = brdf.eval(pairs()[i]);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(std::int64_t(state.iterations() * kPairs));
}
BENCHMARK(BM_NbrdfPerPairLoop)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
