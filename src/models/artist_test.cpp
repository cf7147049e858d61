// Burley's principled BRDF and Oren–Nayar's qualitative model (artist.hpp): values against the
// papers' formulas written again here in angles, closed-form cases computed by hand, reciprocity,
// the limits that reduce them to Lambert, and the registry's entries.
#include "halfback/models/artist.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "halfback/brdf/albedo.hpp"
#include "halfback/models/register.hpp"

namespace halfback::models {
namespace {

constexpr double kPi = std::numbers::pi;

DirPair<double> pair_of(double ti, double pi, double to, double po) {
  return {{std::sin(ti) * std::cos(pi), std::sin(ti) * std::sin(pi), std::cos(ti)},
          {std::sin(to) * std::cos(po), std::sin(to) * std::sin(po), std::cos(to)}};
}

double schlick(double c) {
  return std::pow(1 - c, 5);
}

// Burley 2012 in the angles of the half vector (θh, φh) and θd, as the course notes write it:
// D = 1 / (π αx αy (sin²θh (cos²φh/αx² + sin²φh/αy²) + cos²θh)²), and Smith's separable GGX
// masking G1(θ, φ) = 2 cos θ / (cos θ + sqrt(cos²θ + sin²θ (αx² cos²φ + αy² sin²φ))).
Rgb disney_in_angles(const DisneyParams& p, double ti, double pi, double to, double po) {
  const DirPair<double> d = pair_of(ti, pi, to, po);
  const double hx = d.wi.x + d.wo.x, hy = d.wi.y + d.wo.y, hz = d.wi.z + d.wo.z;
  const double th = std::atan2(std::hypot(hx, hy), hz), ph = std::atan2(hy, hx);
  const double cd = std::cos(
      0.5 * std::acos(std::clamp(d.wi.x * d.wo.x + d.wi.y * d.wo.y + d.wi.z * d.wo.z, -1.0, 1.0)));
  const double aspect = std::sqrt(1 - 0.9 * p.anisotropic);
  const double ax = std::max(0.001, p.roughness * p.roughness / aspect);
  const double ay = std::max(0.001, p.roughness * p.roughness * aspect);
  const double s2 = std::pow(std::sin(th), 2), c2 = std::pow(std::cos(th), 2);
  const double D =
      1 /
      (kPi * ax * ay *
       std::pow(s2 * (std::pow(std::cos(ph) / ax, 2) + std::pow(std::sin(ph) / ay, 2)) + c2, 2));
  const auto g1 = [](double t, double phi, double a, double b) {
    const double c = std::cos(t), s = std::sin(t);
    return 2 * c /
           (c + std::sqrt(c * c + s * s *
                                      (a * a * std::pow(std::cos(phi), 2) +
                                       b * b * std::pow(std::sin(phi), 2))));
  };
  const double G = g1(ti, pi, ax, ay) * g1(to, po, ax, ay);
  const double lum = 0.3 * p.base_color.r + 0.6 * p.base_color.g + 0.1 * p.base_color.b;
  const double base[3] = {p.base_color.r, p.base_color.g, p.base_color.b};
  const double FL = schlick(std::cos(ti)), FV = schlick(std::cos(to)), FH = schlick(cd);
  const double fd90 = 0.5 + 2 * cd * cd * p.roughness, fss90 = cd * cd * p.roughness;
  const double Fd = (1 + (fd90 - 1) * FL) * (1 + (fd90 - 1) * FV);
  const double Fss = (1 + (fss90 - 1) * FL) * (1 + (fss90 - 1) * FV);
  const double ss = 1.25 * (Fss * (1 / (std::cos(ti) + std::cos(to)) - 0.5) + 0.5);
  const double ac = 0.1 + (0.001 - 0.1) * p.clearcoat_gloss, ac2 = ac * ac;
  const double Dr = (ac2 - 1) / (kPi * std::log(ac2) * (1 + (ac2 - 1) * c2));
  const double Gr = g1(ti, 0, 0.25, 0.25) * g1(to, 0, 0.25, 0.25);
  const double coat =
      0.25 * p.clearcoat * Dr * (0.04 + 0.96 * FH) * Gr / (4 * std::cos(ti) * std::cos(to));
  double out[3];
  for (int k = 0; k < 3; ++k) {
    const double tint = lum > 0 ? base[k] / lum : 1;
    const double spec0 = (1 - p.metallic) * 0.08 * p.specular * (1 + (tint - 1) * p.specular_tint) +
                         p.metallic * base[k];
    const double Fs = spec0 + (1 - spec0) * FH;
    const double sheen = FH * p.sheen * (1 + (tint - 1) * p.sheen_tint);
    const double diffuse = base[k] / kPi * (Fd + (ss - Fd) * p.subsurface);
    out[k] = (diffuse + sheen) * (1 - p.metallic) + Fs * D * G / (4 * std::cos(ti) * std::cos(to)) +
             coat;
  }
  return {out[0], out[1], out[2]};
}

TEST(Disney, ValuesAreTheCourseNotesFormulas) {
  DisneyParams all;  // every lobe on
  all.base_color = {0.8, 0.4, 0.1};
  all.subsurface = 0.3, all.metallic = 0.2, all.specular = 0.7, all.specular_tint = 0.4;
  all.roughness = 0.35, all.anisotropic = 0.6, all.sheen = 0.5, all.sheen_tint = 0.3;
  all.clearcoat = 0.8, all.clearcoat_gloss = 0.6;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> t(0.01, 1.5), f(0, 2 * kPi);
  for (const DisneyParams& p : {DisneyParams{}, all}) {
    const Disney brdf(p);
    for (int k = 0; k < 200; ++k) {
      const double ti = t(rng), pi = f(rng), to = t(rng), po = f(rng);
      const Rgb got = brdf.eval(pair_of(ti, pi, to, po));
      const Rgb want = disney_in_angles(p, ti, pi, to, po);
      EXPECT_NEAR(got.r, want.r, 1e-9 * (1 + want.r)) << ti << " " << pi << " " << to << " " << po;
      EXPECT_NEAR(got.g, want.g, 1e-9 * (1 + want.g));
      EXPECT_NEAR(got.b, want.b, 1e-9 * (1 + want.b));
    }
  }
}

// At θi = θo = 0 every Schlick weight is 0, ĥ = n and the separable masking is 1 in each
// direction: ρ = base/π · (1 − s + 0.625 s) + F0 / (4 π α²) by hand.
TEST(Disney, NormalIncidenceByHand) {
  DisneyParams p;  // base 0.5, specular 0.5 (F0 = 0.04), roughness 0.5 (α = 0.25)
  const Rgb v = Disney(p).eval(pair_of(0, 0, 0, 0));
  EXPECT_NEAR(v.r, 0.5 / kPi + 0.04 / (4 * kPi * 0.0625), 1e-14);
  p.subsurface = 1;  // Fss = 1: 1.25 (1/2 − 1/2 + 1/2) = 0.625
  EXPECT_NEAR(Disney(p).eval(pair_of(0, 0, 0, 0)).r, 0.625 * 0.5 / kPi + 0.04 / (4 * kPi * 0.0625),
              1e-14);
}

TEST(Disney, ReciprocalAndZeroBelowTheHorizon) {
  DisneyParams p;
  p.base_color = {0.7, 0.2, 0.5}, p.anisotropic = 0.8, p.sheen = 1, p.clearcoat = 1;
  p.subsurface = 0.5, p.specular_tint = 1;
  const Disney brdf(p);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> t(0.01, 1.55), f(0, 2 * kPi);
  for (int k = 0; k < 500; ++k) {
    const DirPair<double> d = pair_of(t(rng), f(rng), t(rng), f(rng));
    const Rgb a = brdf.eval(d), b = brdf.eval({d.wo, d.wi});
    EXPECT_NEAR(a.r, b.r, 1e-12 * (1 + a.r));
    EXPECT_NEAR(a.b, b.b, 1e-12 * (1 + a.b));
    EXPECT_TRUE(std::isfinite(a.r) && a.r >= 0);
  }
  EXPECT_EQ(brdf.eval(pair_of(1.7, 0, 0.3, 1)).g, 0.0);
  EXPECT_FALSE(brdf.isotropic());
  EXPECT_TRUE(Disney(DisneyParams{}).isotropic());
}

TEST(Disney, OutOfRangeParametersAreRefusedByName) {
  DisneyParams p;
  p.sheen = 1.5;
  try {
    Disney{p};
    FAIL() << "sheen 1.5 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sheen"), std::string::npos) << e.what();
  }
  p.sheen = std::nan("");
  EXPECT_THROW(Disney{p}, std::invalid_argument);
}

