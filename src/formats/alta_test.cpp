// ALTA: strict text parsing (line numbers in errors), the ISOTROPIC_TL_TV_PROJ_DPHI coordinates,
// the cosine factor, the scattered-data interpolation, and the two published files.
#include "halfback/formats/alta.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>
#include <random>
#include <sstream>

#include "support/allocation_probe.hpp"
#include "support/test_support.hpp"

namespace halfback {
namespace {

constexpr double kPi = std::numbers::pi;

// --------------------------------------------------------------------------------------------
// Parsing
// --------------------------------------------------------------------------------------------

TEST(AltaParse, HeaderRowsAndIntervals) {
  const std::string text =
      "#SAMPLE \"test\"\r\n"
      "#DIM 3 1\r\n"
      "#VS 2\n"
      "#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n"
      "#PARAM_OUT INV_STERADIAN\n"
      "\n"
      "0.1 0.2 0.3 1.5 1.4 1.6\n"
      "# a comment between data lines\n"
      "  0.1\t0.25   -0.3 2.5e-1 0.2 0.3  \n";
  const AltaData d = parse_alta(text, "t.dat");
  EXPECT_EQ(d.dim_in, 3u);
  EXPECT_EQ(d.dim_out, 1u);
  EXPECT_EQ(d.vs, 2);
  EXPECT_EQ(d.param_in, "ISOTROPIC_TL_TV_PROJ_DPHI");
  EXPECT_EQ(d.param_out, "INV_STERADIAN");
  EXPECT_EQ(d.header.at("SAMPLE"), "\"test\"");
  ASSERT_EQ(d.rows(), 2u);
  EXPECT_EQ(d.line, (std::vector<std::size_t>{7, 9}));
  EXPECT_EQ(d.x, (std::vector<double>{0.1, 0.2, 0.3, 0.1, 0.25, -0.3}));
  EXPECT_EQ(d.y, (std::vector<double>{1.5, 0.25}));
  EXPECT_EQ(d.interval, (std::vector<double>{1.4, 1.6, 0.2, 0.3}));
  // #VS 1: a symmetric half-width on the first value.
  const AltaData s = parse_alta("#DIM 1 1\n#VS 1\n0.5 2 0.25\n", "s");
  EXPECT_EQ(s.interval, (std::vector<double>{1.75, 2.25}));
  EXPECT_EQ(alta_param_dimension("RUSIN_TH_TD_PD"), 3u);
  EXPECT_EQ(alta_param_dimension("CARTESIAN"), 6u);
  EXPECT_EQ(alta_param_dimension("NOPE"), 0u);
}

TEST(AltaParse, ErrorsNameTheLine) {
  const std::string head =
      "#DIM 3 1\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT INV_STERADIAN\n";
  EXPECT_FORMAT_ERROR(parse_alta("", "e.dat"), "e.dat", "header", "no #DIM");
  EXPECT_FORMAT_ERROR(parse_alta("0.1 0.2\n", "x.dat"), "x.dat", "line 1", "data before #DIM");
  EXPECT_FORMAT_ERROR(parse_alta(head, "n.dat"), "n.dat", "data", "no data lines");
  EXPECT_FORMAT_ERROR(parse_alta(head + "0.1 0.2 0.3 1\n0.1 0.2 0.3\n", "c.dat"), "c.dat", "line 5",
                      "3 numbers, expected 4");
  EXPECT_FORMAT_ERROR(parse_alta(head + "0.1 0.2 0.3 1 5\n", "m"), "line 4", "more than the 4");
  EXPECT_FORMAT_ERROR(parse_alta(head + "0.1 abc 0.3 1\n", "a"), "line 4", "column 2",
                      "'abc' is not a number");
  EXPECT_FORMAT_ERROR(parse_alta(head + "0.1 0.2 0.3 1x\n", "a"), "line 4", "column 4");
  EXPECT_FORMAT_ERROR(parse_alta(head + "0.1 0.2 0.3 nan\n", "nan"), "line 4", "column 4",
                      "'nan' is not finite");
  EXPECT_FORMAT_ERROR(parse_alta(head + "0.1 0.2 inf 1\n", "inf"), "line 4", "not finite");
  EXPECT_FORMAT_ERROR(parse_alta(head + "0.1 0.2 0.3 1e999\n", "big"), "line 4", "not a number");
  EXPECT_FORMAT_ERROR(parse_alta("#DIM 3 1\n#PARAM_IN FOO\n", "p"), "line 2",
                      "unknown input parameterization 'FOO'");
  EXPECT_FORMAT_ERROR(parse_alta("#DIM 2 1\n#PARAM_IN RUSIN_TH_TD_PD\n1 2 3\n", "p"), "line 3",
                      "RUSIN_TH_TD_PD has dimension 3 but #DIM says 2");
  EXPECT_FORMAT_ERROR(parse_alta("#DIM 3 1\n#PARAM_OUT WATTS\n", "o"), "line 2",
                      "unknown output parameterization");
  EXPECT_FORMAT_ERROR(parse_alta("#DIM 3 1\n#VS 3\n", "v"), "line 2", "#VS expects 0, 1 or 2");
  EXPECT_FORMAT_ERROR(parse_alta("#DIM 3\n", "d"), "line 1", "#DIM expects two integers");
  EXPECT_FORMAT_ERROR(parse_alta("#DIM 0 1\n", "d"), "line 1", "input dimension must be 1 to 6");
  EXPECT_FORMAT_ERROR(parse_alta("#DIM 3 9\n", "d"), "line 1", "output dimension must be 1 to 3");
  EXPECT_FORMAT_ERROR(parse_alta("#DIM 3 1\n#DIM 3 1\n", "d"), "line 2", "#DIM given twice");
  EXPECT_FORMAT_ERROR(parse_alta(head + "0.1 0.2 0.3 1\n#DIM 2 1\n", "d"), "line 5",
                      "after the first data line");
  EXPECT_FORMAT_ERROR(parse_alta("#DIM 3 1\n#FORMAT binary\n", "b"), "line 2",
                      "only text ALTA files");
  EXPECT_FORMAT_ERROR(read_alta("/nonexistent/file.dat"), "/nonexistent/file.dat", "file");
}

// A byte-order mark is skipped; a fitted-function file is named as such, not as bad numbers.
TEST(AltaParse, ByteOrderMarkAndFunctionFiles) {
  const std::string body =
      "#DIM 3 1\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT INV_STERADIAN\n0.1 0.2 0.3 1\n";
  const AltaData d = parse_alta("\xEF\xBB\xBF" + body, "bom.dat");
  EXPECT_EQ(d.rows(), 1u);
  EXPECT_EQ(d.dim_in, 3u);
  EXPECT_FORMAT_ERROR(parse_alta("\xEF\xBB" + body, "half-bom.dat"), "line 1", "data before #DIM");
  const std::string fit =
      "#ALTA FUNC HEADER\n#CMD brdf_fit --data x.dat\n#DIM 2 1\n#PARAM_IN RUSIN_TH_TD\n"
      "#PARAM_OUT INV_STERADIAN\n#ALTA HEADER END\n#FUNC nonlinear_function_lambertian\nkd 0.5\n";
  EXPECT_FORMAT_ERROR(parse_alta(fit, "fit.brdf"), "fit.brdf", "line 1", "ALTA function file",
                      "not ALTA data");
  EXPECT_FORMAT_ERROR(parse_alta("#DIM 2 1\n#FUNC nonlinear_function_lambertian\nkd 0.5\n", "f"),
                      "line 2", "ALTA function file");
}

// --------------------------------------------------------------------------------------------
// Evaluation
// --------------------------------------------------------------------------------------------

// A file with samples of f on a grid in the projected plane, at incidences 20°, 40°, 60°.
std::string grid_file(double (*f)(double, double, double), bool cosine, double step = 0.05,
                      double extent = 1.2) {
  std::ostringstream s;
  s.precision(17);
  s << "#DIM 3 1\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT "
    << (cosine ? "INV_STERADIAN_COSINE_FACTOR" : "INV_STERADIAN") << "\n";
  for (double deg : {20.0, 40.0, 60.0}) {
    const double tl = deg * kPi / 180;
    for (double px = -extent; px <= extent + 1e-9; px += step)
      for (double py = -extent; py <= extent + 1e-9; py += step) {
        const double tv = std::hypot(px, py);
        if (tv > kPi / 2) continue;
        s << tl << " " << px << " " << py << " " << f(tl, px, py) * (cosine ? std::cos(tv) : 1.0)
          << "\n";
      }
  }
  return s.str();
}

double smooth(double tl, double px, double py) {
  return 1 + tl + 0.5 * std::sin(px) + 0.2 * py * py;
}

AltaBrdf brdf_of(const std::string& text, AltaOptions options = {}) {
  return AltaBrdf(parse_alta(text, "g.dat"), "g.dat", "g", options);
}

TEST(AltaEval, ReproducesSamplesAndInterpolates) {
  const AltaBrdf b = brdf_of(grid_file(smooth, false));
  EXPECT_EQ(b.incidence_angles().size(), 3u);
  EXPECT_NEAR(b.support_radius(0), 1.5 * 0.05, 1e-9);
  // At the samples: exact.
  const double tl = 40 * kPi / 180;
  EXPECT_NEAR(b.eval_coords(tl, 0.3, -0.45).r, smooth(tl, 0.3, -0.45), 1e-12);
  // Between samples and between incidences: close to the smooth function.
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  double worst = 0;
  for (int n = 0; n < 2000; ++n) {
    const double t = (20 + 40 * u(rng)) * kPi / 180, px = 2.2 * u(rng) - 1.1,
                 py = 2.2 * u(rng) - 1.1;
    if (std::hypot(px, py) > 1.5) continue;
    const Rgb v = b.eval_coords(t, px, py);
    ASSERT_TRUE(std::isfinite(v.r));
    EXPECT_EQ(v.r, v.g);
    worst = std::max(worst, std::abs(v.r - smooth(t, px, py)));
  }
  EXPECT_LT(worst, 0.01);
  // Linear in θl between slices, at a sample position shared by the slices.
  const double t25 = 25 * kPi / 180, t20 = 20 * kPi / 180, t40 = 40 * kPi / 180;
  EXPECT_NEAR(b.eval_coords(t25, 0.5, 0.5).r,
              0.75 * smooth(t20, 0.5, 0.5) + 0.25 * smooth(t40, 0.5, 0.5), 1e-9);
}

TEST(AltaEval, ContinuousAlongAPath) {
  // Modified Shepard weights vanish at the (k+1)-th neighbour: no jumps when the neighbour set
  // changes. Steps of 1e-5 rad must change ρ by far less than the sample spacing would.
  const AltaBrdf b = brdf_of(grid_file(smooth, false, 0.07));
  const double tl = 40 * kPi / 180;
  double prev = b.eval_coords(tl, -0.9, -0.3).r, worst = 0;
  for (int i = 1; i <= 100000; ++i) {
    const double s = i * 1e-5;
    const double v = b.eval_coords(tl, -0.9 + s, -0.3 + 0.4 * s).r;
    worst = std::max(worst, std::abs(v - prev));
    prev = v;
  }
  EXPECT_LT(worst, 2e-3);
}

TEST(AltaEval, OutsideTheDataAndCoordinates) {
  const AltaBrdf b = brdf_of(grid_file(smooth, false, 0.05, 0.5));
  const double tl = 40 * kPi / 180;
  EXPECT_TRUE(std::isfinite(b.eval_coords(tl, 0.5, 0.5).r));
  EXPECT_TRUE(std::isnan(b.eval_coords(tl, 0.8, 0.0).r));              // beyond the support
  EXPECT_TRUE(std::isnan(b.eval_coords(10 * kPi / 180, 0.1, 0.1).r));  // incidence not measured
  EXPECT_TRUE(std::isnan(b.eval_coords(70 * kPi / 180, 0.1, 0.1).r));
  const AltaBrdf z = brdf_of(grid_file(smooth, false, 0.05, 0.5), AltaOptions{8, true});
  EXPECT_EQ(z.eval_coords(tl, 0.8, 0.0).r, 0.0);
  // The pair's canonical pose: light at azimuth 0, view at Δφ; any rotation about n agrees.
  const double tv = 0.4, dphi = 2.5;
  for (double phi : {0.0, 1.0, -2.0}) {
    const Rgb v = b.eval({test::direction(tl, phi), test::direction(tv, phi + dphi)});
    EXPECT_NEAR(v.r, b.eval_coords(tl, tv * std::cos(dphi), tv * std::sin(dphi)).r, 1e-12);
  }
  EXPECT_EQ(b.eval({{0, 0, 1}, {0.6, 0, -0.8}}), (Rgb{0, 0, 0}));
  EXPECT_TRUE(std::isnan(b.eval({{0, 0, std::nan("")}, {0, 0, 1}}).r));
}

// docs/reliability/readers.md, "Missing and negative measurements": a negative sample is a
// measurement of 0 with noise; it is read as 0, counted, and no evaluation (at it or between
// samples) is negative. Where there is no sample, ρ is missing (NaN), as above.
double dips_below_zero(double, double px, double) {
  return px > 0.2 ? -0.003 : 0.5;
}

TEST(AltaEval, NegativeSamplesAreZeroAndCounted) {
  const AltaBrdf b = brdf_of(grid_file(dips_below_zero, false, 0.05, 0.5));
  EXPECT_GT(b.negative_samples(), 100u);
  EXPECT_LT(b.negative_samples(), b.samples());
  bool counted = false;
  for (const auto& f : b.facts())
    counted |= f.label == "negative samples" &&
               f.value == std::to_string(b.negative_samples()) + " (clamped to 0)";
  EXPECT_TRUE(counted);
  const double tl = 40 * kPi / 180;
  EXPECT_EQ(b.eval_coords(tl, 0.45, 0.0).r, 0.0);  // on a negative sample
  for (double px = -0.5; px <= 0.5; px += 0.013) {
    const Rgb v = b.eval_coords(tl + 0.1, px, 0.1);
    EXPECT_FALSE(v.r < 0 || v.g < 0 || v.b < 0) << px << " " << v.r;
  }
  EXPECT_EQ(brdf_of(grid_file(smooth, false)).negative_samples(), 0u);
}

TEST(AltaEval, CosineFactorIsRemoved) {
  // INV_STERADIAN_COSINE_FACTOR stores ρ·cos θv: the BRDF gives ρ.
  const AltaBrdf b = brdf_of(grid_file(smooth, true));
  const double tl = 20 * kPi / 180;
  EXPECT_NEAR(b.eval_coords(tl, 1.0, 0.5).r, smooth(tl, 1.0, 0.5), 1e-9);
  EXPECT_EQ(b.dropped_grazing(), 0u);
  // Samples at θv = 90° carry no information on ρ (0/0): dropped and counted.
  const std::string text =
      grid_file(smooth, true) + "0.6981317007977318 1.5707963267948966 0 0.001\n";
  EXPECT_EQ(brdf_of(text).dropped_grazing(), 1u);
}

TEST(AltaEval, RgbAndUnsupportedFiles) {
  const AltaBrdf rgb = brdf_of(
      "#DIM 3 3\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT INV_STERADIAN\n"
      "0.5 0 0 1 2 3\n0.5 0.1 0 1 2 3\n0.5 0 0.1 1 2 3\n");
  const Rgb c = rgb.eval_coords(0.5, 0.02, 0.03);
  EXPECT_NEAR(c.r, 1, 1e-12);
  EXPECT_NEAR(c.g, 2, 1e-12);
  EXPECT_NEAR(c.b, 3, 1e-12);
  EXPECT_FORMAT_ERROR(
      brdf_of("#DIM 3 1\n#PARAM_IN RUSIN_TH_TD_PD\n#PARAM_OUT INV_STERADIAN\n1 1 1 1\n"), "g.dat",
      "#PARAM_IN", "evaluation supports ISOTROPIC_TL_TV_PROJ_DPHI");
  EXPECT_FORMAT_ERROR(
      brdf_of("#DIM 3 1\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT ENERGY\n1 1 1 1\n"),
      "#PARAM_OUT", "'ENERGY'");
  EXPECT_FORMAT_ERROR(brdf_of("#DIM 3 1\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n1 1 1 1\n"), "header",
                      "no #PARAM_OUT line", "INV_STERADIAN_COSINE_FACTOR");
  EXPECT_FORMAT_ERROR(brdf_of("#DIM 3 1\n#PARAM_OUT INV_STERADIAN\n1 1 1 1\n"), "header",
                      "no #PARAM_IN line", "ISOTROPIC_TL_TV_PROJ_DPHI");
  EXPECT_FORMAT_ERROR(
      brdf_of("#DIM 3 1\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT INV_STERADIAN\n"
              "0.5 0 0 1\n0.5 0.1 0 1\n2.0 0 0 1\n"),
      "line 6", "outside [0, π/2]");
  EXPECT_FORMAT_ERROR(
      brdf_of("#DIM 3 1\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT INV_STERADIAN\n"
              "0.5 1.5 0.5 1\n"),
      "line 4", "exceeds π/2");
  EXPECT_FORMAT_ERROR(
      brdf_of("#DIM 3 1\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT INV_STERADIAN\n"
              "0.5 0 0 1\n0.5 0.1 0 1\n"),
      "data", "has 2 samples", "at least 3");
}

// --------------------------------------------------------------------------------------------
// The published files
// --------------------------------------------------------------------------------------------

TEST(AltaPublished, RetroReflectors) {
  HALFBACK_REQUIRE_SHARED(dir, "alta");
  const auto yellow = load_alta(dir / "retro-3M-jaune.dat");
  const auto orange = load_alta(dir / "retro-orange-tape-dense.dat");
  EXPECT_EQ(yellow->samples() + yellow->dropped_grazing(), 7397u);
  EXPECT_EQ(yellow->dropped_grazing(), 86u);  // the samples at θv = 90°
  EXPECT_EQ(orange->samples(), 79707u);
  EXPECT_EQ(yellow->incidence_angles().size(), 3u);
  std::cout << "[ info ] " << yellow->description() << "\n[ info ] " << orange->description()
            << "\n";

  // Every kept sample is reproduced at its own direction pair (ρ, the cosine removed for 3M).
  for (const auto& [path, brdf, cosine] :
       {std::tuple{dir / "retro-3M-jaune.dat", yellow, true},
        std::tuple{dir / "retro-orange-tape-dense.dat", orange, false}}) {
    const AltaData data = read_alta(path);
    for (std::size_t r = 0; r < data.rows(); r += 97) {
      const double* x = &data.x[3 * r];
      const double tv = std::hypot(x[1], x[2]), dphi = std::atan2(x[2], x[1]);
      if (std::cos(tv) < 1e-3) continue;
      const Rgb v = brdf->eval({test::direction(x[0], 0.4), test::direction(tv, 0.4 + dphi)});
      const double want = data.y[r] / (cosine ? std::cos(tv) : 1.0);
      EXPECT_NEAR(v.r, want, 1e-6 * want + 1e-12) << path << " line " << data.line[r];
    }
  }
  // The orange tape is measured in a ±15° window around the retro direction, where its peak is.
  const double tl = 30 * kPi / 180;
  double best = 0, best_at = 0;
  for (double d = -14; d <= 14; d += 0.25) {
    const double tv = tl + d * kPi / 180;
    const double v = orange->eval({test::direction(tl, 0), test::direction(tv, 0)}).r;
    ASSERT_TRUE(std::isfinite(v)) << d;
    if (v > best) best = v, best_at = d;
  }
  EXPECT_LT(std::abs(best_at), 2.0);
  EXPECT_TRUE(std::isnan(orange->eval({test::direction(tl, 0), test::direction(tl, kPi)}).r));
}

// What INV_STERADIAN_COSINE_FACTOR means for the 3M data: the stored value vanishes linearly as
// the view goes grazing (as ρ·cos θv must), while ρ = value / cos θv stays finite.
TEST(AltaPublished, CosineFactorEvidence) {
  HALFBACK_REQUIRE_SHARED(dir, "alta");
  const AltaData data = read_alta(dir / "retro-3M-jaune.dat");
  EXPECT_EQ(data.param_out, "INV_STERADIAN_COSINE_FACTOR");
  EXPECT_EQ(read_alta(dir / "retro-orange-tape-dense.dat").param_out, "INV_STERADIAN");
  double sum[3] = {0, 0, 0};
  int count[3] = {0, 0, 0};
  const double rings[3] = {81, 87, 90};
  for (std::size_t r = 0; r < data.rows(); ++r) {
    const double tv = std::hypot(data.x[3 * r + 1], data.x[3 * r + 2]) * 180 / kPi;
    for (int k = 0; k < 3; ++k)
      if (std::abs(tv - rings[k]) < 0.5) sum[k] += data.y[r], ++count[k];
  }
  const double v81 = sum[0] / count[0], v87 = sum[1] / count[1], v90 = sum[2] / count[2];
  std::cout << "[ info ] 3M ring means: θv=81°: " << v81 << ", 87°: " << v87 << ", 90°: " << v90
            << "; /cos θv: " << v81 / std::cos(81 * kPi / 180) << ", "
            << v87 / std::cos(87 * kPi / 180) << "\n";
  EXPECT_LT(v90, 0.05 * v81);  // ~0 at grazing
  const double r81 = v81 / std::cos(81 * kPi / 180), r87 = v87 / std::cos(87 * kPi / 180);
  EXPECT_GT(r87, 0.4 * r81);  // ρ itself does not collapse
}

// docs/reliability/readers.md, "Nothing is allocated from a size a file declares before the file is
// checked to hold it": ALTA text declares no sizes, so what the reader holds grows with the lines
// it has read; a real file costs a small multiple of its size.
TEST(AltaAllocation, BoundedByTheFile) {
  HALFBACK_REQUIRE_SHARED(dir, "alta");
  const auto real = dir / "retro-orange-tape-dense.dat";
  test::AllocationProbe probe;
  (void)load_alta(real);
  EXPECT_LT(probe.growth(), 8 * std::filesystem::file_size(real)) << probe.growth();
  // A #DIM claiming the largest dimensions changes nothing: there is no count to trust.
  const std::string text = "#DIM 6 3\n#PARAM_IN CARTESIAN\n0 0 1 0 0 1 0.5 0.5 0.5\n";
  test::AllocationProbe small;
  EXPECT_EQ(parse_alta(text, "small.dat").rows(), 1u);
  EXPECT_LT(small.growth(), 64 * text.size() + 4096) << small.growth();
}

// docs/reliability/readers.md, "One bound on a BRDF's value": a sample whose ρ is above the bound
// on a BRDF's value (a value of 1e308 gave "max ρ: inf" and then vanished from the albedo as
// unmeasured) is refused, naming the line; with the cosine factor, on ρ = value / cos θv.
TEST(AltaBound, SampleAboveTheBoundIsRefused) {
  const std::string head =
      "#DIM 3 1\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT INV_STERADIAN\n"
      "0.5 0 0 1\n0.5 0.1 0 2\n";
  EXPECT_NO_THROW(brdf_of(head + "0.5 0 0.1 1e10\n"));
  EXPECT_FORMAT_ERROR(brdf_of(head + "0.5 0 0.1 1e308\n"), "line 6",
                      "ρ = 1e+308 sr⁻¹, above the bound of 1e+10 sr⁻¹ on a BRDF's value");
  // ρ·cos θv = 1e8: at θv = 1.5 rad ρ = 1.4e9, within; at θv = 1.5697 (cos 1.1e-3) ρ = 9.1e10.
  const std::string cosine =
      "#DIM 3 1\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT INV_STERADIAN_COSINE_FACTOR\n"
      "0.5 0 0 1\n0.5 0.1 0 2\n";
  EXPECT_NO_THROW(brdf_of(cosine + "0.5 0 1.5 1e8\n"));
  EXPECT_FORMAT_ERROR(brdf_of(cosine + "0.5 0 1.5697 1e8\n"), "line 6", "ρ = 9.",
                      "above the bound of 1e+10");
}

// docs/reliability/readers.md, "A reader reads what the file's header declares, and nothing more":
// a text file is read line by line; the zeros of a file extended past its end (truncate -s) are
// binary data, refused at the first line that holds one, without reading the rest.
TEST(AltaTrailingData, NulBytesAreRefusedWithoutReadingTheRest) {
  test::TempDir tmp;
  const std::string text =
      "#DIM 3 1\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT INV_STERADIAN\n"
      "0.5 0 0 1\n0.5 0.1 0 2\n0.5 0 0.1 3\n";
  const auto sparse = tmp / "sparse.dat";
  test::write_bytes(sparse, text.data(), text.size());
  EXPECT_NO_THROW(load_alta(sparse));
  std::filesystem::resize_file(sparse, std::uintmax_t(1) << 30);
  test::AllocationProbe probe;
  EXPECT_FORMAT_ERROR(load_alta(sparse), "sparse.dat", "line 7", "a NUL byte at column 1",
                      "binary data");
  EXPECT_LT(probe.growth(), std::size_t(4) << 20) << probe.growth();
  EXPECT_FORMAT_ERROR(parse_alta(text + std::string("0.5 0.1 0.1\0 4\n", 15), "m.dat"), "m.dat",
                      "line 7", "a NUL byte at column 12");
}

}  // namespace
}  // namespace halfback
