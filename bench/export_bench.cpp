// The RGL writer (formats/rgl_writer.hpp): the time of one export, one thread, at the defaults
// (16 elevations placed by the albedo, hat averages) and in the published layout (8 σ-spaced
// elevations, point samples), against a baseline measured in the same run — evaluating the same
// source at as many pairs as the published layout's RGB tables sample (8 × 32 × 32), so the
// ratio is the writer's own cost (power iteration, σ, VNDF tables, warps) relative to the
// source's; and the spectral variant (the RGB export plus one spectrum fitted per RGB entry)
// against the RGB one. docs/formats.md.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "halfback/formats/rgl_writer.hpp"
#include "halfback/loader/load.hpp"

namespace {

using namespace halfback;

std::vector<DirPair<double>> random_pairs(std::size_t n) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uni(0, 1);
  auto dir = [&] {
    const double z = uni(rng), r = std::sqrt(1 - z * z), phi = 6.283185307179586 * uni(rng);
    return Vec3<double>{r * std::cos(phi), r * std::sin(phi), z};
  };
  std::vector<DirPair<double>> p(n);
  for (auto& x : p) x = {dir(), dir()};
  return p;
}

void eval_baseline(benchmark::State& state, const char* spec) {
  const BrdfPtr brdf = load_brdf(spec);
  const auto pairs = random_pairs(8 * 32 * 32);
  for (auto _ : state) {
    double sum = 0;
    for (const auto& p : pairs) sum += brdf->eval(p).r;
    benchmark::DoNotOptimize(sum);
  }
}

void export_rgl(benchmark::State& state, const char* spec, RglVariant variant,
                bool published = false) {
  const BrdfPtr brdf = load_brdf(spec);
  RglExportOptions o;
  o.threads = 1;
  o.variant = variant;
  if (published) {
    o.theta_i = 8;
    o.incidences = RglIncidences::sigma;
    o.tabulation = RglTabulation::point;
  }
  for (auto _ : state) benchmark::DoNotOptimize(rgl_fields(*brdf, o));
}

BENCHMARK_CAPTURE(eval_baseline, ggx, "ggx:alpha=0.2")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(export_rgl, ggx, "ggx:alpha=0.2", RglVariant::rgb)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(export_rgl, ggx_published, "ggx:alpha=0.2", RglVariant::rgb, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(export_rgl, ggx_spectral, "ggx:alpha=0.2", RglVariant::spectral)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(eval_baseline, neural, "embedded:pink-felt")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(export_rgl, neural, "embedded:pink-felt", RglVariant::rgb)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(export_rgl, neural_published, "embedded:pink-felt", RglVariant::rgb, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(export_rgl, neural_spectral, "embedded:pink-felt", RglVariant::spectral)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
