// Ngan et al. 2005's microfacet-style lobes (cook-torrance, ashikhmin-shirley, he) in the fitter:
// parameters recovered from BRDFs they generate, and every published fit of BBM's files loads as
// a spec (its values inside the registry's ranges) and evaluates finite and positive.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "halfback/fit/fit.hpp"
#include "halfback/fit/published.hpp"
#include "halfback/loader/load.hpp"
#include "recovery_test_support.hpp"
#include "support/test_support.hpp"

namespace halfback::fit::ngan_microfacet_fit_test {  // (own namespace: one unity file)
namespace {

// As `halfback fit --samples 2000`: every fitted parameter to 1e-3 relative (the loss not checked).
void expect_recovered(const std::string& model, const std::string& truth,
                      const std::string& start) {
  recovery_test::expect_recovered(
      model, truth, start,
      {.samples = 2000, .tolerance = 1e-3, .max_loss = std::numeric_limits<double>::infinity()});
}

TEST(NganMicrofacetFit, CookTorranceRecovered) {
  expect_recovered("cook-torrance",
                   "cook-torrance:albedo_r=0.6,albedo_g=0.35,albedo_b=0.1,eta=0.3,roughness=0.2",
                   "cook-torrance:albedo_r=0.5,albedo_g=0.5,albedo_b=0.5,eta=0.1,roughness=0.5");
}

TEST(NganMicrofacetFit, AshikhminShirleyRecovered) {
  expect_recovered("ashikhmin-shirley",
                   "ashikhmin-shirley:albedo_r=0.6,albedo_g=0.35,albedo_b=0.1,f0=0.3,sharpness=60",
                   "ashikhmin-shirley:albedo_r=0.5,albedo_g=0.5,albedo_b=0.5,f0=0.1,sharpness=20");
}

// As `halfback fit --brdf TRUTH --model MODEL --samples 2000`, from the automatic starts.
TEST(NganMicrofacetFit, RecoveredFromTheAutomaticStarts) {
  expect_recovered("cook-torrance",
                   "cook-torrance:albedo_r=0.8,albedo_g=0.5,albedo_b=0.3,eta=0.6,roughness=0.05",
                   "");
  expect_recovered("ashikhmin-shirley",
                   "ashikhmin-shirley:albedo_r=0.8,albedo_g=0.5,albedo_b=0.3,f0=0.6,sharpness=500",
                   "");
  expect_recovered("he",
                   "he:albedo_r=0.8,albedo_g=0.5,albedo_b=0.3,autocorrelation=4,roughness=0.2,"
                   "eta=1.8",
                   "");
}

TEST(NganMicrofacetFit, LambertPlusCookTorranceRecovered) {
  expect_recovered("lambert+cook-torrance",
                   "lambert:albedo_r=0.3,albedo_g=0.2,albedo_b=0.05+cook-torrance:albedo_r=0.5,"
                   "albedo_g=0.4,albedo_b=0.3,eta=0.05,roughness=0.15",
                   "lambert:albedo_r=0.5,albedo_g=0.5,albedo_b=0.5+cook-torrance:albedo_r=0.5,"
                   "albedo_g=0.5,albedo_b=0.5,eta=0.2,roughness=0.3");
}

// The spec of a published line: BBM's names in lower case, fresnelReflectance as f0.
std::string spec_of_published(const PublishedFit& f) {
  static const std::map<std::string, std::string> models{
      {"Lambertian", "lambert"},
      {"NganCookTorrance", "cook-torrance"},
      {"NganAshikhminShirley", "ashikhmin-shirley"}};
  static const std::map<std::string, std::string> params{{"albedo", "albedo"},
                                                         {"eta", "eta"},
                                                         {"roughness", "roughness"},
                                                         {"fresnelReflectance", "f0"},
                                                         {"sharpness", "sharpness"}};
  std::string spec;
  for (const PublishedLobe& lobe : f.lobes) {
    if (!spec.empty()) spec += '+';
    spec += models.at(lobe.model);
    char sep = ':';
    for (const auto& [key, values] : lobe.params) {
      const std::string name = params.at(key);
      for (std::size_t c = 0; c < values.size(); ++c) {
        char buf[80];
        const char* channel = values.size() == 3 ? (c == 0 ? "_r" : c == 1 ? "_g" : "_b") : "";
        std::snprintf(buf, sizeof buf, "%c%s%s=%.17g", sep, name.c_str(), channel, values[c]);
        spec += buf;
        sep = ',';
      }
    }
  }
  return spec;
}

TEST(NganMicrofacetFit, EveryPublishedLineLoadsAndEvaluates) {
  HALFBACK_REQUIRE_SHARED(dir, "fits");
  for (const char* file : {"ngan_cooktorrance.fit", "ngan_ashikhminshirley.fit"}) {
    const auto fits = read_published_fits(dir / file);
    EXPECT_EQ(fits.size(), 86u) << file;
    for (const PublishedFit& f : fits) {
      const std::string spec = spec_of_published(f);
      SCOPED_TRACE(std::string(file) + ": " + f.material + " as " + spec);
      BrdfPtr b;
      ASSERT_NO_THROW(b = load_brdf(spec));
      for (const DirPair<double>& p :
           {DirPair<double>{{0, 0, 1}, {0, 0, 1}}, DirPair<double>{{0.6, 0, 0.8}, {-0.6, 0, 0.8}},
            DirPair<double>{{0.6, 0, 0.8}, {0, 0.8, 0.6}}}) {
        const Rgb v = b->eval(p);
        for (double c : {v.r, v.g, v.b}) {
          EXPECT_TRUE(std::isfinite(c));
          EXPECT_GT(c, 0);
        }
      }
    }
  }
}

// A broad lobe in the series' regime (g_red ≈ 8 at the normal), where σ0 and τ act apart: in the
// rough limit (g_red > 19) only their ratio would be seen. η is seen through F's shape in θd.
TEST(NganMicrofacetFit, HeRecovered) {
  expect_recovered("he",
                   "he:albedo_r=0.6,albedo_g=0.35,albedo_b=0.1,autocorrelation=2,roughness=0.15,"
                   "eta=1.5",
                   "he:albedo_r=0.5,albedo_g=0.5,albedo_b=0.5,autocorrelation=3,roughness=0.25,"
                   "eta=2");
}

// He's lobe through halfback's own mapping of the published lines (fit::spec_of: NganHe -> he,
// BBM's names in lower case). ≥ 0, not > 0: four lines have eta = 1.0, where Cook's F and so the
// lobe vanish, and some Lambertian channels are 0.
TEST(NganMicrofacetFit, EveryPublishedHeLineLoadsAndEvaluates) {
  HALFBACK_REQUIRE_SHARED(dir, "fits");
  const auto fits = read_published_fits(dir / "ngan_he.fit");
  EXPECT_EQ(fits.size(), 86u);
  int positive_at_mirror = 0;
  for (const PublishedFit& f : fits) {
    const std::string spec = spec_of(f);
    SCOPED_TRACE("ngan_he.fit: " + f.material + " as " + spec);
    BrdfPtr b;
    ASSERT_NO_THROW(b = load_brdf(spec));
    for (const DirPair<double>& p :
         {DirPair<double>{{0, 0, 1}, {0, 0, 1}}, DirPair<double>{{0.6, 0, 0.8}, {-0.6, 0, 0.8}},
          DirPair<double>{{0.6, 0, 0.8}, {0, 0.8, 0.6}},
          DirPair<double>{{0.997, 0, 0.0707}, {-0.997, 0, 0.0707}}}) {
      const Rgb v = b->eval(p);
      for (double c : {v.r, v.g, v.b}) {
        EXPECT_TRUE(std::isfinite(c));
        EXPECT_GE(c, 0);
      }
    }
    const BrdfPtr lobe = load_brdf(spec.substr(spec.find("+he:") + 1));
    if (lobe->eval({{0.6, 0, 0.8}, {-0.6, 0, 0.8}}).g > 0) ++positive_at_mirror;
  }
  EXPECT_EQ(positive_at_mirror, 86 - 4);
}

}  // namespace
}  // namespace halfback::fit::ngan_microfacet_fit_test
