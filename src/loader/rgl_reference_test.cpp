// Round trip of the RGL writer through RGL's own reader: files halfback writes are read by the
// reference loader (powitacq_rgb.h of rgl-epfl/brdf-loader, built from HALFBACK_POWITACQ_DIR at
// configure time) and by halfback's reader, and both give the same values.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "halfback/formats/rgl.hpp"
#include "halfback/formats/rgl_writer.hpp"
#include "halfback/loader/load.hpp"
#include "support/test_support.hpp"

#ifdef HALFBACK_HAVE_POWITACQ
#define POWITACQ_IMPLEMENTATION
#include <powitacq_rgb.h>
#endif

namespace halfback {
namespace {

#ifdef HALFBACK_HAVE_POWITACQ

constexpr double kPi = std::numbers::pi;

// The largest difference between the two readers over random pairs, relative to the largest
// value of fr·cos θo seen (the reference loader computes in float).
double largest_difference(const std::string& path, int pairs) {
  const powitacq_rgb::BRDF reference(path);
  const auto ours = load_rgl(path);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uni(0, 1);
  auto direction = [&] {
    const double z = uni(rng), r = std::sqrt(1 - z * z), phi = 2 * kPi * uni(rng);
    return Vec3<double>{r * std::cos(phi), r * std::sin(phi), z};
  };
  double largest = 0, diff = 0;
  for (int k = 0; k < pairs; ++k) {
    const Vec3<double> wi = direction(), wo = direction();
    const auto ref = reference.eval(powitacq_rgb::Vector3f(float(wi.x), float(wi.y), float(wi.z)),
                                    powitacq_rgb::Vector3f(float(wo.x), float(wo.y), float(wo.z)));
    const Rgb mine = ours->eval_cosine({wi, wo});
    const double m[3] = {mine.r, mine.g, mine.b};
    for (int c = 0; c < 3; ++c) {
      largest = std::max(largest, std::abs(m[c]));
      diff = std::max(diff, std::abs(double(ref[c]) - m[c]));
    }
  }
  return diff / largest;
}

TEST(RglReferenceLoader, ReadsWhatHalfbackWritesWithTheSameValues) {
  test::TempDir dir;
  for (const char* spec :
       {"ggx:alpha=0.2,f0_r=0.9,f0_g=0.6,f0_b=0.3", "beckmann:alpha=0.5", "lambert:albedo=0.6",
        "embedded:pink-felt", "embedded:ilm_l3_37_metallic"}) {
    const auto path = dir.path() / "exported.bsdf";
    write_rgl(path, *load_brdf(spec));
    const double d = largest_difference(path.string(), 20000);
    std::printf("%s: largest difference %.2e of the largest value\n", spec, d);
    EXPECT_LT(d, 5e-5) << spec;
  }
}

#else

TEST(RglReferenceLoader, ReadsWhatHalfbackWritesWithTheSameValues) {
  GTEST_SKIP() << "RGL's reference loader is not available: configure with "
                  "-DHALFBACK_POWITACQ_DIR=DIR, DIR holding powitacq_rgb.h and powitacq_rgb.inl "
                  "of rgl-epfl/brdf-loader (given: '" HALFBACK_POWITACQ_DIR_GIVEN "')";
}

#endif

}  // namespace
}  // namespace halfback
