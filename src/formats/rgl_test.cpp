// RGL: the tensor_file container (structure and strict validation), the material fields, the
// inverse VNDF warp (against its forward warp and closed forms), evaluation semantics (fr, not
// fr·cos θo), and physical checks on the 12 published materials in ../shared/data/rgl.
#include "halfback/formats/rgl.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <numbers>
#include <random>
#include <span>
#include <stdexcept>

#include "formats/binary_io.hpp"
#include "formats/rgl_synthetic.hpp"
#include "support/allocation_probe.hpp"
#include "support/every_isa.hpp"
#include "support/test_stats.hpp"
#include "support/test_support.hpp"

namespace halfback {
namespace {

constexpr double kPi = std::numbers::pi;
using test::f32;
using test::Synthetic;

TensorFieldData* find(std::vector<TensorFieldData>& fs, const std::string& name) {
  for (auto& f : fs)
    if (f.name == name) return &f;
  return nullptr;
}

RglBrdf brdf_of(const std::vector<TensorFieldData>& fs) {
  return RglBrdf(parse_tensor_file(serialize_tensor_file(fs), "m.bsdf"), "m");
}

// --------------------------------------------------------------------------------------------
// Container
// --------------------------------------------------------------------------------------------

TEST(TensorFile, RoundTripOfFields) {
  const Synthetic syn;
  const TensorFile tf = parse_tensor_file(syn.bytes(), "syn");
  EXPECT_EQ(tf.version_major, 1);
  EXPECT_EQ(tf.version_minor, 0);
  ASSERT_EQ(tf.fields.size(), 10u);
  const TensorField* vndf = tf.find("vndf");
  ASSERT_NE(vndf, nullptr);
  EXPECT_EQ(vndf->dtype, TensorDtype::float32);
  EXPECT_EQ(vndf->shape, (std::vector<std::uint64_t>{1, 4, 16, 16}));
  EXPECT_EQ(vndf->count(), 1024u);
  EXPECT_EQ(vndf->bytes.size(), 4096u);
  EXPECT_EQ(vndf->offset % 8, 0u);
  EXPECT_EQ(tf.find("nope"), nullptr);
}

TEST(TensorFile, PublishedFileStructure) {
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  const TensorFile tf = read_tensor_file(dir / "paper_white_rgb.bsdf");
  std::vector<std::string> names;
  for (const auto& f : tf.fields) names.push_back(f.name);
  EXPECT_EQ(names,
            (std::vector<std::string>{"version", "description", "phi_i", "theta_i", "sigma", "ndf",
                                      "vndf", "luminance", "rgb", "jacobian", "valid"}));
  EXPECT_EQ(tf.find("rgb")->shape, (std::vector<std::uint64_t>{1, 8, 3, 32, 32}));
  EXPECT_EQ(tf.find("vndf")->shape, (std::vector<std::uint64_t>{1, 8, 128, 128}));
  EXPECT_EQ(tf.find("sigma")->shape, (std::vector<std::uint64_t>{2, 128}));
  EXPECT_EQ(tf.find("valid")->dtype, TensorDtype::uint8);
}

TEST(TensorFileErrors, Container) {
  const std::vector<std::byte> good = Synthetic{}.bytes();
  auto with = [&](auto&& edit) {
    std::vector<std::byte> b = good;
    edit(b);
    return b;
  };
  EXPECT_FORMAT_ERROR(parse_tensor_file(with([](auto& b) { b[0] = std::byte{'T'}; }), "a.bsdf"),
                      "a.bsdf", "magic", "tensor_file");
  EXPECT_FORMAT_ERROR(parse_tensor_file({}, "empty"), "empty", "magic");
  EXPECT_FORMAT_ERROR(parse_tensor_file(with([](auto& b) {
                                          b[12] = std::byte{2};
                                          b[13] = std::byte{1};
                                        }),
                                        "v"),
                      "version", "is 2.1, only 1.0");
  EXPECT_FORMAT_ERROR(parse_tensor_file(with([](auto& b) { b.resize(16); }), "h"), "header",
                      "truncated");
  EXPECT_FORMAT_ERROR(
      parse_tensor_file(
          with([](auto& b) { io_detail::store_le<std::uint32_t>(b.data() + 14, 1000000); }), "c"),
      "field count", "1000000 fields cannot fit");
  EXPECT_FORMAT_ERROR(
      parse_tensor_file(with([](auto& b) { io_detail::store_le<std::uint32_t>(b.data() + 14, 0); }),
                        "z"),
      "field count", "is 0");
  // Cut inside the field table / inside the data.
  EXPECT_FORMAT_ERROR(parse_tensor_file(with([](auto& b) { b.resize(200); }), "t"), "t",
                      "truncated: the field table runs past the end");
  EXPECT_FORMAT_ERROR(parse_tensor_file(with([](auto& b) { b.resize(b.size() - 8); }), "d.bsdf"),
                      "d.bsdf", "field 'jacobian'", "truncated data");
  // Field entries: the first field is "version" (name at 20..26, ndim 27, dtype 29, offset 30,
  // shape 38).
  EXPECT_FORMAT_ERROR(parse_tensor_file(with([](auto& b) { b[29] = std::byte{42}; }), "u"),
                      "field 'version'", "unknown dtype code 42");
  EXPECT_FORMAT_ERROR(parse_tensor_file(with([](auto& b) { b[20] = std::byte{' '}; }), "n"),
                      "field table entry 0", "name has characters");
  EXPECT_FORMAT_ERROR(
      parse_tensor_file(with([](auto& b) { io_detail::store_le<std::uint64_t>(b.data() + 30, 8); }),
                        "o"),
      "field 'version'", "lies inside the header");
  EXPECT_FORMAT_ERROR(parse_tensor_file(with([](auto& b) {
                                          io_detail::store_le<std::uint64_t>(b.data() + 38,
                                                                             ~std::uint64_t{0} / 2);
                                        }),
                                        "s"),
                      "field 'version'", "shape is larger than the file");
  EXPECT_FORMAT_ERROR(
      parse_tensor_file(
          with([](auto& b) { io_detail::store_le<std::uint16_t>(b.data() + 27, 300); }), "k"),
      "field 'version'", "300 dimensions");
  // Two fields with the same name.
  auto fs = Synthetic{}.fields();
  fs.push_back(fs[2]);
  EXPECT_FORMAT_ERROR(parse_tensor_file(serialize_tensor_file(fs), "dup"), "field 'phi_i'",
                      "appears twice");
}

TEST(TensorFileErrors, MaterialFields) {
  auto base = [] { return Synthetic{}.fields(); };
  {
    auto fs = base();
    fs.erase(fs.begin() + 8);  // rgb
    EXPECT_FORMAT_ERROR(brdf_of(fs), "m.bsdf", "field 'rgb'", "missing");
    // The spectral variant: `spectra` needs its `wavelengths`, increasing, one per spectrum sample.
    fs.push_back(f32("spectra", {1, 4, 2, 8, 8}, std::vector<float>(512, 1.0f)));
    EXPECT_FORMAT_ERROR(brdf_of(fs), "field 'wavelengths'", "missing");
    fs.push_back(f32("wavelengths", {2}, {500.0f, 400.0f}));
    EXPECT_FORMAT_ERROR(brdf_of(fs), "field 'wavelengths'", "value 1 is 400 nm", "increasing");
    *find(fs, "wavelengths") = f32("wavelengths", {3}, {400.0f, 500.0f, 600.0f});
    EXPECT_FORMAT_ERROR(brdf_of(fs), "field 'spectra'", "dimension 2 is 2, expected 3",
                        "number of wavelengths");
    *find(fs, "wavelengths") = f32("wavelengths", {2}, {400.0f, 600.0f});
    find(fs, "spectra")->data = test::le_bytes(std::vector<float>(512, NAN));
    EXPECT_FORMAT_ERROR(brdf_of(fs), "field 'spectra'", "NaN");
  }
  {
    auto fs = base();
    find(fs, "ndf")->dtype = TensorDtype::uint32;
    EXPECT_FORMAT_ERROR(brdf_of(fs), "field 'ndf'", "dtype uint32, expected float32");
  }
  {
    auto fs = base();
    find(fs, "ndf")->shape = {32};
    EXPECT_FORMAT_ERROR(brdf_of(fs), "field 'ndf'", "1 dimensions, expected 2");
  }
  {
    auto fs = base();
    *find(fs, "vndf") = f32("vndf", {1, 3, 16, 16}, std::vector<float>(768, 1.0f));
    EXPECT_FORMAT_ERROR(brdf_of(fs), "field 'vndf'", "dimension 1 is 3, expected 4", "theta_i");
  }
  {
    Synthetic s;
    s.vndf = [](std::size_t slice, std::size_t y, std::size_t x) {
      return slice == 2 && y == 3 && x == 5 ? std::nanf("") : 1.0f;
    };
    EXPECT_FORMAT_ERROR(brdf_of(s.fields()), "field 'vndf'", "value 565 is NaN");
  }
  {
    Synthetic s;
    s.rgb = [](auto, auto, auto, auto) { return INFINITY; };
    EXPECT_FORMAT_ERROR(brdf_of(s.fields()), "field 'rgb'", "is infinite");
  }
  {
    Synthetic s;
    s.sigma = 0;
    EXPECT_FORMAT_ERROR(brdf_of(s.fields()), "field 'sigma'", "must be positive");
  }
  {
    Synthetic s;
    s.vndf = [](auto, auto, auto) { return -1.0f; };
    EXPECT_FORMAT_ERROR(brdf_of(s.fields()), "field 'vndf'", "value 0 is -1,",
                        "below the noise tolerance");
  }
  {
    Synthetic s;
    s.vndf = [](auto, auto, auto) { return 0.0f; };
    EXPECT_FORMAT_ERROR(brdf_of(s.fields()), "field 'vndf'", "integrates to zero");
  }
  {
    Synthetic s;
    s.theta_i = {0.0f, 0.5f, 0.5f, 1.0f};
    EXPECT_FORMAT_ERROR(brdf_of(s.fields()), "field 'theta_i'", "not strictly increasing");
    s.theta_i = {0.0f, 0.5f, 1.0f, 2.0f};
    EXPECT_FORMAT_ERROR(brdf_of(s.fields()), "field 'theta_i'", "outside [");
  }
  {
    Synthetic s;
    s.jacobian = 2;
    EXPECT_FORMAT_ERROR(brdf_of(s.fields()), "field 'jacobian'", "is 2, expected 0 or 1");
  }
  {
    Synthetic s;
    s.phi_i = {-3.0f, -2.0f, -1.0f};  // 2 rad span: no 2π/k symmetry
    EXPECT_FORMAT_ERROR(brdf_of(s.fields()), "field 'phi_i'", "expected 2π, π or π/2");
  }
  EXPECT_FORMAT_ERROR(load_rgl("/nonexistent/x.bsdf"), "/nonexistent/x.bsdf", "file");
}

// --------------------------------------------------------------------------------------------
// Inverse warp
// --------------------------------------------------------------------------------------------

TEST(RglWarp, ClosedForms) {
  // Constant density: the CDFs are the identity, so is the inverse warp.
  const RglBrdf flat = Synthetic{}.brdf();
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  for (int n = 0; n < 1000; ++n) {
    const RglWarpPoint p{u(rng), u(rng)};
    const RglWarpPoint s = flat.vndf_inverse(p, 1.2 * u(rng), 0);
    EXPECT_NEAR(s.x, p.x, 1e-12);
    EXPECT_NEAR(s.y, p.y, 1e-12);
  }
  // Density ∝ x (exact for a bilinear interpolant): the x CDF is x², y stays uniform.
  Synthetic lin;
  lin.vndf = [](auto, auto, std::size_t x) { return float(x); };
  const RglBrdf ramp = lin.brdf();
  for (int n = 0; n < 1000; ++n) {
    const RglWarpPoint p{u(rng), u(rng)};
    const RglWarpPoint s = ramp.vndf_inverse(p, 1.2 * u(rng), 0);
    EXPECT_NEAR(s.x, p.x * p.x, 1e-12);
    EXPECT_NEAR(s.y, p.y, 1e-12);
    EXPECT_NEAR(ramp.vndf_density(p, 0.3, 0), 2 * p.x, 1e-12);
  }
  // Incidence interpolation: halfway between a slice ∝ x and a constant one, the mixture's CDF
  // (x² + x) / 2.
  Synthetic mix;
  mix.vndf = [](std::size_t slice, auto, std::size_t x) { return slice == 1 ? float(x) : 1.0f; };
  const RglBrdf mixed = mix.brdf();
  for (int n = 0; n < 200; ++n) {
    const RglWarpPoint p{u(rng), u(rng)};
    const RglWarpPoint s = mixed.vndf_inverse(p, 0.25, 0);  // halfway between θi = 0 and 0.5
    EXPECT_NEAR(s.x, 0.5 * (p.x * p.x + p.x), 1e-12);
  }
}

// forward(inverse(p)) = p where the density is positive, inverse(forward(u)) = u everywhere.
void check_round_trips(const RglBrdf& brdf, std::uint64_t seed, double* worst) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const auto thetas = brdf.theta_i();
  for (int n = 0; n < 4000; ++n) {
    // Incidences on the grid and between grid values.
    const double theta_i = n % 2 ? double(thetas[n / 2 % thetas.size()]) : 0.99 * kPi / 2 * u(rng);
    const RglWarpPoint p{u(rng), u(rng)};
    if (brdf.vndf_density(p, theta_i, 0) > 1e-3) {
      const RglWarpPoint s = brdf.vndf_inverse(p, theta_i, 0);
      const RglWarpPoint q = brdf.vndf_forward(s, theta_i, 0);
      const double e = std::max(std::abs(q.x - p.x), std::abs(q.y - p.y));
      worst[0] = std::max(worst[0], e);
      EXPECT_LT(e, 1e-9) << "p = (" << p.x << ", " << p.y << "), θi = " << theta_i;
    }
    const RglWarpPoint s{u(rng), u(rng)};
    const RglWarpPoint q = brdf.vndf_inverse(brdf.vndf_forward(s, theta_i, 0), theta_i, 0);
    const double e = std::max(std::abs(q.x - s.x), std::abs(q.y - s.y));
    worst[1] = std::max(worst[1], e);
    EXPECT_LT(e, 1e-9) << "u = (" << s.x << ", " << s.y << "), θi = " << theta_i;
  }
}

TEST(RglWarp, InverseOfForwardOnSyntheticData) {
  Synthetic s;
  s.vndf = [](std::size_t slice, std::size_t y, std::size_t x) {
    return float(0.1 + std::pow(std::sin(0.3 * double(x * (slice + 1)) + 0.2 * double(y)), 2));
  };
  double worst[2] = {0, 0};
  check_round_trips(s.brdf(), 5, worst);
}

TEST(RglWarp, InverseOfForwardOnPublishedData) {
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  for (const char* name :
       {"paper_white_rgb.bsdf", "ilm_l3_37_metallic_rgb.bsdf", "chm_mint_rgb.bsdf"}) {
    const auto brdf = load_rgl(dir / name);
    double worst[2] = {0, 0};
    check_round_trips(*brdf, 9, worst);
    std::cout << "[ info ] " << name << ": |forward(inverse(p)) - p| <= " << worst[0]
              << ", |inverse(forward(u)) - u| <= " << worst[1] << "\n";
  }
}

// --------------------------------------------------------------------------------------------
// Evaluation semantics
// --------------------------------------------------------------------------------------------

TEST(RglEval, ReturnsFrNotFrCos) {
  // jacobian = 0, uniform VNDF, constant RGB: the reference's value is the stored RGB, fr·cos θo;
  // fr is that over cos θo.
  const RglBrdf b = Synthetic{}.brdf();
  std::mt19937_64 rng(2);
  for (int n = 0; n < 200; ++n) {
    const auto wi = test::uniform_hemisphere(rng), wo = test::uniform_hemisphere(rng);
    const Rgb c = b.eval_cosine({wi, wo}), f = b.eval({wi, wo});
    EXPECT_NEAR(c.r, 0.1, 1e-6);
    EXPECT_NEAR(c.b, 0.3, 1e-6);
    EXPECT_NEAR(f.g, 0.2 / wo.z, 1e-6 / wo.z);
  }
  // jacobian = 1: × ndf / (4 σ).
  Synthetic s;
  s.jacobian = 1;
  s.ndf = 2.0f;
  s.sigma = 0.5f;
  const RglBrdf bj = s.brdf();
  EXPECT_NEAR(bj.eval_cosine({{0, 0, 1}, {0.6, 0, 0.8}}).r, 0.1 * 2.0 / (4 * 0.5), 1e-6);
  // Horizon, NaN.
  EXPECT_EQ(b.eval({{0, 0, 1}, {1, 0, 0}}), (Rgb{0, 0, 0}));
  EXPECT_EQ(b.eval({{0, 0, 1}, {0.6, 0, -0.8}}), (Rgb{0, 0, 0}));
  EXPECT_TRUE(std::isnan(b.eval({{0, 0, std::nan("")}, {0, 0, 1}}).g));
  EXPECT_FALSE(b.reciprocal());
  EXPECT_TRUE(b.isotropic());
}

// Found by fuzz/rgl_fuzz.cpp: a NaN warp coordinate reached a float-to-index conversion (undefined
// behaviour, reported by UBSan). Non-finite input must give clamped or NaN results, never UB.
TEST(RglEval, NonFiniteInputIsSafe) {
  const RglBrdf b = Synthetic{}.brdf();
  const double nan = std::nan(""), inf = INFINITY;
  const RglWarpPoint s = b.vndf_inverse({nan, nan}, nan, nan);
  EXPECT_TRUE(s.x >= 0 && s.x <= 1 && s.y >= 0 && s.y <= 1);
  const RglWarpPoint f = b.vndf_forward({nan, inf}, inf, -inf);
  EXPECT_TRUE(f.x >= 0 && f.x <= 1 && f.y >= 0 && f.y <= 1);
  EXPECT_TRUE(std::isfinite(b.vndf_density({-inf, nan}, 0.5, 0)));
  const Rgb v = b.eval({{inf, 0, 1}, {-inf, 0, 1}});  // h = NaN
  EXPECT_TRUE(std::isnan(v.r) || v.r >= 0);
  // The batch gives rows with infinite components (which its conversion rejects) to eval().
  const std::vector<DirPair<double>> odd{
      {{inf, 0, 1}, {-inf, 0, 1}}, {{0.6, 0, 0.8}, {0, inf, 1}}, {{inf, inf, 1}, {0, 0, 1}}};
  std::vector<Rgb> batch(odd.size());
  b.eval_batch(odd, batch);
  for (std::size_t i = 0; i < odd.size(); ++i) {
    const Rgb one = b.eval(odd[i]);
    for (auto [x, y] : {std::pair{one.r, batch[i].r}, {one.g, batch[i].g}, {one.b, batch[i].b}})
      EXPECT_TRUE(x == y || (std::isnan(x) && std::isnan(y))) << i << ": " << x << " " << y;
  }
  (void)b.sample({inf, inf, 1}, nan, 0.5);
  EXPECT_FALSE(b.pdf({inf, inf, 1}, {0, 0, 1}) > 0);
}

// docs/reliability/readers.md, "Measurement noise is not an error": a real file (ilm_solo_m_68_rgb)
// has sixteen luminance values between -4e-10 and -7e-11, which the reference loader reads; so must
// this reader, in every density field, while a negative value beyond the noise tolerance is refused
// with a readable number (never "-0.000000").
TEST(RglNoise, TinyNegativeDensitiesLoadAsZero) {
  Synthetic s;
  s.luminance = [](std::size_t slice, std::size_t y, std::size_t x) {
    const std::size_t k = (slice * 8 + y) * 8 + x;
    return k % 16 == 11 ? -4e-10f + 2.1e-11f * float(k / 16) : 1.0f;  // 16 values, -4e-10..-7e-11
  };
  s.vndf = [](std::size_t, std::size_t y, std::size_t x) {
    return y == 0 && x < 3 ? -2e-9f : 1.0f;
  };
  const RglBrdf plain = Synthetic{}.brdf();
  const RglBrdf noisy(parse_tensor_file(s.bytes(), "noisy.bsdf"), "noisy");
  bool found = false;
  for (const auto& f : noisy.facts())
    if (f.label == "negative values") {
      found = true;
      EXPECT_NE(f.value.find("28 tiny negative density values"), std::string::npos) << f.value;
    }
  EXPECT_TRUE(found);
  // The noise is read as 0: the same ρ as the noiseless material within float rounding.
  const DirPair<double> p{{0.3, 0.1, std::sqrt(0.9)}, {-0.2, 0.4, std::sqrt(0.8)}};
  EXPECT_NEAR(noisy.eval(p).g, plain.eval(p).g, 1e-6 * plain.eval(p).g);

  Synthetic bad;
  bad.luminance = [](std::size_t slice, auto, auto) { return slice == 1 ? -0.0123f : 1.0f; };
  try {
    (void)RglBrdf(parse_tensor_file(bad.bytes(), "bad.bsdf"), "bad");
    ADD_FAILURE() << "a luminance of -1.2% of the maximum was accepted";
  } catch (const FormatError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("field 'luminance'"), std::string::npos) << what;
    EXPECT_NE(what.find("value 64 is -0.0123,"), std::string::npos) << what;
    EXPECT_EQ(what.find("0.000000"), std::string::npos) << what;
  }
}

