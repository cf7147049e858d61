// The study's metrics on functions whose answers are known exactly.
#include "halfback/study/metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "halfback/loader/load.hpp"
#include "support/test_brdfs.hpp"

namespace halfback::study {
namespace {

using acquire::ErrorSpace;
using acquire::IsoGrid;
using acquire::IsoSamples;
using acquire::kErrorSpaces;
using acquire::parse_error_space;
using acquire::sample_isotropic;
using acquire::to_error_space;

using Fn = test::FunctionBrdf;

double hbar_of(const DirPair<double>& p) {
  return std::hypot(p.wi.x + p.wo.x, p.wi.y + p.wo.y) / 2;
}
double k_of(const DirPair<double>& p) {
  return std::sqrt((p.wi.x - p.wo.x) * (p.wi.x - p.wo.x) + (p.wi.y - p.wo.y) * (p.wi.y - p.wo.y) +
                   (p.wi.z - p.wo.z) * (p.wi.z - p.wo.z)) /
         2;
}
double theta_h_of(const DirPair<double>& p) {
  return std::atan2(hbar_of(p), (p.wi.z + p.wo.z) / 2);
}

const IsoGrid kGrid{24, 24, 32};

TEST(Azimuthal, ZeroWhereTheBrdfDependsOnTheTwoMagnitudesOnly) {
  // A function of (‖h̄‖, ‖k‖): no azimuthal dependence in hybrid, some in the others.
  const Fn f([](const DirPair<double>& p) { return 1 + 3 * hbar_of(p) * hbar_of(p) + k_of(p); });
  EXPECT_LT(azimuthal_error(sample_isotropic(f, space_of<Hybrid>, kGrid, ErrorSpace::linear)),
            1e-12);
  EXPECT_GT(azimuthal_error(sample_isotropic(f, space_of<Ortho>, kGrid, ErrorSpace::linear)), 1e-3);
  // A function of θh alone: none in halfdiff, and none in hybrid either (θh is a function of
  // ‖h̄‖ and ‖k‖: h_z = √(1 − ‖k‖² − ‖h̄‖²)); some in ortho, whose ‖k̄‖ leaves h_z to φ.
  const Fn g([](const DirPair<double>& p) { return std::exp(-8 * theta_h_of(p)); });
  for (ErrorSpace es : {ErrorSpace::linear, ErrorSpace::log, ErrorSpace::cbrt}) {
    EXPECT_LT(azimuthal_error(sample_isotropic(g, space_of<HalfDiff>, kGrid, es)), 1e-12);
    EXPECT_LT(azimuthal_error(sample_isotropic(g, space_of<Hybrid>, kGrid, es)), 1e-12);
    EXPECT_GT(azimuthal_error(sample_isotropic(g, space_of<Ortho>, kGrid, es)), 1e-3);
  }
}

TEST(Azimuthal, DependsOnTheAzimuthWhenTheBrdfDoes) {
  // ρ ∝ (1 + ωi·ωo)² depends on θd alone (cos θd = ‖h‖): halfdiff sees no azimuthal dependence.
  const Fn f([](const DirPair<double>& p) {
    const double c = p.wi.x * p.wo.x + p.wi.y * p.wo.y + p.wi.z * p.wo.z;
    return (1 + c) * (1 + c);
  });
  EXPECT_LT(azimuthal_error(sample_isotropic(f, space_of<HalfDiff>, kGrid, ErrorSpace::linear)),
            1e-12);
  // ‖k‖² = (1 − ωi·ωo)/2: a function of ‖k‖ alone, so none in hybrid either.
  EXPECT_LT(azimuthal_error(sample_isotropic(f, space_of<Hybrid>, kGrid, ErrorSpace::linear)),
            1e-12);
  // The product cos θi cos θo does depend on φ in every parameterization.
  const Fn g([](const DirPair<double>& p) { return p.wi.z * p.wo.z; });
  for (Space s : {space_of<HalfDiff>, space_of<Ortho>, space_of<Hybrid>})
    EXPECT_GT(azimuthal_error(sample_isotropic(g, s, kGrid, ErrorSpace::linear)), 1e-2)
        << name_of(s);
}

TEST(Separability, RankOneFunctionsHaveZeroRankOneError) {
  // f(θh) g(θd) is of rank 1 in halfdiff's (θh, θd), on whatever domain the slice has.
  const Fn f([](const DirPair<double>& p) {
    const double c = p.wi.x * p.wo.x + p.wi.y * p.wo.y + p.wi.z * p.wo.z;
    const double theta_d = std::acos(std::clamp(std::sqrt((1 + c) / 2), -1.0, 1.0));
    return std::exp(-4 * theta_h_of(p)) * (1 + std::cos(3 * theta_d));
  });
  const IsoSamples s = sample_isotropic(f, space_of<HalfDiff>, kGrid, ErrorSpace::linear);
  const auto e = separability_2d(s, {0, 1, 2});
  EXPECT_DOUBLE_EQ(e[0], 1.0);
  EXPECT_LT(e[1], 1e-6);
  EXPECT_LT(e[2], 1e-6);
  // The 3D table has no azimuthal dependence: the unfolding is of rank 1 too.
  EXPECT_LT(separability_unfolded(s, {1})[0], 1e-6);
  // A sum of two separable terms: rank 2, not 1.
  const Fn g([](const DirPair<double>& p) {
    const double c = p.wi.x * p.wo.x + p.wi.y * p.wo.y + p.wi.z * p.wo.z;
    const double theta_d = std::acos(std::clamp(std::sqrt((1 + c) / 2), -1.0, 1.0));
    return std::exp(-4 * theta_h_of(p)) + theta_d * theta_d;
  });
  const auto e2 =
      separability_2d(sample_isotropic(g, space_of<HalfDiff>, kGrid, ErrorSpace::linear), {1, 2});
  EXPECT_GT(e2[0], 1e-3);
  EXPECT_LT(e2[1], 1e-6);
}

TEST(Measure, WeightsIntegrateTheProjectedSolidAngleMeasure) {
  // ∫∫ cos θi cos θo dωi dωo = π²: the weights are a quadrature of that measure in every
  // parameterization (midpoint rule on a 64³ grid: a few per cent at the integrable
  // singularities of the Jacobians).
  const Fn one([](const DirPair<double>&) { return 1.0; });
  const double pi2 = std::numbers::pi * std::numbers::pi;
  for (Space s : kKernelSpaces) {
    const IsoSamples x = sample_isotropic(one, s, {64, 64, 64}, ErrorSpace::linear);
    EXPECT_NEAR(x.total_weight() / pi2, 1.0, 0.03) << name_of(s);
  }
}

TEST(Metrics, BadInput) {
  const Fn one([](const DirPair<double>&) { return 1.0; });
  EXPECT_THROW(sample_isotropic(one, Space::dirs, kGrid, ErrorSpace::linear),
               std::invalid_argument);
  EXPECT_THROW(sample_isotropic(one, space_of<Hybrid>, {0, 4, 4}, ErrorSpace::linear),
               std::invalid_argument);
  const IsoSamples x = sample_isotropic(one, space_of<Hybrid>, kGrid, ErrorSpace::linear);
  EXPECT_THROW(separability_2d(x, {-1}), std::invalid_argument);
}

TEST(Metrics, ErrorSpacesMatchTheirDefinitions) {
  EXPECT_DOUBLE_EQ(to_error_space(0.5, ErrorSpace::linear, 0.3, 0.2), 0.5);
  EXPECT_DOUBLE_EQ(to_error_space(std::exp(1.0) - 1, ErrorSpace::log, 0.3, 0.2), 1.0);
  EXPECT_DOUBLE_EQ(to_error_space(8, ErrorSpace::cbrt, 0.3, 0.2), 2.0);
  // Nielsen et al. 2015: ln(1 + Y c / ε), c = cos θi cos θo, ε = 0.001; c = 0.8 · 0.5.
  EXPECT_NEAR(to_error_space(0.5, ErrorSpace::nielsen, 0.8, 0.5), std::log(201.0), 1e-12);
  // A difference of two values is their log-relative mapping ln((Y c + ε) / (Y_ref c + ε)).
  const double d = to_error_space(0.7, ErrorSpace::nielsen, 0.6, 0.9) -
                   to_error_space(0.2, ErrorSpace::nielsen, 0.6, 0.9);
  EXPECT_NEAR(d, std::log((0.7 * 0.54 + 0.001) / (0.2 * 0.54 + 0.001)), 1e-12);
  // Their code clamps c to >= 0.01 (grazing pairs): cos 0.05 · 0.1 = 0.005 counts as 0.01.
  EXPECT_NEAR(to_error_space(1, ErrorSpace::nielsen, 0.05, 0.1), std::log(11.0), 1e-12);
  // Löw et al. 2012: ln(1 + Y cos θi), whatever cos θo.
  EXPECT_NEAR(to_error_space(2, ErrorSpace::low, 0.5, 0.9), std::log(2.0), 1e-15);
  EXPECT_EQ(to_error_space(2, ErrorSpace::low, 0.5, 0.1),
            to_error_space(2, ErrorSpace::low, 0.5, 1));
  for (ErrorSpace es : kErrorSpaces) EXPECT_EQ(parse_error_space(name_of(es)), es);
  EXPECT_EQ(parse_error_space("ln"), std::nullopt);
}

TEST(Metrics, CosineErrorSpacesSeeEachPairsCosines) {
  // A constant BRDF: in the Löw space its table is ln(1 + cos θi), not a constant, so dropping
  // the azimuth of spherical (θi, θo, φ) is still exact but the 2D table is not rank 0.
  const Fn one([](const DirPair<double>&) { return 1.0; });
  const IsoSamples s = sample_isotropic(one, space_of<Spherical>, kGrid, ErrorSpace::low);
  EXPECT_LT(azimuthal_error(s), 1e-12);
  // θi is the first axis: each row of the table is ln(1 + cos θi) at its cell centre.
  const double theta = (0.5 + 3) * (std::numbers::pi / 2) / double(kGrid.a);
  const std::size_t p = (3 * kGrid.b + 5) * kGrid.phi + 2;
  ASSERT_GT(s.weight[p], 0);
  EXPECT_NEAR(s.value[p], std::log1p(std::cos(theta)), 1e-12);
}

}  // namespace
}  // namespace halfback::study