// The qualitative model in the paper's angles: sin α tan β cos(φi − φo).
TEST(OrenNayar, ValuesAreThePapersQualitativeModel) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> t(0.01, 1.55), f(0, 2 * kPi);
  for (const double sigma : {0.0, 0.2, 0.5, 1.2}) {
    OrenNayarParams p;
    p.albedo = {0.9, 0.5, 0.1}, p.sigma = sigma;
    const OrenNayar brdf(p);
    const double s2 = sigma * sigma;
    const double A = 1 - 0.5 * s2 / (s2 + 0.33), B = 0.45 * s2 / (s2 + 0.09);
    for (int k = 0; k < 200; ++k) {
      const double ti = t(rng), pi = f(rng), to = t(rng), po = f(rng);
      const double alpha = std::max(ti, to), beta = std::min(ti, to);
      const double want =
          0.9 / kPi * (A + B * std::max(0.0, std::cos(pi - po)) * std::sin(alpha) * std::tan(beta));
      EXPECT_NEAR(brdf.eval(pair_of(ti, pi, to, po)).r, want, 1e-12);
    }
  }
}

// At θo = 0 the B term vanishes: the directional albedo is albedo · A. σ = 0 is Lambert.
TEST(OrenNayar, AlbedoAtNormalViewIsAAndZeroSigmaIsLambert) {
  OrenNayarParams p;
  p.albedo = {1, 1, 1}, p.sigma = 0.6;
  const OrenNayar brdf(p);
  const double s2 = 0.36, A = 1 - 0.5 * s2 / (s2 + 0.33);
  EXPECT_NEAR(directional_albedo(brdf, {0, 0, 1}, 256).mean.r, A, 2e-3);
  p.sigma = 0;
  EXPECT_NEAR(OrenNayar(p).eval(pair_of(0.4, 0, 1.2, 0.3)).g, 1 / kPi, 1e-15);
  p.sigma = 2;
  EXPECT_THROW(OrenNayar{p}, std::invalid_argument);
}

TEST(ArtistModels, RegisteredAndLoadable) {
  ModelRegistry r;
  register_analytic_models(r);
  const BrdfPtr d = r.create("disney:base_color_red=0.9,roughness=0.3,sheen=0.5");
  EXPECT_EQ(d->name(), "disney");
  EXPECT_NEAR(d->eval(pair_of(0, 0, 0, 0)).r - d->eval(pair_of(0, 0, 0, 0)).g, 0.4 / kPi, 1e-12);
  const BrdfPtr o = r.create("oren-nayar:albedo=0.7,sigma=0.4");
  EXPECT_EQ(o->name(), "oren-nayar");
  EXPECT_THROW(r.create("oren-nayar:sigma=3"), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::models
