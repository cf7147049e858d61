// `halfback fit`'s cost (docs/performance.md, "Fitting"): a Lambert + GGX fit to a neural BRDF
// from 10⁵ samples on one thread, with the automatic starts and from one start, beside the unit
// of its work, one evaluation of the model and the loss at the samples, measured in the same run;
// the same for He et al.'s lobe, the slowest model.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "halfback/fit/fit.hpp"
#include "halfback/loader/load.hpp"

namespace {

using namespace halfback;

constexpr const char* kTarget = "embedded:gold-metallic-paint3";
// A fit of `model` to the target from state.range(0) samples on one thread, from `starts` (the
// automatic ones if empty).
// With state.range(1) == 0: the fitter without its shortcuts (fit::detail::set_fit_shortcuts), the
// baseline of the same run.
void fit_run(benchmark::State& state, const char* model, std::vector<std::string> starts) {
  const BrdfPtr target = load_brdf(kTarget);
  fit::detail::set_fit_shortcuts(state.range(1) != 0);
  fit::FitOptions o;
  o.samples = std::size_t(state.range(0));
  o.threads = 1;
  o.starts = std::move(starts);
  fit::FitResult r;
  for (auto _ : state) {
    r = fit::fit(*target, model, o);
    // Not DoNotOptimize(r.loss_value): with Debian's Google Benchmark 1.7 and GCC 12, its "+r"
    // constraint on a double member came back as garbage (4.9e-324) in this file.
    benchmark::DoNotOptimize(r.spec.data());
  }
  state.counters["fit_loss"] = r.loss_value;
  state.counters["fit_iterations"] = r.iterations;
  state.counters["fit_starts"] = double(r.starts);
  fit::detail::set_fit_shortcuts(true);
}

void BM_FitLambertGgx(benchmark::State& state) {
  fit_run(state, "lambert+ggx", {});
}
void BM_FitLambertGgxOneStart(benchmark::State& state) {
  fit_run(state, "lambert+ggx", {"lambert+ggx:alpha=0.2"});
}
// A Lambert + He fit as the whole-database fit runs it (scripts/fit_database.py: 2·10⁴ samples,
// the automatic starts, one thread).
void BM_FitLambertHe(benchmark::State& state) {
  fit_run(state, "lambert+he", {});
}

// One residual evaluation of `model`: its ρ at state.range(0) samples and the loss (the fit does
// about 1 + parameters of these per iteration: the residuals and a forward difference per
// parameter).
void loss_run(benchmark::State& state, const char* model) {
  const BrdfPtr target = load_brdf(kTarget);
  const BrdfPtr m = load_brdf(model);
  const fit::Samples s = fit::halfdiff_samples(std::size_t(state.range(0)));
  std::vector<Rgb> t(s.pairs.size());
  for (std::size_t i = 0; i < t.size(); ++i) t[i] = target->eval(s.pairs[i]);
  for (auto _ : state) benchmark::DoNotOptimize(fit::loss_value(t, *m, fit::Loss::ngan, s, 1));
  state.SetItemsProcessed(std::int64_t(state.iterations()) * state.range(0));
}

void BM_ModelLossAtSamples(benchmark::State& state) {
  loss_run(state, "lambert:albedo=0.1+ggx:alpha=0.2,f0=0.3");
}

// He et al.'s lobe (the slowest model: a series of up to 64 terms per channel), for a smooth, a
// mid (a fit to gold-metallic-paint3) and a rough surface (state.range(1)); beside GGX above.
void BM_HeLossAtSamples(benchmark::State& state) {
  static const char* const kHe[] = {"he:autocorrelation=3,roughness=0.05,eta=1.5",
                                    "he:autocorrelation=31.6,roughness=0.3,eta=5.4",
                                    "he:autocorrelation=2,roughness=1.5,eta=1.5"};
  loss_run(state, kHe[state.range(1)]);
}

BENCHMARK(BM_ModelLossAtSamples)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitLambertGgxOneStart)
    ->Args({100000, 0})
    ->Args({100000, 1})
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK(BM_FitLambertGgx)
    ->Args({100000, 0})
    ->Args({100000, 1})
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK(BM_HeLossAtSamples)
    ->Args({100000, 0})
    ->Args({100000, 1})
    ->Args({100000, 2})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitLambertHe)
    ->Args({20000, 0})
    ->Args({20000, 1})
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