TEST(RglEval, SpectralVariantReadsAsItsRgb) {
  // Grey spectra (the same value at every wavelength) are that grey in RGB: the spectral file
  // evaluates like the RGB file whose three channels hold the spectra's values.
  test::Synthetic grey;
  grey.rgb = [](std::size_t s, auto, std::size_t y, std::size_t x) {
    return 0.05f * float(s + 1) + 0.01f * float(x + 2 * y);
  };
  const RglBrdf rgb = grey.brdf();
  auto fs = grey.fields();
  const std::vector<float> lambda{360, 450, 451, 700, 830};
  std::vector<float> spectra;
  for (std::size_t s = 0; s < 4; ++s)
    for (std::size_t k = 0; k < lambda.size(); ++k)
      for (std::size_t y = 0; y < 8; ++y)
        for (std::size_t x = 0; x < 8; ++x) spectra.push_back(grey.rgb(s, 0, y, x));
  fs.erase(fs.begin() + 8);  // rgb
  fs.insert(fs.begin() + 8, f32("wavelengths", {lambda.size()}, lambda));
  fs.insert(fs.begin() + 9, f32("spectra", {1, 4, lambda.size(), 8, 8}, spectra));
  const RglBrdf spectral = brdf_of(fs);
  std::mt19937_64 rng(3);
  for (int k = 0; k < 500; ++k) {
    const Vec3<double> wi = test::uniform_hemisphere(rng), wo = test::uniform_hemisphere(rng);
    const Rgb a = rgb.eval({wi, wo}), b = spectral.eval({wi, wo});
    EXPECT_NEAR(b.r, a.r, 1e-9 * (1 + a.r));
    EXPECT_NEAR(b.g, a.g, 1e-9 * (1 + a.g));
    EXPECT_NEAR(b.b, a.b, 1e-9 * (1 + a.b));
  }
  EXPECT_NE(spectral.facts()[0].value.find("spectral variant (5 wavelengths"), std::string::npos);
}

