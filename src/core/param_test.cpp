// Tests of the parameterization kernels, the same on every built-in parameterization: round trips
// of the ORDERED pair, isotropic forms, domain predicates, symmetries. What they need to know of
// each parameterization (its conditioning, its domain by an independent reference, ...) is stated
// beside it, in params/NAME_test.cpp (core/params/param_facts.hpp), with the facts of that
// parameterization alone (the paper's identities: params/hybrid_test.cpp). Jacobians are tested in
// jacobian_test.cpp. Error bounds are derived in docs/math.md ("Accuracy").
#include "halfback/core/param.hpp"
#include "halfback/core/space.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <limits>

#include "core/params/param_facts.hpp"
#include "support/param_types.hpp"
#include "support/test_util.hpp"

namespace halfback {
namespace {

using test::angle_diff;
using test::kPi;
using test::kTwoPiD;
using test::ParamFacts;

// Which coordinates are azimuths (compared on the circle).
template <std::size_t N>
std::array<bool, N> azimuth_flags(const std::array<Axis, N>& axes) {
  std::array<bool, N> f{};
  for (std::size_t i = 0; i < N; ++i) f[i] = axes[i].kind == AxisKind::azimuth;
  return f;
}

// The error grows like ε / cond down to cond = √ε, where the maps clamp or change form; further
// down where the map's facts say so.
template <class T>
double round_trip_bound(double cond, const ParamFacts& facts) {
  const double eps = std::numeric_limits<T>::epsilon();
  const double floor = facts.error_grows_below_sqrt_eps ? 0.0 : std::sqrt(eps);
  return 8 * eps / std::max(cond, floor);
}

// Each test has the facts of its parameterization, and fails without them.
template <class P>
class ParamTest : public ::testing::Test {
 protected:
  void SetUp() override {
    facts_ = test::find_param_facts(P::name);
    ASSERT_NE(facts_, nullptr) << P::name << " has no facts: state them in params/"
                               << test::gtest_name(P::name)
                               << "_test.cpp (core/params/param_facts.hpp)";
  }
  const ParamFacts& facts() const { return *facts_; }

