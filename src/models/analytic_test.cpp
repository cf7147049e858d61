#include "halfback/models/analytic.hpp"

#include <gtest/gtest.h>

#include <complex>
#include <numbers>
#include <random>
#include <vector>

#include "halfback/brdf/albedo.hpp"

namespace halfback::models {
namespace {

constexpr double kPi = std::numbers::pi;

Vec3<double> dir(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// Independent reference: the Fresnel amplitudes with complex arithmetic,
// rs = (cos θ − η cos θt)/(cos θ + η cos θt), rp = (η cos θ − cos θt)/(η cos θ + cos θt), with
// η cos θt = √(η² − sin²θ).
double fresnel_complex(std::complex<double> eta, double c) {
  const double s2 = 1 - c * c;
  const std::complex<double> root = std::sqrt(eta * eta - s2);  // η cos θt
  const std::complex<double> rs = (c - root) / (c + root);
  const std::complex<double> rp = (eta * eta * c - root) / (eta * eta * c + root);
  return 0.5 * (std::norm(rs) + std::norm(rp));
}

TEST(Fresnel, ConductorMatchesComplexAmplitudes) {
  const double etas[] = {0.2, 0.5, 1.0, 1.5, 2.9};
  const double ks[] = {0.0, 0.5, 2.0, 3.9, 8.0};
  for (double eta : etas)
    for (double k : ks)
      for (double c = 0.0; c <= 1.0; c += 0.01) {
        if (eta == 1.0 && k == 0.0 && c == 0.0) continue;  // no interface: 0/0 (limit 0)
        EXPECT_NEAR(fresnel_conductor(eta, k, c), fresnel_complex({eta, k}, c), 1e-12)
            << eta << " " << k << " " << c;
      }
}

TEST(Fresnel, DielectricMatchesComplexAmplitudesAndLimits) {
  for (double eta : {1.01, 1.33, 1.5, 2.4})
    for (double c = 0.0; c <= 1.0; c += 0.01) {
      EXPECT_NEAR(fresnel_dielectric(eta, c), fresnel_complex({eta, 0}, c), 1e-12);
      EXPECT_NEAR(fresnel_conductor(eta, 0, c), fresnel_dielectric(eta, c), 1e-12);
    }
  EXPECT_NEAR(fresnel_dielectric(1.5, 1.0), 0.04, 1e-15);  // ((η−1)/(η+1))²
  EXPECT_NEAR(fresnel_dielectric(1.5, 0.0), 1.0, 1e-15);
  EXPECT_EQ(fresnel_dielectric(1 / 1.5, 0.5), 1.0);  // total internal reflection
  EXPECT_EQ(fresnel_schlick(0.3, 1.0), 0.3);
  EXPECT_EQ(fresnel_schlick(0.3, 0.0), 1.0);
}

// ∫ f(m) dm over the hemisphere by the midpoint rule in (θ, φ), fine enough in θ for α ≥ 0.1.
template <class F>
double hemisphere_quadrature(F f, int n_theta = 6000, int n_phi = 256) {
  double sum = 0;
  const double dt = (kPi / 2) / n_theta, dp = 2 * kPi / n_phi;
  for (int i = 0; i < n_theta; ++i) {
    const double t = (i + 0.5) * dt;
    for (int j = 0; j < n_phi; ++j) sum += f(dir(t, (j + 0.5) * dp)) * std::sin(t);
  }
  return sum * dt * dp;
}

struct Roughness {
  MicrofacetParams::Distribution d;
  double ax, ay;
};
const Roughness kRoughness[] = {
    {MicrofacetParams::Distribution::ggx, 0.2, 0.2},
    {MicrofacetParams::Distribution::ggx, 0.1, 0.5},
    {MicrofacetParams::Distribution::ggx, 0.8, 0.3},
    {MicrofacetParams::Distribution::beckmann, 0.2, 0.2},
    {MicrofacetParams::Distribution::beckmann, 0.15, 0.6},
};

Microfacet make(const Roughness& r, Fresnel f = {Fresnel::Kind::none}) {
  MicrofacetParams p;
  p.distribution = r.d;
  p.alpha_x = r.ax;
  p.alpha_y = r.ay;
  p.fresnel = f;
  return Microfacet(p);
}

TEST(Microfacet, DistributionIsNormalized) {
  for (const auto& r : kRoughness) {
    const Microfacet m = make(r);
    const double integral =
        hemisphere_quadrature([&](const Vec3<double>& w) { return m.distribution(w) * w.z; });
    EXPECT_NEAR(integral, 1.0, 1e-4) << m.description();
  }
}

// Heitz 2014: the projected area of the visible microsurface equals that of the macrosurface,
// ∫ max(0, ωo·m) D(m) dm = cos θo (1 + Λ(ωo)); this ties Λ to D.
TEST(Microfacet, SmithLambdaIsConsistentWithDistribution) {
  for (const auto& r : kRoughness) {
    const Microfacet m = make(r);
    for (double theta : {0.0, 0.5, 1.0, 1.4})
      for (double phi : {0.0, 0.7, 2.0}) {
        const Vec3<double> wo = dir(theta, phi);
        const double integral = hemisphere_quadrature([&](const Vec3<double>& n) {
          return std::max(0.0, wo.x * n.x + wo.y * n.y + wo.z * n.z) * m.distribution(n);
        });
        EXPECT_NEAR(integral, wo.z * (1 + m.lambda(wo)), 2e-4 * (1 + m.lambda(wo)))
            << m.description() << " θo=" << theta << " φo=" << phi;
      }
  }
}

TEST(Microfacet, ValueAtNormalIncidence) {
  // ωi = ωo = n: m = n, D(n) = 1/(π αx αy), Λ(n) = 0, so ρ = F(1) / (4 π αx αy).
  for (const auto& r : kRoughness) {
    Fresnel f;
    f.kind = Fresnel::Kind::schlick;
    f.f0 = {0.9, 0.5, 0.1};
    const Microfacet m = make(r, f);
    const Rgb v = m.eval({{0, 0, 1}, {0, 0, 1}});
    const double d = 1 / (4 * kPi * r.ax * r.ay);
    EXPECT_NEAR(v.r, 0.9 * d, 1e-12 * d);
    EXPECT_NEAR(v.b, 0.1 * d, 1e-12 * d);
  }
}

// eval() and pdf() of GGX use closed forms without normalizing the half vector
// (docs/models.md); the reference is the textbook composition of distribution() and lambda():
// ρ = F(ωi·m) D(m) / ((1 + Λ(ωi) + Λ(ωo)) 4 cos θi cos θo), pdf = D(m) / ((1 + Λ(ωo)) 4 cos θo).
// eval_batch() returns eval() bit for bit.
TEST(Microfacet, GgxClosedFormsMatchDistributionAndLambda) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (const auto& r : kRoughness) {
    if (r.d != MicrofacetParams::Distribution::ggx) continue;
    Fresnel f;
    f.kind = Fresnel::Kind::schlick;
    f.f0 = {0.9, 0.5, 0.1};
    const Microfacet m = make(r, f);
    std::vector<DirPair<double>> pairs;
    for (int k = 0; k < 2000; ++k) {
      // Down to 0.1° above the horizon, where Λ grows large.
      const double ti = std::acos(std::max(2e-3, u(rng))), to = std::acos(std::max(2e-3, u(rng)));
      pairs.push_back({dir(ti, 2 * kPi * u(rng)), dir(to, 2 * kPi * u(rng))});
    }
    for (const auto& p : pairs) {
      Vec3<double> h{p.wi.x + p.wo.x, p.wi.y + p.wo.y, p.wi.z + p.wo.z};
      const double len = std::hypot(h.x, h.y, h.z);
      h = {h.x / len, h.y / len, h.z / len};
      const double d = m.distribution(h), cos_d = p.wi.x * h.x + p.wi.y * h.y + p.wi.z * h.z;
      const double rho = fresnel_schlick(0.9, cos_d) * d /
                         ((1 + m.lambda(p.wi) + m.lambda(p.wo)) * 4 * p.wi.z * p.wo.z);
      EXPECT_NEAR(m.eval(p).r, rho, 1e-12 * rho) << m.description();
      const double pdf = d / ((1 + m.lambda(p.wo)) * 4 * p.wo.z);
      EXPECT_NEAR(m.pdf(p.wo, p.wi), pdf, 1e-12 * pdf) << m.description();
    }
    std::vector<Rgb> batch(pairs.size());
    m.eval_batch(pairs, batch);
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const Rgb one = m.eval(pairs[i]);
      ASSERT_TRUE(batch[i].r == one.r && batch[i].g == one.g && batch[i].b == one.b) << i;
    }
  }
}

TEST(Microfacet, AnisotropyRotatesWithTheFrame) {
  const Roughness r{MicrofacetParams::Distribution::ggx, 0.1, 0.5};
  const Microfacet a = make(r), b = make({r.d, r.ay, r.ax});
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 1000; ++i) {
    const Vec3<double> wi = dir(1.5 * u(rng), 2 * kPi * u(rng)),
                       wo = dir(1.5 * u(rng), 2 * kPi * u(rng));
    auto rot = [](const Vec3<double>& w) { return Vec3<double>{-w.y, w.x, w.z}; };  // +90° about n
    const double va = a.eval({wi, wo}).r, vb = b.eval({rot(wi), rot(wo)}).r;
    EXPECT_NEAR(va, vb, 1e-12 * std::max(1.0, va));
  }
  EXPECT_FALSE(a.isotropic());
}

