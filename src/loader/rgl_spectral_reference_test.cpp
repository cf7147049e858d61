// Round trip of the RGL writer's spectral variant through RGL's own spectral reader: files
// halfback writes with `spectra` are read by the reference loader powitacq.h of
// rgl-epfl/brdf-loader (built from HALFBACK_POWITACQ_DIR at configure time), its spectra are
// integrated to RGB here (core/spectrum.hpp), and they give halfback's values of the RGB table.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "halfback/core/spectrum.hpp"
#include "halfback/formats/rgl.hpp"
#include "halfback/formats/rgl_writer.hpp"
#include "halfback/loader/load.hpp"
#include "support/test_support.hpp"

#ifdef HALFBACK_HAVE_POWITACQ_SPECTRAL
#define POWITACQ_IMPLEMENTATION
#include <powitacq.h>
#endif

namespace halfback {
namespace {

#ifdef HALFBACK_HAVE_POWITACQ_SPECTRAL

// The largest difference, over random pairs, between the reference loader's spectrum integrated
// to RGB and halfback's reading of the file's `rgb` table, relative to the largest value of
// fr·cos θo seen (the reference loader computes in float).
double largest_difference(const std::string& path, int pairs) {
  const powitacq::BRDF reference(path);
  const auto ours = load_rgl(path);
  const powitacq::Spectrum& lambda = reference.wavelengths();
  const spectral::SpectrumToRgb to_rgb(std::vector<double>(std::begin(lambda), std::end(lambda)));
  std::mt19937_64 rng(13);
  double largest = 0, diff = 0;
  std::vector<double> values(lambda.size());
  for (int k = 0; k < pairs; ++k) {
    const Vec3<double> wi = test::uniform_hemisphere(rng), wo = test::uniform_hemisphere(rng);
    const powitacq::Spectrum s =
        reference.eval(powitacq::Vector3f(float(wi.x), float(wi.y), float(wi.z)),
                       powitacq::Vector3f(float(wo.x), float(wo.y), float(wo.z)));
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = s[i];
    const Rgb ref = to_rgb(values), mine = ours->eval_cosine({wi, wo}), d = ref - mine;
    largest = std::max(largest, mine.max_channel());
    diff = std::max({diff, std::abs(d.r), std::abs(d.g), std::abs(d.b)});
  }
  return diff / largest;
}

TEST(RglSpectralReferenceLoader, ReadsWhatHalfbackWritesWithTheSameColours) {
  test::TempDir dir;
  for (const char* spec : {"ggx:alpha=0.2,f0_r=0.9,f0_g=0.6,f0_b=0.3", "lambert:albedo=0.6",
                           "embedded:pink-felt", "embedded:colodur_azure_4e"}) {
    const auto path = dir.path() / "exported.bsdf";
    RglExportOptions o;
    o.variant = RglVariant::both;  // halfback reads `rgb`, the reference loader `spectra`
    write_rgl(path, *load_brdf(spec), o);
    const double d = largest_difference(path.string(), 5000);
    std::printf("%s: largest difference %.2e of the largest value\n", spec, d);
    EXPECT_LT(d, 5e-5) << spec;
  }
}

#else

TEST(RglSpectralReferenceLoader, ReadsWhatHalfbackWritesWithTheSameColours) {
  GTEST_SKIP() << "RGL's spectral reference loader is not available: configure with "
                  "-DHALFBACK_POWITACQ_DIR=DIR, DIR holding powitacq.h and powitacq.inl of "
                  "rgl-epfl/brdf-loader (given: '" HALFBACK_POWITACQ_DIR_GIVEN "')";
}

#endif

}  // namespace
}  // namespace halfback