TEST(RglEval, NegativeRgbIsClampedByDefault) {
  Synthetic s;
  s.rgb = [](auto, std::size_t c, auto, auto) { return c == 0 ? -0.05f : 0.2f; };
  const TensorFile tf = parse_tensor_file(s.bytes(), "neg");
  const RglBrdf clamped(tf, "neg"), raw(tf, "neg", RglOptions{false});
  const DirPair<double> p{{0, 0, 1}, {0.6, 0, 0.8}};
  EXPECT_EQ(clamped.eval(p).r, 0.0);
  EXPECT_NEAR(raw.eval(p).r, -0.05 / 0.8, 1e-7);
}

TEST(RglEval, AnisotropicSymmetryReduction) {
  // φi covering [-π, 0] (a half-turn symmetry): ωi at +φ is evaluated as ωi at φ - π. Slices hold
  // constant RGB values 1, 2, 3 at φi = -π, -π/2, 0.
  Synthetic s;
  s.phi_i = {float(-kPi), float(-kPi / 2), 0.0f};
  s.theta_i = {0.0f, 1.5f};
  s.rgb = [](std::size_t slice, auto, auto, auto) { return float(slice / 2 + 1); };
  const RglBrdf b = s.brdf();
  EXPECT_FALSE(b.isotropic());
  auto value = [&](double phi) {
    return b.eval_cosine({test::direction(0.7, phi), test::direction(0.4, phi + 2.0)}).r;
  };
  EXPECT_NEAR(value(-kPi / 2), 2.0, 1e-6);
  EXPECT_NEAR(value(-kPi / 4), 2.5, 1e-6);
  EXPECT_NEAR(value(kPi / 2), 2.0, 1e-6);      // rotated by π onto -π/2
  EXPECT_NEAR(value(3 * kPi / 4), 2.5, 1e-6);  // onto -π/4
}