std::vector<BrdfPtr> all_models() {
  Fresnel gold;
  gold.kind = Fresnel::Kind::conductor;
  gold.eta = {0.143, 0.374, 1.442};
  gold.k = {3.983, 2.385, 1.603};
  MicrofacetParams ggx;
  ggx.alpha_x = 0.3;
  ggx.alpha_y = 0.3;
  ggx.fresnel = gold;
  MicrofacetParams beck = ggx;
  beck.distribution = MicrofacetParams::Distribution::beckmann;
  beck.alpha_x = 0.15;
  beck.alpha_y = 0.6;
  AbcParams abc;
  abc.kd = {0.2, 0.2, 0.2};
  return {std::make_shared<Lambert>(Rgb{0.5, 0.6, 0.7}),
          std::make_shared<Microfacet>(ggx),
          std::make_shared<Microfacet>(beck),
          std::make_shared<Abc>(abc),
          std::make_shared<Sheen>(SheenParams{}),
          std::make_shared<Sum>(
              std::vector<BrdfPtr>{std::make_shared<Lambert>(Rgb{0.4, 0.4, 0.4}),
                                   std::make_shared<Sheen>(SheenParams{{0.5, 0.5, 0.5}, 0.4})})};
}

TEST(Models, Reciprocity) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (const auto& brdf : all_models()) {
    ASSERT_TRUE(brdf->reciprocal());
    for (int i = 0; i < 2000; ++i) {
      const Vec3<double> a = dir(1.55 * u(rng), 2 * kPi * u(rng)),
                         b = dir(1.55 * u(rng), 2 * kPi * u(rng));
      const Rgb x = brdf->eval({a, b}), y = brdf->eval({b, a});
      EXPECT_NEAR(x.r, y.r, 1e-12 * std::max(1.0, x.r)) << brdf->name();
      EXPECT_NEAR(x.b, y.b, 1e-12 * std::max(1.0, x.b)) << brdf->name();
      EXPECT_GE(x.g, 0.0) << brdf->name();
    }
  }
}

