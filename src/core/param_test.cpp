// Tests of the parameterization kernels: round trips of the ORDERED pair, isotropic forms,
// domain predicates, identities (and the paper's erratum), symmetries. Jacobians are tested in
// jacobian_test.cpp. Error bounds are derived in docs/math.md ("Accuracy").
#include "halfback/core/param.hpp"
#include "halfback/core/space.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <limits>

#include "support/param_types.hpp"
#include "support/test_util.hpp"

namespace halfback {
namespace {

using test::angle_diff;
using test::kPi;
using test::kTwoPiD;
constexpr double kEps = std::numeric_limits<double>::epsilon();

// Conditioning of each inverse map at a pair (docs/math.md, "Accuracy"): the round-trip error is
// bounded by C·ε / max(cond, √ε).
double condition(const Spherical&, const DirPair<double>&) {
  return 1;
}
double condition(const HalfDiff&, const DirPair<double>& p) {
  return std::sqrt(std::max(0.0, 0.5 * (1 + detail::dot(p.wi, p.wo))));  // ‖h‖ = cos θd
}
double condition(const Ortho&, const DirPair<double>& p) {
  return std::min(p.wi.z, p.wo.z);
}
double condition(const Hybrid&, const DirPair<double>& p) {
  return 0.5 * (p.wi.z + p.wo.z);
}
double condition(const RectifiedHybrid&, const DirPair<double>& p) {
  return condition(Hybrid{}, p);
}
double condition(const StereoHalfDiff&, const DirPair<double>& p) {
  return condition(HalfDiff{}, p) / 2;  // halfdiff's, and the projection's own rounding
}
double condition(const Stereographic&, const DirPair<double>&) {
  return 1;
}
double condition(const HalfwayDisk&, const DirPair<double>& p) {
  return p.wi.z / 4;  // the disk is built at ωi's height: errors up to ~30 ε / zi
}

// Pairs on which a parameterization is not a bijection (the maps' degenerate faces): the halfway
// disk at a grazing ωi maps every disk point to a grazing ωo.
template <class P>
bool degenerate(const DirPair<double>& p) {
  if constexpr (std::is_same_v<P, HalfwayDisk>) return p.wi.z < 1e-6;
  return false;
}

// Which coordinates are azimuths (compared on the circle).
template <std::size_t N>
std::array<bool, N> azimuth_flags(const std::array<Axis, N>& axes) {
  std::array<bool, N> f{};
  for (std::size_t i = 0; i < N; ++i) f[i] = axes[i].kind == AxisKind::azimuth;
  return f;
}

// The error grows like ε / cond down to cond = √ε, where the maps clamp or change form; the
// halfway disk's keeps growing like ε / zi (it is not a bijection at zi = 0).
template <class T, class P = Spherical>
double round_trip_bound(double cond) {
  const double eps = std::numeric_limits<T>::epsilon();
  const double floor = std::is_same_v<P, HalfwayDisk> ? 0.0 : std::sqrt(eps);
  return 8 * eps / std::max(cond, floor);
}

template <class P>
class ParamTest : public ::testing::Test {};
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
void check_round_trip(std::size_t n) {
  auto pairs = test::random_pairs(n, 20261122);
  const auto edges = test::edge_pairs();
  pairs.insert(pairs.end(), edges.begin(), edges.end());
  double worst_ratio = 0, worst_well_conditioned = 0, worst_above_001 = 0;
  std::size_t failures = 0;
  for (const auto& p64 : pairs) {
    if (degenerate<P>(p64)) continue;
    const DirPair<T> p = test::cast_pair<T>(p64);
    const DirPair<double> exact = test::cast_pair<double>(p);  // the input as T represents it
    const Solved<T> s = inverse<P>(P::forward(p));
    ASSERT_TRUE(s.in_domain) << P::name << ": forward image of a valid pair is not valid";
    const DirPair<double> back = test::cast_pair<double>(s.pair);
    ASSERT_GE(back.wi.z, 0.0);
    ASSERT_GE(back.wo.z, 0.0);
    const double err = test::max_abs_diff(exact, back);
    const double cond = condition(P{}, exact);
    const double bound = round_trip_bound<T, P>(cond);
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
  // ≤ 1e-12 wherever both z ≥ 0.01. Float ≤ 1e-5 there for spherical and halfdiff; ortho and
  // hybrid store ‖h̄‖, ‖k̄‖ / ‖k‖ with 6e-8 relative rounding, which alone moves z by ~ε/z, so
  // for them 1e-5 holds where the conditioning number is ≥ 0.05 and the bound above elsewhere.
  if constexpr (std::is_same_v<T, double>) {
    EXPECT_LE(worst_above_001, 1e-12) << P::name;
  } else if constexpr (std::is_same_v<P, Spherical> || std::is_same_v<P, HalfDiff>) {
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
  check_round_trip<TypeParam, double>(1000000);
}
TYPED_TEST(ParamTest, RoundTripOrderedPairFloat) {
  check_round_trip<TypeParam, float>(1000000);
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
    if (degenerate<P>(p)) continue;
    const Tuple3<double> q = P::forward_iso(p);
    const Solved<double> s = inverse_iso<P>(q);
    ASSERT_TRUE(s.in_domain) << P::name;
    const double hx = p.wi.x + p.wo.x, hy = p.wi.y + p.wo.y;
    const bool flat = hx == 0 && hy == 0;
    const double ref = flat ? std::atan2(p.wi.y, p.wi.x) : std::atan2(hy, hx);
    const DirPair<double> expected = test::rotate_pair(p, -ref);
    // The pose's angle is as well conditioned as the azimuth of h̄ (or of ωi).
    const double hbar = 0.5 * std::hypot(hx, hy);
    // The halfway disk's pair is known to ε/zi, and the pose turns it by an angle known to
    // (ε/zi)/‖h̄‖: the two conditionings multiply.
    const double pose_cond = flat ? 1.0 : hbar;
    const double cond = std::is_same_v<P, HalfwayDisk>
                            ? condition(P{}, p) * std::min(pose_cond, 1.0)
                            : std::min(condition(P{}, p), pose_cond);
    const double err = test::max_abs_diff(expected, s.pair);
    const double bound = round_trip_bound<double, P>(cond);
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
    // The rectified ‖h̄‖ is divided by a function of the relative azimuth: it inherits that
    // azimuth's rounding (1e-9 below).
    EXPECT_NEAR(a[0], b[0], (std::is_same_v<P, RectifiedHybrid> ? 1e-9 : 1e-12));
    EXPECT_NEAR(a[1], b[1], 1e-12);
    EXPECT_LE(angle_diff(a[2], b[2]), 1e-9) << P::name;
  }
}

// Independent reference for the domain: textbook inverse formulas in long double, "the inverse
// gives z >= 0 for both directions" (plus the coordinate ranges).
// Azimuths are periodic: any finite value is one (the maps reduce it to [0, 2π)).
bool azimuths_ok(const Tuple4<long double>& q) {
  return std::isfinite(q[1]) && std::isfinite(q[3]);
}
bool reference_valid(const Spherical&, const Tuple4<long double>& q) {
  return q[0] >= 0 && q[0] <= kPi / 2 && q[2] >= 0 && q[2] <= kPi / 2 && azimuths_ok(q);
}
bool reference_valid(const HalfDiff&, const Tuple4<long double>& q) {
  if (!(q[0] >= 0 && q[0] <= kPi / 2 && q[2] >= 0 && q[2] <= kPi / 2 && azimuths_ok(q)))
    return false;
  const long double a = cosl(q[2]) * cosl(q[0]), b = sinl(q[2]) * cosl(q[3]) * sinl(q[0]);
  return a - b >= 0 && a + b >= 0;
}
bool reference_valid(const Ortho&, const Tuple4<long double>& q) {
  if (!(q[0] >= 0 && q[0] <= 1 && q[2] >= 0 && q[2] <= 1 && azimuths_ok(q))) return false;
  const long double hx = q[0] * cosl(q[1]), hy = q[0] * sinl(q[1]);
  const long double kx = q[2] * cosl(q[3]), ky = q[2] * sinl(q[3]);
  return (hx + kx) * (hx + kx) + (hy + ky) * (hy + ky) <= 1 &&
         (hx - kx) * (hx - kx) + (hy - ky) * (hy - ky) <= 1;
}
// The box-domain maps: their domain is the box of their ranges.
bool reference_valid(const RectifiedHybrid&, const Tuple4<long double>& q) {
  return q[0] >= 0 && q[0] <= 1 && q[2] >= 0 && q[2] <= 1 && azimuths_ok(q);
}
bool reference_valid(const HalfwayDisk&, const Tuple4<long double>& q) {
  return q[0] >= 0 && q[0] <= kPi / 2 && q[2] >= 0 && q[2] <= 1 && azimuths_ok(q);
}
// Two unit disks; and halfdiff's condition in half-angle form (1 − ρh²)(1 − ρd²) ≥ 4ρh|sd_x|.
bool reference_valid(const Stereographic&, const Tuple4<long double>& q) {
  return q[0] * q[0] + q[1] * q[1] <= 1 && q[2] * q[2] + q[3] * q[3] <= 1;
}
bool reference_valid(const StereoHalfDiff&, const Tuple4<long double>& q) {
  const long double rh2 = q[0] * q[0] + q[1] * q[1], rd2 = q[2] * q[2] + q[3] * q[3];
  return rh2 <= 1 && rd2 <= 1 && (1 - rh2) * (1 - rd2) >= 4 * sqrtl(rh2) * fabsl(q[2]);
}
bool reference_valid(const Hybrid&, const Tuple4<long double>& q) {
  if (!(q[0] >= 0 && q[0] <= 1 && q[2] >= 0 && q[2] <= 1 && azimuths_ok(q))) return false;
  const long double hz2 = 1 - q[0] * q[0] - q[2] * q[2];
  if (hz2 < 0) return false;
  const long double hz = sqrtl(hz2);
  const long double theta_k = atan2l(hz, -q[0] * cosl(q[3] - q[1]));
  const long double kz = q[2] * cosl(theta_k);
  return hz + kz >= 0 && hz - kz >= 0;
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
    const bool want = reference_valid(P{}, Tuple4<long double>{q[0], q[1], q[2], q[3]});
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

// Azimuths are periodic (issue 35, class I): a tuple whose azimuths are moved by whole turns,
// negative ones included, is the same pair, in the 4D and the isotropic forms; within the
// rounding of the turn's subtraction. On the code before, φ < 0 or ≥ 2π was invalid.
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

// Outside the disk/hemisphere, specific to each parameterization.
TEST(Domain, SpecificInvalidTuples) {
  // halfdiff: θh = θd = 60°, φd = 0 puts ωi below the horizon.
  EXPECT_FALSE((valid<HalfDiff>(Tuple4<double>{kPi / 3, 0, kPi / 3, 0})));
  EXPECT_TRUE((valid<HalfDiff>(Tuple4<double>{kPi / 3, 0, kPi / 3, kPi / 2})));
  // ortho: |h̄ + k̄| = 1.2.
  EXPECT_FALSE((valid<Ortho>(Tuple4<double>{0.6, 0, 0.6, 0})));
  EXPECT_TRUE((valid<Ortho>(Tuple4<double>{0.6, 0, 0.6, kPi / 2})));
  // hybrid: ‖h̄‖² + ‖k‖² > 1; and ‖h̄‖² + ‖k‖² < 1 but a direction below the horizon.
  EXPECT_FALSE((valid<Hybrid>(Tuple4<double>{0.8, 0, 0.7, kPi / 2})));
  EXPECT_FALSE((valid<Hybrid>(Tuple4<double>{0.7, 0, 0.7, 0.1})));
  EXPECT_TRUE((valid<Hybrid>(Tuple4<double>{0.7, 0, 0.7, kPi / 2})));
}

// --- Identities of the paper's appendix -----------------------------------------------------

TEST(Identities, HalfAndDifferenceVectors) {
  for (const auto& p : test::random_pairs(200000, 5)) {
    const Vec3<double> h{(p.wi.x + p.wo.x) / 2, (p.wi.y + p.wo.y) / 2, (p.wi.z + p.wo.z) / 2};
    const Vec3<double> k{(p.wi.x - p.wo.x) / 2, (p.wi.y - p.wo.y) / 2, (p.wi.z - p.wo.z) / 2};
    EXPECT_NEAR(detail::dot(h, h) + detail::dot(k, k), 1.0, 8 * kEps);  // unit inputs ± 2ε
    EXPECT_NEAR(detail::dot(h, k), 0.0, 4 * kEps);
    const Tuple4<double> hd = HalfDiff::forward(p), hy = Hybrid::forward(p);
    const double h_len = std::sqrt(detail::dot(h, h));
    EXPECT_NEAR(std::cos(hd[2]), h_len, 8 * kEps);  // cos θd = ‖h‖
    EXPECT_NEAR(hy[0] * hy[0], std::pow(std::sin(hd[0]) * std::cos(hd[2]), 2), 1e-15);  // ‖h̄‖²
    EXPECT_NEAR(hy[2], std::sqrt(detail::dot(k, k)), 1e-15);
  }
}

// (ωi·n)(ωo·n) = hz² − kz², and in hybrid coordinates the polynomial margin
// zi zo (hz² + c²) = hz² (hz² + c²) − ‖k‖² c², c = ‖h̄‖ cos(φk − φh).
TEST(Identities, GrazingProduct) {
  for (const auto& p : test::random_pairs(200000, 6)) {
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
    EXPECT_LE(test::max_abs_diff(hy.pair, ov.pair), 1e-12);
  }
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
    if (std::min(p.wi.z, p.wo.z) < 1e-4 || condition(P{}, p) < 1e-4) continue;
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
    if (std::min(p.wi.z, p.wo.z) < 1e-4 || condition(P{}, p) < 1e-4) continue;
    const double phi_h = std::atan2(p.wi.y + p.wo.y, p.wi.x + p.wo.x);
    expect_same_coordinates(P::mirror(P::forward(p)), P::forward(mirror_pair(p, phi_h)),
                            azimuth_flags(P::axes), 1e-9, P::name);
    // The isotropic form does not depend on which vertical plane mirrors the pair.
    expect_same_coordinates(P::mirror_iso(P::forward_iso(p)), P::forward_iso(mirror_pair(p, 0.37)),
                            azimuth_flags(P::iso_axes), 1e-9, P::name);
  }
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