// --------------------------------------------------------------------------------------------
// Published materials
// --------------------------------------------------------------------------------------------

const std::vector<std::string>& materials() {
  static const std::vector<std::string> names{
      "acrylic_felt_green", "aurora_white",     "cardboard",          "cc_ibiza_sunset",
      "chm_mint",           "colodur_azure_4e", "ilm_l3_37_metallic", "irid_flake_paint2",
      "leaf_maple",         "paper_white",      "satin_rosaline",     "vch_golden_yellow"};
  return names;
}

struct Albedo {
  double c[3];
};

// Directional albedo ∫ fr cos θo dωo by VNDF importance sampling (the data's own warp), on a
// jittered n×n grid.
Albedo albedo_vndf(const RglBrdf& b, const Vec3<double>& wi, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  double sum[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      // The warp of the data's incidence wi, here the given direction of Brdf::sample.
      const BrdfSample s = b.sample(wi, (i + u(rng)) / n, (j + u(rng)) / n);
      if (!(s.pdf > 0) || !(s.wi.z > 0)) continue;
      const Rgb f = b.eval_cosine({wi, s.wi});
      sum[0] += f.r / s.pdf;
      sum[1] += f.g / s.pdf;
      sum[2] += f.b / s.pdf;
    }
  const double nn = double(n) * n;
  return {{sum[0] / nn, sum[1] / nn, sum[2] / nn}};
}

// The same by cosine-weighted sampling (independent of the warp), jittered n×n grid.
Albedo albedo_cosine(const RglBrdf& b, const Vec3<double>& wi, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  double sum[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u1 = (i + u(rng)) / n, u2 = (j + u(rng)) / n;
      const double r = std::sqrt(u1), phi = 2 * kPi * u2;
      const Vec3<double> wo{r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1 - u1))};
      const Rgb f = b.eval({wi, wo});
      sum[0] += f.r;
      sum[1] += f.g;
      sum[2] += f.b;
    }
  const double nn = double(n) * n;
  return {{kPi * sum[0] / nn, kPi * sum[1] / nn, kPi * sum[2] / nn}};
}

TEST(RglPublished, LoadAll) {
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  for (const auto& m : materials()) {
    const auto b = load_rgl(dir / (m + "_rgb.bsdf"));
    EXPECT_EQ(b->name(), "rgl:" + m + "_rgb");
    EXPECT_TRUE(b->isotropic()) << m;
    EXPECT_FALSE(b->material_description().empty()) << m;
    EXPECT_EQ(b->theta_i().size(), 8u) << m;
  }
}

// Brdf::sample and Brdf::pdf of the RGL materials (the VNDF warp): the pdf a sample carries is
// pdf() at its direction, and pdf() integrates over the upper hemisphere to the fraction of samples
// that stay above it. The integral is estimated with the defensive mixture q = ½ uniform + ½ the
// sampler itself (the weights pdf/q lie in [0, 2], so 2 × 20000 samples give about 0.005 of
// error, even for the sharp lobes of the glossy films); it equals the fraction only when pdf() is
// the density sample() draws from.
TEST(RglPublished, SampleAndPdfAgree) {
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (const auto& m : materials()) {
    const auto b = load_rgl(dir / (m + "_rgb.bsdf"));
    ASSERT_TRUE(b->has_importance_sampling());
    for (double theta_o : {0.1, 0.6, 1.2}) {
      const Vec3<double> wo = test::direction(theta_o, 0.4);
      int valid = 0;
      for (int k = 0; k < 400; ++k) {
        const BrdfSample s = b->sample(wo, u(rng), u(rng));
        if (!(s.pdf > 0)) continue;
        ++valid;
        EXPECT_NEAR(s.pdf, b->pdf(wo, s.wi), 1e-6 * s.pdf) << m << " θo " << theta_o;
      }
      EXPECT_GT(valid, 200) << m;
      const int n = 20000;
      const double uniform = 1 / (2 * kPi);
      auto weight = [&](const Vec3<double>& w) {
        const double p = b->pdf(wo, w);
        return p / (0.5 * uniform + 0.5 * p);
      };
      double integral = 0;
      int above = 0;
      for (int k = 0; k < n; ++k) {
        const double z = u(rng), phi = 2 * kPi * u(rng);
        const double r = std::sqrt(std::max(0.0, 1 - z * z));
        integral += weight({r * std::cos(phi), r * std::sin(phi), z});
        const BrdfSample s = b->sample(wo, u(rng), u(rng));
        if (s.pdf > 0) {
          ++above;
          integral += weight(s.wi);
        }
      }
      integral /= 2.0 * n;
      EXPECT_NEAR(integral, double(above) / n, 0.02) << m << " θo " << theta_o;
    }
  }
}

