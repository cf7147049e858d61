// The cost of one training step of a neural BRDF (docs/neural.md): a batch of 512 pairs through
// the forward pass, the loss and the backward pass, and Adam's update, for the authors' 6-21-21-3
// network, on one thread and on all; the baseline in the same run is the forward pass alone of
// the same batch (the step's lower bound without the gradient). items/s counts pairs.
#include <benchmark/benchmark.h>

#include <numeric>
#include <vector>

#include "halfback/loader/load.hpp"
#include "neural/mlp.hpp"
#include "neural/trainer.hpp"

namespace {

using namespace halfback;
using namespace halfback::neural;

constexpr std::size_t kBatch = 512;

const TrainingSet& training_set() {
  static const TrainingSet set = sample_training_set(*load_brdf("ggx:alpha=0.3"), 8192, 1);
  return set;
}

std::vector<std::size_t> batch() {
  std::vector<std::size_t> b(kBatch);
  std::iota(b.begin(), b.end(), std::size_t{0});
  return b;
}

const MlpLayout kLayout({6, 21, 21, 3});

void BM_TrainStep(benchmark::State& state) {
  const int threads = int(state.range(0));
  Rng rng(2);
  Trainer trainer(kLayout, sztrajman_initial_parameters(kLayout, rng), {}, threads);
  const auto b = batch();
  for (auto _ : state) benchmark::DoNotOptimize(trainer.step(training_set(), b));
  state.SetItemsProcessed(state.iterations() * std::int64_t(kBatch));
}
BENCHMARK(BM_TrainStep)->Arg(1)->Arg(0)->UseRealTime();

void BM_ForwardOnly(benchmark::State& state) {
  Rng rng(2);
  const Vector params = sztrajman_initial_parameters(kLayout, rng);
  const auto b = batch();
  for (auto _ : state)
    benchmark::DoNotOptimize(loss_and_gradient(kLayout, params, training_set(), b, 1, nullptr));
  state.SetItemsProcessed(state.iterations() * std::int64_t(kBatch));
}
BENCHMARK(BM_ForwardOnly)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
