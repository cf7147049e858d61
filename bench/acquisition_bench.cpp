// `halfback plan` and `halfback reconstruct` at 10⁵ measurements (the target: each ≤ 2 s; docs/
// acquisition.md, "Speed"): the plan of a design with its instrument order, and the reconstruction
// from values at its rows, beside the unit of both measured in the same run, the design's points
// alone (gonio_plan). Isotropic hybrid (the 3D gonio-reflectometer), regular and stratified; the
// sequential design's main stage; the sample-turning instrument.
#include <benchmark/benchmark.h>

#include <vector>

#include "halfback/acquire/acquisition.hpp"
#include "halfback/loader/load.hpp"

namespace {

using namespace halfback;
using namespace halfback::acquire;

GonioSetup setup_of(const benchmark::State& state) {
  PlanSettings p;
  p.budget = std::size_t(state.range(0));
  p.design = state.range(1) == 0 ? "regular" : "stratified";
  return plan_setup(p);
}

// The design's points only: the baseline of the two below.
void BM_DesignPoints(benchmark::State& state) {
  const GonioSetup s = setup_of(state);
  for (auto _ : state) benchmark::DoNotOptimize(gonio_plan(s).points.data());
}

// The plan: the points, each configuration once (isotropy, reciprocity), the instrument's order.
void BM_Plan(benchmark::State& state) {
  const GonioSetup s = setup_of(state);
  AcquisitionPlan plan;
  for (auto _ : state) {
    plan = acquisition_plan(s);
    benchmark::DoNotOptimize(plan.measured.data());
  }
  state.counters["rows"] = double(plan.measured.size());
  state.counters["travel_vs_cell_order"] = plan.travel / plan.cell_order_travel;
}

// The reconstruction from the values measured at the rows (a GGX's, evaluated once outside).
void BM_Reconstruct(benchmark::State& state) {
  const AcquisitionPlan plan = acquisition_plan(setup_of(state));
  const BrdfPtr truth = load_brdf("ggx:alpha=0.15");
  std::vector<Rgb> values(plan.measured.size());
  for (std::size_t r = 0; r < values.size(); ++r) values[r] = truth->eval(plan.measured[r]);
  for (auto _ : state) {
    GonioReconstruction rec = reconstruct(plan, values, "ggx");
    benchmark::DoNotOptimize(rec.samples());
  }
}

// The sequential design's main stage from the pilot's values at its rows (the pilot's demand,
// the warps, the plan of the rest of the budget), the design's budget 10⁵; the sample-turning
// instrument's plan (its motors' angles and order) beside the light-detector one's above.
void BM_SequentialMainPlan(benchmark::State& state) {
  PlanSettings p;
  p.budget = std::size_t(state.range(0));
  p.design = "sequential";
  const AcquisitionPlan pilot = sequential_pilot_plan(plan_setup(p));
  const BrdfPtr truth = load_brdf("ggx:alpha=0.15");
  std::vector<Rgb> values(pilot.measured.size());
  for (std::size_t r = 0; r < values.size(); ++r) values[r] = truth->eval(pilot.measured[r]);
  AcquisitionPlan main;
  for (auto _ : state) {
    main = sequential_main_plan(pilot, values);
    benchmark::DoNotOptimize(main.measured.data());
  }
  state.counters["rows"] = double(main.measured.size());
}

void BM_PlanSampleTurning(benchmark::State& state) {
  const GonioSetup s = setup_of(state);
  AcquisitionPlan plan;
  for (auto _ : state) {
    plan = acquisition_plan(s, Instrument::sample_turning);
    benchmark::DoNotOptimize(plan.measured.data());
  }
  state.counters["travel_vs_cell_order"] = plan.travel / plan.cell_order_travel;
}

BENCHMARK(BM_DesignPoints)->Args({100000, 0})->Args({100000, 1})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Plan)->Args({100000, 0})->Args({100000, 1})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Reconstruct)->Args({100000, 0})->Args({100000, 1})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SequentialMainPlan)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlanSampleTurning)->Args({100000, 0})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