 private:
  const ParamFacts* facts_ = nullptr;
};
using AllParams = test::BuiltinParamTypes;
class ParamNames {
 public:
  template <class P>
  static std::string GetName(int) {
    return test::gtest_name(P::name);
  }
};
TYPED_TEST_SUITE(ParamTest, AllParams, ParamNames);

// Round trip (ωi, ωo) -> q -> (ωi, ωo) in precision T over 10⁶ random pairs and the edge cases.
template <class P, class T>
void check_round_trip(std::size_t n, const ParamFacts& facts) {
  auto pairs = test::random_pairs(n, 20261122);
  const auto edges = test::edge_pairs();
  pairs.insert(pairs.end(), edges.begin(), edges.end());
  double worst_ratio = 0, worst_well_conditioned = 0, worst_above_001 = 0;
  std::size_t failures = 0;
  for (const auto& p64 : pairs) {
    if (facts.degenerate(p64)) continue;
    const DirPair<T> p = test::cast_pair<T>(p64);
    const DirPair<double> exact = test::cast_pair<double>(p);  // the input as T represents it
    const Solved<T> s = inverse<P>(P::forward(p));
    ASSERT_TRUE(s.in_domain) << P::name << ": forward image of a valid pair is not valid";
    const DirPair<double> back = test::cast_pair<double>(s.pair);
    ASSERT_GE(back.wi.z, 0.0);
    ASSERT_GE(back.wo.z, 0.0);
    const double err = test::max_abs_diff(exact, back);
    const double cond = facts.condition(exact);
    const double bound = round_trip_bound<T>(cond, facts);
    worst_ratio = std::max(worst_ratio, err / bound);
    if (std::min(exact.wi.z, exact.wo.z) >= 0.01) {
      worst_above_001 = std::max(worst_above_001, err);
      if (cond >= 0.05) worst_well_conditioned = std::max(worst_well_conditioned, err);
    }
    if (err > bound && failures++ < 5)
      ADD_FAILURE() << P::name << ": round trip error " << err << " > bound " << bound << " (cond "
                    << cond << ") for wi=(" << exact.wi.x << "," << exact.wi.y << "," << exact.wi.z
                    << ") wo=(" << exact.wo.x << "," << exact.wo.y << "," << exact.wo.z << ")";
  }
  // The absolute targets, where the conditioning allows them (docs/math.md, "Accuracy"): double
  // ≤ 1e-12 wherever both z ≥ 0.01. Float ≤ 1e-5 there where the facts say so (spherical,
  // halfdiff); else 1e-5 where the conditioning number is ≥ 0.05 and the bound above elsewhere.
  if constexpr (std::is_same_v<T, double>) {
    EXPECT_LE(worst_above_001, 1e-12) << P::name;
  } else if (facts.float_accurate_wherever_z_above_001) {
    EXPECT_LE(worst_above_001, 1e-5) << P::name;
  } else {
    EXPECT_LE(worst_well_conditioned, 1e-5) << P::name;
  }
  auto sci = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return std::string(buf);
  };
  ::testing::Test::RecordProperty("worst_error_over_bound", sci(worst_ratio));
  ::testing::Test::RecordProperty("worst_error_well_conditioned", sci(worst_well_conditioned));
  ::testing::Test::RecordProperty("worst_error_both_z_above_0.01", sci(worst_above_001));
}

TYPED_TEST(ParamTest, RoundTripOrderedPairDouble) {
  check_round_trip<TypeParam, double>(1000000, this->facts());
}
TYPED_TEST(ParamTest, RoundTripOrderedPairFloat) {
  check_round_trip<TypeParam, float>(1000000, this->facts());
}

// Some libraries return (ωo, ωi) from the orthographic and hybrid inverses. Pin the order down on
// a pair whose directions differ in every component.
TYPED_TEST(ParamTest, InverseDoesNotSwapDirections) {
  using P = TypeParam;
  const DirPair<double> p{test::direction(0.8, 0.3), test::direction(0.4, 2.1)};
  const Solved<double> s = inverse<P>(P::forward(p));
  EXPECT_NEAR(s.pair.wi.x, p.wi.x, 1e-14);
  EXPECT_NEAR(s.pair.wi.z, 0.8, 1e-14);
  EXPECT_NEAR(s.pair.wo.z, 0.4, 1e-14);
}

// Isotropic forms: the inverse returns the canonical pose, a rotation of the pair about n with
// φh = 0 (with ωi at azimuth 0 when h̄ = 0).
TYPED_TEST(ParamTest, IsotropicRoundTripGivesCanonicalPose) {
  using P = TypeParam;
  auto pairs = test::random_pairs(200000, 7);
  const auto edges = test::edge_pairs();
  pairs.insert(pairs.end(), edges.begin(), edges.end());
  std::size_t failures = 0;
  for (const auto& p : pairs) {
    if (this->facts().degenerate(p)) continue;
    const Tuple3<double> q = P::forward_iso(p);
    const Solved<double> s = inverse_iso<P>(q);
    ASSERT_TRUE(s.in_domain) << P::name;
    const double hx = p.wi.x + p.wo.x, hy = p.wi.y + p.wo.y;
    const bool flat = hx == 0 && hy == 0;
    const double ref = flat ? std::atan2(p.wi.y, p.wi.x) : std::atan2(hy, hx);
    const DirPair<double> expected = test::rotate_pair(p, -ref);
    // The pose's angle is as well conditioned as the azimuth of h̄ (or of ωi).
    const double hbar = 0.5 * std::hypot(hx, hy);
    const double pose_cond = flat ? 1.0 : hbar;
    const double map_cond = this->facts().condition(p);
    const double cond = this->facts().pose_conditioning_multiplies
                            ? map_cond * std::min(pose_cond, 1.0)
                            : std::min(map_cond, pose_cond);
    const double err = test::max_abs_diff(expected, s.pair);
    const double bound = round_trip_bound<double>(cond, this->facts());
    if (err > bound && failures++ < 5)
      ADD_FAILURE() << P::name << ": canonical pose error " << err << " > " << bound;
  }
}

TYPED_TEST(ParamTest, IsotropicFormIsRotationInvariant) {
  using P = TypeParam;
  const auto pairs = test::random_pairs(100000, 11);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, kTwoPiD);
  for (const auto& p : pairs) {
    if (std::min(p.wi.z, p.wo.z) < 1e-3) continue;  // keep to the well-conditioned set
    const Tuple3<double> a = P::forward_iso(p), b = P::forward_iso(test::rotate_pair(p, u(rng)));
    EXPECT_NEAR(a[0], b[0], this->facts().iso_rotation_tolerance) << P::name;
    EXPECT_NEAR(a[1], b[1], 1e-12);
    EXPECT_LE(angle_diff(a[2], b[2]), 1e-9) << P::name;
  }
}

