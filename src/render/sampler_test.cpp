// The tabulated BRDF sampler, in each parameterization: sample() and pdf() agree, the pdf
// integrates to the probability of a valid sample, samples follow the pdf (χ²), and the sampled
// albedo agrees with eval through the directional albedo.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <random>

#include "halfback/brdf/albedo.hpp"
#include "halfback/models/analytic.hpp"
#include "halfback/render/brdf_sampler.hpp"
#include "sampler_test_support.hpp"
#include "support/test_stats.hpp"

namespace halfback::render {
namespace {

// Hides a model's own sampler, as for measured data.
using namespace test_support;

struct Config {
  Space param;
  bool warp;
};
// Every chart: spherical, the half vector (halfdiff), the projected half vector (hybrid; ortho's
// too), warped and not.
const Config kSetups[] = {{space_of<Spherical>, false},
                          {space_of<HalfDiff>, true},
                          {space_of<Hybrid>, true},
                          {space_of<Hybrid>, false}};

TabulationOptions small(const Config& s) {
  TabulationOptions o;
  o.param = s.param;
  o.warp = s.warp;
  o.radial = 32;
  o.azimuthal = 64;
  o.theta_slices = 16;
  o.aniso_theta_slices = 8;
  o.aniso_phi_slices = 8;
  return o;
}

TEST(TabulatedSampler, OwnSamplerIsPreferred) {
  const auto g = ggx(0.2, 0.2);
  EXPECT_NE(with_importance_sampling(*g)->describe_sampling().find("own sampler"),
            std::string::npos);
  const Opaque o(g);
  EXPECT_NE(with_importance_sampling(o)->describe_sampling().find("tabulated"), std::string::npos);
  EXPECT_NE(with_importance_sampling(*g, {}, true)->describe_sampling().find("tabulated"),
            std::string::npos);
  EXPECT_NE(TabulatedSampler(o, {}).describe_sampling().find("halfdiff"), std::string::npos);
}

TEST(TabulatedSampler, SampleAndPdfAgree) {
  const Opaque iso(ggx(0.1, 0.1)), aniso(ggx(0.1, 0.4));
  for (const Config& s : kSetups)
    for (const Brdf* b : {static_cast<const Brdf*>(&iso), static_cast<const Brdf*>(&aniso)}) {
      const TabulatedSampler t(*b, small(s));
      std::mt19937_64 rng(1);
      std::uniform_real_distribution<double> u(0, 1);
      for (const auto& wo : kViews) {
        int valid = 0;
        for (int k = 0; k < 3000; ++k) {
          const BrdfSample x = t.sample(wo, u(rng), u(rng));
          if (!(x.pdf > 0)) continue;
          ++valid;
          ASSERT_GT(x.wi.z, 0);
          EXPECT_NEAR(std::hypot(x.wi.x, x.wi.y, x.wi.z), 1, 1e-12);
          EXPECT_NEAR(x.pdf, t.pdf(wo, x.wi), 1e-9 * x.pdf) << t.describe_sampling();
        }
        EXPECT_GT(valid, 2000) << t.describe_sampling();
      }
    }
}

TEST(TabulatedSampler, ChiSquareAndIntegral) {
  const Opaque iso(ggx(0.3, 0.3)), aniso(ggx(0.2, 0.5));
  for (const Config& s : kSetups)
    for (const Brdf* b : {static_cast<const Brdf*>(&iso), static_cast<const Brdf*>(&aniso)}) {
      const TabulatedSampler t(*b, small(s));
      for (const auto& wo : kViews) {
        const auto r = testing::chi2_test(
            [&](double u1, double u2) {
              const BrdfSample x = t.sample(wo, u1, u2);
              return testing::DirSample{x.wi, x.pdf};
            },
            [&](const Vec3<double>& wi) { return t.pdf(wo, wi); }, 100000, false, 16, 32, 24, 7,
            s.param == space_of<Spherical> ? Vec3<double>{0, 0, 1}
                                           : Vec3<double>{-wo.x, -wo.y, wo.z},
            10);
        // The quadrature is least accurate at the pdf's integrable singularity.
        EXPECT_LE(r.integral, 1.02) << t.describe_sampling();
        EXPECT_NEAR(r.integral, r.valid_fraction, 0.02) << t.describe_sampling();
        EXPECT_LT(r.z, 4.5) << t.describe_sampling() << " θo=" << std::acos(wo.z)
                            << " chi2=" << r.chi2 << " dof=" << r.dof;
      }
    }
}

TEST(TabulatedSampler, SampledAlbedoMatchesDirectionalAlbedo) {
  const Opaque glossy(ggx(0.08, 0.08)),
      lambert(std::make_shared<models::Lambert>(Rgb{0.6, 0.6, 0.6}));
  for (const Config& s : kSetups)
    for (const Brdf* b : {static_cast<const Brdf*>(&glossy), static_cast<const Brdf*>(&lambert)}) {
      const TabulatedSampler t(*b, small(s));
      for (const auto& wo : kViews) {
        constexpr int n = 200;
        double sum = 0;
        for (int i = 0; i < n; ++i)
          for (int j = 0; j < n; ++j) {
            const BrdfSample x = t.sample(wo, (i + 0.5) / n, (j + 0.5) / n);
            if (x.pdf > 0) sum += b->eval({x.wi, wo}).luminance() * x.wi.z / x.pdf;
          }
        const double mean = sum / (n * n);
        const AlbedoEstimate ref = directional_albedo(*b, wo, 512, 3);
        EXPECT_NEAR(mean, ref.mean.luminance(),
                    5 * ref.standard_error.luminance() + 0.01 * ref.mean.luminance())
            << t.describe_sampling() << " θo=" << std::acos(wo.z);
      }
    }
}

TEST(TabulatedSampler, BlackBrdfGivesNoSampleButCosineDefence) {
  const Opaque black(std::make_shared<models::Lambert>(Rgb{0, 0, 0}));
  const TabulatedSampler t(black, small(kSetups[2]));
  // Only the defensive cosine component can produce a sample.
  const BrdfSample x = t.sample(dir(30, 0), 0.01, 0.5);
  EXPECT_GT(x.pdf, 0);
  EXPECT_EQ(t.sample(dir(30, 0), 0.5, 0.5).pdf, 0);
}

}  // namespace
}  // namespace halfback::render
