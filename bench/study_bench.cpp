// The per-BRDF cost of `halfback study` (docs/performance.md, "Study"), on one core, with a
// baseline in the same run: evaluating the same BRDF at 10^6 pairs (eval_batch). The study's
// stages are timed apart (metrics 1-2 of one parameterization, its gonio-reflectometer, the
// renderings), and the whole study_brdf() with the default settings. The BRDF is the neural
// BRDF ../shared/data/nbrdf/merl_nbrdf/blue-acrylic.h5 when present (the kind that most of the
// full study is made of), else the embedded gold-metallic-paint3 (same network shape).
// Times are process CPU time (all threads), one core: a shared machine's load changes the wall
// time, much less the CPU time; compare a stage with the baseline of the same run.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <numbers>
#include <random>
#include <vector>

#include "bench_brdfs.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/study/study.hpp"

namespace {

using namespace halfback;

const Brdf& network() {
  return bench::neural_brdf(HALFBACK_SOURCE_DIR);
}

void on_one_core(benchmark::State& state, const std::function<void()>& work) {
  tbb::task_arena one_core(1);
  for (auto _ : state) one_core.execute(work);
}

void BM_Baseline_Eval1M(benchmark::State& state) {
  std::mt19937_64 rng(2021);
  std::uniform_real_distribution<double> u(0, 1);
  auto dir = [&] {
    const double z = u(rng), phi = 2 * std::numbers::pi * u(rng), s = std::sqrt(1 - z * z);
    return Vec3<double>{s * std::cos(phi), s * std::sin(phi), z};
  };
  std::vector<DirPair<double>> pairs(1'000'000);
  for (auto& p : pairs) p = {dir(), dir()};
  std::vector<Rgb> out(pairs.size());
  on_one_core(state, [&] {
    network().eval_batch(pairs, out);
    benchmark::DoNotOptimize(out.data());
  });
}

// Metrics 1-2 of one parameterization on the default 64^3 grid.
void BM_Stage_Metrics12(benchmark::State& state) {
  const study::StudyConfig c;
  on_one_core(state, [&] {
    const acquire::IsoSamples x =
        acquire::sample_isotropic(network(), space_of<Hybrid>, c.grid, c.space);
    benchmark::DoNotOptimize(study::azimuthal_error(x));
    benchmark::DoNotOptimize(study::separability_2d(x, c.ranks));
    benchmark::DoNotOptimize(study::separability_unfolded(x, c.ranks));
  });
}

// The gonio-reflectometer of one parameterization: both designs at the default budgets,
// checked at the default 2 x 10^5 test pairs.
void BM_Stage_Gonio(benchmark::State& state) {
  const study::StudyConfig c;
  const acquire::TestPairs test =
      acquire::draw_test_pairs(network(), c.test_pairs, c.seed, c.space, c.max_theta_deg);
  on_one_core(state, [&] {
    for (acquire::Design d : acquire::kDesigns)
      for (std::size_t budget : c.budgets) {
        acquire::GonioSetup setup{space_of<Hybrid>, true, d, budget, c.seed};
        setup.max_theta_deg = c.max_theta_deg;
        const acquire::GonioReconstruction rec(network(), setup);
        benchmark::DoNotOptimize(acquire::reconstruction_error(rec, test));
      }
  });
}

// The whole study of one BRDF: default settings, with (1) or without (0) the renderings.
void BM_StudyBrdf(benchmark::State& state) {
  study::StudyConfig c;
  if (state.range(0)) c.environments = render::default_environments();
  on_one_core(state, [&] {
    benchmark::DoNotOptimize(study::study_brdf(network(), "bench", c).params.size());
  });
}

}  // namespace

BENCHMARK(BM_Baseline_Eval1M)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
BENCHMARK(BM_Stage_Metrics12)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
BENCHMARK(BM_Stage_Gonio)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
BENCHMARK(BM_StudyBrdf)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->Iterations(1);
BENCHMARK_MAIN();
