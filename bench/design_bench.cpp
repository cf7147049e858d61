// The cost of the gonio-reflectometer's designs (docs/study.md, "Designs"): measuring a BRDF
// (GonioReconstruction) and evaluating the reconstruction at the study's test pairs, in each
// spacing, against the own spacing measured in the same run. The BRDF is an analytic GGX, so
// that the cost is the design's and not the BRDF's; the learned warps come from two other GGX.
// One thread (the study runs one task per parameterization).
#include <benchmark/benchmark.h>

#include <vector>

#include "halfback/acquire/design.hpp"
#include "halfback/acquire/gonio.hpp"
#include "halfback/loader/load.hpp"

namespace {

using namespace halfback;
using namespace halfback::acquire;

const Brdf& truth() {
  static const BrdfPtr b = model_registry().create("ggx:alpha=0.15");
  return *b;
}

const TestPairs& test_pairs() {
  static const TestPairs t = draw_test_pairs(truth(), 20000, 1, ErrorSpace::log, 85);
  return t;
}

GonioSetup setup_of(Space space, Spacing spacing) {
  GonioSetup s;
  s.space = space;
  s.budget = 10000;
  s.max_theta_deg = 85;
  s.spacing = spacing;
  if (spacing == Spacing::learned) {
    static const std::vector<LearnedWarps> learned = [] {
      std::vector<DesignProfile> profiles;
      for (const char* spec : {"ggx:alpha=0.1", "ggx:alpha=0.3"})
        profiles.push_back(design_profile(*model_registry().create(spec), kKernelSpaces,
                                          {32, 32, 32}, ErrorSpace::log));
      profiles.push_back({});  // the held-out slot: never read
      return learn_warps(profiles, 2);
    }();
    for (const LearnedWarps& w : learned)
      if (w.space == space) s.learned = w;
  }
  return s;
}

// Measure and score one reconstruction; items = test pairs evaluated.
void BM_Design(benchmark::State& state) {
  const auto space = Space::from_id(static_cast<std::uint16_t>(state.range(0)));
  const auto spacing = static_cast<Spacing>(state.range(1));
  const GonioSetup setup = setup_of(space, spacing);
  for (auto _ : state) {
    const GonioReconstruction rec(truth(), setup);
    benchmark::DoNotOptimize(reconstruction_error(rec, test_pairs()));
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(test_pairs().pairs.size()));
  state.SetLabel(std::string(name_of(space)) + " " + std::string(name_of(spacing)));
}

void designs(benchmark::internal::Benchmark* b) {
  for (Space s : {space_of<HalfDiff>, space_of<Hybrid>})
    for (Spacing d : kSpacings) b->Args({static_cast<long>(s.id()), static_cast<long>(d)});
}
BENCHMARK(BM_Design)->Apply(designs)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
