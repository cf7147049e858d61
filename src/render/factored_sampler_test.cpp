// The factored sampler (Lawrence et al. 2004's manner), in each chart: sample() and pdf() agree,
// the pdf integrates to the probability of a valid sample and its draws follow it (χ²), the
// sampled albedo is unbiased, and the factorization is exact where ρ cos θi does not depend on ωo.
#include "halfback/render/factored_sampler.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "halfback/brdf/albedo.hpp"
#include "halfback/models/analytic.hpp"
#include "halfback/render/sampling_metric.hpp"
#include "sampler_test_support.hpp"
#include "support/test_stats.hpp"

namespace halfback::render {
namespace {

using namespace test_support;

BrdfPtr lambert() {
  return std::make_shared<models::Lambert>(Rgb{0.6, 0.6, 0.6});
}

FactorOptions small(Space param, int terms = 3) {
  FactorOptions o;
  o.param = param;
  o.terms = terms;
  o.radial = 32;
  o.azimuthal = 64;
  o.theta_views = 12;
  o.aniso_theta_views = o.aniso_phi_views = 6;
  o.iterations = 100;
  return o;
}

const Space kCharts[] = {space_of<Spherical>, space_of<HalfDiff>, space_of<Hybrid>};

TEST(FactoredSampler, SampleAndPdfAgree) {
  const Opaque iso(ggx(0.1, 0.1)), aniso(ggx(0.1, 0.4));
  for (Space param : kCharts)
    for (const Brdf* b : {static_cast<const Brdf*>(&iso), static_cast<const Brdf*>(&aniso)}) {
      const FactoredSampler f(*b, small(param));
      std::mt19937_64 rng(1);
      std::uniform_real_distribution<double> u(0, 1);
      for (const auto& wo : kViews) {
        int valid = 0;
        for (int k = 0; k < 3000; ++k) {
          const BrdfSample x = f.sample(wo, u(rng), u(rng));
          if (!(x.pdf > 0)) continue;
          ++valid;
          ASSERT_GT(x.wi.z, 0);
          EXPECT_NEAR(std::hypot(x.wi.x, x.wi.y, x.wi.z), 1, 1e-12);
          // sample() takes the Jacobian from the forward map, pdf() from the inverse: they
          // round differently where the warped chart's Jacobian vanishes (the lobe's centre).
          EXPECT_NEAR(x.pdf, f.pdf(wo, x.wi), 1e-7 * x.pdf) << f.describe_sampling();
        }
        // Terms shared by every view put some mass where a view has no direction (the half
        // vectors that send ωi below the horizon at grazing ωo): a share, not most.
        EXPECT_GT(valid, 1500) << f.describe_sampling();
      }
    }
}

TEST(FactoredSampler, ChiSquareAndIntegral) {
  const Opaque iso(ggx(0.3, 0.3)), aniso(ggx(0.2, 0.5));
  for (Space param : kCharts)
    for (const Brdf* b : {static_cast<const Brdf*>(&iso), static_cast<const Brdf*>(&aniso)}) {
      const FactoredSampler f(*b, small(param));
      for (const auto& wo : kViews) {
        const auto r = testing::chi2_test(
            [&](double u1, double u2) {
              const BrdfSample x = f.sample(wo, u1, u2);
              return testing::DirSample{x.wi, x.pdf};
            },
            [&](const Vec3<double>& wi) { return f.pdf(wo, wi); }, 100000, false, 16, 32, 24, 7,
            param == space_of<Spherical> ? Vec3<double>{0, 0, 1} : Vec3<double>{-wo.x, -wo.y, wo.z},
            10);
        EXPECT_LE(r.integral, 1.02) << f.describe_sampling();
        EXPECT_NEAR(r.integral, r.valid_fraction, 0.02) << f.describe_sampling();
        EXPECT_LT(r.z, 4.5) << f.describe_sampling() << " θo=" << std::acos(wo.z)
                            << " chi2=" << r.chi2 << " dof=" << r.dof;
      }
    }
}

TEST(FactoredSampler, SampledAlbedoMatchesDirectionalAlbedo) {
  const Opaque glossy(ggx(0.08, 0.08)), diffuse(lambert());
  for (Space param : kCharts)
    for (const Brdf* b : {static_cast<const Brdf*>(&glossy), static_cast<const Brdf*>(&diffuse)}) {
      const FactoredSampler f(*b, small(param));
      for (const auto& wo : kViews) {
        constexpr int n = 200;
        double sum = 0;
        for (int i = 0; i < n; ++i)
          for (int j = 0; j < n; ++j) {
            const BrdfSample x = f.sample(wo, (i + 0.5) / n, (j + 0.5) / n);
            if (x.pdf > 0) sum += b->eval({x.wi, wo}).luminance() * x.wi.z / x.pdf;
          }
        const AlbedoEstimate ref = directional_albedo(*b, wo, 512, 3);
        EXPECT_NEAR(sum / (n * n), ref.mean.luminance(),
                    5 * ref.standard_error.luminance() + 0.01 * ref.mean.luminance())
            << f.describe_sampling() << " θo=" << std::acos(wo.z);
      }
    }
}

// In the spherical chart a Lambertian's ρ cos θi is the same function of the cell at every ωo:
// one term is exact, and its samples are the cosine's (up to the cells' piecewise constancy).
TEST(FactoredSampler, OneTermIsExactForASeparableBrdf) {
  const Opaque diffuse(lambert());
  const FactoredSampler f(diffuse, small(space_of<Spherical>, 1));
  EXPECT_LT(f.approximation_error(), 1e-9);
  const SamplingMeasure m = measure_sampling(diffuse, f, {.theta_count = 4, .samples = 20000});
  EXPECT_LT(m.relative_variance, 0.01);  // piecewise-constant cells of a cosine: ~1e-3
}

// More terms fit a glossy lobe better (its shape in the half-vector chart changes with θo), and
// as many terms as views fit it nearly exactly.
TEST(FactoredSampler, MoreTermsFitBetter) {
  const Opaque glossy(ggx(0.15, 0.15));
  FactorOptions o = small(space_of<HalfDiff>, 1);
  o.theta_views = 6;
  const double one = FactoredSampler(glossy, o).approximation_error();
  o.terms = 3;
  const double three = FactoredSampler(glossy, o).approximation_error();
  o.terms = 6;
  o.iterations = 400;
  const double six = FactoredSampler(glossy, o).approximation_error();
  EXPECT_GT(one, 0.02);
  EXPECT_LT(three, one);
  EXPECT_LT(six, 0.2 * one);
}

TEST(FactoredSampler, BlackBrdfGivesNoSampleButCosineDefence) {
  const Opaque black(std::make_shared<models::Lambert>(Rgb{0, 0, 0}));
  const FactoredSampler f(black, small(space_of<HalfDiff>));
  EXPECT_GT(f.sample(dir(30, 0), 0.01, 0.5).pdf, 0);
  EXPECT_EQ(f.sample(dir(30, 0), 0.5, 0.5).pdf, 0);
  EXPECT_EQ(f.approximation_error(), 0);
}

TEST(FactoredSampler, InvalidOptionsAreRefused) {
  const Opaque diffuse(lambert());
  for (auto edit :
       {+[](FactorOptions& o) { o.terms = 0; },
        +[](FactorOptions& o) { o.terms = FactoredSampler::kMaxTerms + 1; },
        +[](FactorOptions& o) { o.radial = 1; }, +[](FactorOptions& o) { o.iterations = 0; },
        +[](FactorOptions& o) { o.defensive = 1; }, +[](FactorOptions& o) { o.theta_views = 0; }}) {
    FactorOptions o = small(space_of<HalfDiff>);
    edit(o);
    EXPECT_THROW(FactoredSampler(diffuse, o), std::invalid_argument);
  }
}

TEST(FactoredSampler, MemoryBudgetIsKept) {
  const Opaque diffuse(lambert());
  for (const std::size_t bytes : {std::size_t(64) << 10, std::size_t(1) << 20})
    for (int terms : {2, 4, 8}) {
      FactorOptions o = factoring_for_memory(space_of<HalfDiff>, bytes, terms);
      o.iterations = 1;
      const FactoredSampler f(diffuse, o);
      EXPECT_NEAR(double(f.bytes()), double(bytes), 0.05 * double(bytes)) << terms;
    }
}

}  // namespace
}  // namespace halfback::render
