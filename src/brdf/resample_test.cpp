// Resampling onto grids of the parameterizations, and the table files (.exr, .npy; the .npz is
// read back by NumPy itself in tests/python/test_brdf_cli.py).
#include "halfback/brdf/resample.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <sstream>

#include "halfback/brdf/test_functions.hpp"
#include "halfback/core/batch.hpp"
#include "support/test_brdfs.hpp"
#include "support/test_support.hpp"

namespace halfback {
namespace {

constexpr double kPi = std::numbers::pi;

using test::Smooth;

// The coordinates of grid point `flat` (row-major, last axis fastest), the slice azimuth added.
std::vector<double> coords_of(const GridSpec& g, std::size_t flat) {
  std::vector<double> x(g.axes.size());
  for (std::size_t a = g.axes.size(); a-- > 0;) {
    x[a] = g.axes[a].position(flat % g.axes[a].count, g.sampling);
    flat /= g.axes[a].count;
  }
  if (g.kind == GridKind::slice) x.push_back(g.slice_azimuth);
  return x;
}

TEST(Resample, EveryPointIsTheBrdfAtTheCheckedInverse) {
  const Smooth brdf;
  for (Space s : kKernelSpaces) {
    for (GridKind kind : {GridKind::full, GridKind::isotropic, GridKind::slice}) {
      const std::size_t n = kind == GridKind::full ? 7 : kind == GridKind::isotropic ? 11 : 23;
      GridSpec g = default_grid(s, kind, {n}, 1.1);
      for (GridSampling sampling : {GridSampling::centres, GridSampling::nodes}) {
        g.sampling = sampling;
        const ResampledTable t = resample(brdf, g);
        ASSERT_EQ(t.rgb.size(), 3 * g.points());
        std::size_t valid = 0;
        for (std::size_t p = 0; p < g.points(); ++p) {
          const auto x = coords_of(g, p);
          std::array<double, 6> d{};
          const bool ok = convert_one<double>(g.form(), {Space::dirs, false}, x, d);
          ASSERT_EQ(bool(t.valid[p]), ok) << name_of(s) << " " << name_of(kind) << " point " << p;
          if (!ok) {
            EXPECT_TRUE(std::isnan(t.rgb[3 * p]) && std::isnan(t.rgb[3 * p + 2]));
            continue;
          }
          ++valid;
          const Rgb ref = brdf.eval(DirPair<double>{{d[0], d[1], d[2]}, {d[3], d[4], d[5]}});
          // The batch inverse (SIMD math) and convert_one agree to a few ulps, except for ortho
          // at the horizon, where z = √(1 − ‖ω̄‖²) is known to √ε only (docs/math.md).
          const double tol = std::min(d[2], d[5]) < 1e-7 ? 1e-7 : 1e-12;
          EXPECT_NEAR(t.rgb[3 * p], ref.r, tol) << name_of(s) << " " << name_of(kind);
          EXPECT_NEAR(t.rgb[3 * p + 1], ref.g, tol) << name_of(s) << " " << name_of(kind);
          EXPECT_NEAR(t.rgb[3 * p + 2], ref.b, tol) << name_of(s) << " " << name_of(kind);
        }
        EXPECT_EQ(valid, t.valid_count());
        // Every grid has points on both sides of the domain boundary.
        EXPECT_GT(valid, 0u) << name_of(s) << " " << name_of(kind);
        if (s != space_of<Spherical>) {
          EXPECT_LT(valid, g.points()) << name_of(s);
        }
      }
    }
  }
}

// Closed forms on the paper's slices, computed here from the coordinates alone:
// S = 1 − ‖h̄‖ on ortho and hybrid slices; F = 1 − cos θd on halfdiff slices.
TEST(Resample, SlicesOfTheTestFunctionsMatchTheirClosedForms) {
  const TestFunctionBrdf specular(TestFunction::specular), fresnel(TestFunction::fresnel);
  for (double az_deg : {0.0, 45.0, 90.0}) {
    for (Space s : {space_of<Ortho>, space_of<Hybrid>}) {
      const GridSpec g = default_grid(s, GridKind::slice, {64}, az_deg * kPi / 180);
      const ResampledTable t = resample(specular, g);
      for (std::size_t p = 0; p < g.points(); ++p) {
        if (!t.valid[p]) continue;
        const double hbar = g.axes[0].position(p / 64, g.sampling);
        EXPECT_NEAR(t.rgb[3 * p], 1 - hbar, 1e-12);
      }
    }
    const GridSpec g = default_grid(space_of<HalfDiff>, GridKind::slice, {64}, az_deg * kPi / 180);
    const ResampledTable t = resample(fresnel, g);
    for (std::size_t p = 0; p < g.points(); ++p) {
      if (!t.valid[p]) continue;
      const double theta_d = g.axes[1].position(p % 64, g.sampling);
      EXPECT_NEAR(t.rgb[3 * p], 1 - std::cos(theta_d), 1e-12);
    }
  }
}

// A halfdiff slice at φd = 90° is valid exactly where θh ≤ π/2 and θd ≤ π/2 with
// cos θi, cos θo ≥ 0: at φd = 90° the difference vector is along b, so z = cos θh cos θd for both
// directions and the whole square is valid; at φd = 0, z = cos(θh ± θd), valid iff θh + θd ≤ π/2.
TEST(Resample, HalfdiffSliceDomainsHaveTheirClosedForm) {
  const TestFunctionBrdf g_fn(TestFunction::grazing);
  const GridSpec g90 = default_grid(space_of<HalfDiff>, GridKind::slice, {40}, kPi / 2);
  EXPECT_EQ(resample(g_fn, g90).valid_count(), g90.points());
  const GridSpec g0 = default_grid(space_of<HalfDiff>, GridKind::slice, {40}, 0);
  const ResampledTable t0 = resample(g_fn, g0);
  for (std::size_t p = 0; p < g0.points(); ++p) {
    const double th = g0.axes[0].position(p / 40, g0.sampling);
    const double td = g0.axes[1].position(p % 40, g0.sampling);
    if (std::abs(th + td - kPi / 2) < 1e-9) continue;  // on the boundary: either way by rounding
    EXPECT_EQ(bool(t0.valid[p]), th + td < kPi / 2) << th << " " << td;
  }
}

TEST(Resample, SamplePositions) {
  GridAxis a{"x", 0, 1, 4};
  EXPECT_DOUBLE_EQ(a.position(0, GridSampling::centres), 0.125);
  EXPECT_DOUBLE_EQ(a.position(3, GridSampling::centres), 0.875);
  EXPECT_EQ(a.position(0, GridSampling::nodes), 0);
  EXPECT_EQ(a.position(3, GridSampling::nodes), 1);
  GridAxis phi{"phi", 0, 2 * kPi, 7};
  EXPECT_EQ(phi.position(6, GridSampling::nodes), 2 * kPi);
  GridAxis one{"x", 0.3, 0.3, 1};
  EXPECT_EQ(one.position(0, GridSampling::nodes), 0.3);
}

TEST(Resample, DefaultGridsAndValidation) {
  const GridSpec g = default_grid(space_of<Hybrid>, GridKind::isotropic, {4, 5, 6});
  ASSERT_EQ(g.axes.size(), 3u);
  EXPECT_EQ(g.axes[0].name, "hbar");
  EXPECT_EQ(g.axes[1].name, "k");
  EXPECT_EQ(g.axes[2].name, "dphi");
  EXPECT_EQ(g.axes[2].hi, 2 * kPi);
  EXPECT_EQ(g.points(), 120u);
  const GridSpec f = default_grid(space_of<HalfDiff>, GridKind::full, {3});
  EXPECT_EQ(f.axes[0].name, "theta_h");
  EXPECT_EQ(f.axes[0].hi, kPi / 2);
  EXPECT_EQ(f.axes[1].name, "phi_h");
  EXPECT_EQ(f.points(), 81u);
  const GridSpec s = default_grid(space_of<Ortho>, GridKind::slice, {8});
  ASSERT_EQ(s.axes.size(), 2u);
  EXPECT_EQ(s.axes[1].name, "kbar");

  auto message = [](auto f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([] { default_grid(Space::dirs, GridKind::full, {4}); }).find("dirs"),
            std::string::npos);
  EXPECT_NE(message([] {
              default_grid(space_of<Hybrid>, GridKind::full, {4, 4});
            }).find("4 axes"),
            std::string::npos);
  EXPECT_NE(
      message([] { default_grid(space_of<Hybrid>, GridKind::slice, {0}); }).find("no samples"),
      std::string::npos);
  GridSpec bad = g;
  bad.axes[1].lo = 2, bad.axes[1].hi = 1;
  EXPECT_NE(message([&] { validate(bad); }).find("lo <= hi"), std::string::npos);
  bad = g;
  bad.axes[0].hi = NAN;
  EXPECT_NE(message([&] { validate(bad); }).find("finite"), std::string::npos);
  bad = g;
  bad.axes[0].name = "theta_h";
  EXPECT_NE(message([&] { validate(bad); }).find("'theta_h'"), std::string::npos);
  EXPECT_NE(message([] { default_grid(space_of<Hybrid>, GridKind::full, {400}); }).find("2^26"),
            std::string::npos);
  // 91^4 = 68574961 points is just above the limit, 90^4 = 65610000 just below it.
  EXPECT_NE(message([] { default_grid(space_of<Hybrid>, GridKind::full, {91}); }).find("1.7 GB"),
            std::string::npos);
  EXPECT_NO_THROW(validate(default_grid(space_of<Hybrid>, GridKind::full, {90})));
}

TEST(Resample, CoordinatesToPairs) {
  // Hybrid isotropic (‖h̄‖, ‖k‖, φ): (0, 0.6, 0) is the pair ωi = (0.6, 0, 0.8), ωo = (−0.6, 0,
  // 0.8); ‖k‖ = 1 with ‖h̄‖ = 0.5 is outside the domain.
  const std::vector<double> hbar{0, 0.5}, k{0.6, 1}, phi{0, 0};
  const std::vector<std::span<const double>> columns{hbar, k, phi};
  std::vector<DirPair<double>> pairs(2);
  std::vector<std::uint8_t> valid(2);
  coordinates_to_pairs({space_of<Hybrid>, true}, columns, pairs, valid);
  ASSERT_EQ(valid[0], 1);
  EXPECT_EQ(valid[1], 0);
  EXPECT_NEAR(pairs[0].wi.z, 0.8, 1e-12);
  EXPECT_NEAR(pairs[0].wo.z, 0.8, 1e-12);
  EXPECT_NEAR(std::abs(pairs[0].wi.x - pairs[0].wo.x), 1.2, 1e-12);
  EXPECT_TRUE(std::isnan(pairs[1].wi.z));
  // Two columns for a 3D form, or columns of the wrong length, are refused.
  EXPECT_THROW(coordinates_to_pairs({space_of<Hybrid>, true},
                                    std::vector<std::span<const double>>{hbar, k}, pairs, valid),
               std::invalid_argument);
  const std::vector<double> one{0};
  EXPECT_THROW(
      coordinates_to_pairs({space_of<Hybrid>, true},
                           std::vector<std::span<const double>>{hbar, k, one}, pairs, valid),
      std::invalid_argument);
}

TEST(Resample, ThreadCountDoesNotChangeTheBits) {
  const Smooth brdf;
  const GridSpec g = default_grid(space_of<Ortho>, GridKind::isotropic, {33, 17, 29});
  const ResampledTable a = resample(brdf, g, {1}), b = resample(brdf, g, {0});
  EXPECT_EQ(a.valid, b.valid);
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  EXPECT_EQ(std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(double)), 0);
}

// docs/reliability/numerics.md, "Azimuths are periodic": one rule for azimuths everywhere, wrap any
// finite value into [0°, 360°).
TEST(Resample, AzimuthsWrapIntoZeroTo360Degrees) {
  const std::pair<double, double> cases[] = {
      {0, 0},       {-90, 270}, {360, 0},       {400, 40},   {-45, 315},
      {720.5, 0.5}, {-360, 0},  {359.5, 359.5}, {-1e-20, 0}, {1e17, std::fmod(1e17, 360.0)}};
  for (const auto& [in, out] : cases) {
    const double w = wrap_azimuth_degrees(in, "--azimuth");
    EXPECT_EQ(w, out) << in;
    EXPECT_TRUE(w >= 0 && w < 360) << in;
  }
  for (const double bad : {std::nan(""), double(INFINITY), -double(INFINITY)}) {
    try {
      wrap_azimuth_degrees(bad, "--azimuth");
      ADD_FAILURE() << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind("--azimuth: '", 0), 0u) << e.what();
    }
  }
  for (const double r : {-1e-17, -kPi / 2, 2 * kPi, 7.0, -100.0}) {
    const double w = wrap_azimuth_radians(r);
    EXPECT_TRUE(w >= 0 && w < 2 * kPi) << r;
    EXPECT_NEAR(std::remainder(w - r, 2 * kPi), 0, 1e-13) << r;
  }
}

