// The study's sampling metric (metric 5): a row per parameterization, table size and
// sampler (tabulated, factored), parameterizations sharing a chart sharing the numbers, and the
// charts ranked as they should be on a broad and a glossy lobe; the report's section.
#include <gtest/gtest.h>

#include <algorithm>

#include "halfback/models/analytic.hpp"
#include "halfback/render/brdf_sampler.hpp"
#include "halfback/render/renderer.hpp"
#include "halfback/study/image_metrics.hpp"
#include "halfback/study/metric.hpp"
#include "halfback/study/metric_tables.hpp"
#include "halfback/study/report.hpp"
#include "halfback/study/study.hpp"
#include "report_internal.hpp"
#include "support/test_support.hpp"

namespace halfback::study {
namespace {

using acquire::Spacing;

StudyConfig sampling_only() {
  StudyConfig c;
  c.params = {space_of<HalfDiff>, space_of<Hybrid>, space_of<Ortho>, space_of<Spherical>};
  c.grid = {8, 8, 8};
  c.budgets.clear();  // no gonio-reflectometer, no images
  c.options["sampler_kib"] = "64,1024";
  c.options["sampler_samples"] = "2048";
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
    // The tabulated and the factored sampler of each parameterization and size.
    ASSERT_EQ(r->table("sampling").rows.size(), 2 * c.params.size() * 2);
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
  // The factored sampler: within the memory asked, and on the glossy lobe in the half-vector
  // chart far better than the cosine (as the tabulated one: 10³ there).
  for (const BrdfResult* r : {&b, &g})
    for (Space s : c.params) {
      const auto factored = sampling_points(*r, s, "factored");
      ASSERT_EQ(factored.size(), 2u) << name_of(s);
      for (const SamplingPoint& p : factored) {
        EXPECT_EQ(p.sampler, "factored");
        EXPECT_LE(p.sampler_kib, 1.05 * double(p.kib)) << name_of(s);
        EXPECT_GT(p.sampler_kib, 0.9 * double(p.kib)) << name_of(s);
        EXPECT_GT(p.relative_variance_error, 0) << name_of(s);
      }
    }
  for (const SamplingPoint& p : sampling_points(g, space_of<HalfDiff>, "factored"))
    EXPECT_GT(p.efficiency_vs_cosine, 30) << p.kib;
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
  // its own sampler: the same variance, so the ratio of the two efficiencies is the ratio of their
  // times per sample, about 5 on an idle machine and up to 16 measured under load (2 cores, load
  // 9-18); a mixture that sampled another lobe would have far more variance.
  for (Space s : c.params) {
    for (const SamplingPoint& p : sampling_points(b, s))
      EXPECT_LT(p.efficiency_vs_fitted_mixture, 1) << name_of(s);
    for (const SamplingPoint& p : sampling_points(g, s)) {
      EXPECT_GT(p.efficiency_vs_fitted_mixture, 0.1 * p.efficiency_vs_own) << name_of(s);
      EXPECT_LT(p.efficiency_vs_fitted_mixture, 40 * p.efficiency_vs_own) << name_of(s);
    }
  }
}

// The image's relative variance per pixel sample with the cosine sampler, rendered as the study
// renders the pixel columns' reference (config.image_size, image_spp and seed; the sphere's
// pixels): the variance the pixel efficiencies compare with, without the time per sample.
double cosine_pixel_variance(const Brdf& brdf, const StudyConfig& c, render::Strategy strategy) {
  render::RenderSettings s;
  s.width = s.height = c.image_size;
  s.spp = c.image_spp;
  s.seed = c.seed;
  s.strategy = strategy;
  s.variance = true;
  const render::RenderResult r =
      render::render_sampled(*render::with_cosine_sampling(brdf), *c.environments.front().map, s);
  return render::relative_pixel_variance(r, sphere_mask(s.width, s.height));
}

// The pixel columns: a Lambertian under a constant sky is rendered without variance by cosine
// samples alone (each weighs albedo × radiance), so no table does as well there; on a glossy lobe
// the half-vector table has far less variance than the cosine, alone and with MIS, under uniform
// light, and with MIS under the sky. Variances only (fixed seeds and sample counts): the
// efficiencies also hold the time per sample, which a loaded machine changes.
TEST(SamplingTable, PixelVarianceKnownCaseAndGlossy) {
  StudyConfig c = sampling_only();
  c.params = {space_of<HalfDiff>, space_of<Spherical>};
  c.options["fit_model"].clear();
  c.image_size = 48;
  c.environments = {render::load_environment("constant:1")};
  const models::Lambert broad(Rgb{0.5, 0.5, 0.5});
  const BrdfResult b = study_brdf(broad, "broad", c);
  const double cosine_broad = cosine_pixel_variance(broad, c, render::Strategy::brdf);  // 0
  for (Space s : c.params)
    for (const SamplingPoint& p : sampling_points(b, s)) {
      EXPECT_LT(cosine_broad, 1e-6 * p.pixel_relative_variance_brdf) << name_of(s);  // 0.002-0.02
      // Environment samples do not follow the cosine.
      EXPECT_GT(p.pixel_relative_variance_mis, 0) << name_of(s);
      EXPECT_EQ(p.efficiency_vs_fitted_mixture, 0);  // no fit model
    }
  // The glossy lobe under a uniform sky (the lobe alone decides) and under the sky with a sun.
  models::MicrofacetParams gp;
  gp.alpha_x = gp.alpha_y = 0.08;
  for (const char* env : {"constant:1", "sky"}) {
    c.environments = {render::load_environment(env)};
    const models::Microfacet glossy(gp);
    const BrdfResult g = study_brdf(glossy, "glossy", c);
    const auto half = sampling_points(g, space_of<HalfDiff>);
    ASSERT_EQ(half.size(), 2u);
    const bool uniform = std::string(env) == "constant:1";
    const double cosine_alone = cosine_pixel_variance(glossy, c, render::Strategy::brdf);
    const double cosine_mis = cosine_pixel_variance(glossy, c, render::Strategy::mis);
    for (const SamplingPoint& p : half) {
      // The cosine's variance over the table's, at 64 and 1024 KiB: uniform light, 206 and 391
      // alone, 82 and 127 with MIS; the sky, 9.5 and 9.6 with MIS.
      if (uniform) {
        EXPECT_GT(cosine_alone / p.pixel_relative_variance_brdf, 100) << p.kib;
      }
      EXPECT_GT(cosine_mis / p.pixel_relative_variance_mis, uniform ? 30 : 5) << p.kib;
    }
    // (Not asserted under the sky: the brdf strategy alone, 0.68 and 0.67. Its image variance is
    // the sun's: a 1.5° sun found by BRDF samples alone, in the few pixels that reflect it, whose
    // 16 samples rarely see it; that noise dominates the image's variance whichever the sampler.)
    if (uniform) {
      EXPECT_LT(half[1].pixel_relative_variance_brdf, half[0].pixel_relative_variance_brdf);
    }
  }
}

TEST(SamplingTable, SettingsAreChecked) {
  StudyConfig c = sampling_only();
  c.options["sampler_kib"] = "0";
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c.options["sampler_kib"] = std::to_string(kMaxSamplerKib + 1);
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c.options["sampler_kib"] = "64,32";
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c.options["sampler_kib"] = "64";
  c.options["sampler_samples"] = "1";
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c.options["sampler_samples"] = "2";
  EXPECT_NO_THROW(c.validate());
}

// The report's Summary (what `halfback study` prints) gives the sampling metric too: with
// --no-gonio it is the only one asked for beyond metrics 1-2.
TEST(SamplingTable, TheSummaryHasTheSamplingMetric) {
  StudyConfig c = sampling_only();
  c.params = {space_of<HalfDiff>, space_of<StereoHalfDiff>, space_of<Spherical>};
  c.options["sampler_kib"] = "8,16";
  c.options["sampler_samples"] = "256";
  c.image_size = 24;
  find_metric("fit")->switch_off(c);
  models::MicrofacetParams p;
  p.alpha_x = p.alpha_y = 0.08;
  const std::vector<BrdfResult> results{
      study_brdf(models::Lambert(Rgb{0.5, 0.5, 0.5}), "lambert", c),
      study_brdf(models::Microfacet(p), "ggx", c)};
  const test::TempDir tmp;
  const std::string md = write_study(tmp.path(), results, c, 1.0).markdown;
  const std::size_t summary = md.find("## Summary"), next = md.find("\n## ", summary);
  ASSERT_NE(summary, std::string::npos);
  const std::string head = md.substr(summary, next - summary);
  const std::size_t at = head.find(
      "**importance sampling, relative variance of the albedo estimate, tables of 8 KiB**");
  ASSERT_NE(at, std::string::npos) << head;
  // Its table: the two BRDFs, halfdiff's chart the better sampler of the glossy lobe.
  EXPECT_NE(head.find("| models | 2 |", at), std::string::npos) << head;
  const auto halfdiff = sampling_points(results[1], space_of<HalfDiff>, "tabulated");
  const auto spherical = sampling_points(results[1], space_of<Spherical>, "tabulated");
  ASSERT_FALSE(halfdiff.empty());
  ASSERT_FALSE(spherical.empty());
  EXPECT_LT(halfdiff.front().relative_variance, spherical.front().relative_variance);

  // The Answers section names parameterizations that share a sampler together, never one as the
  // other's runner-up ("tie").
  const std::size_t row = md.find("| importance sampling (a table of equal memory) |");
  ASSERT_NE(row, std::string::npos) << md;
  const std::string answer = md.substr(row, md.find('\n', row) - row);
  EXPECT_NE(answer.find("halfdiff = stereo-halfdiff"), std::string::npos) << answer;
  EXPECT_EQ(answer.find("tie"), std::string::npos) << answer;

  // The plot: one curve per sampler chart, named by the parameterizations that share it
  // (halfdiff's is stereo-halfdiff's: one curve, not one hidden under the other), the cosine in
  // a colour no chart has.
  const report::ReportPlots plots = report::report_plots(results, c, report::contents_of(results),
                                                         report::summary_metrics(results, c, {}));
  std::vector<std::string> texts;
  for (const figure::Item& item : plots.sampling.items)
    if (const auto* t = std::get_if<figure::TextItem>(&item)) texts.push_back(t->text);
  const auto has = [&](const std::string& s) {
    return std::find(texts.begin(), texts.end(), s) != texts.end();
  };
  EXPECT_TRUE(has("halfdiff / stereo-halfdiff tabulated"));
  EXPECT_TRUE(has("spherical factored"));
  EXPECT_FALSE(has("stereo-halfdiff tabulated"));
  EXPECT_FALSE(has("halfdiff tabulated"));
  EXPECT_TRUE(has("cosine"));
}

}  // namespace
}  // namespace halfback::study
