// The first published fit of each of Ngan et al. 2005's microfacet-style lobes (BBM's
// fits/ngan_cooktorrance.fit, ngan_ashikhminshirley.fit and ngan_he.fit, blue-acrylic), turned by
// hand into a spec: it loads, and its value at normal incidence is the Lambertian term plus the
// lobe's closed form there.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "halfback/loader/load.hpp"

namespace halfback::ngan_microfacet_load_test {  // (own namespace: one unity file)
namespace {

constexpr double kPi = std::numbers::pi;
const DirPair<double> kNormal{{0, 0, 1}, {0, 0, 1}};

void expect_rgb_near(const Rgb& got, const Rgb& want) {
  for (auto [g, w] : {std::pair{got.r, want.r}, {got.g, want.g}, {got.b, want.b}}) {
    EXPECT_TRUE(std::isfinite(g));
    EXPECT_GT(g, 0);
    EXPECT_NEAR(g, w, 1e-12 * w);
  }
}

// blue-acrylic = Aggregate(Lambertian(albedo = [0.0143, 0.033, 0.0639]),
//   NganCookTorrance(albedo = [0.0291, 0.0193, 0.0118], eta = 0.117, roughness = 0.0137))
TEST(NganMicrofacetLoad, FirstPublishedCookTorranceLine) {
  const BrdfPtr b = load_brdf(
      "lambert:albedo_r=0.0143,albedo_g=0.033,albedo_b=0.0639"
      "+cook-torrance:albedo_r=0.0291,albedo_g=0.0193,albedo_b=0.0118,eta=0.117,roughness=0.0137");
  // At ωi = ωo = n: kd/π + albedo · eta / (π² m²) (D = 1/(π m²), G = 1, F = eta).
  const double lobe = 0.117 / (kPi * kPi * 0.0137 * 0.0137);
  expect_rgb_near(b->eval(kNormal), {0.0143 / kPi + 0.0291 * lobe, 0.033 / kPi + 0.0193 * lobe,
                                     0.0639 / kPi + 0.0118 * lobe});
  EXPECT_EQ(b->name(), "lambert+cook-torrance");
}

// blue-acrylic = Aggregate(Lambertian(albedo = [0.0143, 0.0331, 0.0639]),
//   NganAshikhminShirley(albedo = [0.0366, 0.0241, 0.0147], fresnelReflectance = 0.0949,
//   sharpness = 11600.0))
TEST(NganMicrofacetLoad, FirstPublishedAshikhminShirleyLine) {
  const BrdfPtr b = load_brdf(
      "lambert:albedo_r=0.0143,albedo_g=0.0331,albedo_b=0.0639"
      "+ashikhmin-shirley:albedo_r=0.0366,albedo_g=0.0241,albedo_b=0.0147,f0=0.0949,"
      "sharpness=11600");
  // At ωi = ωo = n: kd/π + albedo · (n + 1)/(8π) · F0.
  const double lobe = 11601 / (8 * kPi) * 0.0949;
  expect_rgb_near(b->eval(kNormal), {0.0143 / kPi + 0.0366 * lobe, 0.0331 / kPi + 0.0241 * lobe,
                                     0.0639 / kPi + 0.0147 * lobe});
  EXPECT_EQ(b->name(), "lambert+ashikhmin-shirley");
}

// blue-acrylic = Aggregate(Lambertian(albedo = [0.0147, 0.0334, 0.0641]), NganHe(albedo = [2.93,
//   1.92, 1.17], autocorrelation = 28.7, roughness = 0.063, eta = 1.08))
TEST(NganMicrofacetLoad, FirstPublishedHeLine) {
  const BrdfPtr b = load_brdf(
      "lambert:albedo_r=0.0147,albedo_g=0.0334,albedo_b=0.0641"
      "+he:albedo_r=2.93,albedo_g=1.92,albedo_b=1.17,autocorrelation=28.7,roughness=0.063,"
      "eta=1.08");
  // At ωi = ωo = n: kd/π + albedo · F0 · π τ²/λ² · e^(−g) (Ei(g) − γ − ln g), g = (4πσ0/λ)²
  // (S = 1, G = 4, v_xy = 0; docs/models.md), λ = BBM's 0.645, 0.526, 0.444 µm.
  const auto lobe = [](double lambda) {
    const double f0 = std::pow(0.08 / 2.08, 2), g = std::pow(4 * kPi * 0.063 / lambda, 2);
    return f0 * kPi * 28.7 * 28.7 / (lambda * lambda) * std::exp(-g) *
           (std::expint(g) - std::numbers::egamma - std::log(g));
  };
  const Rgb got = b->eval(kNormal);
  const Rgb want{0.0147 / kPi + 2.93 * lobe(0.645), 0.0334 / kPi + 1.92 * lobe(0.526),
                 0.0641 / kPi + 1.17 * lobe(0.444)};
  for (auto [g, w] : {std::pair{got.r, want.r}, {got.g, want.g}, {got.b, want.b}})
    EXPECT_NEAR(g, w, 1e-10 * w);  // std::expint: ~5e-12
  EXPECT_EQ(b->name(), "lambert+he");
}

TEST(NganMicrofacetLoad, ModelsAreInTheBuiltInRegistry) {
  EXPECT_NE(model_registry().find("cook-torrance"), nullptr);
  EXPECT_NE(model_registry().find("ashikhmin-shirley"), nullptr);
  EXPECT_NE(model_registry().find("he"), nullptr);
}

}  // namespace
}  // namespace halfback::ngan_microfacet_load_test