// Albedo ≤ 1 within the measurement's noise: tolerance 2% (MC error of the VNDF estimator with
// 96² jittered samples is below 0.5%, checked against a second seed). Incidences 0-60°, where
// every material has measured slices on both sides.
TEST(RglPublished, DirectionalAlbedoAtMostOne) {
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  const double tolerance = 0.02;
  for (const auto& m : materials()) {
    const auto b = load_rgl(dir / (m + "_rgb.bsdf"));
    std::cout << "[ info ] albedo " << m << ":";
    for (double deg : {0.0, 20.0, 40.0, 60.0}) {
      const Vec3<double> wi = test::direction(deg * kPi / 180, 0.7);
      const Albedo a = albedo_vndf(*b, wi, 96, 1), a2 = albedo_vndf(*b, wi, 96, 2);
      std::cout << " " << deg << "°: " << a.c[0] << "/" << a.c[1] << "/" << a.c[2];
      for (int c = 0; c < 3; ++c) {
        EXPECT_LE(a.c[c], 1 + tolerance) << m << " θi = " << deg << " channel " << c;
        EXPECT_GT(a.c[c], 0.01) << m;
        EXPECT_NEAR(a.c[c], a2.c[c], 0.005 + 0.005 * a.c[c]) << m << " (MC noise)";
      }
    }
    std::cout << "\n";
  }
}

// The importance-sampled estimate agrees with plain cosine-weighted sampling, which does not use
// the warp: a check of the inverse warp and its density together. Diffuse-looking materials only
// (cosine sampling is too noisy on the glossy films).
TEST(RglPublished, AlbedoEstimatorsAgree) {
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  for (const char* m : {"paper_white", "cardboard", "acrylic_felt_green", "colodur_azure_4e"}) {
    const auto b = load_rgl(dir / (std::string(m) + "_rgb.bsdf"));
    for (double deg : {10.0, 45.0}) {
      const Vec3<double> wi = test::direction(deg * kPi / 180, 0.2);
      const Albedo a = albedo_vndf(*b, wi, 64, 3), c = albedo_cosine(*b, wi, 128, 3);
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(a.c[k], c.c[k], 0.01 + 0.02 * c.c[k]) << m << " θi = " << deg << " ch " << k;
    }
  }
}

// The data are measured, not exactly reciprocal: report |ρ(ωi,ωo) - ρ(ωo,ωi)| / mean for pairs
// up to 70° (luminance, where ρ is not negligible). The glossy films (chm_mint, cc_ibiza_sunset)
// differ most, around their sharp specular peaks; the matte materials within a few percent.
// Loose bounds: median < 0.5 for all, < 0.05 for the matte ones.
TEST(RglPublished, ReciprocityStatistics) {
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0, 1);
  for (const auto& m : materials()) {
    const auto b = load_rgl(dir / (m + "_rgb.bsdf"));
    std::vector<double> rel;
    for (int n = 0; n < 3000; ++n) {
      const double max_theta = 70 * kPi / 180;
      const auto wi =
          test::direction(std::acos(1 - u(rng) * (1 - std::cos(max_theta))), 2 * kPi * u(rng));
      const auto wo =
          test::direction(std::acos(1 - u(rng) * (1 - std::cos(max_theta))), 2 * kPi * u(rng));
      const double a = b->eval({wi, wo}).luminance(), c = b->eval({wo, wi}).luminance();
      if (a + c < 1e-3) continue;
      rel.push_back(2 * std::abs(a - c) / (a + c));
    }
    ASSERT_GT(rel.size(), 1000u);
    std::sort(rel.begin(), rel.end());
    const double median = rel[rel.size() / 2], p90 = rel[rel.size() * 9 / 10];
    std::cout << "[ info ] reciprocity " << m << ": median " << median << ", 90% " << p90
              << ", max " << rel.back() << "\n";
    EXPECT_LT(median, 0.5) << m;
    if (m == "paper_white" || m == "acrylic_felt_green" || m == "cardboard" ||
        m == "colodur_azure_4e") {
      EXPECT_LT(median, 0.05) << m;
    }
  }
}

// No NaN, no negative values, finite everywhere on a dense grid (including grazing view).
TEST(RglPublished, DenseGridIsFiniteAndNonNegative) {
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  for (const auto& m : materials()) {
    const auto b = load_rgl(dir / (m + "_rgb.bsdf"));
    std::size_t n = 0;
    for (double ti = 0; ti <= 89.5; ti += 4.5)
      for (double to = 0; to <= 89.9; to += 4.5)
        for (double dphi = 0; dphi < 360; dphi += 15) {
          const Rgb v = b->eval({test::direction(ti * kPi / 180, 0.3),
                                 test::direction(to * kPi / 180, 0.3 + dphi * kPi / 180)});
          ++n;
          ASSERT_TRUE(std::isfinite(v.r) && std::isfinite(v.g) && std::isfinite(v.b))
              << m << " " << ti << " " << to << " " << dphi;
          ASSERT_TRUE(v.r >= 0 && v.g >= 0 && v.b >= 0)
              << m << " " << ti << " " << to << " " << dphi;
        }
    EXPECT_EQ(n, 20u * 20u * 24u);
  }
}

TEST(RglPublished, EvalIsReferenceValueOverCosine) {
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  const auto b = load_rgl(dir / "ilm_l3_37_metallic_rgb.bsdf");
  std::mt19937_64 rng(6);
  for (int n = 0; n < 1000; ++n) {
    const auto wi = test::uniform_hemisphere(rng), wo = test::uniform_hemisphere(rng);
    const Rgb f = b->eval({wi, wo}), c = b->eval_cosine({wi, wo});
    EXPECT_NEAR(f.r * wo.z, c.r, 1e-12 * std::abs(c.r) + 1e-300);
  }
}