TEST(Models, BelowHorizonIsZero) {
  for (const auto& brdf : all_models()) {
    EXPECT_EQ(brdf->eval({{0, 0, 1}, {0.6, 0, -0.8}}), Rgb{}) << brdf->name();
    EXPECT_EQ(brdf->eval({{0.6, 0, -0.8}, {0, 0, 1}}), Rgb{}) << brdf->name();
  }
}

TEST(Models, EnergyConservation) {
  for (const auto& brdf : all_models())
    for (double theta : {0.0, 0.6, 1.2, 1.5}) {
      const AlbedoEstimate a = directional_albedo(*brdf, dir(theta, 0.3), 400, 9);
      for (double m_plus_3se :
           {a.mean.r + 3 * a.standard_error.r, a.mean.g + 3 * a.standard_error.g,
            a.mean.b + 3 * a.standard_error.b})
        EXPECT_LE(m_plus_3se - 6 * (a.standard_error.r + a.standard_error.g + a.standard_error.b),
                  1.0)
            << brdf->name() << " θi=" << theta;
      EXPECT_LE(a.mean.r, 1.0) << brdf->name() << " θi=" << theta;
      EXPECT_LE(a.mean.g, 1.0) << brdf->name() << " θi=" << theta;
      EXPECT_LE(a.mean.b, 1.0) << brdf->name() << " θi=" << theta;
    }
}