// A slice at −90° (or 630°) is the slice at 270°, point for point; it was all NaN (the core's
// inverse wants [0, 2π)). A hand-made GridSpec with an unwrapped azimuth is wrapped too.
TEST(Resample, SlicesAtEquivalentAzimuthsAreTheSame) {
  const Smooth brdf;
  for (Space s : kKernelSpaces) {
    const ResampledTable ref = resample(brdf, default_grid(s, GridKind::slice, {16}, 1.5 * kPi));
    ASSERT_GT(ref.valid_count(), 16u) << name_of(s);
    for (const double az : {-0.5 * kPi, 3.5 * kPi, -2.5 * kPi}) {
      const GridSpec g = default_grid(s, GridKind::slice, {16}, az);
      EXPECT_NEAR(g.slice_azimuth, 1.5 * kPi, 1e-13);
      GridSpec raw = g;
      raw.slice_azimuth = az;
      for (const GridSpec& grid : {g, raw}) {
        const ResampledTable t = resample(brdf, grid);
        ASSERT_EQ(t.valid, ref.valid) << name_of(s) << " at " << az;
        for (std::size_t i = 0; i < t.rgb.size(); ++i) {
          if (!ref.valid[i / 3]) continue;
          EXPECT_NEAR(t.rgb[i], ref.rgb[i], 1e-12 * std::abs(ref.rgb[i]));
        }
      }
    }
  }
}

}  // namespace
}  // namespace halfback