// White paper: ρ roughly constant away from grazing (within ±25% of its mean for θi, θo ≤ 50°,
// no forward-scattering lobe there), albedo in [0.75, 1].
TEST(RglPublished, PaperWhiteIsNearLambertian) {
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  const auto b = load_rgl(dir / "paper_white_rgb.bsdf");
  std::vector<double> values;
  for (double ti = 0; ti <= 50; ti += 5)
    for (double to = 0; to <= 50; to += 5)
      for (double dphi = 0; dphi < 360; dphi += 30)
        values.push_back(b->eval({test::direction(ti * kPi / 180, 0),
                                  test::direction(to * kPi / 180, dphi * kPi / 180)})
                             .luminance());
  double mean = 0;
  for (double v : values) mean += v;
  mean /= double(values.size());
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  std::cout << "[ info ] paper_white ρ (θ <= 50°): mean " << mean << ", min " << *lo << ", max "
            << *hi << " sr^-1\n";
  EXPECT_GT(*lo, 0.75 * mean);
  EXPECT_LT(*hi, 1.25 * mean);
  const Albedo a = albedo_vndf(*b, test::direction(0.3, 0), 96, 1);
  for (double c : a.c) {
    EXPECT_GT(c, 0.75);
    EXPECT_LT(c, 1.0);
  }
  EXPECT_NEAR(mean * kPi, (Rgb{a.c[0], a.c[1], a.c[2]}.luminance()), 0.1);
}

// --------------------------------------------------------------------------------------------
// Batch evaluation
// --------------------------------------------------------------------------------------------

// Random pairs with the rows eval() treats apart shuffled among them: NaN, below and at the
// horizon, grazing, not unit, in the plane of incidence (azimuths ±π, signed zeros), ωi or the
// half vector along the normal, mirror pairs.
std::vector<DirPair<double>> batch_pairs(std::size_t random) {
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<DirPair<double>> p;
  for (std::size_t n = 0; n < random; ++n)
    p.push_back({test::uniform_hemisphere(rng), test::uniform_hemisphere(rng)});
  for (int n = 0; n < 200; ++n) {
    const double phi = 2 * kPi * u(rng), z = std::pow(10.0, -9 + 8 * u(rng));  // grazing
    const Vec3<double> g = test::direction(std::acos(z), phi), o = test::uniform_hemisphere(rng);
    p.push_back({g, o});
    p.push_back({o, g});
    const double t = 1.4 * u(rng), to = 1.4 * u(rng);  // in the plane y = ±0, either side
    p.push_back({{-std::sin(t), 0.0, std::cos(t)}, {std::sin(to), -0.0, std::cos(to)}});
    p.push_back({{-std::sin(t), -0.0, std::cos(t)}, {-std::sin(to), 0.0, std::cos(to)}});
    p.push_back({o, {-o.x, -o.y, o.z}});  // mirror: the half vector is the normal
    p.push_back({{0.0, -0.0, 1.0}, o});   // ωi along the normal
    p.push_back({o, {o.x, o.y, -o.z}});   // below the horizon
  }
  const double nan = std::nan("");
  p.push_back({{0, 0, nan}, {0, 0, 1}});
  p.push_back({{0.6, nan, 0.8}, {0, 0, 1}});
  p.push_back({{0.6, 0, 0.8}, {0, 0, 1e-300}});
  p.push_back({{1, 0, 0}, {0, 0.6, 0.8}});        // at the horizon
  p.push_back({{0.66, 0, 0.88}, {0, 0.6, 0.8}});  // not unit: eval() takes it as given
  p.push_back({{0.3, 0.4, 0.5}, {0.1, -0.2, 0.3}});
  std::shuffle(p.begin(), p.end(), rng);  // special rows inside SIMD vectors and blocks
  return p;
}

bool same_value(double a, double b) {
  return a == b || (std::isnan(a) && std::isnan(b));
}

// eval_batch against eval() pair by pair. The batch's angles come from the SIMD atan2 of the batch
// engine (within a few ulps of libm's) and its half vector is normalized first; the values are
// continuous in the angles (bilinear tables, linear blends of slices), so they agree to ~1e-13
// relative (at most 7e-15 of |value| + the largest value on the published files), and rows near a
// discontinuity (an azimuth seam, the normal) are eval()'s own. The tolerance is 1e-12 of
// |value| + the largest value (the latter for values clamped near 0). Returns how many rows are
// bit-identical.
std::size_t expect_batch_is_eval(const RglBrdf& b, const std::vector<DirPair<double>>& pairs) {
  std::vector<Rgb> batch(pairs.size());
  b.eval_batch(pairs, batch);
  std::vector<Rgb> one(pairs.size());
  double peak = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    one[i] = b.eval(pairs[i]);
    for (double x : {one[i].r, one[i].g, one[i].b})
      if (std::isfinite(x)) peak = std::max(peak, std::abs(x));
  }
  std::size_t identical = 0, checked = 0;
  double worst = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    bool same = true;
    for (auto [a, c] :
         {std::pair{one[i].r, batch[i].r}, {one[i].g, batch[i].g}, {one[i].b, batch[i].b}}) {
      same = same && same_value(a, c);
      if (std::isnan(a) || a == 0 || !(pairs[i].wi.z > 0) || !(pairs[i].wo.z > 0)) {
        EXPECT_TRUE(same_value(a, c)) << i << ": " << a << " " << c;  // NaN, horizon: exact
        continue;
      }
      ++checked;
      worst = std::max(worst, std::abs(a - c) / (std::abs(a) + peak));
      EXPECT_NEAR(c, a, 1e-12 * (std::abs(a) + peak)) << i;
    }
    identical += same ? 1 : 0;
  }
  EXPECT_GT(checked, pairs.size());  // most rows have positive values to compare
  std::cout << "[ info ] " << b.name() << ": " << identical << " of " << pairs.size()
            << " rows bit-identical, largest |batch - eval| / (|eval| + peak) " << worst << "\n";
  return identical;
}

TEST(RglBatch, EqualsEvalOnSyntheticAnisotropicData) {
  // Tables varying everywhere, three φi slices covering a half-turn (the symmetry flips), the
  // NDF/sigma Jacobian, negative RGB values to clamp.
  Synthetic s;
  s.phi_i = {float(-kPi), float(-kPi / 2), 0.0f};
  s.theta_i = {0.0f, 0.4f, 0.9f, 1.5f};
  s.vndf = [](std::size_t slice, std::size_t y, std::size_t x) {
    return float(1 + slice + 0.5 * std::sin(0.7 * double(x) + 0.3 * double(y)));
  };
  s.rgb = [](std::size_t slice, std::size_t c, std::size_t y, std::size_t x) {
    return float(0.2 * std::cos(0.9 * double(x) - 0.4 * double(y) + double(c + slice)) + 0.05);
  };
  s.jacobian = 1;
  const RglBrdf b = s.brdf();
  ASSERT_FALSE(b.isotropic());
  // The block kernel in the version of every instruction set (isa_versions.hpp: what HALFBACK_ISA
  // runs; the conversion too runs that set's kernels).
  test::under_every_isa([&](SimdIsa) { expect_batch_is_eval(b, batch_pairs(3000)); });
  // One pair at a time, and a batch split anywhere, give the same values as the whole batch (the
  // rows of a block are independent).
  const auto pairs = batch_pairs(500);
  std::vector<Rgb> whole(pairs.size()), parts(pairs.size());
  b.eval_batch(pairs, whole);
  const std::span<const DirPair<double>> p(pairs);
  const std::span<Rgb> o(parts);
  for (auto [first, last] :
       {std::pair<std::size_t, std::size_t>{0, 1}, {1, 17}, {17, 200}, {200, pairs.size()}})
    b.eval_batch(p.subspan(first, last - first), o.subspan(first, last - first));
  for (std::size_t i = 0; i < pairs.size(); ++i)
    EXPECT_TRUE(same_value(whole[i].r, parts[i].r) && same_value(whole[i].g, parts[i].g) &&
                same_value(whole[i].b, parts[i].b))
        << i;
  EXPECT_THROW(b.eval_batch(pairs, o.first(3)), std::invalid_argument);
}

