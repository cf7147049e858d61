// Ngan et al.'s lobes as BBM defines them (ngan_lobes.hpp): values against the formulas written
// again here in angles, reciprocity, the normalisations' promises, and the registry's names.
#include "halfback/models/ngan_lobes.hpp"

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

// θh of a pair from its angles (the half vector's elevation), written apart from the models'
// vector form.
double theta_h(double ti, double pi, double to, double po) {
  const double x = std::sin(ti) * std::cos(pi) + std::sin(to) * std::cos(po);
  const double y = std::sin(ti) * std::sin(pi) + std::sin(to) * std::sin(po);
  return std::atan2(std::hypot(x, y), std::cos(ti) + std::cos(to));
}

// cos of the angle between ωo and ωi's mirror direction: the spherical law of cosines.
double cos_mirror(double ti, double pi, double to, double po) {
  return std::cos(ti) * std::cos(to) - std::sin(ti) * std::sin(to) * std::cos(pi - po);
}

TEST(NganLobes, ValuesAreTheFormulas) {
  const double configs[][4] = {{0.3, 0.2, 0.5, 3.1}, {1.0, 0.0, 0.2, 2.0}, {0.6, 1.5, 0.6, 4.6}};
  for (const auto& c : configs) {
    const DirPair<double> p = pair_of(c[0], c[1], c[2], c[3]);
    const double th = theta_h(c[0], c[1], c[2], c[3]), a = 0.15;
    const double e = std::exp(-std::pow(std::tan(th) / a, 2)) / (4 * kPi * a * a);
    EXPECT_NEAR(Ward({0.2, 0.2, 0.2}, a, false).eval(p).g,
                0.2 * e / std::sqrt(std::cos(c[0]) * std::cos(c[2])), 1e-12 * (1 + e));
    EXPECT_NEAR(Ward({0.2, 0.2, 0.2}, a, true).eval(p).g,
                0.2 * e / (std::cos(c[0]) * std::cos(c[2])), 1e-12 * (1 + e));
    const double m = std::max(0.0, cos_mirror(c[0], c[1], c[2], c[3])), n = 40;
    EXPECT_NEAR(BlinnPhong({0.1, 0.1, 0.1}, n).eval(p).g,
                0.1 * (n + 2) / (2 * kPi) * std::pow(m, n), 1e-12);
    // Lafortune with Cxy = −Cz: Ngan's normalisation makes it the Phong lobe of the same n.
    EXPECT_NEAR(Lafortune({0.1, 0.1, 0.1}, -0.577, 0.577, n).eval(p).g,
                BlinnPhong({0.1, 0.1, 0.1}, n).eval(p).g, 1e-10);
    // A general Lafortune lobe from its definition.
    const double cxy = -0.7, cz = 0.3,
                 d = cxy * (p.wi.x * p.wo.x + p.wi.y * p.wo.y) + cz * p.wi.z * p.wo.z;
    EXPECT_NEAR(Lafortune({1, 1, 1}, cxy, cz, 3).eval(p).g,
                std::pow(std::max(0.0, d), 3) * 5 / (2 * kPi * std::pow(0.49, 1.5)), 1e-12);
  }
}

TEST(NganLobes, ReciprocalAndZeroBelowTheHorizon) {
  const Ward w({0.3, 0.2, 0.1}, 0.2, false), wd({0.3, 0.2, 0.1}, 0.2, true);
  const BlinnPhong b({0.1, 0.1, 0.1}, 30);
  const Lafortune l({0.2, 0.2, 0.2}, -0.8, 0.5, 12);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0, 1);
  for (int k = 0; k < 200; ++k) {
    const DirPair<double> p = pair_of(1.5 * u(rng), 6.28 * u(rng), 1.5 * u(rng), 6.28 * u(rng));
    for (const Brdf* f : std::initializer_list<const Brdf*>{&w, &wd, &b, &l}) {
      const Rgb a = f->eval(p), c = f->eval({p.wo, p.wi});
      EXPECT_NEAR(a.g, c.g, 1e-12 * (1 + a.g)) << f->name();
      EXPECT_EQ(f->eval({{p.wi.x, p.wi.y, -p.wi.z}, p.wo}).g, 0) << f->name();
    }
  }
}

// What the normalisations promise: Phong's (n+2)/(2π) makes ∫ ρ cos θi dωi = albedo at normal
// incidence of ωo, exactly (the lobe about the normal); Ward's albedo at normal incidence tends
// to the albedo for a narrow lobe.
TEST(NganLobes, Normalisations) {
  const BlinnPhong b({0.5, 0.5, 0.5}, 20);
  EXPECT_NEAR(directional_albedo(b, {0, 0, 1}, 256).mean.g, 0.5, 0.01);
  const Ward w({0.5, 0.5, 0.5}, 0.05, false);
  EXPECT_NEAR(directional_albedo(w, {0, 0, 1}, 512).mean.g, 0.5, 0.02);
  EXPECT_THROW(Ward({0.1, 0.1, 0.1}, 0, false), std::invalid_argument);
  EXPECT_THROW(BlinnPhong({-0.1, 0.1, 0.1}, 10), std::invalid_argument);
  EXPECT_THROW(Lafortune({0.1, 0.1, 0.1}, 0, 0, 10), std::invalid_argument);
  // A published line (Cz ≈ 0, n = 16600): finite everywhere, not inf × 0.
  const Lafortune sharp({0.03, 0.03, 0.03}, -0.707, 1.23e-10, 16600);
  for (double t : {0.0, 0.2, 0.7, 1.4}) {
    const double v = sharp.eval(pair_of(t, 0, t, kPi)).g;
    EXPECT_TRUE(std::isfinite(v) && v >= 0) << t << ": " << v;
  }
}

TEST(NganLobes, RegisteredWithBbmsNames) {
  ModelRegistry r;
  register_analytic_models(r);
  const BrdfPtr w =
      r.create("ward:albedo_r=0.00774,albedo_g=0.00547,albedo_b=0.00339,roughness=0.0162");
  EXPECT_EQ(w->name(), "ward");
  EXPECT_GT(w->eval(pair_of(0.3, 0, 0.3, kPi)).r, 0);
  EXPECT_EQ(r.create("lafortune:albedo=0.0238,cxy=-0.577,cz=0.577,sharpness=4060")->name(),
            "lafortune");
  EXPECT_EQ(r.create("blinn-phong:albedo=0.0016,sharpness=13700")->name(), "blinn-phong");
  EXPECT_EQ(r.create("ward-duer:albedo=0.005,roughness=0.0162")->name(), "ward-duer");
  EXPECT_THROW(r.create("ward:roughness=2"), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::models
