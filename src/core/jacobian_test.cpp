// Jacobians: dωi dωo = J dq, checked two independent ways:
//  1. Monte-Carlo: ∫ J(q) 1[q valid] dq over a box enclosing the domain = ∫∫ dωi dωo = (2π)²;
//  2. finite differences: J = sqrt(det(AᵀA)) with A the 6×4 derivative of the inverse map
//     q -> (ωi, ωo) ∈ S²×S² ⊂ R⁶ (S²×S² sits isometrically in R⁶, so the Gram determinant is the
//     volume element).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "halfback/core/param.hpp"
#include "support/param_types.hpp"
#include "support/test_util.hpp"

namespace halfback {
namespace {

using test::kPi;
using test::kTwoPiD;

template <class P>
class JacobianTest : public ::testing::Test {};
using AllParams = test::BuiltinParamTypes;
class ParamNames {
 public:
  template <class P>
  static std::string GetName(int) {
    return test::gtest_name(P::name);
  }
};
TYPED_TEST_SUITE(JacobianTest, AllParams, ParamNames);

// The box of the coordinates' ranges (the descriptor's axes), which encloses the valid domain.
template <class P>
std::vector<std::pair<double, double>> box_of(bool isotropic) {
  std::vector<std::pair<double, double>> box;
  if (isotropic)
    for (const Axis& a : P::iso_axes) box.emplace_back(a.lo, a.hi);
  else
    for (const Axis& a : P::axes) box.emplace_back(a.lo, a.hi);
  return box;
}

struct Estimate {
  double mean, standard_error;
};

// Uniform over the box; returns ∫ f over it.
template <class F>
Estimate integrate(F f, const std::vector<std::pair<double, double>>& box, std::size_t n,
                   std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  double volume = 1;
  for (const auto& [lo, hi] : box) volume *= hi - lo;
  double sum = 0, sum2 = 0;
  std::vector<double> x(box.size());
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t d = 0; d < x.size(); ++d)
      x[d] = box[d].first + u(rng) * (box[d].second - box[d].first);
    const double v = f(x) * volume;
    sum += v;
    sum2 += v * v;
  }
  const double mean = sum / double(n);
  const double var = std::max(0.0, sum2 / double(n) - mean * mean);
  return {mean, std::sqrt(var / double(n))};
}

// ∫ J 1[valid] dq over the box = ∫∫ w dωi dωo, for w = 1 ((2π)²) and for the cosine-weighted
// measure w = cos θi cos θo (π²). The second is the well-posed one for ortho, whose plain J has a
// 1/(zi zo) singularity on the domain boundary and so an infinite-variance estimator.
template <class P>
void check_integrals(bool isotropic) {
  // More samples where the estimator's variance is larger: the halfway disk's heavy tail
  // (J ~ zi/|P|⁴ near grazing ωi), the stereographic halfdiff's box that is 12 % valid.
  const bool wide = std::is_same_v<P, HalfwayDisk> || std::is_same_v<P, StereoHalfDiff>;
  const std::size_t n = wide ? 8'000'000 : 2'000'000;
  auto weight_and_j = [&](const std::vector<double>& x, bool cosine) {
    Solved<double> s;
    double j;
    if (isotropic) {
      const Tuple3<double> q{x[0], x[1], x[2]};
      s = inverse_iso<P>(q);
      j = s.in_domain ? jacobian_iso<P>(q) : 0.0;
    } else {
      const Tuple4<double> q{x[0], x[1], x[2], x[3]};
      s = inverse<P>(q);
      j = s.in_domain ? P::jacobian(q) : 0.0;
    }
    if (!s.in_domain) return 0.0;
    return cosine ? j * s.pair.wi.z * s.pair.wo.z : j;
  };
  const auto box = box_of<P>(isotropic);
  const char* form = isotropic ? " isotropic" : " 4D";
  const Estimate plain =
      integrate([&](const auto& x) { return weight_and_j(x, false); }, box, n, 17);
  EXPECT_NEAR(plain.mean, 4 * kPi * kPi, 3 * plain.standard_error) << P::name << form;
  // Meaningful only if it can tell a 1% error in J (not so for ortho's infinite variance, nor for
  // the halfway disk's heavy tail near grazing ωi: docs/math-more-parameterizations.md §3).
  if (!std::is_same_v<P, Ortho> && !std::is_same_v<P, HalfwayDisk>) {
    EXPECT_LT(plain.standard_error, 0.0033 * 4 * kPi * kPi);
  }

  const Estimate cosine =
      integrate([&](const auto& x) { return weight_and_j(x, true); }, box, n, 19);
  EXPECT_NEAR(cosine.mean, kPi * kPi, 3 * cosine.standard_error) << P::name << form;
  EXPECT_LT(cosine.standard_error, 0.0033 * kPi * kPi) << P::name << form;
}

TYPED_TEST(JacobianTest, IntegratesToTheMeasureOfPairs) {
  check_integrals<TypeParam>(false);
}
TYPED_TEST(JacobianTest, IsotropicIntegratesToTheMeasureOfPairs) {
  check_integrals<TypeParam>(true);
}