TEST(RglBatch, EqualsEvalOnPublishedData) {
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  const auto pairs = batch_pairs(20000);
  for (const char* m : {"ilm_l3_37_metallic", "chm_mint", "paper_white"}) {
    const auto b = load_rgl(dir / (std::string(m) + "_rgb.bsdf"));
    // Most rows are bit-identical: the SIMD atan2 usually rounds as libm's does.
    EXPECT_GT(expect_batch_is_eval(*b, pairs), pairs.size() / 10) << m;
  }
}

// --------------------------------------------------------------------------------------------
// Batched sampling (the renderer's path): the guided warp, sample_batch, pdf_batch
// --------------------------------------------------------------------------------------------

Vec3<double> unit_direction(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// The forward warp started from the slices' guide tables returns the point of the plain binary
// searches bit for bit: random numbers, the ends 0 and 1 and grid values, any incidence.
void expect_guided_warp_is_search(const RglBrdf& b, int n) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  int differ = 0;
  for (int k = 0; k < n; ++k) {
    const double theta = u(rng) * kPi / 2, phi = (2 * u(rng) - 1) * kPi;
    RglWarpPoint p{u(rng), u(rng)};
    if (k % 8 == 0) p = {double(k % 9) / 8, double(k % 5) / 4};
    const RglWarpPoint a = b.vndf_forward(p, theta, phi);
    const RglWarpPoint r = b.vndf_forward_by_search(p, theta, phi);
    differ += a.x != r.x || a.y != r.y;
  }
  EXPECT_EQ(differ, 0) << b.name();
}

TEST(RglSampling, GuidedWarpEqualsBinarySearch) {
  Synthetic s;  // several φi slices (anisotropic), tables varying everywhere, zero rows
  s.phi_i = {float(-kPi), float(-kPi / 2), 0.0f};
  s.theta_i = {0.0f, 0.4f, 0.9f, 1.5f};
  s.vndf = [](std::size_t slice, std::size_t y, std::size_t x) {
    if (y == 2) return 0.0f;
    return float(std::pow(std::sin(0.3 * double(x * (slice + 1)) + 0.2 * double(y)), 4));
  };
  expect_guided_warp_is_search(s.brdf(), 20000);
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  for (const char* m : {"ilm_l3_37_metallic", "chm_mint", "paper_white", "irid_flake_paint2"})
    expect_guided_warp_is_search(*load_rgl(dir / (std::string(m) + "_rgb.bsdf")), 20000);
}

// sample_batch and pdf_batch (the SIMD angles) against sample and pdf one at a time: the same
// directions and densities up to rounding; rows at the seam, on the axis, at or below the horizon
// or not unit go through sample and pdf and are equal exactly.
void expect_batches_are_one_at_a_time(const RglBrdf& b) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3<double>> wo;
  std::vector<double> u1, u2;
  for (int k = 0; k < 3000; ++k) {
    const double theta = k % 50 == 0 ? 0.0 : std::acos(u(rng)), phi = (2 * u(rng) - 1) * kPi;
    wo.push_back(k % 37 == 0 ? Vec3<double>{-std::sin(theta), 0.0, std::cos(theta)}  // φ = π
                             : unit_direction(theta, phi));
    u1.push_back(u(rng));
    u2.push_back(u(rng));
  }
  wo.push_back({0, 0, -1});
  u1.push_back(0.5);
  u2.push_back(0.5);
  std::vector<BrdfSample> batch(wo.size());
  b.sample_batch(wo, u1, u2, batch);
  std::vector<DirPair<double>> pairs;
  int mismatched = 0;
  for (std::size_t k = 0; k < wo.size(); ++k) {
    const BrdfSample one = b.sample(wo[k], u1[k], u2[k]);
    const bool both = one.pdf > 0 && batch[k].pdf > 0;
    if (!both) {  // only at the horizon may rounding decide differently
      mismatched += (one.pdf > 0) != (batch[k].pdf > 0);
      continue;
    }
    EXPECT_NEAR(batch[k].pdf, one.pdf, 1e-9 * one.pdf) << k;
    EXPECT_NEAR(batch[k].wi.x, one.wi.x, 1e-12) << k;
    EXPECT_NEAR(batch[k].wi.y, one.wi.y, 1e-12) << k;
    EXPECT_NEAR(batch[k].wi.z, one.wi.z, 1e-12) << k;
    pairs.push_back({one.wi, wo[k]});
    pairs.push_back({unit_direction(std::acos(u(rng)), 2 * kPi * u(rng)), wo[k]});
  }
  EXPECT_LE(mismatched, 2) << b.name();
  pairs.push_back({{0, 0, 1}, {0, 0, 1}});            // both along the normal
  pairs.push_back({{0.6, 0, 0.8}, {-0.6, 0, 0.8}});   // the half vector along the normal
  pairs.push_back({{0.6, 0, 0.8}, {0.6, 0, -0.8}});   // below the horizon
  pairs.push_back({{0.66, 0, 0.88}, {0, 0.6, 0.8}});  // not unit
  pairs.push_back({{0, 0, std::nan("")}, {0, 0, 1}});
  std::vector<double> pdfs(pairs.size());
  b.pdf_batch(pairs, pdfs);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const double one = b.pdf(pairs[k].wo, pairs[k].wi);
    if (!(one > 0) || !std::isfinite(one))
      EXPECT_TRUE(pdfs[k] == one || (std::isnan(one) && std::isnan(pdfs[k]))) << k;
    else
      EXPECT_NEAR(pdfs[k], one, 1e-9 * one) << k;
  }
  EXPECT_THROW(b.pdf_batch(pairs, std::span(pdfs).first(1)), std::invalid_argument);
  EXPECT_THROW(b.sample_batch(wo, u1, std::span(u2).first(1), batch), std::invalid_argument);
}

TEST(RglSampling, BatchesEqualOneAtATime) {
  Synthetic s;
  s.phi_i = {float(-kPi), float(-kPi / 2), 0.0f};  // anisotropic, a half-turn symmetry
  s.theta_i = {0.0f, 0.4f, 0.9f, 1.5f};
  s.vndf = [](std::size_t slice, std::size_t y, std::size_t x) {
    return float(1 + slice + 0.5 * std::sin(0.7 * double(x) + 0.3 * double(y)));
  };
  // The warp's block loops in the version of every instruction set (isa_versions.hpp).
  const RglBrdf b = s.brdf();
  test::under_every_isa([&](SimdIsa) { expect_batches_are_one_at_a_time(b); });
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  for (const char* m : {"ilm_l3_37_metallic", "chm_mint", "paper_white"})
    expect_batches_are_one_at_a_time(*load_rgl(dir / (std::string(m) + "_rgb.bsdf")));
}

