// Dupuy & Jakob's layout as a design (docs/acquisition.md, "Dupuy & Jakob's layout"): sized to the
// budget with every measurement counted, the published layout at its budget, the same material as
// export-rgl writes, and an error that falls with the budget.
#include "halfback/acquire/dupuy_jakob_design.hpp"

#include <gtest/gtest.h>

#include <random>

#include "halfback/acquire/gonio.hpp"
#include "halfback/formats/adaptive_param.hpp"
#include "halfback/loader/load.hpp"
#include "support/test_support.hpp"

namespace halfback::acquire {
namespace {

TEST(DupuyJakobLayout, EveryMeasurementCountsAgainstTheBudget) {
  for (const std::size_t budget : {48u, 100u, 1000u, 3000u, 10000u, 100000u, 1000000u}) {
    const DupuyJakobLayout l = dupuy_jakob_layout(budget);
    EXPECT_LE(l.measurements(), budget);
    EXPECT_EQ(l.measurements(), l.retro_measurements() + l.slice_measurements());
    EXPECT_EQ(l.theta_i, 8);
    // The largest resolution that fits: one more would not.
    DupuyJakobLayout more = l;
    ++more.resolution;
    EXPECT_GT(more.measurements(), budget) << budget;
    if (budget >= 1000) {
      EXPECT_GE(double(l.measurements()), 0.8 * double(budget)) << budget;
    }
  }
  // Dupuy & Jakob's published isotropic files: 8 slices of 32 × 32 and an NDF of 128 nodes.
  const DupuyJakobLayout published = dupuy_jakob_layout(8 * 32 * 32 + 128);
  EXPECT_EQ(published.resolution, 32);
  EXPECT_EQ(published.ndf_nodes, 128);
  EXPECT_THROW(dupuy_jakob_layout(47), std::invalid_argument);
  EXPECT_THROW(dupuy_jakob_layout(0), std::invalid_argument);
}

TEST(DupuyJakobLayout, TheAcquisitionIsWhatExportRglWrites) {
  const BrdfPtr brdf = load_brdf("lambert:albedo=0.2+ggx:alpha=0.15,f0=0.8");
  const DupuyJakobLayout layout = dupuy_jakob_layout(10000);
  const test::TempDir dir;
  write_rgl(dir / "written.bsdf", *brdf, layout.export_options());
  const BrdfPtr file = load_brdf((dir / "written.bsdf").string());
  const auto acquired = dupuy_jakob_acquisition(*brdf, layout);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int k = 0; k < 2000; ++k) {
    const auto dir_of = [&] {
      const double z = u(rng), phi = 2 * 3.141592653589793 * u(rng), s = std::sqrt(1 - z * z);
      return Vec3<double>{s * std::cos(phi), s * std::sin(phi), z};
    };
    const DirPair<double> pair{dir_of(), dir_of()};
    const Rgb a = acquired->eval(pair), b = file->eval(pair);
    ASSERT_EQ(a.r, b.r);
    ASSERT_EQ(a.g, b.g);
    ASSERT_EQ(a.b, b.b);
  }
}

TEST(DupuyJakobLayout, MoreMeasurementsLessError) {
  const BrdfPtr brdf = load_brdf("lambert:albedo=0.2+ggx:alpha=0.15,f0=0.8");
  const TestPairs test = draw_test_pairs(*brdf, 20000, 1, ErrorSpace::log, 85);
  double previous = 1e300;
  for (const std::size_t budget : {1000u, 10000u, 100000u}) {
    const double e =
        reconstruction_error(*dupuy_jakob_acquisition(*brdf, dupuy_jakob_layout(budget)), test);
    EXPECT_LT(e, previous) << budget;
    previous = e;
  }
  EXPECT_LT(previous, 0.05);  // a smooth lobe, 10⁵ measurements
}

TEST(DupuyJakobLayout, AnisotropicBrdfsAreRefused) {
  const BrdfPtr aniso = load_brdf("ggx:alpha_x=0.1,alpha_y=0.4");
  EXPECT_THROW(dupuy_jakob_acquisition(*aniso, dupuy_jakob_layout(1000)), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::acquire
