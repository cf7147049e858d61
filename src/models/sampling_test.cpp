// Importance sampling of the analytic models: sample() and pdf() agree, the pdf integrates to the
// probability of a valid sample, sampled directions follow the pdf (χ²), and the sampling weight
// ρ cos θi / pdf agrees with eval (exactly where the weight is known in closed form, and through
// the directional albedo otherwise).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "halfback/brdf/albedo.hpp"
#include "halfback/models/analytic.hpp"
#include "sampling_detail.hpp"
#include "support/test_stats.hpp"

namespace halfback::models {
namespace {

using render::testing::chi2_test;
using render::testing::DirSample;

Vec3<double> dir(double theta_deg, double phi_deg) {
  const double t = theta_deg * std::numbers::pi / 180, p = phi_deg * std::numbers::pi / 180;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

std::shared_ptr<Microfacet> microfacet(MicrofacetParams::Distribution d, double ax, double ay,
                                       double f0 = 1) {
  MicrofacetParams p;
  p.distribution = d;
  p.alpha_x = ax;
  p.alpha_y = ay;
  p.fresnel.kind = Fresnel::Kind::schlick;
  p.fresnel.f0 = {f0, f0, f0};
  return std::make_shared<Microfacet>(p);
}

struct Case {
  std::string name;
  std::shared_ptr<const Brdf> brdf;
  bool chi2 = true;  // lobes too sharp for the quadrature of the χ² cells skip that test
};

std::vector<Case> cases() {
  using D = MicrofacetParams::Distribution;
  AbcParams abc;
  abc.kd = {0.3, 0.2, 0.1};
  abc.b = 100;
  AbcParams abc_c1 = abc;  // C = 1: the logarithmic branch of the radial inversion
  abc_c1.c = 1;
  std::vector<Case> v{
      {"lambert", std::make_shared<Lambert>(Rgb{0.8, 0.5, 0.2})},
      {"ggx_0.3", microfacet(D::ggx, 0.3, 0.3)},
      {"ggx_aniso", microfacet(D::ggx, 0.15, 0.5)},
      {"ggx_0.05", microfacet(D::ggx, 0.05, 0.05), false},
      {"beckmann_0.3", microfacet(D::beckmann, 0.3, 0.3)},
      {"beckmann_aniso", microfacet(D::beckmann, 0.5, 0.2)},
      {"abc", std::make_shared<Abc>(abc)},
      {"abc_c1", std::make_shared<Abc>(abc_c1)},
      {"sheen", std::make_shared<Sheen>(SheenParams{{1, 1, 1}, 0.3})},
  };
  v.push_back({"sum", std::make_shared<Sum>(
                          std::vector<BrdfPtr>{std::make_shared<Lambert>(Rgb{0.5, 0.5, 0.5}),
                                               microfacet(D::ggx, 0.2, 0.2, 0.04)})});
  return v;
}

const std::vector<Vec3<double>> kViews{dir(0, 0), dir(35, 20), dir(65, 200), dir(85, 110)};

TEST(ModelSampling, SampleAndPdfAgree) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  for (const Case& c : cases()) {
    const Brdf& s = *c.brdf;
    ASSERT_TRUE(s.has_importance_sampling()) << c.name;
    for (const auto& wo : kViews) {
      int valid = 0;
      for (int k = 0; k < 2000; ++k) {
        const BrdfSample b = s.sample(wo, u(rng), u(rng));
        if (!(b.pdf > 0)) continue;
        ++valid;
        ASSERT_GT(b.wi.z, 0) << c.name;
        EXPECT_NEAR(std::hypot(b.wi.x, b.wi.y, b.wi.z), 1, 1e-12) << c.name;
        EXPECT_NEAR(b.pdf, s.pdf(wo, b.wi), 1e-9 * b.pdf) << c.name;
      }
      EXPECT_GT(valid, 1000) << c.name;
    }
    // Below the horizon, no density.
    EXPECT_EQ(s.pdf(dir(30, 0), {0, 0.6, -0.8}), 0) << c.name;
    EXPECT_EQ(s.pdf({0, 0.6, -0.8}, dir(30, 0)), 0) << c.name;
    EXPECT_EQ(s.sample({0, 0.6, -0.8}, 0.3, 0.3).pdf, 0) << c.name;
  }
}

TEST(ModelSampling, ChiSquareAndIntegral) {
  for (const Case& c : cases()) {
    if (!c.chi2) continue;
    const Brdf& s = *c.brdf;
    ASSERT_TRUE(s.has_importance_sampling()) << c.name;
    for (const auto& wo : kViews) {
      const auto r = chi2_test(
          [&](double u1, double u2) {
            const BrdfSample b = s.sample(wo, u1, u2);
            return DirSample{b.wi, b.pdf};
          },
          [&](const Vec3<double>& wi) { return s.pdf(wo, wi); }, 200000, false, 16, 32, 24);
      // ∫ pdf over the hemisphere is the probability of a valid sample.
      EXPECT_LE(r.integral, 1.002) << c.name;
      EXPECT_NEAR(r.integral, r.valid_fraction, 0.006) << c.name << " θo=" << std::acos(wo.z);
      EXPECT_LT(r.z, 4.5) << c.name << " θo=" << std::acos(wo.z) << " chi2=" << r.chi2
                          << " dof=" << r.dof;
    }
  }
}

TEST(ModelSampling, LambertWeightIsTheAlbedo) {
  const Lambert l({0.8, 0.5, 0.2});
  for (const auto& wo : kViews)
    for (double u1 : {0.01, 0.4, 0.93})
      for (double u2 : {0.0, 0.3, 0.77}) {
        const BrdfSample b = l.sample(wo, u1, u2);
        const Rgb f = l.eval({b.wi, wo});
        EXPECT_NEAR(f.r * b.wi.z / b.pdf, 0.8, 1e-12);
        EXPECT_NEAR(f.b * b.wi.z / b.pdf, 0.2, 1e-12);
      }
}

// With visible-normal sampling and F = 1 the weight is G2(ωi, ωo) / G1(ωo) in closed form.
TEST(ModelSampling, GgxWeightIsTheMaskingRatio) {
  const auto m = microfacet(MicrofacetParams::Distribution::ggx, 0.25, 0.6);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (const auto& wo : kViews)
    for (int k = 0; k < 500; ++k) {
      const BrdfSample b = m->sample(wo, u(rng), u(rng));
      if (!(b.pdf > 0)) continue;
      const double weight = m->eval({b.wi, wo}).r * b.wi.z / b.pdf;
      const double expected = (1 + m->lambda(wo)) / (1 + m->lambda(wo) + m->lambda(b.wi));
      EXPECT_NEAR(weight, expected, 1e-9 * expected);
    }
}

// The albedo by each model's own sampler agrees with the independent cosine-sampled estimate.
TEST(ModelSampling, SampledAlbedoMatchesDirectionalAlbedo) {
  for (const Case& c : cases()) {
    const Brdf& s = *c.brdf;
    ASSERT_TRUE(s.has_importance_sampling()) << c.name;
    for (const auto& wo : kViews) {
      constexpr int n = 256;
      double sum = 0, sum2 = 0;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const BrdfSample b = s.sample(wo, (i + 0.5) / n, (j + 0.5) / n);
          if (!(b.pdf > 0)) continue;
          const double w = c.brdf->eval({b.wi, wo}).luminance() * b.wi.z / b.pdf;
          sum += w;
          sum2 += w * w;
        }
      const double mean = sum / (n * n);
      const AlbedoEstimate ref = directional_albedo(*c.brdf, wo, 512, 5);
      const double ref_l = ref.mean.luminance(), ref_se = ref.standard_error.luminance();
      EXPECT_NEAR(mean, ref_l, 5 * ref_se + 2e-3 * ref_l + 1e-4)
          << c.name << " θo=" << std::acos(wo.z);
    }
  }
}

// The polynomial sine and cosine of GGX's sampling against libm: at the octants' edges and
// middles, 0, 1 − 2⁻⁵³, 1 and random numbers, within a few rounding errors.
TEST(ModelSampling, SincosTurnsMatchesLibm) {
  std::vector<double> us{0, 0x1.fffffffffffffp-1, 1};
  for (int k = 0; k <= 16; ++k) us.push_back(k / 16.0);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (int k = 0; k < 100000; ++k) us.push_back(u(rng));
  double worst = 0;
  for (double x : us) {
    double s, c;
    detail::sincos_turns(x, s, c);
    const double phi = 2 * std::numbers::pi * x;
    worst = std::max({worst, std::abs(s - std::sin(phi)), std::abs(c - std::cos(phi))});
  }
  // 2πu itself rounds by up to 4·10⁻¹⁶ near u = 1 in the reference.
  EXPECT_LT(worst, 2e-15);
}

// sample_batch() returns sample()'s numbers bit for bit (GGX's own batch, the others' default),
// and refuses spans of different sizes.
TEST(ModelSampling, BatchEqualsOneAtATime) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3<double>> wo;
  std::vector<double> u1, u2;
  for (int k = 0; k < 1000; ++k) {
    wo.push_back(dir(90 * u(rng) + (k % 50 == 0 ? 95 : 0), 360 * u(rng)));  // some below
    u1.push_back(u(rng));
    u2.push_back(u(rng));
  }
  wo.push_back({0, 0, 1});  // the view along n: the frame's fallback
  u1.push_back(0.3);
  u2.push_back(0.7);
  for (const Case& c : cases()) {
    std::vector<BrdfSample> out(wo.size());
    c.brdf->sample_batch(wo, u1, u2, out);
    for (std::size_t i = 0; i < wo.size(); ++i) {
      const BrdfSample one = c.brdf->sample(wo[i], u1[i], u2[i]);
      ASSERT_TRUE(one.pdf == out[i].pdf && one.wi.x == out[i].wi.x && one.wi.y == out[i].wi.y &&
                  one.wi.z == out[i].wi.z)
          << c.name << " " << i;
    }
    EXPECT_THROW(c.brdf->sample_batch(wo, u1, std::span(u2).first(3), out), std::invalid_argument)
        << c.name;
  }
}

TEST(ModelSampling, SumMixesItsTerms) {
  const auto lam = std::make_shared<Lambert>(Rgb{0.5, 0.5, 0.5});
  const auto ggx = microfacet(MicrofacetParams::Distribution::ggx, 0.1, 0.1);
  const Sum sum({lam, ggx});
  // The mixture pdf lies between the terms' pdfs.
  const auto wo = dir(40, 10);
  for (const auto& wi : {dir(40, 190), dir(10, 50), dir(70, 0)}) {
    const double p = sum.pdf(wo, wi), a = lam->pdf(wo, wi), b = ggx->pdf(wo, wi);
    EXPECT_GE(p, std::min(a, b) * (1 - 1e-12));
    EXPECT_LE(p, std::max(a, b) * (1 + 1e-12));
  }
}

}  // namespace
}  // namespace halfback::models