TYPED_TEST(ParamTest, DomainPredicateAgreesWithInverseElevations) {
  using P = TypeParam;
  std::mt19937_64 rng(99);
  // A box a little larger than the coordinate ranges, so the range checks are exercised too.
  std::array<std::uniform_real_distribution<double>, 4> coordinate;
  for (std::size_t c = 0; c < 4; ++c) {
    const Axis& a = P::axes[c];
    const double margin = a.kind == AxisKind::azimuth ? 0.3 : 0.05 * (a.hi - a.lo);
    coordinate[c] = std::uniform_real_distribution<double>(a.lo - margin, a.hi + margin);
  }
  std::size_t n_valid = 0, mismatches = 0;
  const std::size_t n = 1000000;
  for (std::size_t i = 0; i < n; ++i) {
    const Tuple4<double> q{coordinate[0](rng), coordinate[1](rng), coordinate[2](rng),
                           coordinate[3](rng)};
    const bool got = valid<P>(q);
    const bool want = this->facts().reference_valid(Tuple4<long double>{q[0], q[1], q[2], q[3]});
    n_valid += want;
    if (got != want && mismatches++ < 5)
      ADD_FAILURE() << P::name << ": predicate " << got << " vs reference " << want << " at ("
                    << q[0] << ", " << q[1] << ", " << q[2] << ", " << q[3] << ")";
    if (got) {
      const Solved<double> s = inverse<P>(q);
      ASSERT_GE(s.pair.wi.z, 0.0);
      ASSERT_GE(s.pair.wo.z, 0.0);
      ASSERT_NEAR(detail::dot(s.pair.wi, s.pair.wi), 1.0, 1e-12);
      ASSERT_NEAR(detail::dot(s.pair.wo, s.pair.wo), 1.0, 1e-12);
    }
  }
  // The sample must cover both sides of the boundary for the agreement to mean anything.
  EXPECT_GT(n_valid, n / 20);
  EXPECT_LT(n_valid, n * 9 / 10);
}

TYPED_TEST(ParamTest, InvalidTuplesGiveNaNDirections) {
  using P = TypeParam;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Tuple4<double> base =
      P::forward(DirPair<double>{test::direction(0.8, 0.3), test::direction(0.6, 2.1)});
  ASSERT_TRUE(valid<P>(base)) << P::name;
  std::vector<Tuple4<double>> bad;
  for (std::size_t c = 0; c < 4; ++c) {
    const Axis& a = P::axes[c];
    const double inf = std::numeric_limits<double>::infinity();
    const std::vector<double> values = a.kind == AxisKind::azimuth
                                           ? std::vector<double>{nan, inf, -inf}  // else periodic
                                           : std::vector<double>{nan, a.lo - 1e-3, a.hi + 1e-3};
    for (double v : values) {
      bad.push_back(base);
      bad.back()[c] = v;
    }
  }
  for (const auto& q : bad) {
    const Solved<double> s = inverse<P>(q);
    EXPECT_FALSE(s.in_domain) << P::name << " (" << q[0] << ", " << q[1] << ", " << q[2] << ", "
                              << q[3] << ")";
    EXPECT_TRUE(std::isnan(s.pair.wi.x) && std::isnan(s.pair.wo.z)) << P::name;
  }
}

