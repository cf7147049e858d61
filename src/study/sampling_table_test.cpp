// The study's sampling metric (metric 5, issue 36): a row per parameterization and table size,
// parameterizations sharing a chart sharing the numbers, and the charts ranked as they should be
// on a broad and a glossy lobe; the report's section.
#include <gtest/gtest.h>

#include "halfback/models/analytic.hpp"
#include "halfback/study/metric_tables.hpp"
#include "halfback/study/study.hpp"

namespace halfback::study {
namespace {

StudyConfig sampling_only() {
  StudyConfig c;
  c.params = {space_of<HalfDiff>, space_of<Hybrid>, space_of<Ortho>, space_of<Spherical>};
  c.grid = {8, 8, 8};
  c.budgets.clear();  // no gonio-reflectometer, no images
  c.sampler_kib = {64, 1024};
  c.sampler_samples = 2048;
  c.spacings = {Spacing::own};
  return c;
}

TEST(SamplingTable, ChartsRankedAndSharedCharts) {
  const models::Lambert broad(Rgb{0.5, 0.5, 0.5});
  models::MicrofacetParams p;
  p.alpha_x = p.alpha_y = 0.08;
  const models::Microfacet glossy(p);
  const StudyConfig c = sampling_only();
  const BrdfResult b = study_brdf(broad, "broad", c), g = study_brdf(glossy, "glossy", c);
  for (const BrdfResult* r : {&b, &g}) {
    ASSERT_EQ(r->table("sampling").rows.size(), c.params.size() * c.sampler_kib.size());
    const auto hybrid = sampling_points(*r, space_of<Hybrid>);
    const auto ortho = sampling_points(*r, space_of<Ortho>);
    ASSERT_EQ(hybrid.size(), 2u);
    EXPECT_EQ(hybrid[0].chart, ortho[0].chart);  // one chart: the same sampler, the same numbers
    EXPECT_EQ(hybrid[0].relative_variance, ortho[0].relative_variance);
    EXPECT_NE(hybrid[0].own_sampler, "none");  // both sample themselves
    EXPECT_GT(hybrid[0].relative_variance_error, 0);
  }
  // More memory, less variance on the glossy lobe (not always between near sizes: the projected
  // chart gave 0.356 at 64 KiB and 0.361 at 256).
  for (Space s : c.params)
    EXPECT_LT(sampling_points(g, s)[1].relative_variance,
              sampling_points(g, s)[0].relative_variance)
        << name_of(s);
  // A broad lobe: the spherical chart; a glossy one: the half-vector chart.
  const auto v = [](const BrdfResult& r, Space s) {
    return sampling_points(r, s)[1].relative_variance;
  };
  EXPECT_LT(v(b, space_of<Spherical>), v(b, space_of<HalfDiff>));
  EXPECT_LT(v(g, space_of<HalfDiff>), v(g, space_of<Spherical>));
  EXPECT_LT(v(g, space_of<HalfDiff>), v(g, space_of<Hybrid>));
  // The cosine samples Lambert exactly: no table is more efficient.
  EXPECT_LT(sampling_points(b, space_of<Spherical>)[1].efficiency_vs_cosine, 1);
  // Dupuy & Jakob's warp within each size. (Which wins is not asserted: efficiency includes the
  // time per sample, which an ASan build changes — the warp lost to the half-vector table there.)
  for (const BrdfResult* r : {&b, &g})
    for (Space s : c.params)
      for (const SamplingPoint& p : sampling_points(*r, s)) {
        EXPECT_LE(p.vndf_warp_kib, double(p.kib)) << name_of(s);
        EXPECT_GT(p.vndf_warp_kib, 0) << name_of(s);
        EXPECT_GT(p.efficiency_vs_vndf_warp, 0) << name_of(s);
      }
  // The fitted mixture (config.fit_model, lambert+ggx, fitted to each): on the Lambertian the fit
  // is nearly a Lambertian (a faint GGX term left), its mixture nearly the cosine, more efficient
  // than every table (7 to 500 times here); on the glossy lobe the fit is that lobe, sampled by
  // its own sampler.
  for (Space s : c.params) {
    for (const SamplingPoint& p : sampling_points(b, s))
      EXPECT_LT(p.efficiency_vs_fitted_mixture, 1) << name_of(s);
    for (const SamplingPoint& p : sampling_points(g, s)) {
      EXPECT_GT(p.efficiency_vs_fitted_mixture, 0.1 * p.efficiency_vs_own) << name_of(s);
      EXPECT_LT(p.efficiency_vs_fitted_mixture, 10 * p.efficiency_vs_own) << name_of(s);
    }
  }
}

// The pixel columns: a Lambertian under a constant sky is rendered without variance by cosine
// samples alone (each weighs albedo × radiance), so no table is as efficient there; on a glossy
// lobe the half-vector table beats the cosine by far, alone and with MIS.
TEST(SamplingTable, PixelVarianceKnownCaseAndGlossy) {
  StudyConfig c = sampling_only();
  c.params = {space_of<HalfDiff>, space_of<Spherical>};
  c.fit_model.clear();
  c.image_size = 48;
  c.environments = {render::load_environment("constant:1")};
  const models::Lambert broad(Rgb{0.5, 0.5, 0.5});
  const BrdfResult b = study_brdf(broad, "broad", c);
  for (Space s : c.params)
    for (const SamplingPoint& p : sampling_points(b, s)) {
      EXPECT_LT(p.pixel_efficiency_vs_cosine_brdf, 1e-6) << name_of(s);
      // Environment samples do not follow the cosine.
      EXPECT_GT(p.pixel_relative_variance_mis, 0) << name_of(s);
      EXPECT_EQ(p.efficiency_vs_fitted_mixture, 0);  // no fit model
    }
  c.environments = {render::load_environment("sky")};
  models::MicrofacetParams gp;
  gp.alpha_x = gp.alpha_y = 0.08;
  const BrdfResult g = study_brdf(models::Microfacet(gp), "glossy", c);
  const auto half = sampling_points(g, space_of<HalfDiff>);
  ASSERT_EQ(half.size(), 2u);
  // (Not asserted: less variance with more memory. Under the sky the brdf strategy's variance is
  // the radiance's within the lobe, which the table cannot follow: 0.12 at 64 KiB, 0.18 at 1 MiB
  // with 16 samples per pixel; with MIS 0.15 and 0.11.)
  for (const SamplingPoint& p : half) {
    EXPECT_GT(p.pixel_efficiency_vs_cosine_brdf, 3) << p.kib;  // 14-20 in a release build
    EXPECT_GT(p.pixel_efficiency_vs_cosine_mis, 3) << p.kib;   // 18-25
  }
}

TEST(SamplingTable, SettingsAreChecked) {
  StudyConfig c = sampling_only();
  c.sampler_kib = {0};
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c.sampler_kib = {kMaxSamplerKib + 1};
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c.sampler_kib = {64};
  c.sampler_samples = 1;
  EXPECT_THROW(c.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::study
