// The lobes of Ngan et al. 2005 as BBM defines them: values against a restatement in angles,
// reciprocity, energy, parameter checks and their registry entries.
#include "halfback/models/ngan_microfacet.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "halfback/brdf/albedo.hpp"

// (A namespace of its own: the layer's tests are compiled as one unity file.)
namespace halfback::models::ngan_microfacet_test {
namespace {

constexpr double kPi = std::numbers::pi;

Vec3<double> dir(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// A configuration in angles: (θi, φi, θo, φo).
struct Angles {
  double ti, pi, to, po;
};
const Angles kConfigs[] = {
    {0.3, 0.1, 0.5, 2.9},  // near the mirror direction
    {1.2, 0.0, 1.2, kPi},  // exactly the mirror direction, 69° off the normal
    {0.7, 1.0, 1.4, 1.5},  // off-specular, grazing view: the V-groove masks
    {1.5, 0.2, 0.2, 3.0},  // grazing light: the V-groove shadows
    {0.9, 0.0, 0.4, 0.3},  // both on the same side (back-scattering)
};

// The half and difference angles from the directions' angles alone (no vectors):
// ωi·ωo = cos 2θd, so cos θd = √((1 + ωi·ωo)/2), and cos θh = (cos θi + cos θo) / (2 cos θd).
struct HalfAngles {
  double cos_h, cos_d;
};
HalfAngles half_angles(const Angles& a) {
  const double cos_2d =
      std::sin(a.ti) * std::sin(a.to) * std::cos(a.pi - a.po) + std::cos(a.ti) * std::cos(a.to);
  const double cos_d = std::sqrt((1 + cos_2d) / 2);
  return {(std::cos(a.ti) + std::cos(a.to)) / (2 * cos_d), cos_d};
}

double schlick_ref(double f0, double cos_d) {
  return f0 + (1 - f0) * std::pow(1 - cos_d, 5);
}

// BBM's NganCookTorrance restated in angles: D G F / (π cos θi cos θo), one channel.
double cook_torrance_ref(const Angles& a, double albedo, double eta, double m) {
  const auto [ch, cd] = half_angles(a);
  const double tan2 = 1 / (ch * ch) - 1;
  const double d = std::exp(-tan2 / (m * m)) / (kPi * m * m * std::pow(ch, 4));
  const double g = std::min({1.0, 2 * ch * std::cos(a.ti) / cd, 2 * ch * std::cos(a.to) / cd});
  return albedo * d * g * schlick_ref(eta, cd) / (kPi * std::cos(a.ti) * std::cos(a.to));
}

// BBM's NganAshikhminShirley restated in angles, one channel.
double ashikhmin_shirley_ref(const Angles& a, double albedo, double f0, double n) {
  const auto [ch, cd] = half_angles(a);
  return albedo * (n + 1) / (8 * kPi) * std::pow(ch, n) * schlick_ref(f0, cd) /
         (cd * std::max(std::cos(a.ti), std::cos(a.to)));
}

Rgb eval_at(const Brdf& b, const Angles& a) {
  return b.eval({dir(a.ti, a.pi), dir(a.to, a.po)});
}

std::vector<DirPair<double>> random_pairs(int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<DirPair<double>> pairs;
  for (int k = 0; k < n; ++k)
    pairs.push_back({dir(std::acos(std::max(1e-3, u(rng))), 2 * kPi * u(rng)),
                     dir(std::acos(std::max(1e-3, u(rng))), 2 * kPi * u(rng))});
  return pairs;
}

// Checks mean + 3 standard errors ≤ bound for every channel of the albedo at θi.
void expect_albedo_at_most(const Brdf& b, double theta, double bound) {
  const AlbedoEstimate a = directional_albedo(b, dir(theta, 0.4), 512, 5);
  EXPECT_LE(a.mean.r - 3 * a.standard_error.r, bound) << b.description() << " θi=" << theta;
  EXPECT_LE(a.mean.g - 3 * a.standard_error.g, bound) << b.description() << " θi=" << theta;
  EXPECT_LE(a.mean.b - 3 * a.standard_error.b, bound) << b.description() << " θi=" << theta;
}

// --- cook-torrance ----------------------------------------------------------------------------

TEST(NganCookTorrance, MatchesTheRestatementInAngles) {
  const Rgb albedo{0.9, 0.5, 0.05};
  for (double eta : {0.117, 0.5, 1.0})
    for (double m : {0.0137, 0.2, 0.943}) {
      const NganCookTorrance ct({albedo, eta, m});
      for (const Angles& a : kConfigs) {
        const Rgb v = eval_at(ct, a);
        const double want_r = cook_torrance_ref(a, albedo.r, eta, m);
        const double want_b = cook_torrance_ref(a, albedo.b, eta, m);
        EXPECT_NEAR(v.r, want_r, 1e-11 * want_r) << eta << " " << m << " θi=" << a.ti;
        EXPECT_NEAR(v.b, want_b, 1e-11 * want_b) << eta << " " << m << " θi=" << a.ti;
      }
    }
}

TEST(NganCookTorrance, HandValueAtNormalIncidence) {
  // ωi = ωo = n: θh = θd = 0, D = 1/(π m²), G = 1, F = F0 = eta: ρ = albedo eta / (π² m²).
  const NganCookTorrance ct({{0.5, 0.5, 0.5}, 0.2, 0.3});
  EXPECT_NEAR(ct.eval({{0, 0, 1}, {0, 0, 1}}).g, 0.5 * 0.2 / (kPi * kPi * 0.09), 1e-14);
  // eta is F0, not an index: eta = 1 reflects everything at every angle (F = 1).
  const NganCookTorrance white({{1, 1, 1}, 1.0, 0.3});
  const Angles grazing{1.5, 0.2, 0.2, 3.0};
  EXPECT_NEAR(eval_at(white, grazing).r, cook_torrance_ref(grazing, 1, 1, 0.3), 1e-12);
}

TEST(NganCookTorrance, IsReciprocalBitForBit) {
  const NganCookTorrance ct({{0.7, 0.4, 0.2}, 0.3, 0.25});
  for (const auto& p : random_pairs(2000, 3)) {
    const Rgb a = ct.eval(p), b = ct.eval({p.wo, p.wi});
    EXPECT_EQ(a, b);
  }
  EXPECT_TRUE(ct.reciprocal());
}

TEST(NganCookTorrance, ZeroBelowTheHorizon) {
  const NganCookTorrance ct({{0.7, 0.4, 0.2}, 0.3, 0.25});
  EXPECT_EQ(ct.eval({{0, 0.6, -0.8}, {0, 0, 1}}), Rgb{});
  EXPECT_EQ(ct.eval({{0, 0, 1}, {0.6, 0, -0.8}}), Rgb{});
}

// The 1/π normalization (where Walter's microfacet form has 1/4) gives a white lobe up to 4/π of
// the light: the albedo is at most 4/π · albedo (docs/models.md), so BBM's albedo ≤ π/4 keeps it
// ≤ 1, and a smooth white lobe at normal incidence reflects more than it receives.
TEST(NganCookTorrance, AlbedoAtMostFourOverPiTimesTheScale) {
  for (double m : {0.2, 0.5, 0.943, 2.0}) {
    const NganCookTorrance white({{1, 1, 1}, 1.0, m});
    const NganCookTorrance scaled({{kPi / 4, kPi / 4, kPi / 4}, 1.0, m});
    for (double theta : {0.0, 0.6, 1.2, 1.5}) {
      expect_albedo_at_most(white, theta, 4 / kPi);
      expect_albedo_at_most(scaled, theta, 1.0);
    }
  }
  const AlbedoEstimate smooth =
      directional_albedo(NganCookTorrance({{1, 1, 1}, 1.0, 0.2}), dir(0, 0), 512, 5);
  EXPECT_NEAR(smooth.mean.r, 4 / kPi, 0.01 + 3 * smooth.standard_error.r);  // > 1: not conserving
}

TEST(NganCookTorrance, RejectsParametersOutsideTheirRanges) {
  auto message = [](const NganCookTorranceParams& p) -> std::string {
    try {
      NganCookTorrance{p};
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message({{0.5, 1.5, 0.5}, 0.1, 0.1}).find("albedo_g"), std::string::npos);
  EXPECT_NE(message({{0.5, 0.5, 0.5}, 1.2, 0.1}).find("eta"), std::string::npos);
  EXPECT_NE(message({{0.5, 0.5, 0.5}, 0.1, 0.0}).find("roughness"), std::string::npos);
  EXPECT_NE(message({{0.5, 0.5, 0.5}, 0.1, std::nan("")}).find("roughness"), std::string::npos);
  EXPECT_EQ(message({{1, 1, 1}, 1, 2}), "");
}

// --- ashikhmin-shirley ------------------------------------------------------------------------

TEST(NganAshikhminShirley, MatchesTheRestatementInAngles) {
  const Rgb albedo{0.9, 0.5, 0.05};
  for (double f0 : {0.0949, 0.5, 1.0})
    for (double n : {0.5, 30.0, 11600.0}) {
      const NganAshikhminShirley as({albedo, f0, n});
      for (const Angles& a : kConfigs) {
        const Rgb v = eval_at(as, a);
        const double want_r = ashikhmin_shirley_ref(a, albedo.r, f0, n);
        const double want_b = ashikhmin_shirley_ref(a, albedo.b, f0, n);
        EXPECT_NEAR(v.r, want_r, 1e-10 * want_r) << f0 << " " << n << " θi=" << a.ti;
        EXPECT_NEAR(v.b, want_b, 1e-10 * want_b) << f0 << " " << n << " θi=" << a.ti;
      }
    }
}

TEST(NganAshikhminShirley, HandValueAtNormalIncidence) {
  // ωi = ωo = n: cos θh = cos θd = 1: ρ = albedo (n + 1)/(8π) F0.
  const NganAshikhminShirley as({{0.5, 0.5, 0.5}, 0.2, 31});
  EXPECT_NEAR(as.eval({{0, 0, 1}, {0, 0, 1}}).g, 0.5 * 32 / (8 * kPi) * 0.2, 1e-14);
}

TEST(NganAshikhminShirley, IsReciprocalBitForBit) {
  const NganAshikhminShirley as({{0.7, 0.4, 0.2}, 0.3, 40});
  for (const auto& p : random_pairs(2000, 4)) {
    const Rgb a = as.eval(p), b = as.eval({p.wo, p.wi});
    EXPECT_EQ(a, b);
  }
  EXPECT_TRUE(as.reciprocal());
}

TEST(NganAshikhminShirley, ZeroBelowTheHorizon) {
  const NganAshikhminShirley as({{0.7, 0.4, 0.2}, 0.3, 40});
  EXPECT_EQ(as.eval({{0, 0.6, -0.8}, {0, 0, 1}}), Rgb{});
  EXPECT_EQ(as.eval({{0, 0, 1}, {0.6, 0, -0.8}}), Rgb{});
}

// With ωo the mirror of ωi about ĥ, dωo = 4 (ωi·ĥ) dωh: the albedo is albedo ∫ (n+1)/(2π) cos^n θh
// F cos θo / max(cos θi, cos θo) dωh ≤ albedo, since the lobe integrates to 1 over ĥ.
TEST(NganAshikhminShirley, AlbedoAtMostTheScale) {
  for (double n : {0.5, 5.0, 50.0})
    for (double theta : {0.0, 0.6, 1.2, 1.5}) {
      expect_albedo_at_most(NganAshikhminShirley({{1, 1, 1}, 1.0, n}), theta, 1.0);
      expect_albedo_at_most(NganAshikhminShirley({{0.6, 0.6, 0.6}, 1.0, n}), theta, 0.6);
    }
}

TEST(NganAshikhminShirley, RejectsParametersOutsideTheirRanges) {
  auto message = [](const NganAshikhminShirleyParams& p) -> std::string {
    try {
      NganAshikhminShirley{p};
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message({{0.5, 0.5, -0.1}, 0.1, 10}).find("albedo_b"), std::string::npos);
  EXPECT_NE(message({{0.5, 0.5, 0.5}, -0.1, 10}).find("f0"), std::string::npos);
  EXPECT_NE(message({{0.5, 0.5, 0.5}, 0.1, -1}).find("sharpness"), std::string::npos);
  EXPECT_NE(message({{0.5, 0.5, 0.5}, 0.1, 2e6}).find("sharpness"), std::string::npos);
  EXPECT_EQ(message({{1, 1, 1}, 1, 0}), "");
}

// --- registry ---------------------------------------------------------------------------------

// BBM's parameter names in lower case: a published line maps 1:1 onto a spec.
TEST(NganMicrofacetRegistry, SpecsNameBbmsParameters) {
  ModelRegistry r;
  register_ngan_microfacet_models(r);
  const Angles a = kConfigs[0];
  const BrdfPtr ct = r.create(
      "cook-torrance:albedo_r=0.0291,albedo_g=0.0193,albedo_b=0.0118,eta=0.117,roughness=0.0137");
  const NganCookTorrance ct_direct({{0.0291, 0.0193, 0.0118}, 0.117, 0.0137});
  EXPECT_EQ(eval_at(*ct, a), eval_at(ct_direct, a));
  const BrdfPtr as = r.create(
      "ashikhmin-shirley:albedo_r=0.0366,albedo_g=0.0241,albedo_b=0.0147,f0=0.0949,"
      "sharpness=11600");
  const NganAshikhminShirley as_direct({{0.0366, 0.0241, 0.0147}, 0.0949, 11600});
  EXPECT_EQ(eval_at(*as, a), eval_at(as_direct, a));
  EXPECT_NE(r.find("cook-torrance")->description.find("NganCookTorrance"), std::string::npos);
  EXPECT_NE(r.find("ashikhmin-shirley")->description.find("NganAshikhminShirley"),
            std::string::npos);
  EXPECT_THROW(r.create("cook-torrance:eta=1.5"), std::invalid_argument);
  EXPECT_THROW(r.create("ashikhmin-shirley:sharpness=-1"), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::models::ngan_microfacet_test
