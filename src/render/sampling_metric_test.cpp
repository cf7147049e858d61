// The sampling metric (sampling_metric.hpp): a known zero variance, the known weight of GGX's
// visible-normal sampler, the tabulated sampler's memory, and samplers ranked as they should be.
#include "halfback/render/sampling_metric.hpp"

#include <gtest/gtest.h>

#include <random>

#include "halfback/brdf/albedo.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/models/analytic.hpp"

namespace halfback::render {
namespace {

// Lambert sampled by the cosine: every estimate is the albedo, the variance is zero.
TEST(SamplingMetric, LambertByTheCosineHasNoVariance) {
  const BrdfPtr lambert = load_brdf("lambert:albedo=0.4");
  const SamplingMeasure m = measure_sampling(*lambert, *lambert, {.samples = 512});
  ASSERT_EQ(m.per_wo.size(), 8u);
  for (const OutgoingEstimate& e : m.per_wo) {
    EXPECT_NEAR(e.mean, 0.4, 1e-12);
    EXPECT_LT(e.variance, 1e-25);
  }
  EXPECT_LT(m.relative_variance, 1e-24);
  EXPECT_GT(m.seconds_per_sample, 0);
}

// GGX (F = 1) sampled by its visible normals: each estimate is the known weight
// G2(ωi, ωo) / G1(ωo) = (1 + Λ(ωo)) / (1 + Λ(ωi) + Λ(ωo)), 0 below the horizon; the metric's
// moments are those of these weights, drawn here from the same numbers.
TEST(SamplingMetric, GgxByItsVisibleNormalsHasTheKnownWeight) {
  models::MicrofacetParams p;
  p.alpha_x = p.alpha_y = 0.3;
  p.fresnel.f0 = {1, 1, 1};
  const models::Microfacet ggx(p);
  const SamplingMetricOptions o{.theta_count = 3, .samples = 2000, .seed = 7};
  const SamplingMeasure m = measure_sampling(ggx, ggx, o);
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> u(0, 1);
  for (const OutgoingEstimate& e : m.per_wo) {
    std::vector<double> w(o.samples);
    double mean = 0;
    for (std::size_t k = 0; k < o.samples; ++k) {
      const double u1 = u(rng), u2 = u(rng);
      const BrdfSample s = ggx.sample(e.wo, u1, u2);
      w[k] = s.pdf > 0 && s.wi.z > 0
                 ? (1 + ggx.lambda(e.wo)) / (1 + ggx.lambda(s.wi) + ggx.lambda(e.wo))
                 : 0;
      mean += w[k] / double(o.samples);
    }
    double var = 0;
    for (double x : w) var += (x - mean) * (x - mean) / double(o.samples - 1);
    EXPECT_NEAR(e.mean, mean, 1e-12);
    EXPECT_NEAR(e.variance, var, 1e-12);
    // And the mean is the albedo (an independent estimate, within its errors).
    const AlbedoEstimate a = directional_albedo(ggx, e.wo, 256);
    EXPECT_NEAR(e.mean, a.mean.luminance(),
                4 * (std::sqrt(var / double(o.samples)) + a.standard_error.luminance()));
  }
}

// A glossy lobe: its own sampler beats the cosine by far, a tabulated sampler of 1 MB in between;
// the tables take about the memory asked for.
TEST(SamplingMetric, SamplersRankAsExpected) {
  const BrdfPtr ggx = load_brdf("ggx:alpha=0.08,f0=0.9");
  const auto cosine = with_cosine_sampling(*ggx);
  const TabulationOptions t = tabulation_for_memory(space_of<Hybrid>, std::size_t(1) << 20);
  const TabulatedSampler tabulated(*ggx, t);
  EXPECT_NEAR(double(tabulated.cells()) * 20, double(1 << 20), 0.3 * double(1 << 20));
  const SamplingMetricOptions o{.samples = 4000};
  const SamplingMeasure own = measure_sampling(*ggx, *ggx, o);
  const SamplingMeasure tab = measure_sampling(*ggx, tabulated, o);
  const SamplingMeasure cos = measure_sampling(*ggx, *cosine, o);
  EXPECT_GT(cos.relative_variance, 10 * tab.relative_variance);
  EXPECT_GT(tab.relative_variance, own.relative_variance);
  // The errors are reported and smaller than the differences found.
  EXPECT_GT(cos.relative_variance_error, 0);
  EXPECT_LT(cos.relative_variance_error, 0.5 * cos.relative_variance);
}

}  // namespace
}  // namespace halfback::render
