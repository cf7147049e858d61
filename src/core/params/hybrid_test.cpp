// The paper's hybrid parameterization (‖h̄‖, φh, ‖k‖, φk): its facts for the generic property
// tests (core/param_test.cpp), tuples outside its domain, and the identities of the paper's
// appendix that relate it to the half and difference vectors, halfdiff and ortho.
#include "halfback/core/params/hybrid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "halfback/core/param.hpp"
#include "param_facts.hpp"
#include "support/test_util.hpp"

namespace halfback::test {
namespace {

ParamFacts hybrid_facts() {
  ParamFacts f;
  f.condition = [](const DirPair<double>& p) { return 0.5 * (p.wi.z + p.wo.z); };
  f.reference_valid = [](const Tuple4<long double>& q) {
    if (!(q[0] >= 0 && q[0] <= 1 && q[2] >= 0 && q[2] <= 1 && reference_azimuths_ok(q)))
      return false;
    const long double hz2 = 1 - q[0] * q[0] - q[2] * q[2];
    if (hz2 < 0) return false;
    const long double hz = sqrtl(hz2);
    const long double theta_k = atan2l(hz, -q[0] * cosl(q[3] - q[1]));
    const long double kz = q[2] * cosl(theta_k);
    return hz + kz >= 0 && hz - kz >= 0;
  };
  return f;
}
const RegisterParamFacts kHybridFacts(Hybrid::name, hybrid_facts());

// ‖h̄‖² + ‖k‖² > 1; and ‖h̄‖² + ‖k‖² < 1 but a direction below the horizon.
TEST(Domain, HybridSpecificInvalidTuples) {
  EXPECT_FALSE((valid<Hybrid>(Tuple4<double>{0.8, 0, 0.7, kPi / 2})));
  EXPECT_FALSE((valid<Hybrid>(Tuple4<double>{0.7, 0, 0.7, 0.1})));
  EXPECT_TRUE((valid<Hybrid>(Tuple4<double>{0.7, 0, 0.7, kPi / 2})));
}

// --- Identities of the paper's appendix -----------------------------------------------------

constexpr double kDoubleEps = std::numeric_limits<double>::epsilon();

TEST(Identities, HalfAndDifferenceVectors) {
  for (const auto& p : random_pairs(200000, 5)) {
    const Vec3<double> h{(p.wi.x + p.wo.x) / 2, (p.wi.y + p.wo.y) / 2, (p.wi.z + p.wo.z) / 2};
    const Vec3<double> k{(p.wi.x - p.wo.x) / 2, (p.wi.y - p.wo.y) / 2, (p.wi.z - p.wo.z) / 2};
    EXPECT_NEAR(detail::dot(h, h) + detail::dot(k, k), 1.0, 8 * kDoubleEps);  // unit inputs ± 2ε
    EXPECT_NEAR(detail::dot(h, k), 0.0, 4 * kDoubleEps);
    const Tuple4<double> hd = HalfDiff::forward(p), hy = Hybrid::forward(p);
    const double h_len = std::sqrt(detail::dot(h, h));
    EXPECT_NEAR(std::cos(hd[2]), h_len, 8 * kDoubleEps);  // cos θd = ‖h‖
    EXPECT_NEAR(hy[0] * hy[0], std::pow(std::sin(hd[0]) * std::cos(hd[2]), 2), 1e-15);  // ‖h̄‖²
    EXPECT_NEAR(hy[2], std::sqrt(detail::dot(k, k)), 1e-15);
  }
}

// (ωi·n)(ωo·n) = hz² − kz², and in hybrid coordinates the polynomial margin
// zi zo (hz² + c²) = hz² (hz² + c²) − ‖k‖² c², c = ‖h̄‖ cos(φk − φh).
TEST(Identities, GrazingProduct) {
  for (const auto& p : random_pairs(200000, 6)) {
    const double zz = p.wi.z * p.wo.z;
    const double hz = (p.wi.z + p.wo.z) / 2, kz = (p.wi.z - p.wo.z) / 2;
    EXPECT_NEAR(zz, hz * hz - kz * kz, 1e-15);
    const Tuple4<double> q = Hybrid::forward(p);
    const double hz2 = 1 - q[0] * q[0] - q[2] * q[2];
    EXPECT_NEAR(zz, hz2 - kz * kz, 1e-14);
    const double c = q[0] * std::cos(q[3] - q[1]);
    EXPECT_NEAR(zz * (hz2 + c * c), hz2 * (hz2 + c * c) - q[2] * q[2] * c * c, 1e-14);
  }
}

// (ωi·n)(ωo·n) = 1 − ‖h̄‖² − ‖k‖² holds only where kz = 0, i.e. on the slice φk − φh = ±90° (and
// when zi = zo): G is not a function of (‖h̄‖, ‖k‖) alone. The paper's identity keeps the
// ‖k‖² cos²θk term and holds (docs/paper.md #25). A counter-example: ωi = n, ωo = t.
TEST(Identities, GrazingProductIsNotAFunctionOfHbarAndKAlone) {
  const DirPair<double> p{{0, 0, 1}, {1, 0, 0}};
  const Tuple4<double> q = Hybrid::forward(p);
  const double claimed = 1 - q[0] * q[0] - q[2] * q[2];
  EXPECT_NEAR(claimed, 0.25, 1e-15);
  EXPECT_EQ(p.wi.z * p.wo.z, 0.0);
  // Two pairs with the same (‖h̄‖, ‖k‖) but different (ωi·n)(ωo·n):
  const Tuple4<double> on_slice{q[0], 0, q[2], kPi / 2}, off_slice{q[0], 0, q[2], kPi};
  const Solved<double> a = inverse<Hybrid>(on_slice), b = inverse<Hybrid>(off_slice);
  ASSERT_TRUE(a.in_domain && b.in_domain);
  EXPECT_NEAR(a.pair.wi.z * a.pair.wo.z, claimed, 1e-15);  // holds on the 90° slice
  EXPECT_GT(std::abs(b.pair.wi.z * b.pair.wo.z - claimed), 0.2);
}

// θk = 90° (kz = 0) when φk − φh = 90°, so ortho and hybrid coincide on that slice.
TEST(Identities, OrthoEqualsHybridOnTheNinetyDegreeSlice) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0, 1), az(0, kTwoPiD);
  int checked = 0;
  while (checked < 100000) {
    const double hbar = u(rng), k = u(rng), phi_h = az(rng);
    const double phi_k = detail::wrap_two_pi(phi_h + (u(rng) < 0.5 ? 0.5 : 1.5) * kPi);
    const Tuple4<double> q{hbar, phi_h, k, phi_k};
    const Solved<double> hy = inverse<Hybrid>(q), ov = inverse<Ortho>(q);
    ASSERT_EQ(hy.in_domain, ov.in_domain) << hbar << " " << k;
    if (!hy.in_domain) continue;
    ++checked;
    EXPECT_LE(std::abs(hy.pair.wi.z - hy.pair.wo.z), 1e-12);  // kz = 0
    EXPECT_LE(max_abs_diff(hy.pair, ov.pair), 1e-12);
  }
}

}  // namespace
}  // namespace halfback::test