TEST(Models, LambertAlbedoIsExact) {
  const Lambert l({0.25, 0.5, 0.75});
  const AlbedoEstimate a = directional_albedo(l, dir(0.7, 1.0), 64, 3);
  EXPECT_NEAR(a.mean.r, 0.25, 1e-12);
  EXPECT_NEAR(a.mean.b, 0.75, 1e-12);
}

// The albedo at normal incidence computed independently in microfacet-normal space: with ωi = n,
// ωo = 2 m_z m − n and dωo = 4 m_z dm, a(n) = ∫_{m_z > cos 45°} D(m) m_z G2 dm (F = 1).
// For α = 0.8, 39 % of the normals (P(θm > 45°) = 1 − 1/(1 + α²)) reflect below the horizon.
TEST(Models, WhiteMicrofacetAlbedoMatchesNormalSpaceQuadrature) {
  for (double alpha : {0.1, 0.4, 0.8}) {
    const Microfacet m = make({MicrofacetParams::Distribution::ggx, alpha, alpha});
    const double reference = hemisphere_quadrature([&](const Vec3<double>& h) {
      const Vec3<double> wo{2 * h.z * h.x, 2 * h.z * h.y, 2 * h.z * h.z - 1};
      if (wo.z <= 0) return 0.0;
      return m.distribution(h) * h.z / (1 + m.lambda(wo));
    });
    const AlbedoEstimate a = directional_albedo(m, {0, 0, 1}, 600, 2);
    EXPECT_NEAR(a.mean.r, reference, 3 * a.standard_error.r + 1e-4) << "alpha " << alpha;
    if (alpha == 0.8) {
      EXPECT_NEAR(reference, 0.43, 0.02);
    }
    if (alpha == 0.1) {  // 1 % of the normals beyond 45°, a little masking
      EXPECT_GT(reference, 0.98);
    }
  }
}

TEST(Models, InvalidParametersAreRejectedWithTheirName) {
  auto message = [](auto make_it) {
    try {
      make_it();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  MicrofacetParams p;
  p.alpha_x = 0;
  EXPECT_NE(message([&] { Microfacet m(p); }).find("alpha_x"), std::string::npos);
  p.alpha_x = std::nan("");
  EXPECT_NE(message([&] { Microfacet m(p); }).find("alpha_x"), std::string::npos);
  p.alpha_x = 0.2;
  p.fresnel.f0 = {2, 0, 0};
  EXPECT_NE(message([&] { Microfacet m(p); }).find("f0"), std::string::npos);
  EXPECT_NE(message([] { Lambert l({1.5, 0, 0}); }).find("albedo"), std::string::npos);
  EXPECT_NE(message([] { Sheen s({{1, 1, 1}, 0}); }).find("alpha"), std::string::npos);
  EXPECT_NE(message([] { Sum s({}); }).find("at least one"), std::string::npos);
}

}  // namespace
}  // namespace halfback::models
