// The lobes of Löw et al. 2012's and Bagher et al. 2012's fits against values worked out by hand
// from the papers' formulas (as BBM restates them) at configurations where they reduce to closed
// forms: normal incidence and view (ĥ = n, θh = 0), the mirror pair at 30° or 60° (ĥ = n,
// ωi·ĥ = cos θ), and ωo = n with ωi at 20° or 30° (θh = θi/2).
#include "halfback/models/published_lobes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace halfback::models {
namespace {
namespace published_lobes_test {  // (named: the unity build shares one anonymous namespace)

constexpr double kPi = std::numbers::pi;

Vec3<double> at(double theta_deg, double phi_deg) {
  const double t = theta_deg * kPi / 180, p = phi_deg * kPi / 180;
  return {std::cos(p) * std::sin(t), std::sin(p) * std::sin(t), std::cos(t)};
}

// The lobes through a registry holding only them (the models layer does not see the loader).
BrdfPtr load_brdf(const std::string& spec) {
  static ModelRegistry registry;
  static const bool registered = (register_published_lobe_models(registry), true);
  (void)registered;
  return registry.create(spec);
}

const DirPair<double> kNormal{{0, 0, 1}, {0, 0, 1}};

void expect_rgb(const Rgb& got, const Rgb& want, const char* what) {
  EXPECT_NEAR(got.r, want.r, 1e-12 * std::abs(want.r) + 1e-15) << what;
  EXPECT_NEAR(got.g, want.g, 1e-12 * std::abs(want.g) + 1e-15) << what;
  EXPECT_NEAR(got.b, want.b, 1e-12 * std::abs(want.b) + 1e-15) << what;
}

TEST(CookFresnel, HandValues) {
  // Normal incidence: g = η, b = 1, F = ((η − 1)/(η + 1))²; grazing: F = 1.
  EXPECT_NEAR(cook_fresnel(1.5, 1), 0.04, 1e-15);
  EXPECT_NEAR(cook_fresnel(1.5, 0), 1, 1e-15);
  // η = 1.5, c = cos 30° = √3/2: g = √2, a = (√2 − c)/(√2 + c) = 0.2404082…,
  // b = (c(√2 + c) − 1)/(c(√2 − c) + 1) = 0.6609557…, F = ½ a² (1 + b²) = 0.0415226…
  EXPECT_NEAR(cook_fresnel(1.5, std::sqrt(3.0) / 2), 0.04152262597582155, 1e-12);
}

TEST(LowCookTorrance, HandValues) {
  const BrdfPtr b = load_brdf(
      "low-cook-torrance:albedo_r=0.2,albedo_g=0.4,albedo_b=1.5,"
      "roughness=0.1,eta=1.5");
  // θh = 0: D = 1/m², G = 1, F = 0.04: ρ = albedo · 0.04 / (π m²) = albedo · 4/π.
  expect_rgb(b->eval(kNormal), Rgb{0.2, 0.4, 1.5} * (4 / kPi), "normal");
  // Mirror pair at 30°: ĥ = n, G = min(1, 2, 2) = 1, F = 0.0415226…: ρ = albedo F / (π m² cos²30°).
  const DirPair<double> mirror{at(30, 0), at(30, 180)};
  expect_rgb(b->eval(mirror), Rgb{0.2, 0.4, 1.5} * (0.04152262597582155 / (kPi * 0.01 * 0.75)),
             "mirror");
  // ωi at 20°, ωo = n, m = 0.3: θh = 10°, ωi·ĥ = cos 10°, D = exp(−tan²10°/0.09) / (0.09 cos⁴10°),
  // G = min(1, 2 cos10° cos20°/cos10°, 2 cos10°/cos10°) = 1 (2 cos 20° > 1).
  const BrdfPtr r = load_brdf("low-cook-torrance:albedo=1,roughness=0.3,eta=2");
  const double c10 = std::cos(10 * kPi / 180), t10 = std::tan(10 * kPi / 180);
  const double d = std::exp(-t10 * t10 / 0.09) / (0.09 * std::pow(c10, 4));
  const double want = d * cook_fresnel(2, c10) / (kPi * std::cos(20 * kPi / 180));
  EXPECT_NEAR(r->eval({at(20, 0), {0, 0, 1}}).g, want, 1e-12 * want);
}

TEST(LowAshikhminShirley, HandValues) {
  const BrdfPtr b = load_brdf("low-ashikhmin-shirley:albedo=1.5,sharpness=99,eta=1.5");
  // θh = 0, ωi·ĥ = 1, max cos = 1: ρ = albedo (n + 1)/(8π) F = 1.5 · 100/(8π) · 0.04.
  EXPECT_NEAR(b->eval(kNormal).r, 1.5 * 100 / (8 * kPi) * 0.04, 1e-12);
  // Mirror at 30°: ρ = albedo (n + 1)/(8π) F(cos30°) / (cos30° · cos30°).
  const double want = 1.5 * 100 / (8 * kPi) * 0.04152262597582155 / 0.75;
  EXPECT_NEAR(b->eval({at(30, 0), at(30, 180)}).b, want, 1e-12 * want);
}

TEST(LowSmooth, HandValues) {
  const BrdfPtr b = load_brdf("low-smooth:a_r=100,a_g=50,a_b=10,b=400,c=0.7,eta=1.5");
  // Mirror at 30°: p = 0, S = 1; |ωi,xy − ωo,xy|² / 4 = sin²30° so d = cos 30°: ρ = A F(cos 30°).
  expect_rgb(b->eval({at(30, 0), at(30, 180)}), Rgb{100, 50, 10} * 0.04152262597582155, "mirror");
  // ωi at 30°, ωo = n: |p|² = sin²30° = 1/4, S = (1 + 100)^(−0.7); d = √(1 − 1/16).
  const double want = 10 * std::pow(101.0, -0.7) * cook_fresnel(1.5, std::sqrt(15.0 / 16));
  EXPECT_NEAR(b->eval({at(30, 0), {0, 0, 1}}).b, want, 1e-12 * want);
  // The exponent is −C, not −(C + 1)/2 (halfback's abc): doubling B nearly scales S by 2^−C far
  // from the peak.
}

TEST(LowMicrofacet, HandValues) {
  const BrdfPtr b = load_brdf("low-microfacet:a_r=300,a_g=200,a_b=100,b=1000,c=1.2,eta=1.5");
  // θh = 0: S = 1, G = 1, F = 0.04: ρ = A · 0.04 / π (the fits' π).
  expect_rgb(b->eval(kNormal), Rgb{300, 200, 100} * (0.04 / kPi), "normal");
  // ωi at 20°, ωo = n: S = (1 + B(1 − cos 10°))^(−C), G = 1, F(cos 10°), 1/(π cos 20°).
  const double c10 = std::cos(10 * kPi / 180);
  const double want = 100 * std::pow(1 + 1000 * (1 - c10), -1.2) * cook_fresnel(1.5, c10) /
                      (kPi * std::cos(20 * kPi / 180));
  EXPECT_NEAR(b->eval({at(20, 0), {0, 0, 1}}).b, want, 1e-12 * want);
}

TEST(BagherSgd, HandValues) {
  const BrdfPtr b = load_brdf(
      "bagher-sgd:albedo=2,alpha=0.05,p=0.5,f0=0.9,f1=0.1,kscale=40,lambda=3,c=2,k=6,theta0=0.5");
  // θh = 0, θi = θo = 0 ≤ θ0: u = α, D = K e^(−α) / (α^p π), G = 1, F = F0 − F1:
  // ρ = albedo D (F0 − F1) / π.
  const double d0 = 40 * std::exp(-0.05) / (std::sqrt(0.05) * kPi);
  EXPECT_NEAR(b->eval(kNormal).r, 2 * d0 * 0.8 / kPi, 1e-12 * d0);
  // Mirror at 60° (> θ0): D = d0, G1 = 1 + Λ(1 − exp(c (π/3 − θ0)^k)) for both directions,
  // F = F0 + (1 − F0) · 0.5⁵ − F1 · 0.5, 1/(π cos²60°).
  const double g1 = 1 + 3 * (1 - std::exp(2 * std::pow(kPi / 3 - 0.5, 6)));
  const double f = 0.9 + 0.1 * std::pow(0.5, 5) - 0.1 * 0.5;
  const double want = 2 * d0 * g1 * g1 * f / (kPi * 0.25);
  EXPECT_NEAR(b->eval({at(60, 0), at(60, 180)}).g, want, 1e-12 * std::abs(want));
}

TEST(PublishedLobes, BelowTheHorizonIsZeroAndTheSmoothLobeCountsTheHorizon) {
  const DirPair<double> below{at(30, 0), {0, 0.6, -0.8}};
  for (const char* spec :
       {"low-cook-torrance", "low-ashikhmin-shirley", "low-smooth", "low-microfacet", "bagher-sgd"})
    EXPECT_EQ(load_brdf(spec)->eval(below).r, 0) << spec;
  // BBM's LowSmooth tests z ≥ 0 (the microfacet lobes z > 0): on the horizon it is not 0.
  EXPECT_GT(load_brdf("low-smooth")->eval({at(30, 0), {-1, 0, 0}}).r, 0);
  EXPECT_EQ(load_brdf("low-microfacet")->eval({at(30, 0), {-1, 0, 0}}).r, 0);
}

}  // namespace published_lobes_test
}  // namespace
}  // namespace halfback::models