// Azimuths are periodic (docs/reliability/numerics.md, "Azimuths are periodic"): a tuple whose
// azimuths are moved by whole turns, negative ones included, is the same pair, in the 4D and the
// isotropic forms; within the rounding of the turn's subtraction. On the code before, φ < 0 or ≥ 2π
// was invalid.
TYPED_TEST(ParamTest, AzimuthsArePeriodic) {
  using P = TypeParam;
  const DirPair<double> p{test::direction(0.8, 0.3), test::direction(0.6, 2.1)};
  const Tuple4<double> q = P::forward(p);
  const Tuple3<double> q3 = P::forward_iso(p);
  const auto near = [](const DirPair<double>& a, const DirPair<double>& b) {
    return std::abs(a.wi.x - b.wi.x) + std::abs(a.wi.y - b.wi.y) + std::abs(a.wi.z - b.wi.z) +
               std::abs(a.wo.x - b.wo.x) + std::abs(a.wo.y - b.wo.y) + std::abs(a.wo.z - b.wo.z) <
           1e-12;
  };
  int azimuths = 0;
  for (const int turns : {-3, -1, 1, 2, 100}) {
    Tuple4<double> moved = q;
    for (std::size_t c = 0; c < 4; ++c)
      if (P::axes[c].kind == AxisKind::azimuth) moved[c] += turns * kTwoPiD, ++azimuths;
    const Solved<double> s = inverse<P>(moved);
    EXPECT_TRUE(s.in_domain && near(s.pair, inverse<P>(q).pair)) << P::name << " " << turns;
    EXPECT_TRUE(valid<P>(moved)) << P::name;
    Tuple3<double> moved3 = q3;
    for (std::size_t c = 0; c < 3; ++c)
      if (P::iso_axes[c].kind == AxisKind::azimuth) moved3[c] += turns * kTwoPiD, ++azimuths;
    const Solved<double> s3 = inverse_iso<P>(moved3);
    EXPECT_TRUE(s3.in_domain && near(s3.pair, inverse_iso<P>(q3).pair)) << P::name << " " << turns;
    EXPECT_TRUE(valid_iso<P>(moved3)) << P::name;
  }
  if (azimuths == 0) GTEST_SKIP() << P::name << " has no azimuth coordinate";
}

// --- Symmetries -------------------------------------------------------------------------------

DirPair<double> mirror_pair(const DirPair<double>& p, double alpha) {
  // Reflection across the vertical plane at azimuth alpha.
  auto m = [&](const Vec3<double>& v) {
    const double c = std::cos(2 * alpha), s = std::sin(2 * alpha);
    return Vec3<double>{c * v.x + s * v.y, s * v.x - c * v.y, v.z};
  };
  return {m(p.wi), m(p.wo)};
}

template <std::size_t N>
void expect_same_coordinates(const std::array<double, N>& a, const std::array<double, N>& b,
                             const std::array<bool, N>& is_azimuth, double tol,
                             std::string_view what) {
  for (std::size_t i = 0; i < N; ++i) {
    const double d = is_azimuth[i] ? angle_diff(a[i], b[i]) : std::abs(a[i] - b[i]);
    EXPECT_LE(d, tol) << what << " coordinate " << i << ": " << a[i] << " vs " << b[i];
  }
}

TYPED_TEST(ParamTest, ReciprocityMapEqualsConversionOfSwappedPair) {
  using P = TypeParam;
  for (const auto& p : test::random_pairs(100000, 21)) {
    if (std::min(p.wi.z, p.wo.z) < 1e-4 || this->facts().condition(p) < 1e-4) continue;
    const DirPair<double> swapped{p.wo, p.wi};
    expect_same_coordinates(P::reciprocal(P::forward(p)), P::forward(swapped),
                            azimuth_flags(P::axes), 1e-9, P::name);
    expect_same_coordinates(P::reciprocal_iso(P::forward_iso(p)), P::forward_iso(swapped),
                            azimuth_flags(P::iso_axes), 1e-9, P::name);
  }
}

