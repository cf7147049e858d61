// halfback_view_bench: the slice handler of `halfback view` (docs/performance.md, "Viewer").
//
// A 256 × 256 slice (the pairs of the canonical poses, then ρ of the valid ones) for an analytic
// model, MERL data (an analytic lobe tabulated in memory, so no file is needed), an RGL material
// and a neural BRDF (both embedded in the library), on ONE thread: oneTBB is limited to one worker
// (tbb::global_control), so all the work is on the calling thread, whose CPU time is the
// "CPU" column (on the shared machine, wall time is several times longer and varies). Baseline in
// the same run: Brdf::eval_batch of the same valid pairs alone (BM_EvalOnly), so the ratio is the
// cost the slice adds to ρ. Also the whole request, through Api::handle (BM_Request: the parameter
// checks and the copy to the float32 body), and a slider update's four slices as four requests or
// one (BM_SliderUpdate).
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <fmt/format.h>

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "bench_brdfs.hpp"
#include "halfback/figure/coordinates.hpp"
#include "halfback/figure/slices.hpp"
#include "halfback/formats/merl.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/view/api.hpp"
#include "halfback/view/server.hpp"
#include "view/fields.hpp"

namespace {

using namespace halfback;

constexpr std::size_t kSide = 256;
constexpr double kAzimuth = 40 * 3.14159265358979323846 / 180;  // radians

BrdfPtr brdf_of(int which) {
  switch (which) {
    case 0:
      return load_brdf("ggx:alpha=0.2,f0=0.9");
    case 1:
      return std::make_shared<MerlBrdf>(tabulate_merl(bench::Lobe{}));
    case 2:
      return load_brdf("embedded:acrylic_felt_green");
    default:
      return load_brdf("embedded:pink-felt");
  }
}
const char* kNames[] = {"analytic_ggx", "merl_lobe", "rgl_felt", "neural_pink_felt"};

void BM_Slice(benchmark::State& state) {
  const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const BrdfPtr brdf = brdf_of(int(state.range(0)));
  state.SetLabel(kNames[state.range(0)]);
  for (auto _ : state) {
    auto v = view::slice_field(*brdf, space_of<Hybrid>, kAzimuth, kSide, 1);
    benchmark::DoNotOptimize(v.data());
  }
}
BENCHMARK(BM_Slice)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

// The pairs alone, two ways: the core's batch engine (what slice_field does) and figure's
// sample_slice (a tuple at a time, inverse_iso and valid_iso).
void BM_PairsBatch(benchmark::State& state) {
  const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const BrdfPtr lambert = load_brdf("lambert");
  for (auto _ : state) {
    auto v = view::slice_field(*lambert, space_of<Hybrid>, kAzimuth, kSide, 1);
    benchmark::DoNotOptimize(v.data());
  }
}
BENCHMARK(BM_PairsBatch)->Unit(benchmark::kMillisecond);

void BM_PairsPerTuple(benchmark::State& state) {
  const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const auto c = figure::iso_coordinates(space_of<Hybrid>);
  const auto grid = figure::Grid::pixel_centres(kSide, kSide, 0, c[0].max, 0, c[1].max);
  for (auto _ : state) {
    auto s = figure::sample_slice(space_of<Hybrid>, kAzimuth, grid, 1);
    benchmark::DoNotOptimize(s.pairs.data());
  }
}
BENCHMARK(BM_PairsPerTuple)->Unit(benchmark::kMillisecond);

void BM_EvalOnly(benchmark::State& state) {
  const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const BrdfPtr brdf = brdf_of(int(state.range(0)));
  state.SetLabel(kNames[state.range(0)]);
  const auto c = figure::iso_coordinates(space_of<Hybrid>);
  const figure::SliceSample s =
      figure::sample_slice(space_of<Hybrid>, kAzimuth,
                           figure::Grid::pixel_centres(kSide, kSide, 0, c[0].max, 0, c[1].max), 1);
  std::vector<DirPair<double>> pairs;
  for (std::size_t k = 0; k < s.pairs.size(); ++k)
    if (s.valid[k]) pairs.push_back(s.pairs[k]);
  std::vector<Rgb> out(pairs.size());
  for (auto _ : state) {
    brdf->eval_batch(pairs, out);
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK(BM_EvalOnly)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

view::ApiConfig one_thread_config() {
  view::ApiConfig config;
  config.token = std::string(1, 't');  // (= "t" trips GCC 12's false -Wrestrict once inlined)
  config.port = 1;
  config.threads = 1;
  return config;
}

view::Request slices_request(std::string forms, std::size_t side) {
  view::Request r;
  r.path = "/api/slices";
  r.query = {{"token", "t"},
             {"brdf", "ggx:alpha=0.2,f0=0.9"},
             {"forms", std::move(forms)},
             {"azimuth", "40"},
             {"n", std::to_string(side)}};
  r.headers = {{"host", "127.0.0.1:1"}};
  return r;
}

void BM_Request(benchmark::State& state) {
  const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const view::Api api(one_thread_config());
  const view::Request r = slices_request("hybrid", kSide);
  for (auto _ : state) {
    const view::Response res = api.handle(r);
    if (res.status != 200) state.SkipWithError("request failed");
    benchmark::DoNotOptimize(res.body.data());
  }
}
BENCHMARK(BM_Request)->Unit(benchmark::kMillisecond);

// What one move of the azimuth slider asks of the server: the four forms' 128 × 128 slices, as
// four single-form requests (/0: the page before /api/slices took several forms) or one (/1).
void BM_SliderUpdate(benchmark::State& state) {
  const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const view::Api api(one_thread_config());
  std::vector<view::Request> requests;
  if (state.range(0) == 0)
    for (const char* form : {"spherical", "halfdiff", "ortho", "hybrid"})
      requests.push_back(slices_request(form, 128));
  else
    requests.push_back(slices_request("spherical,halfdiff,ortho,hybrid", 128));
  state.SetLabel(state.range(0) == 0 ? "four requests" : "one request");
  for (auto _ : state)
    for (const view::Request& r : requests) {
      const view::Response res = api.handle(r);
      if (res.status != 200) state.SkipWithError("request failed");
      benchmark::DoNotOptimize(res.body.data());
    }
}
BENCHMARK(BM_SliderUpdate)->DenseRange(0, 1)->Unit(benchmark::kMillisecond);

}  // namespace

// As `halfback view` does (view::keep_freed_memory): the buffers of one request are reused by the
// next instead of being mapped afresh (page faults cost ~30 ms per slice on this virtual machine).
int main(int argc, char** argv) {
  if (argc > 1 && std::string_view(argv[1]) == "--fresh-memory") {
    --argc;
    ++argv;
  } else {
    view::keep_freed_memory();
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