// sqrt(det(MᵀM)) for a 6×k matrix given by columns.
template <std::size_t K>
double gram_volume(const std::array<std::array<double, 6>, K>& cols) {
  std::array<std::array<double, K>, K> g{};
  for (std::size_t a = 0; a < K; ++a)
    for (std::size_t b = 0; b < K; ++b)
      for (std::size_t r = 0; r < 6; ++r) g[a][b] += cols[a][r] * cols[b][r];
  // Determinant by Gaussian elimination with partial pivoting.
  double det = 1;
  for (std::size_t c = 0; c < K; ++c) {
    std::size_t piv = c;
    for (std::size_t r = c + 1; r < K; ++r)
      if (std::abs(g[r][c]) > std::abs(g[piv][c])) piv = r;
    if (piv != c) {
      std::swap(g[piv], g[c]);
      det = -det;
    }
    det *= g[c][c];
    for (std::size_t r = c + 1; r < K; ++r) {
      const double f = g[r][c] / g[c][c];
      for (std::size_t k = c; k < K; ++k) g[r][k] -= f * g[c][k];
    }
  }
  return std::sqrt(std::abs(det));
}

// Coordinates at least 0.05 (azimuths 0.01) inside their ranges, and magnitudes at least 0.05
// from 0 (polar singularities), so that central differences do not straddle an edge.
template <class P, std::size_t N>
bool away_from_edges(const std::array<double, N>& q, const std::array<Axis, N>& axes) {
  for (std::size_t i = 0; i < N; ++i) {
    const double margin = axes[i].kind == AxisKind::azimuth ? 0.01 : 0.05;
    if (q[i] < axes[i].lo + margin || q[i] > axes[i].hi - margin) return false;
    if (axes[i].kind != AxisKind::azimuth && std::abs(q[i]) < 0.05) return false;
  }
  return true;
}

std::array<double, 6> flat(const DirPair<double>& p) {
  return {p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z};
}

TYPED_TEST(JacobianTest, MatchesFiniteDifferenceVolume) {
  using P = TypeParam;
  const double step = 1e-6;
  int checked = 0;
  for (const auto& p : test::random_pairs(20000, 31)) {
    // Stay away from the boundary and the coordinate singularities, where differences straddle.
    if (std::min(p.wi.z, p.wo.z) < 0.05) continue;
    const Tuple4<double> q = P::forward(p);
    if (!away_from_edges<P>(q, P::axes)) continue;
    std::array<std::array<double, 6>, 4> cols;
    bool inside = true;
    for (int d = 0; d < 4; ++d) {
      Tuple4<double> a = q, b = q;
      a[d] += step;
      b[d] -= step;
      const Solved<double> sa = inverse<P>(a), sb = inverse<P>(b);
      inside = inside && sa.in_domain && sb.in_domain;
      const auto fa = flat(sa.pair), fb = flat(sb.pair);
      for (int r = 0; r < 6; ++r) cols[d][r] = (fa[r] - fb[r]) / (2 * step);
    }
    if (!inside) continue;
    const double fd = gram_volume(cols), j = P::jacobian(q);
    EXPECT_NEAR(j, fd, 1e-6 * std::max(1.0, j)) << P::name;

    // Isotropic: the 3 coordinates plus the rotation about n span the 4D volume; the orbit has
    // length 2π.
    // Same precautions for the isotropic form; also keep ‖h̄‖ away from 0, where the canonical
    // rotation turns like 1/‖h̄‖ and central differences of that size lose their accuracy.
    const Tuple3<double> q3 = P::forward_iso(p);
    const double hbar = 0.5 * std::hypot(p.wi.x + p.wo.x, p.wi.y + p.wo.y);
    if (hbar < 0.05 || !away_from_edges<P>(q3, P::iso_axes)) continue;
    std::array<std::array<double, 6>, 4> cols3;
    for (int d = 0; d < 3; ++d) {
      Tuple3<double> a = q3, b = q3;
      a[d] += step;
      b[d] -= step;
      const auto fa = flat(inverse_iso<P>(a).pair), fb = flat(inverse_iso<P>(b).pair);
      for (int r = 0; r < 6; ++r) cols3[d][r] = (fa[r] - fb[r]) / (2 * step);
    }
    const auto c = flat(inverse_iso<P>(q3).pair);
    cols3[3] = {-c[1], c[0], 0, -c[4], c[3], 0};  // d/dα of the pair rotated by α
    const double fd3 = 2 * kPi * gram_volume(cols3), j3 = jacobian_iso<P>(q3);
    EXPECT_NEAR(j3, fd3, 1e-6 * std::max(1.0, j3)) << P::name << " isotropic";
    ++checked;
  }
  EXPECT_GT(checked, 1000) << P::name;
}

// Closed forms at a few points computed by hand (docs/math.md).
TEST(JacobianValues, ClosedForms) {
  // halfdiff: 4 cos θd sin θd sin θh at θh = 30°, θd = 45°: 4·(1/2)·(1/2) = 1.
  EXPECT_NEAR((HalfDiff::jacobian(Tuple4<double>{kPi / 6, 1.0, kPi / 4, 2.0})), 1.0, 1e-15);
  // ortho at ωi = ωo = (0.6, 0, 0.8): ‖k̄‖ = 0 so J = 0; and at ‖h̄‖ = ‖k̄‖ = 0.5, Δφ = 90°:
  // zi = zo = √0.5, J = 4·0.25/0.5 = 2.
  EXPECT_NEAR((Ortho::jacobian(Tuple4<double>{0.5, 0, 0.5, kPi / 2})), 2.0, 1e-15);
  // hybrid at the same point (kz = 0 there): hz² = 0.5, c = 0 → J = 4·0.25/0.5 = 2, as ortho.
  EXPECT_NEAR((Hybrid::jacobian(Tuple4<double>{0.5, 0, 0.5, kPi / 2})), 2.0, 1e-15);
  // hybrid at Δφ = 0: hz² = 0.5, c = 0.5 → 4·0.25/0.75.
  EXPECT_NEAR((Hybrid::jacobian(Tuple4<double>{0.5, 0, 0.5, 0})), 1.0 / 0.75, 1e-15);
}

}  // namespace
}  // namespace halfback
