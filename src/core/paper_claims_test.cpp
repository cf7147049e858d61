// The mathematical statements of Barla, Belcour and Pacanowski 2015, each decided numerically
// against the core's exact maps (docs/paper.md lists every claim, its verdict and its test). A
// test here passes when the verdict of docs/paper.md is right: "holds" claims are checked on
// random pairs, "false" claims by their counter-example and by the corrected statement.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "halfback/core/param.hpp"
#include "support/test_util.hpp"

namespace halfback {
namespace {

using test::angle_diff;
using test::kPi;
using test::kTwoPiD;
using V = Vec3<double>;

constexpr double kDeg = kPi / 180;

V add(const V& a, const V& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
V sub(const V& a, const V& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
V scale(double s, const V& a) {
  return {s * a.x, s * a.y, s * a.z};
}
double norm(const V& a) {
  return std::sqrt(detail::dot(a, a));
}
double dist(const V& a, const V& b) {
  return norm(sub(a, b));
}
V half_vector(const DirPair<double>& p) {  // h = (ωi + ωo)/2, not normalized
  return scale(0.5, add(p.wi, p.wo));
}
V back_vector(const DirPair<double>& p) {  // k = (ωi − ωo)/2, not normalized
  return scale(0.5, sub(p.wi, p.wo));
}
V spherical_dir(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}
// Right-handed rotations: rot_n about n = z, rot_b about b = y (rot_b(θ) n = (sin θ, 0, cos θ)).
V rot_n(double a, const V& v) {
  return {std::cos(a) * v.x - std::sin(a) * v.y, std::sin(a) * v.x + std::cos(a) * v.y, v.z};
}
V rot_b(double a, const V& v) {
  return {std::cos(a) * v.x + std::sin(a) * v.z, v.y, -std::sin(a) * v.x + std::cos(a) * v.z};
}
double grazing_product(const DirPair<double>& p) {  // (ωi·n)(ωo·n) = 1 − G
  return p.wi.z * p.wo.z;
}
// Pairs away from the degenerate sets where an azimuth is undefined or ill-conditioned.
std::vector<DirPair<double>> generic_pairs(std::size_t n, std::uint64_t seed) {
  std::vector<DirPair<double>> out;
  for (const auto& p : test::random_pairs(n, seed)) {
    const V h = half_vector(p), k = back_vector(p);
    if (std::min(p.wi.z, p.wo.z) > 1e-3 && std::hypot(h.x, h.y) > 1e-3 &&
        std::hypot(k.x, k.y) > 1e-3)
      out.push_back(p);
  }
  return out;
}

// --- Section 2 --------------------------------------------------------------------------------

// §2: "for isotropic BRDFs, ρ(θi, θo, |φi − φo|)". Isotropy gives the signed Δφ; the absolute
// value also needs bilateral (mirror) symmetry. A counter-example: ρ = 1 + ½ (zi − zo)(ωi × ωo)·n
// is rotation invariant and reciprocal, but differs at Δφ = ±60°.
TEST(PaperClaims, AbsoluteAzimuthDifferenceNeedsBilateralSymmetry) {
  auto chiral = [](const DirPair<double>& p) {
    return 1 + 0.5 * (p.wi.z - p.wo.z) * (p.wi.x * p.wo.y - p.wi.y * p.wo.x);
  };
  for (const auto& p : test::random_pairs(20000, 1)) {
    EXPECT_NEAR(chiral(p), chiral(test::rotate_pair(p, 1.234)), 1e-14) << "isotropic";
    EXPECT_NEAR(chiral(p), chiral({p.wo, p.wi}), 1e-14) << "reciprocal";
  }
  const DirPair<double> plus{spherical_dir(30 * kDeg, 0), spherical_dir(60 * kDeg, 60 * kDeg)};
  const DirPair<double> minus{spherical_dir(30 * kDeg, 0), spherical_dir(60 * kDeg, -60 * kDeg)};
  // Same (θi, θo, |φi − φo|), values 1 ± 0.0686.
  EXPECT_NEAR(chiral(plus) - chiral(minus), 2 * 0.5 * (std::cos(kPi / 6) - 0.5) * 0.375, 1e-14);
  EXPECT_GT(chiral(plus) - chiral(minus), 0.13);
  // halfback's isotropic spherical form keeps the sign: Δφ = 60° and 300°.
  EXPECT_NEAR(Spherical::forward_iso(plus)[2], kPi / 3, 1e-14);
  EXPECT_NEAR(Spherical::forward_iso(minus)[2], 5 * kPi / 3, 1e-14);
}

// §2: "an isotropic BRDF is invariant to φh". A rotation about n shifts φh alone in halfdiff, but
// φh and φk together in ortho and hybrid: there the BRDF is a function of φk − φh, not of φk.
TEST(PaperClaims, IsotropyDropsPhiHOnlyWithARelativeSecondAzimuth) {
  const double alpha = 0.9;
  for (const auto& p : generic_pairs(20000, 2)) {
    const DirPair<double> r = test::rotate_pair(p, alpha);
    const Tuple4<double> hd = HalfDiff::forward(p), hd_r = HalfDiff::forward(r);
    EXPECT_NEAR(angle_diff(hd_r[1], hd[1] + alpha), 0, 1e-9);
    EXPECT_NEAR(angle_diff(hd_r[3], hd[3]), 0, 1e-9) << "φd is already relative";
    const std::array<std::array<Tuple4<double>, 2>, 2> planar{
        {{Ortho::forward(p), Ortho::forward(r)}, {Hybrid::forward(p), Hybrid::forward(r)}}};
    for (const auto& [q, q_r] : planar) {
      EXPECT_NEAR(angle_diff(q_r[1], q[1] + alpha), 0, 1e-9);
      EXPECT_NEAR(angle_diff(q_r[3], q[3] + alpha), 0, 1e-9) << "φk turns with the pair";
    }
  }
  // Counter-example: hybrid (‖h̄‖, φh, ‖k‖, φk) = (½, 0, ½, 0) and (½, 90°, ½, 0) have different
  // (ωi·n)(ωo·n), 5/12 and 1/2, so an isotropic G depends on φh at fixed φk.
  const Solved<double> a = inverse<Hybrid>(Tuple4<double>{0.5, 0, 0.5, 0});
  const Solved<double> b = inverse<Hybrid>(Tuple4<double>{0.5, kPi / 2, 0.5, 0});
  ASSERT_TRUE(a.in_domain && b.in_domain);
  EXPECT_NEAR(grazing_product(a.pair), 5.0 / 12, 1e-14);
  EXPECT_NEAR(grazing_product(b.pair), 0.5, 1e-14);
}

// §2, printed forward halfdiff map: d̂ = rot_b(−θh) rot_n(φh) ωi. It is not the inverse of
// Equation (1) unless rot_n(φh) = rot_n(−φh), i.e. φh ∈ {0, π}; the correct map has rot_n(−φh).
TEST(PaperClaims, PrintedHalfDiffForwardRotationHasTheWrongSignOfPhiH) {
  for (const auto& p : generic_pairs(20000, 3)) {
    const Tuple4<double> q = HalfDiff::forward(p);
    const V d = spherical_dir(q[2], q[3]);
    EXPECT_LE(dist(rot_b(-q[0], rot_n(-q[1], p.wi)), d), 1e-9) << "corrected form";
  }
  // Counter-example: ωi = (0, 0.6, 0.8), ωo = n; φh = 90°, θh = atan(1/3), cos θd = ‖h‖ = 0.9487.
  const DirPair<double> p{{0, 0.6, 0.8}, {0, 0, 1}};
  const Tuple4<double> q = HalfDiff::forward(p);
  ASSERT_NEAR(q[1], kPi / 2, 1e-15);
  EXPECT_NEAR(std::cos(q[2]), std::sqrt(0.9), 1e-15);
  const V printed = rot_b(-q[0], rot_n(q[1], p.wi));
  EXPECT_NEAR(printed.z, 0.8 * 3 / std::sqrt(10.0) - 0.6 / std::sqrt(10.0), 1e-15);  // 0.5692
  EXPECT_GT(dist(printed, spherical_dir(q[2], q[3])), 0.5);
}

// §2, Equations (1) and (2): ωi = rot_n(φh) rot_b(θh) d̂ and ωo = 2(ωi·ĥ)ĥ − ωi. Both hold.
TEST(PaperClaims, HalfDiffInverseEquationsOneAndTwoHold) {
  for (const auto& p : generic_pairs(20000, 4)) {
    const Tuple4<double> q = HalfDiff::forward(p);
    const V wi = rot_n(q[1], rot_b(q[0], spherical_dir(q[2], q[3])));
    const V hhat = spherical_dir(q[0], q[1]);
    const V wo = sub(scale(2 * detail::dot(wi, hhat), hhat), wi);
    EXPECT_LE(dist(wi, p.wi), 1e-12);
    EXPECT_LE(dist(wo, p.wo), 1e-12);
    EXPECT_LE(dist(hhat, scale(1 / norm(half_vector(p)), half_vector(p))), 1e-12);
  }
}

// §2: reciprocity (ωi ↔ ωo) is φd → φd + π in halfdiff, φk → φk + π (k̄ → −k̄, k → −k) in ortho
// and hybrid, every other coordinate unchanged. Holds.
TEST(PaperClaims, ReciprocityIsAHalfTurnOfTheSecondAzimuth) {
  auto check = [](const Tuple4<double>& q, const Tuple4<double>& s) {
    EXPECT_NEAR(s[0], q[0], 1e-12);
    EXPECT_NEAR(angle_diff(s[1], q[1]), 0, 1e-9);
    EXPECT_NEAR(s[2], q[2], 1e-12);
    EXPECT_NEAR(angle_diff(s[3], q[3] + kPi), 0, 1e-9);
  };
  for (const auto& p : generic_pairs(20000, 5)) {
    const DirPair<double> swapped{p.wo, p.wi};
    check(HalfDiff::forward(p), HalfDiff::forward(swapped));
    check(Ortho::forward(p), Ortho::forward(swapped));
    check(Hybrid::forward(p), Hybrid::forward(swapped));
    const V k = back_vector(p), k_swapped = back_vector(swapped);
    EXPECT_LE(dist(k_swapped, scale(-1, k)), 1e-15);
  }
}

// §2, Equations (3) and (4): ωi = ω̄i + √(1 − ‖ω̄i‖²) n with ω̄i = h̄ + k̄, ωo likewise with
// ω̄o = h̄ − k̄ (the sum is ωi: the order matters). Hold.
TEST(PaperClaims, OrthoInverseEquationsThreeAndFourHold) {
  for (const auto& p : generic_pairs(20000, 6)) {
    const Tuple4<double> q = Ortho::forward(p);
    const V hbar{q[0] * std::cos(q[1]), q[0] * std::sin(q[1]), 0};
    const V kbar{q[2] * std::cos(q[3]), q[2] * std::sin(q[3]), 0};
    auto lift = [](const V& planar) {
      return V{planar.x, planar.y, std::sqrt(std::max(0.0, 1 - detail::dot(planar, planar)))};
    };
    const double tol = 1e-12 / std::min(p.wi.z, p.wo.z);  // dz/dr = −r/z
    EXPECT_LE(dist(lift(add(hbar, kbar)), p.wi), tol);
    EXPECT_LE(dist(lift(sub(hbar, kbar)), p.wo), tol);
  }
}

// §2 (Figure 1, ortho): ‖k̄‖ has "the same formula" as ‖h̄‖. Exactly: k̄(ωi, ωo) = h̄(ωi, ωo'),
// ωo' = ωo turned by π about n, so ‖k̄‖'s isolines around the back direction are ‖h̄‖'s around the
// mirror direction. Holds.
TEST(PaperClaims, OrthoKbarIsHbarOfTheHalfTurnedOutgoingDirection) {
  for (const auto& p : generic_pairs(20000, 7)) {
    const Tuple4<double> q = Ortho::forward(p);
    const Tuple4<double> turned = Ortho::forward(DirPair<double>{p.wi, rot_n(kPi, p.wo)});
    EXPECT_NEAR(q[2], turned[0], 1e-15);
    EXPECT_NEAR(angle_diff(q[3], turned[1]), 0, 1e-9);
  }
}

// §2, hybrid: ‖h̄‖ is ortho's first coordinate (identical red isolines, Figure 1), and
// Equations (5) and (6), ωi = h + k and ωo = h − k, with h and k rebuilt from the coordinates as in
// the appendix: h = (‖h̄‖ cos φh, ‖h̄‖ sin φh, √(1 − ‖k‖² − ‖h̄‖²)), k = ‖k‖ (sin θk cos φk,
// sin θk sin φk, cos θk), and h·k = ‖h̄‖‖k‖ sin θk cos(φh − φk) + (h·n)‖k‖ cos θk = 0. Hold (θk from
// the quadrant-correct form; PrintedThetaKFormulaSwapsThePairWhenKbarPointsAlongHbar tests the
// printed one).
TEST(PaperClaims, HybridInverseFromTheAppendixHolds) {
  for (const auto& p : generic_pairs(20000, 8)) {
    const Tuple4<double> q = Hybrid::forward(p);
    EXPECT_EQ(q[0], Ortho::forward(p)[0]);
    const double hz = std::sqrt(1 - q[2] * q[2] - q[0] * q[0]);
    EXPECT_NEAR(hz, half_vector(p).z, 1e-9);
    const V h{q[0] * std::cos(q[1]), q[0] * std::sin(q[1]), hz};
    const double c = q[0] * std::cos(q[1] - q[3]);
    const double theta_k = std::atan2(hz, -c);
    EXPECT_NEAR(
        q[0] * q[2] * std::sin(theta_k) * std::cos(q[1] - q[3]) + hz * q[2] * std::cos(theta_k), 0,
        1e-14);
    const V k = scale(q[2], spherical_dir(theta_k, q[3]));
    const double tol = 1e-12 / hz;  // hz = √(…) amplifies rounding by 1/hz
    EXPECT_LE(dist(add(h, k), p.wi), tol);
    EXPECT_LE(dist(sub(h, k), p.wo), tol);
  }
}

// Appendix: θk = tan⁻¹(−√(1 − ‖k‖² − ‖h̄‖²) / (‖h̄‖ cos(φh − φk))). The tangent is right, but
// tan⁻¹ returns (−90°, 90°) while θk ∈ [0°, 180°] (sin θk ≥ 0, since φk is k̄'s azimuth). The
// printed θk is right only when cos(φk − φh) < 0; when it is > 0 it gives θk − π, i.e. −k, and the
// inverse returns the pair swapped. Counter-example: ωi = (0.6, 0, 0.8), ωo = n.
TEST(PaperClaims, PrintedThetaKFormulaSwapsThePairWhenKbarPointsAlongHbar) {
  auto printed_pair = [](const Tuple4<double>& q) {
    const double hz = std::sqrt(1 - q[2] * q[2] - q[0] * q[0]);
    const double theta_k = std::atan(-hz / (q[0] * std::cos(q[1] - q[3])));
    const V h{q[0] * std::cos(q[1]), q[0] * std::sin(q[1]), hz};
    const V k = scale(q[2], spherical_dir(theta_k, q[3]));
    return DirPair<double>{add(h, k), sub(h, k)};
  };
  int along = 0, against = 0;
  for (const auto& p : generic_pairs(20000, 9)) {
    const Tuple4<double> q = Hybrid::forward(p);
    const double c = std::cos(q[3] - q[1]);
    if (std::abs(c) < 1e-3 || std::abs(p.wi.z - p.wo.z) < 1e-3) continue;
    const DirPair<double> r = printed_pair(q);
    const double tol = 1e-11 / half_vector(p).z;
    const double err = test::max_abs_diff(r, p), err_swapped = test::max_abs_diff(r, {p.wo, p.wi});
    if (c < 0) {
      ++against;
      EXPECT_LE(err, tol);
    } else {
      ++along;
      EXPECT_LE(err_swapped, tol);
      EXPECT_GT(err, 1e-3);
    }
  }
  EXPECT_GT(along, 5000);
  EXPECT_GT(against, 5000);
  // The counter-example: h̄ = (0.3, 0), k = (0.3, 0, −0.1), θk = 108.43°; printed −71.57°.
  const DirPair<double> p{{0.6, 0, 0.8}, {0, 0, 1}};
  const Tuple4<double> q = Hybrid::forward(p);
  EXPECT_NEAR(std::atan(-0.9 / 0.3), -71.565 * kDeg, 1e-5);
  const DirPair<double> r = printed_pair(q);
  EXPECT_LE(test::max_abs_diff(r, {p.wo, p.wi}), 1e-14);  // (n, (0.6, 0, 0.8)): swapped
}

// §2 (Figure 1, hybrid): ‖k‖'s isolines are concentric around the back direction ωi = ωo, like
// halfdiff's θd, with a different spacing. Exactly: ‖k‖² = (1 − ωi·ωo)/2 = sin²θd, so ‖k‖ depends
// only on the angle between ωi and ωo, and its level sets are θd's. Holds.
TEST(PaperClaims, HybridKIsSinThetaDAndConcentricAroundTheBackDirection) {
  for (const auto& p : generic_pairs(20000, 10)) {
    const double k = Hybrid::forward(p)[2];
    EXPECT_NEAR(k, std::sin(HalfDiff::forward(p)[2]), 1e-12);
    EXPECT_NEAR(k * k, (1 - detail::dot(p.wi, p.wo)) / 2, 1e-15);
  }
  // Turning ωi about ωo (Rodrigues) keeps ‖k‖: a circle of ωi around ωo is an isoline.
  const V wo = spherical_dir(0.7, 0.3), wi = spherical_dir(0.4, 2.0);
  const double k0 = Hybrid::forward(DirPair<double>{wi, wo})[2];
  for (double a = 0.1; a < kTwoPiD; a += 0.37) {
    const double c = std::cos(a), s = std::sin(a), d = detail::dot(wo, wi);
    const V cross{wo.y * wi.z - wo.z * wi.y, wo.z * wi.x - wo.x * wi.z, wo.x * wi.y - wo.y * wi.x};
    const V turned = add(add(scale(c, wi), scale(s, cross)), scale((1 - c) * d, wo));
    EXPECT_NEAR(Hybrid::forward(DirPair<double>{turned, wo})[2], k0, 1e-15);
  }
}

// --- Section 3 --------------------------------------------------------------------------------

// §3: "ortho and hybrid are identical at φk = 90°, because k then lies in the tangent plane".
// Holds on the slice φk − φh = ±90° (the paper fixes φh = 0); already decided on 10⁵ tuples by
// Identities.OrthoEqualsHybridOnTheNinetyDegreeSlice. Off that slice they differ: at
// (½, 90°, ½, 90°), i.e. Δφ = 0, hybrid's ‖k̄‖ is √(1/6) = 0.408, not ½.
TEST(PaperClaims, OrthoAndHybridDifferOffTheNinetyDegreeSlice) {
  const Tuple4<double> q{0.5, kPi / 2, 0.5, kPi / 2};
  const Solved<double> hy = inverse<Hybrid>(q), ov = inverse<Ortho>(q);
  ASSERT_TRUE(hy.in_domain && ov.in_domain);
  EXPECT_NEAR(Ortho::forward(hy.pair)[2], std::sqrt(1.0 / 6), 1e-15);
  EXPECT_GT(test::max_abs_diff(hy.pair, ov.pair), 0.05);
  EXPECT_GT(std::abs(hy.pair.wi.z - hy.pair.wo.z), 0.1) << "k is not in the tangent plane";
}

// §3: in ortho, F's isolines (fixed ‖k‖, since cos θd = √(1 − ‖k‖²)) "bend toward the
// anti-diagonal" when φk departs from 90°. Exactly: ‖k̄‖² = ‖k‖² H / (H + c²) with
// H = 1 − ‖h̄‖² − ‖k‖², c = ‖h̄‖ cos Δφ, so along an F isoline ‖k̄‖ falls as ‖h̄‖ grows unless
// cos Δφ = 0, where ‖k̄‖ = ‖k‖ (a horizontal line). Holds.
TEST(PaperClaims, FresnelIsolinesBendInOrthoAwayFromNinetyDegrees) {
  const double k = 0.5;
  for (double dphi_deg : {0.0, 30.0, 60.0, 85.0, 90.0, 120.0, 180.0}) {
    double previous = k + 1e-12;
    int points = 0;
    for (double hbar = 0.02; hbar < 0.86; hbar += 0.02, ++points) {
      const Solved<double> s = inverse<Hybrid>(Tuple4<double>{hbar, 0, k, dphi_deg * kDeg});
      if (!s.in_domain) break;  // past the domain's edge for this Δφ
      EXPECT_NEAR(std::cos(HalfDiff::forward(s.pair)[2]), std::sqrt(1 - k * k), 1e-12);
      const double kbar = Ortho::forward(s.pair)[2];
      if (dphi_deg == 90.0) {
        EXPECT_NEAR(kbar, k, 1e-12);
      } else {
        EXPECT_LT(kbar, previous - 1e-6) << "Δφ " << dphi_deg << ", ‖h̄‖ " << hbar;
      }
      previous = kbar;
    }
    EXPECT_GE(points, 10) << dphi_deg;
  }
}

// §3: "‖h̄‖² = sin θh cos θd". False: the squares are missing on the right; ‖h̄‖ = sin θh cos θd,
// which the appendix's own ‖h̄‖² = (1 − cos²θh)(1 − sin²θd) says. Counter-example: ωi = ωo at 30°
// (θh = 30°, θd = 0): ‖h̄‖² = ¼, sin θh cos θd = ½. Also the appendix's
// cos²θh = (1 − ‖h̄‖² − ‖k‖²)/(1 − ‖k‖²), which holds.
TEST(PaperClaims, HbarIsSinThetaHCosThetaDNotItsSquare) {
  const V w = spherical_dir(30 * kDeg, 1.0);
  const DirPair<double> retro{w, w};
  const Tuple4<double> hd = HalfDiff::forward(retro), hy = Hybrid::forward(retro);
  EXPECT_NEAR(hd[0], 30 * kDeg, 1e-15);
  EXPECT_NEAR(hd[2], 0, 1e-15);
  EXPECT_NEAR(hy[0] * hy[0], 0.25, 1e-15);
  EXPECT_NEAR(std::sin(hd[0]) * std::cos(hd[2]), 0.5, 1e-15);
  for (const auto& p : generic_pairs(20000, 11)) {
    const Tuple4<double> h = HalfDiff::forward(p), y = Hybrid::forward(p);
    const double sh = std::sin(h[0]), ch = std::cos(h[0]), sd = std::sin(h[2]), cd = std::cos(h[2]);
    EXPECT_NEAR(y[0], sh * cd, 1e-12);
    EXPECT_NEAR(y[0] * y[0], (1 - ch * ch) * (1 - sd * sd), 1e-12);
    EXPECT_NEAR(ch * ch, (1 - y[0] * y[0] - y[2] * y[2]) / (1 - y[2] * y[2]), 1e-9);
  }
}

// §3: S = 1 − ‖h̄‖ is distorted in halfdiff "independently of φd": ‖h̄‖ = sin θh cos θd depends on
// θd at fixed θh, and not at all on φd. Holds.
TEST(PaperClaims, HbarDoesNotDependOnPhiD) {
  for (double theta_h : {0.2, 0.6, 1.0}) {
    for (double theta_d : {0.1, 0.4}) {
      double first = -1;
      for (double phi_d = 0; phi_d < kTwoPiD; phi_d += 0.3) {
        const Solved<double> s = inverse<HalfDiff>(Tuple4<double>{theta_h, 0.4, theta_d, phi_d});
        ASSERT_TRUE(s.in_domain);
        const double hbar = Hybrid::forward(s.pair)[0];
        if (first < 0) first = hbar;
        EXPECT_NEAR(hbar, first, 1e-14);
      }
      EXPECT_NEAR(first, std::sin(theta_h) * std::cos(theta_d), 1e-14);
    }
  }
}

// §3 and appendix: (ωi·n)(ωo·n) = (h·n)² − (k·n)² = 1 − ‖h̄‖² − ‖k‖²(1 + cos²θk). Holds for every
// pair (the earlier erratum of docs/math.md read it without the cos²θk term). On the slice
// φk − φh = ±90°, θk = 90°, so 1 − G = 1 − ‖h̄‖² − ‖k‖² there: circular isolines of G in
// (‖h̄‖, ‖k‖), and in (‖h̄‖, ‖k̄‖) since ‖k̄‖ = ‖k‖ there.
TEST(PaperClaims, GrazingIdentityOfTheAppendixHolds) {
  for (const auto& p : generic_pairs(20000, 12)) {
    const Tuple4<double> q = Hybrid::forward(p);
    const V k = back_vector(p);
    const double cos_theta_k = k.z / q[2];
    const double hz = half_vector(p).z;
    EXPECT_NEAR(grazing_product(p), hz * hz - k.z * k.z, 1e-15);
    EXPECT_NEAR(grazing_product(p), 1 - q[0] * q[0] - q[2] * q[2] * (1 + cos_theta_k * cos_theta_k),
                1e-14);
  }
  for (double dphi : {kPi / 2, 3 * kPi / 2}) {
    for (double hbar = 0.05; hbar < 1; hbar += 0.1) {
      for (double k = 0.05; hbar * hbar + k * k < 1; k += 0.1) {
        const Solved<double> s = inverse<Hybrid>(Tuple4<double>{hbar, 0, k, dphi});
        ASSERT_TRUE(s.in_domain);
        EXPECT_NEAR(s.pair.wi.z - s.pair.wo.z, 0, 1e-14) << "θk = 90°";
        EXPECT_NEAR(grazing_product(s.pair), 1 - hbar * hbar - k * k, 1e-15);
        EXPECT_NEAR(Ortho::forward(s.pair)[2], k, 1e-15);
      }
    }
  }
}

// §3 and appendix: "φk = φh + φd". False: d̄ is tilted by rot_b(θh) before the turn by φh, so
// φk − φh = atan2(sin φd, cos θh cos φd). It holds when θh = 0 or φd ∈ {0°, 90°, 180°, 270°}.
// Counter-example: θh = 60°, φd = 45° gives φk − φh = atan2(1, ½) = 63.43°.
TEST(PaperClaims, AzimuthRelationPhiKEqualsPhiHPlusPhiDIsFalse) {
  double worst_printed = 0;
  for (const auto& p : generic_pairs(20000, 13)) {
    const Tuple4<double> hd = HalfDiff::forward(p), hy = Hybrid::forward(p);
    if (std::sin(hd[2]) < 1e-3) continue;  // φd undefined at θd = 0
    const double corrected = hd[1] + std::atan2(std::sin(hd[3]), std::cos(hd[0]) * std::cos(hd[3]));
    EXPECT_NEAR(angle_diff(hy[3], corrected), 0, 1e-8);
    worst_printed = std::max(worst_printed, angle_diff(hy[3], hd[1] + hd[3]));
  }
  EXPECT_GT(worst_printed, 0.5);
  const Solved<double> s = inverse<HalfDiff>(Tuple4<double>{60 * kDeg, 0, 20 * kDeg, 45 * kDeg});
  ASSERT_TRUE(s.in_domain);
  EXPECT_NEAR(Hybrid::forward(s.pair)[3], std::atan2(1.0, 0.5), 1e-12);
  EXPECT_NEAR(std::atan2(1.0, 0.5) / kDeg, 63.435, 1e-3);
  // Where it holds: θh = 0, or φd a multiple of 90°.
  for (double phi_d : {0.3, 1.9, 4.0}) {
    const Solved<double> flat = inverse<HalfDiff>(Tuple4<double>{0, 0, 0.5, phi_d});
    EXPECT_NEAR(angle_diff(Hybrid::forward(flat.pair)[3], phi_d), 0, 1e-12);
  }
  for (double phi_d : {0.5 * kPi, kPi, 1.5 * kPi}) {
    const Solved<double> on_axis = inverse<HalfDiff>(Tuple4<double>{0.7, 0.2, 0.3, phi_d});
    EXPECT_NEAR(angle_diff(Hybrid::forward(on_axis.pair)[3], 0.2 + phi_d), 0, 1e-12);
  }
}

// §3: "any slice in the hybrid parametrization corresponds to a warped slice in the half/difference
// parametrization". False except at Δφ ∈ {0°, 90°, 180°, 270°}: the hybrid slice Δφ = 45° holds
// pairs whose φd spans tan φd = cos θh tan Δφ, here from 45° down to 14°.
TEST(PaperClaims, HybridSlicesAreHalfDiffSlicesOnlyAtMultiplesOfNinetyDegrees) {
  for (double dphi_deg : {0.0, 45.0, 90.0, 180.0, 270.0}) {
    double lo = 10, hi = -10;
    for (double hbar = 0.0; hbar < 0.96; hbar += 0.05) {
      const Solved<double> s = inverse<Hybrid>(Tuple4<double>{hbar, 0, 0.2, dphi_deg * kDeg});
      ASSERT_TRUE(s.in_domain);
      const Tuple4<double> hd = HalfDiff::forward(s.pair);
      const double expected =
          std::atan2(std::cos(hd[0]) * std::sin(dphi_deg * kDeg), std::cos(dphi_deg * kDeg));
      EXPECT_NEAR(angle_diff(hd[3], expected), 0, 1e-12);
      lo = std::min(lo, hd[3]);
      hi = std::max(hi, hd[3]);
    }
    if (dphi_deg == 45.0)
      EXPECT_GT(hi - lo, 20 * kDeg);
    else
      EXPECT_LT(angle_diff(hi, lo), 1e-12) << dphi_deg;
  }
}

// --- Appendix ---------------------------------------------------------------------------------

// ‖h‖² = (1 + ωi·ωo)/2, ‖k‖² = (1 − ωi·ωo)/2 (their sum 1 and h·k = 0 are decided by
// Identities.HalfAndDifferenceVectors), h in polar form (‖h̄‖ cos φh, ‖h̄‖ sin φh, h·n) with
// h·n = √(1 − ‖k‖² − ‖h̄‖²), and cos θd = ωi·ĥ = (1 + ωi·ωo)/(2‖h‖) = ‖h‖ = √(1 − ‖k‖²). Hold.
TEST(PaperClaims, AppendixNormsAndCosThetaDChainHold) {
  for (const auto& p : generic_pairs(20000, 14)) {
    const V h = half_vector(p), k = back_vector(p);
    const double c = detail::dot(p.wi, p.wo);
    EXPECT_NEAR(detail::dot(h, h), (1 + c) / 2, 1e-15);
    EXPECT_NEAR(detail::dot(k, k), (1 - c) / 2, 1e-15);
    const Tuple4<double> y = Hybrid::forward(p), hd = HalfDiff::forward(p);
    EXPECT_NEAR(h.x, y[0] * std::cos(y[1]), 1e-15);
    EXPECT_NEAR(h.y, y[0] * std::sin(y[1]), 1e-15);
    EXPECT_NEAR(h.z, std::sqrt(std::max(0.0, 1 - y[2] * y[2] - y[0] * y[0])),
                1e-15 / std::max(h.z, 1e-8));
    const V hhat = scale(1 / norm(h), h);
    const double cos_d = std::cos(hd[2]);
    EXPECT_NEAR(cos_d, detail::dot(p.wi, hhat), 1e-12);
    EXPECT_NEAR(cos_d, (1 + c) / (2 * norm(h)), 1e-12);
    EXPECT_NEAR(cos_d, norm(h), 1e-12);
    EXPECT_NEAR(cos_d, std::sqrt(1 - y[2] * y[2]), 1e-12);
  }
}

// Appendix: k = ωi − ĥ‖h‖ = rot_n(φh) rot_b(θh) (d̂ − n(n·d̂)) = rot_n(φh) rot_b(θh) d̄. Holds.
TEST(PaperClaims, BackVectorIsTheRotatedPlanarDifferenceVector) {
  for (const auto& p : generic_pairs(20000, 15)) {
    const Tuple4<double> q = HalfDiff::forward(p);
    const V d = spherical_dir(q[2], q[3]);
    const V dbar{d.x, d.y, 0};
    const V k = back_vector(p);
    const V h = half_vector(p);
    EXPECT_LE(dist(k, sub(p.wi, scale(norm(h), spherical_dir(q[0], q[1])))), 1e-12);
    EXPECT_LE(dist(k, rot_n(q[1], rot_b(q[0], dbar))), 1e-12);
  }
}

// Domain (not stated by the paper): not every tuple of the coordinate box is a pair. Ortho needs
// ‖h̄ ± k̄‖ ≤ 1, hybrid ‖h̄‖² + ‖k‖² ≤ 1 and |kz| ≤ h·n (docs/math.md §3; decided on 10⁶ tuples
// by ParamTest.DomainPredicateAgreesWithInverseElevations).
TEST(PaperClaims, CoordinateBoxIsLargerThanTheDomain) {
  EXPECT_FALSE((valid<Ortho>(Tuple4<double>{0.6, 0, 0.6, 0})));         // ‖h̄ + k̄‖ = 1.2
  EXPECT_TRUE((valid<Ortho>(Tuple4<double>{0.6, 0, 0.6, kPi / 2})));    // ‖h̄ ± k̄‖ = 0.85
  EXPECT_FALSE((valid<Hybrid>(Tuple4<double>{0.8, 0, 0.7, kPi / 2})));  // ‖h̄‖² + ‖k‖² > 1
  EXPECT_FALSE((valid<Hybrid>(Tuple4<double>{0.7, 0, 0.7, 0.1})));      // |kz| > h·n
  EXPECT_FALSE((valid<HalfDiff>(Tuple4<double>{1.2, 0, 1.0, 0})));  // θh + θd > 90° at φd = 0
  EXPECT_TRUE((valid<HalfDiff>(Tuple4<double>{1.2, 0, 1.0, kPi / 2})));  // but fine at φd = 90°
}

}  // namespace
}  // namespace halfback