// The batched sampler's directions follow the batched pdf: χ² over (cos θ, φ) cells, the cells
// within 10° of the mirror direction (where the pdf has an integrable singularity, from the warp's
// u = √(2θm/π)) pooled with the failed samples. The incidences fall between slices, where the
// sampler draws a slice of the blend (Warp::draw): 2 slices for the published (isotropic) data, 4
// for the synthetic anisotropic data, whose slices differ strongly.
void expect_sampler_follows_pdf(const RglBrdf& b, const std::string& m) {
  for (double theta_o : {0.3, 1.0}) {
    const Vec3<double> wo = unit_direction(theta_o, 0.7);
    const auto r = render::testing::chi2_test(
        [&](double u1, double u2) {
          BrdfSample x;
          b.sample_batch(std::span(&wo, 1), std::span(&u1, 1), std::span(&u2, 1), std::span(&x, 1));
          return render::testing::DirSample{x.wi, x.pdf};
        },
        [&](const Vec3<double>& wi) {
          double p;
          const DirPair<double> pair{wi, wo};
          b.pdf_batch(std::span(&pair, 1), std::span(&p, 1));
          return p;
        },
        100000, false, 16, 32, 24, 7, {-wo.x, -wo.y, wo.z}, 10);
    EXPECT_LE(r.integral, 1.02) << m << " θo " << theta_o;
    EXPECT_NEAR(r.integral, r.valid_fraction, 0.02) << m << " θo " << theta_o;
    EXPECT_LT(r.z, 4.5) << m << " θo " << theta_o << " χ² " << r.chi2 << " dof " << r.dof;
  }
}

TEST(RglSampling, BatchSamplerChiSquare) {
  Synthetic s;
  s.phi_i = {float(-kPi), float(-kPi / 2), 0.0f};  // anisotropic, a half-turn symmetry
  s.theta_i = {0.0f, 0.7f, 1.5f};
  s.vndf = [](std::size_t slice, std::size_t y,
              std::size_t x) {  // a lobe moving with the slice, away from the
    // mirror direction (x = 0: the integrable singularity, pooled in the test)
    const double dx = double(x) - 5.0 - double(slice),
                 dy = double(y) - 2.0 - 4.0 * double(slice % 3);
    return float(0.05 + std::exp(-0.1 * (dx * dx + dy * dy)));
  };
  expect_sampler_follows_pdf(s.brdf(), "synthetic");
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  for (const char* m : {"ilm_l3_37_metallic", "paper_white"})
    expect_sampler_follows_pdf(*load_rgl(dir / (std::string(m) + "_rgb.bsdf")), m);
}

// docs/reliability/readers.md, "Nothing is allocated from a size a file declares before the file is
// checked to hold it": a tensor file declaring a field far larger than itself is refused before
// anything is allocated from that shape; a real file costs a small multiple of its size (the bytes,
// and the float tables as doubles).
TEST(RglAllocation, BoundedByTheFile) {
  test::TempDir tmp;
  auto fields = Synthetic{}.fields();
  find(fields, "rgb")->shape = {1, 4, 3, 1u << 20, 1u << 20};
  const std::vector<std::byte> hostile = serialize_tensor_file(fields);
  test::write_bytes(tmp / "hostile.bsdf", hostile.data(), hostile.size());
  {
    test::AllocationProbe probe;
    EXPECT_FORMAT_ERROR(load_rgl(tmp / "hostile.bsdf"), "field 'rgb'", "larger than the file");
    EXPECT_LT(probe.growth(), 4 * hostile.size() + 64 * 1024) << probe.growth();
  }
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  const auto real = dir / "paper_white_rgb.bsdf";
  test::AllocationProbe probe;
  (void)load_rgl(real);
  EXPECT_LT(probe.growth(), 8 * std::filesystem::file_size(real)) << probe.growth();
}

// docs/reliability/readers.md, "A reader reads what the file's header declares, and nothing more":
// a tensor file ends where its last field does (the writers' zero padding to 8 bytes aside).
// Trailing data is refused with both byte counts, and a small file extended to a gigabyte (sparse,
// as `truncate -s` makes it) is refused without reading the extension.
TEST(RglTrailingData, RefusedUnreadWithBothCounts) {
  test::TempDir tmp;
  std::vector<std::byte> bytes = Synthetic{}.bytes();
  const TensorFile tf = parse_tensor_file(bytes, "m");
  std::uint64_t end = 0;
  for (const TensorField& f : tf.fields) end = std::max(end, f.offset + f.bytes.size());
  // The published files end at their last field, halfback's writer pads it to 8 bytes.
  bytes.resize(end);
  EXPECT_NO_THROW(parse_tensor_file(bytes, "exact"));
  bytes.resize((end + 7) / 8 * 8 + 1);
  EXPECT_FORMAT_ERROR(parse_tensor_file(bytes, "m.bsdf"), std::string("m.bsdf: file size"),
                      "declares " + std::to_string(end) + " bytes",
                      "has " + std::to_string(bytes.size()) + " bytes",
                      std::string("of trailing data"));
  bytes.resize(end + 1);
  bytes.back() = std::byte{7};  // not the writers' zero padding
  EXPECT_FORMAT_ERROR(parse_tensor_file(bytes, "m.bsdf"), "1 byte of trailing data");

  bytes.resize(end);
  const auto sparse = tmp / "sparse.bsdf";
  test::write_bytes(sparse, bytes.data(), bytes.size());
  std::filesystem::resize_file(sparse, std::uintmax_t(1) << 30);
  test::AllocationProbe probe;
  EXPECT_FORMAT_ERROR(load_rgl(sparse), "sparse.bsdf", "has 1073741824 bytes", "trailing data");
  EXPECT_LT(probe.growth(), 4 * end + 64 * 1024) << probe.growth();
}

// docs/reliability/readers.md, "One bound on a BRDF's value": ρ·cos θo = rgb · ndf / (4 sigma) can
// reach at most the largest |rgb| times the largest ndf over 4 times the smallest sigma: a file
// where that exceeds the bound on ρ is refused, naming the fields and their extremes (an ndf value
// of 1e30 gave ρ = 1e31).
TEST(RglBound, TablesAboveTheBoundAreRefused) {
  Synthetic s;
  s.jacobian = 1;
  EXPECT_NO_THROW(s.brdf());
  auto fields = s.fields();
  std::vector<float> ndf(2 * s.w, 1.0f);
  ndf[17] = 1e30f;
  *find(fields, "ndf") = test::f32("ndf", {2, s.w}, ndf);
  EXPECT_FORMAT_ERROR(brdf_of(fields), "m.bsdf", "fields 'rgb', 'ndf' and 'sigma'",
                      "ρ·cos θo = 7.5e+28 sr⁻¹ at the tables' extremes",
                      "above the bound of 1e+10 sr⁻¹ on a BRDF's value",
                      "the largest 'ndf', value 17, 1e+30");
  s.sigma = 1e-12f;  // divides ρ
  EXPECT_FORMAT_ERROR(s.brdf(), "the smallest 'sigma', value 0, 1e-12");
  // Without the Jacobian, rgb alone is ρ·cos θo.
  Synthetic plain;
  plain.rgb = [](auto, auto, auto, auto) { return 2e10f; };
  EXPECT_FORMAT_ERROR(plain.brdf(), "field 'rgb'", "ρ·cos θo = 2e+10 sr⁻¹");
  // The published materials are far below the bound (chm_mint, the sharpest, 7e6).
  HALFBACK_REQUIRE_SHARED(dir, "rgl");
  EXPECT_NO_THROW(load_rgl(dir / "chm_mint_rgb.bsdf"));
}

}  // namespace
}  // namespace halfback