TYPED_TEST(ParamTest, MirrorMapEqualsConversionOfMirroredPair) {
  using P = TypeParam;
  for (const auto& p : test::random_pairs(100000, 22)) {
    if (std::min(p.wi.z, p.wo.z) < 1e-4 || this->facts().condition(p) < 1e-4) continue;
    const double phi_h = std::atan2(p.wi.y + p.wo.y, p.wi.x + p.wo.x);
    expect_same_coordinates(P::mirror(P::forward(p)), P::forward(mirror_pair(p, phi_h)),
                            azimuth_flags(P::axes), 1e-9, P::name);
    // The isotropic form does not depend on which vertical plane mirrors the pair.
    expect_same_coordinates(P::mirror_iso(P::forward_iso(p)), P::forward_iso(mirror_pair(p, 0.37)),
                            azimuth_flags(P::iso_axes), 1e-9, P::name);
  }
}

// The facts registered are whole, each of a built-in parameterization, one for each (a renamed
// parameterization leaves no facts behind).
TEST(ParamFacts, OneWholeSetForEachBuiltinParameterization) {
  std::vector<std::string> builtin;
  for (const Space s : kBuiltinSpaces) builtin.emplace_back(name_of(s));
  for (const auto& [name, facts] : test::param_facts_registry()) {
    EXPECT_NE(std::find(builtin.begin(), builtin.end(), name), builtin.end()) << name;
    EXPECT_TRUE(facts.condition && facts.reference_valid && facts.degenerate) << name;
  }
  EXPECT_EQ(test::param_facts_registry().size(), builtin.size());
}

TEST(Azimuth, RangeAndZeroVector) {
  EXPECT_EQ(LaneOps<double>::azimuth(0.0, 0.0), 0.0);
  EXPECT_EQ(LaneOps<double>::azimuth(0.0, -0.0), 0.0);  // std::atan2 would say π
  EXPECT_FALSE(std::signbit(LaneOps<double>::azimuth(-0.0, 1.0)));
  EXPECT_LT(LaneOps<double>::azimuth(-1e-30, 1.0), kTwoPiD);
  // -tiny + 2π rounds up to 2π in float.
  EXPECT_LT(LaneOps<float>::azimuth(-1e-30f, 1.0f), kTwoPi<float>);
  EXPECT_NEAR(LaneOps<double>::azimuth(-1.0, 0.0), 1.5 * kPi, 1e-15);
}

}  // namespace
}  // namespace halfback

namespace halfback {
namespace {

TEST(Space, BuiltinSpacesFollowTheListAndDirsIsNoParameterization) {
  auto name_of_p = [](auto p) { return decltype(p)::name; };
  EXPECT_EQ(visit_kernel_param(space_of<Spherical>.kernel_index(), name_of_p), "spherical");
  EXPECT_EQ(visit_kernel_param(space_of<HalfDiff>.kernel_index(), name_of_p), "halfdiff");
  EXPECT_EQ(visit_kernel_param(space_of<Ortho>.kernel_index(), name_of_p), "ortho");
  EXPECT_EQ(visit_kernel_param(space_of<Hybrid>.kernel_index(), name_of_p), "hybrid");
  for (Space s : kKernelSpaces) EXPECT_EQ(s.param().name(), name_of(s));
  EXPECT_EQ(space_names(),
            "dirs, spherical, halfdiff, ortho, hybrid, rectified-hybrid, stereo-halfdiff, "
            "stereographic, halfway-disk");
  EXPECT_THROW((void)Space::dirs.param(), std::invalid_argument);
  EXPECT_THROW((void)Space::from_id(60000).param(), std::invalid_argument);
}

}  // namespace
}  // namespace halfback
