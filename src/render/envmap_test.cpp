// Environment maps: the lat-long convention, lookups, rotation and exposure, importance sampling
// (pdf integrates to 1, sample/pdf/eval agree, χ²), the real maps of shared/, and bad input.
#include "halfback/render/envmap.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <numbers>
#include <random>
#include <string>

#include "halfback/render/distribution.hpp"
#include "halfback/render/image.hpp"
#include "halfback/util/format_error.hpp"
#include "support/allocation_probe.hpp"
#include "support/test_stats.hpp"
#include "support/test_support.hpp"

namespace halfback::render {
namespace {

constexpr double kPi = std::numbers::pi;

std::filesystem::path shared_envmaps() {
  const char* dir = std::getenv("HALFBACK_SHARED_DIR");
  return dir ? std::filesystem::path(dir) / "data" / "envmaps" : std::filesystem::path();
}

#define REQUIRE_SHARED(path)                                             \
  if (!std::filesystem::exists(path)) {                                  \
    const char* ci = std::getenv("CI");                                  \
    if (ci && std::string(ci) == "true") FAIL() << "missing " << (path); \
    GTEST_SKIP() << "shared data not found: " << (path)                  \
                 << " (set HALFBACK_SHARED_DIR to the shared/ folder)";  \
  }

void write_text(const std::filesystem::path& p, const std::string& s) {
  std::ofstream(p, std::ios::binary) << s;
}

// A small map with random non-negative values and a few bright pixels.
EnvMap random_map(int w, int h, EnvOptions o = {}, std::uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<float> rgb(std::size_t(w * h * 3));
  for (float& v : rgb) v = u(rng) < 0.1f ? 20 * u(rng) : u(rng);
  rgb[0] = rgb[1] = rgb[2] = 0;  // a black pixel is never sampled
  return EnvMap(w, h, std::move(rgb), "random", o);
}

Vec3<double> unit(double x, double y, double z) {
  const double l = std::sqrt(x * x + y * y + z * z);
  return {x / l, y / l, z / l};
}

TEST(Distribution, SamplesFollowTheWeights) {
  const std::vector<double> w{1, 0, 3, 0, 4};
  const Distribution1D d(w);
  EXPECT_DOUBLE_EQ(d.probability(2), 3.0 / 8);
  std::vector<int> count(5, 0);
  constexpr int n = 80000;
  for (int i = 0; i < n; ++i) {
    const auto s = d.sample((i + 0.5) / n);
    ++count[s.index];
    EXPECT_GE(s.remapped, 0);
    EXPECT_LT(s.remapped, 1);
  }
  EXPECT_EQ(count[1], 0);
  EXPECT_EQ(count[3], 0);
  EXPECT_NEAR(count[2], n * 3 / 8, 2);
  EXPECT_NEAR(count[4], n / 2, 2);
  EXPECT_THROW(Distribution1D(std::vector<double>{1, -1}), std::invalid_argument);
  EXPECT_THROW(Distribution1D(std::vector<double>{}), std::invalid_argument);
  EXPECT_EQ(Distribution1D(std::vector<double>{0, 0}).sample(0.5).probability, 0);
}

TEST(EnvMap, LatLongConvention) {
  auto near = [](const Vec3<double>& a, const Vec3<double>& b) {
    return std::abs(a.x - b.x) < 1e-12 && std::abs(a.y - b.y) < 1e-12 &&
           std::abs(a.z - b.z) < 1e-12;
  };
  EXPECT_TRUE(near(EnvMap::map_direction(0.5, 0.5), {0, 0, -1}));  // centre: where the camera looks
  EXPECT_TRUE(near(EnvMap::map_direction(0.75, 0.5), {1, 0, 0}));  // right half: +x
  EXPECT_TRUE(near(EnvMap::map_direction(0.25, 0.5), {-1, 0, 0}));
  EXPECT_TRUE(near(EnvMap::map_direction(0.0, 0.5), {0, 0, 1}));  // edges: behind the camera
  EXPECT_NEAR(EnvMap::map_direction(0.3, 0).y, 1, 1e-12);         // top row: zenith, +y
  double u, v;
  EnvMap::map_coordinates(unit(0.3, -0.4, 0.5), u, v);
  const auto d = EnvMap::map_direction(u, v);
  EXPECT_TRUE(near(d, unit(0.3, -0.4, 0.5)));

  // A 4 × 2 map with one distinct pixel per quadrant of directions.
  std::vector<float> rgb(24, 0);
  for (int i = 0; i < 8; ++i) rgb[std::size_t(3 * i)] = float(i + 1);
  const EnvMap m(4, 2, rgb, "quadrants");
  EXPECT_EQ(m.eval({0, 0.5, -0.8}).r, 2 + 1);  // upper row, column 2 (φ in [0, π/2))
  EXPECT_EQ(m.eval(unit(0.1, -0.5, -0.8)).r, 6 + 1);
  EXPECT_EQ(m.eval(unit(-0.1, 0.5, -0.8)).r, 1 + 1);
  EXPECT_EQ(m.eval(unit(0.1, 0.5, 0.8)).r, 3 + 1);
}

TEST(EnvMap, RotationAndExposure) {
  const EnvMap a = random_map(64, 32);
  const EnvMap b = random_map(64, 32, {90, 2});
  // Turning by +90° about +y moves what was at −z to −x (counter-clockwise seen from above).
  const Vec3<double> d = unit(0.2, 0.3, -0.9);
  const Vec3<double> turned{d.z, d.y, -d.x};  // R_y(+90°) d
  const Rgb x = a.eval(d), y = b.eval(turned);
  EXPECT_NEAR(y.r, 4 * x.r, 1e-5);
  EXPECT_NEAR(y.g, 4 * x.g, 1e-5);
  EXPECT_NEAR(b.pdf(turned), a.pdf(d), 1e-9 * a.pdf(d));
}

TEST(EnvMap, ConstantIsUniform) {
  const EnvMap c = EnvMap::from_spec("constant:0.5,1,2");
  EXPECT_EQ(c.eval(unit(1, 2, 3)).g, 1);
  EXPECT_EQ(c.eval(unit(1, 2, 3)).b, 2);
  for (const auto& d : {unit(0, 1, 0), unit(1, 0, 0), unit(0.2, -0.9, 0.1)})
    EXPECT_NEAR(c.pdf(d), 1 / (4 * kPi), 1e-12);
  const auto s = c.sample(0.3, 0.8);
  EXPECT_NEAR(s.pdf, 1 / (4 * kPi), 1e-12);
  EXPECT_EQ(EnvMap::from_spec("constant:3").eval({0, 0, 1}).r, 3);
  const EnvMap black = EnvMap::from_spec("constant:0");
  EXPECT_EQ(black.sample(0.5, 0.5).pdf, 0);
  EXPECT_EQ(black.pdf({0, 0, 1}), 0);
}

TEST(EnvMap, SampleAgreesWithPdfAndEval) {
  for (const EnvMap& m : {random_map(64, 32, {37, 0}), EnvMap::default_sky({-20, 1})}) {
    std::mt19937_64 rng(2);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < 5000; ++i) {
      const auto s = m.sample(u(rng), u(rng));
      ASSERT_GT(s.pdf, 0);
      EXPECT_NEAR(std::hypot(s.dir.x, s.dir.y, s.dir.z), 1, 1e-12);
      // Away from pixel borders the direction maps back to its own pixel.
      const double p = m.pdf(s.dir);
      if (std::abs(p - s.pdf) > 1e-9 * s.pdf) {
        double uu, vv;
        EnvMap::map_coordinates(s.dir, uu, vv);
        const double fu = uu * m.width() - std::floor(uu * m.width());
        const double fv = vv * m.height() - std::floor(vv * m.height());
        EXPECT_TRUE(std::min(fu, 1 - fu) < 1e-6 || std::min(fv, 1 - fv) < 1e-6) << i;
      } else {
        const Rgb e = m.eval(s.dir);
        EXPECT_EQ(e.r, s.radiance.r);
        EXPECT_EQ(e.b, s.radiance.b);
      }
    }
  }
}

TEST(EnvMap, PdfIntegratesToOneAndChiSquare) {
  // The sphere's (cos, φ) cells do not line up with the map's pixels (the map is rotated).
  const EnvMap m = random_map(32, 16, {23, 0}, 5);
  // Directions in the test's frame: z is the map's up axis (+y).
  auto to_world = [](const Vec3<double>& d) { return Vec3<double>{d.x, d.z, -d.y}; };
  auto from_world = [](const Vec3<double>& d) { return Vec3<double>{d.x, -d.z, d.y}; };
  const auto r = testing::chi2_test(
      [&](double u1, double u2) {
        const auto s = m.sample(u1, u2);
        return testing::DirSample{from_world(s.dir), s.pdf};
      },
      [&](const Vec3<double>& d) { return m.pdf(to_world(d)); }, 300000, true, 48, 96, 16);
  EXPECT_NEAR(r.integral, 1, 2e-3);
  EXPECT_EQ(r.valid_fraction, 1);
  EXPECT_LT(r.z, 4.5) << "chi2 " << r.chi2 << " dof " << r.dof;
}

// The brightest pixel's direction, in the map's world frame.
Vec3<double> brightest(const EnvMap& m) {
  std::size_t best = 0;
  const auto px = m.pixels();
  for (std::size_t p = 0; p < px.size() / 3; ++p)
    if (px[3 * p] + px[3 * p + 1] + px[3 * p + 2] >
        px[3 * best] + px[3 * best + 1] + px[3 * best + 2])
      best = p;
  const int c = int(best % std::size_t(m.width())), r = int(best / std::size_t(m.width()));
  return EnvMap::map_direction((c + 0.5) / m.width(), (r + 0.5) / m.height());
}

TEST(EnvMap, BuiltInStudioAndSunset) {
  for (const std::string& name : EnvMap::builtin_names()) {
    const EnvMap m = EnvMap::from_spec(name);
    EXPECT_EQ(m.width(), 2 * m.height()) << name;
    for (float v : m.pixels()) ASSERT_TRUE(std::isfinite(v) && v >= 0) << name;
  }
  const double deg = kPi / 180;
  // Sunset: the sun 4° above the horizon, 110° from +z towards +x (to the right, behind).
  const Vec3<double> s = brightest(EnvMap::sunset());
  EXPECT_NEAR(std::asin(s.y), 4 * deg, 2.5 * deg);
  EXPECT_NEAR(std::atan2(s.x, s.z), 110 * deg, 2.5 * deg);
  EXPECT_GT(EnvMap::sunset().eval(s).r, 100);
  // Studio: the key softbox (40° up, 40° to the left of +z) at radiance (9, 8.2, 7); the walls dim.
  const EnvMap st = EnvMap::studio();
  const Vec3<double> key{-std::cos(40 * deg) * std::sin(40 * deg), std::sin(40 * deg),
                         std::cos(40 * deg) * std::cos(40 * deg)};
  EXPECT_NEAR(st.eval(key).r, 9.0, 1e-6);
  EXPECT_NEAR(st.eval(key).b, 7.0, 1e-6);
  EXPECT_LT(st.eval({0, 0, -1}).r, 0.1);
  EXPECT_THROW(EnvMap::from_spec("studio2"), std::exception);
}

// One name for the default environment everywhere, "sky" (the CLI and Python used to say
// "default", the explorer "sky"); "default" is still taken, and is the same map.
TEST(EnvMap, TheSkyHasOneName) {
  EXPECT_EQ(EnvMap::builtin_names(), (std::vector<std::string>{"sky", "studio", "sunset"}));
  const EnvMap sky = EnvMap::from_spec("sky"), old = EnvMap::from_spec("default");
  EXPECT_EQ(sky.name(), "sky");
  EXPECT_EQ(old.name(), "sky");
  for (const Vec3<double>& d : {Vec3<double>{0, 1, 0}, Vec3<double>{0.6, 0, 0.8}})
    EXPECT_EQ(sky.eval(d).g, old.eval(d).g);
  EXPECT_EQ(load_environment("default").label, "sky (built-in)");
}

TEST(EnvMap, DefaultSkyHasASun) {
  const EnvMap d = EnvMap::from_spec("default");
  EXPECT_EQ(d.width(), 1024);
  EXPECT_EQ(d.height(), 512);
  // The sun: 40° up, 35° from +z towards −x.
  const double e = 40 * kPi / 180, a = 35 * kPi / 180;
  const Vec3<double> sun{-std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a)};
  EXPECT_GT(d.eval(sun).r, 500);
  EXPECT_LT(d.eval({0, 1, 0}).r, 1);
  EXPECT_LT(d.eval({0, -1, 0}).r, d.eval({0, 1, 0}).b);  // ground darker than the sky
  EXPECT_GT(d.pdf(sun), 100 * d.pdf({0, 1, 0}));
}

TEST(EnvMap, RealMaps) {
  const auto dir = shared_envmaps();
  REQUIRE_SHARED(dir / "uffizi.hdr");
  for (const char* name : {"uffizi", "grace", "pisa", "ennis", "wells", "venice_sunset_1k"}) {
    const EnvMap m = EnvMap::load(dir / (std::string(name) + ".hdr"));
    EXPECT_EQ(m.width(), 2 * m.height()) << name;
    EXPECT_GT(m.pdf(m.sample(0.5, 0.5).dir), 0) << name;
  }
  const EnvMap u = EnvMap::load(dir / "uffizi.hdr");
  EXPECT_EQ(u.width(), 256);
  // The uffizi probe has its bright sky at the top: the zenith outshines the floor.
  EXPECT_GT(u.eval({0, 1, 0}).r, 4 * u.eval({0, -1, 0}).r);
}

TEST(EnvMap, OpenExrRoundTrip) {
  Image img{8, 4, {}};
  for (int i = 0; i < 32 * 3; ++i) img.rgb.push_back(float(i) * 0.25f);
  const test::TempDir tmp;
  const auto p = tmp / "ok.exr";
  write_exr(p, img);
  const EnvMap m = EnvMap::load(p);
  EXPECT_EQ(m.width(), 8);
  EXPECT_EQ(m.pixels()[5], img.rgb[5]);
  EXPECT_EQ(EnvMap::from_spec(p.string()).pixels()[95], img.rgb[95]);
}

// Every bad input gets a FormatError naming the file and the problem.
void expect_error(const std::filesystem::path& p, const std::string& words) {
  try {
    EnvMap::load(p);
    ADD_FAILURE() << "no error for " << p;
  } catch (const FormatError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(p.string()), std::string::npos) << what;
    EXPECT_NE(what.find(words), std::string::npos) << what;
  }
}

// docs/reliability/readers.md, "Nothing is allocated from a size a file declares before the file is
// checked to hold it": a small file whose header declares a huge image must be refused before the
// pixels are allocated: the reader may allocate a small multiple of the file's size, not what the
// header claims. The bytes of an EXR file whose dataWindow claims 16384 x 8192 pixels (1.6 GB of
// floats), the rest of the file unchanged: the reproduction of class 4.
std::string with_huge_data_window(const std::filesystem::path& exr) {
  std::string bytes = test::read_file(exr);
  const std::string key("dataWindow\0box2i\0", 17);
  const std::size_t at = bytes.find(key);
  if (at == std::string::npos) ADD_FAILURE() << "no dataWindow attribute in " << exr;
  const std::int32_t window[4] = {0, 0, 16383, 8191};
  if (at != std::string::npos)
    std::memcpy(bytes.data() + at + key.size() + 4, window, sizeof window);
  return bytes;
}

void expect_refused_small(const std::filesystem::path& p, const std::string& words) {
  const std::size_t size = std::filesystem::file_size(p);
  test::AllocationProbe probe;
  expect_error(p, words);
  EXPECT_LT(probe.growth(), 64 * size + (1u << 20)) << p << ": " << size << " bytes";
}

TEST(EnvMapAllocation, ExrHeaderClaimingHugeSizeFailsBeforeAllocating) {
  const test::TempDir tmp;
  const auto small = tmp / "small.exr";
  // Noise, so that the file (about 20 KB) holds the offset table of the claimed size and OpenEXR
  // opens it.
  Image img{96, 48, std::vector<float>(96 * 48 * 3)};
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0, 1);
  for (float& v : img.rgb) v = u(rng);
  write_exr(small, img);
  EXPECT_EQ(EnvMap::load(small).width(), 96);
  // The reproduction: the dataWindow patched to 16384 x 8192 (1.6 GB of floats).
  const std::string bytes = with_huge_data_window(small);
  const std::size_t at = bytes.find("dataWindow");
  const auto huge = tmp / "huge.exr";
  write_text(huge, bytes);
  expect_refused_small(huge, "too short for its header");
  // The same with the file cut after its header and offset table.
  write_text(huge, bytes.substr(0, at + 200));
  expect_refused_small(huge, "huge.exr");
}

// A file that has all the chunks its header declares, but chunks that do not decode: the pixels
// are decoded in bands into a growing output, so the failure at the first band costs that band and
// OpenEXR's own buffers for a chunk of the declared width (10 MB here), not the declared image.
TEST(EnvMapAllocation, ExrChunksThatDoNotDecodeFailAtTheFirstBand) {
  const test::TempDir tmp;
  const auto small = tmp / "small.exr";
  write_exr(small, Image{8, 4, std::vector<float>(8 * 4 * 3, 0.5f)});
  std::string bytes = with_huge_data_window(small);
  // The header (write_exr uses ZIP: 16 scanlines a chunk), a zero offset table (OpenEXR then
  // finds the chunks by walking them), and 512 chunks of one byte that is not zlib data.
  const std::size_t header_end = bytes.find(std::string("screenWindowWidth\0float\0", 24));
  ASSERT_NE(header_end, std::string::npos);
  bytes.resize(header_end + 24 + 4 + 4 + 1);
  bytes.append(8 * 512, '\0');
  for (std::int32_t chunk = 0; chunk < 512; ++chunk) {
    const std::int32_t head[2] = {16 * chunk, 1};
    bytes.append(reinterpret_cast<const char*>(head), sizeof head);
    bytes.push_back('\x55');
  }
  const auto bad = tmp / "bad-chunks.exr";
  write_text(bad, bytes);
  const std::size_t size = bytes.size();
  const std::size_t chunk_of_lines = 16u * 16384 * 3 * sizeof(float);  // 3 MiB
  test::AllocationProbe probe;
  expect_error(bad, "Data decompression (zlib) failed");
  EXPECT_LT(probe.growth(), 64 * size + 6 * chunk_of_lines) << size << " bytes";
}

TEST(EnvMapAllocation, RadianceHeaderClaimingHugeSizeFailsBeforeAllocating) {
  const test::TempDir tmp;
  const auto huge = tmp / "huge.hdr";
  write_text(huge, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n");
  expect_refused_small(huge, "image too large: 100000 x 100000 pixels, more than the limit");
  write_text(huge, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8192 +X 16384\n\x02\x02\x40");
  expect_refused_small(huge, "truncated");
  write_text(huge, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8192 +X 8192\n");
  expect_refused_small(huge, "not a latitude-longitude map");
}

TEST(EnvMapAllocation, RealMapNeedsAboutItsPixels) {
  HALFBACK_REQUIRE_SHARED(dir, "envmaps");
  const auto p = dir / "venice_sunset_1k.hdr";
  test::AllocationProbe probe;
  const EnvMap m = EnvMap::load(p);
  // The file, the decoded floats (twice: stb's and ours), the two sampling distributions.
  const std::size_t pixels = std::size_t(m.width()) * std::size_t(m.height());
  EXPECT_LT(probe.growth(), std::filesystem::file_size(p) + pixels * (3 * 4 * 2 + 8 * 6))
      << probe.growth();
}

// Class 1: a map with tiny negative values (noise) loads, the values read as 0 and counted; a
// negative value beyond the noise tolerance is still refused.
TEST(EnvMap, TinyNegativeRadianceIsNoise) {
  const test::TempDir tmp;
  Image img{8, 4, std::vector<float>(8 * 4 * 3, 0.5f)};
  img.rgb[7] = -2e-7f;
  img.rgb[40] = -1e-4f;
  const auto p = tmp / "noisy.exr";
  write_exr(p, img);
  const EnvMap m = EnvMap::load(p);
  EXPECT_EQ(m.noise_clamped(), 2u);
  EXPECT_EQ(m.pixels()[7], 0.0f);
  EXPECT_EQ(m.pixels()[8], 0.5f);
  img.rgb[40] = -1e-3f;  // 0.2 % of the largest value: not noise
  write_exr(p, img);
  expect_error(p, "-0.001");
}

// No whole-file read without a bound (docs/reliability/readers.md, "A reader reads what the file's
// header declares, and nothing more"): a map's file ends where its pixel data does: trailing data
// is refused with both byte counts, and a small map extended to a gigabyte (truncate -s) is refused
// without reading the extension (it was read whole: 2.1 GB).
void expect_refused_unread(const std::filesystem::path& p, const std::string& words) {
  test::AllocationProbe probe;
  expect_error(p, words);
  EXPECT_LT(probe.growth(), std::size_t(1) << 20) << p;
}

TEST(EnvMapTrailingData, RefusedUnreadWithBothCounts) {
  const test::TempDir tmp;
  // Radiance, flat RGBE (a width below 8 is never run-length encoded): 4 × 2 pixels.
  const std::string header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n";
  std::string hdr = header;
  for (int i = 0; i < 8; ++i) hdr += std::string("\x80\x40\x20\x81", 4);
  const auto flat = tmp / "flat.hdr";
  write_text(flat, hdr);
  EXPECT_EQ(EnvMap::load(flat).width(), 4);
  write_text(flat, hdr + "x");
  expect_error(flat, "file size: the header declares " + std::to_string(hdr.size()) + " bytes");
  expect_error(flat, "1 byte of trailing data");
  write_text(flat, hdr);
  std::filesystem::resize_file(flat, std::uintmax_t(1) << 30);
  expect_refused_unread(flat, "4 × 2 pixels take at most 72 bytes after the " +
                                  std::to_string(header.size()) + "-byte header");
  // OpenEXR, one chunk per 16 scanlines (ZIP).
  const auto exr = tmp / "map.exr";
  write_exr(exr, Image{8, 4, std::vector<float>(8 * 4 * 3, 0.5f)});
  const std::string bytes = test::read_file(exr);
  write_text(exr, bytes + "junk");
  expect_error(exr, "file size: the header declares " + std::to_string(bytes.size()) +
                        " bytes (8 × 4 pixels in 1 chunks)");
  expect_error(exr, "4 bytes of trailing data");
  write_text(exr, bytes);
  std::filesystem::resize_file(exr, std::uintmax_t(1) << 30);
  expect_refused_unread(exr, "has 1073741824 bytes");
  // The real maps end where their pixels do.
  HALFBACK_REQUIRE_SHARED(dir, "envmaps");
  for (const auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_NO_THROW(EnvMap::load(e.path())) << e.path();
}

TEST(EnvMap, BadInput) {
  const test::TempDir tmp;
  expect_error(tmp / "does_not_exist.hdr", "cannot open");
  expect_error(tmp.path(), "directory");
  const auto empty = tmp / "empty.hdr";
  write_text(empty, "");
  expect_error(empty, "empty file");
  const auto png = tmp / "ldr.hdr";
  write_text(png, std::string("\x89PNG\r\n\x1a\n", 8) + "not really");
  expect_error(png, "not an HDR image");
  const auto zero = tmp / "zero.hdr";
  write_text(zero, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 0\n");
  expect_error(zero, "zero-size");
  const auto truncated = tmp / "truncated.hdr";
  write_text(truncated, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 16\n\x01\x02");
  expect_error(truncated, "truncated");
  const auto noheader = tmp / "noheader.hdr";
  write_text(noheader, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n");
  expect_error(noheader, "header");

  auto exr_with = [&tmp](const std::string& name, float bad, int w = 8, int h = 4) {
    Image img{w, h, std::vector<float>(std::size_t(w * h * 3), 0.5f)};
    img.rgb[std::size_t(3 * (w + 2) + 1)] = bad;  // pixel (2, 1), channel G
    const auto p = tmp / name;
    write_exr(p, img);
    return p;
  };
  expect_error(exr_with("nan.exr", std::nanf("")), "NaN");
  expect_error(exr_with("nan.exr", std::nanf("")), "pixel (x=2, y=1) channel G");
  expect_error(exr_with("inf.exr", INFINITY), "Inf");
  expect_error(exr_with("neg.exr", -1.0f), "-1");
  expect_error(exr_with("square.exr", 1.0f, 4, 4), "not a latitude-longitude map");
  const auto bad_exr = tmp / "bad.exr";
  write_text(bad_exr, std::string("\x76\x2f\x31\x01", 4) + "garbage");
  expect_error(bad_exr, "OpenEXR");

  // Built-ins and in-memory maps.
  EXPECT_THROW(EnvMap::from_spec("constant:abc"), std::invalid_argument);
  EXPECT_THROW(EnvMap::from_spec("constant:1,2"), std::invalid_argument);
  EXPECT_THROW(EnvMap::from_spec("constant:-1"), std::invalid_argument);
  EXPECT_THROW(EnvMap::from_spec("constant:nan"), std::invalid_argument);
  EXPECT_THROW(EnvMap(0, 0, {}, "empty"), std::invalid_argument);
  EXPECT_THROW(EnvMap(2, 1, {1, 1, 1, 1, 1, NAN}, "nan"), std::invalid_argument);
  EXPECT_THROW(EnvMap(2, 1, {1, 1, 1}, "short"), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::render

namespace halfback::render {
namespace {

// A map whose pixel i has radiance i (red), so that eval() names the pixel it looked up.
EnvMap numbered_map(int w, int h, EnvOptions o = {}) {
  std::vector<float> rgb(std::size_t(w) * std::size_t(h) * 3, 1.0f);
  for (std::size_t i = 0; i < rgb.size() / 3; ++i) rgb[3 * i] = float(i);
  return EnvMap(w, h, std::move(rgb), "numbered", o);
}

// The pixel lookup (a guess corrected by exact edge tests) picks the pixel map_coordinates()
// places a direction in, except within rounding of a pixel's edge; on the poles, the seam and
// the axes too.
TEST(EnvMap, PixelLookupAgreesWithMapCoordinates) {
  for (const auto& [w, h] : {std::pair{256, 128}, std::pair{1024, 512}, std::pair{64, 32}}) {
    const EnvMap m = numbered_map(w, h);
    std::mt19937_64 rng(8);
    std::normal_distribution<double> g;
    std::vector<Vec3<double>> dirs{{0, 1, 0},         {0, -1, 0},        {0, 0, 1},
                                   {0, 0, -1},        {1, 0, 0},         {-1, 0, 0},
                                   {1e-300, 1, 0},    {-0.0, 0.0, 1},    {0, 0.6, 0.8},
                                   {1e-12, 0.6, 0.8}, {-1e-12, 0.6, 0.8}};
    for (int i = 0; i < 200000; ++i) dirs.push_back(unit(g(rng), g(rng), g(rng)));
    int near_edge = 0;
    for (const auto& d : dirs) {
      double u, v;
      EnvMap::map_coordinates(d, u, v);
      const double col = std::min(std::floor(u * w), w - 1.0);
      const double row = std::min(std::floor(v * h), h - 1.0);
      const float expected = float(row * w + col);
      const float got = float(m.eval(d).r);
      if (got == expected) continue;
      const double fu = u * w - std::floor(u * w), fv = v * h - std::floor(v * h);
      const bool edge = std::min(fu, 1 - fu) < 1e-9 || std::min(fv, 1 - fv) < 1e-9;
      EXPECT_TRUE(edge) << w << " x " << h << ": (" << d.x << ", " << d.y << ", " << d.z
                        << ") looked up " << got << ", expected " << expected;
      near_edge += edge;
    }
    EXPECT_LT(near_edge, 5);
  }
}

TEST(EnvMap, BatchSampleAndLookupEqualOneAtATime) {
  const EnvMap m = random_map(128, 64, {31, 0.5}, 4);
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(0, 1);
  constexpr std::size_t n = 100;
  for (const bool comp : {false, true}) {
    std::vector<double> u1(n), u2(n);
    for (std::size_t i = 0; i < n; ++i) {
      u1[i] = u(rng);
      u2[i] = u(rng);
    }
    std::vector<EnvMap::Sample> s(n);
    m.sample(u1, u2, comp, s);
    std::vector<Vec3<double>> dirs(n);
    for (std::size_t i = 0; i < n; ++i) {
      const EnvMap::Sample one = m.sample(u1[i], u2[i], comp);
      EXPECT_EQ(s[i].dir.x, one.dir.x);
      EXPECT_EQ(s[i].dir.y, one.dir.y);
      EXPECT_EQ(s[i].dir.z, one.dir.z);
      EXPECT_EQ(s[i].pdf, one.pdf);
      EXPECT_EQ(s[i].radiance.g, one.radiance.g);
      dirs[i] = unit(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    }
    std::vector<EnvMap::Lookup> l(n);
    m.lookup(dirs, comp, l);
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_EQ(l[i].pdf, m.pdf(dirs[i], comp));
      EXPECT_EQ(l[i].radiance.r, m.eval(dirs[i]).r);
      EXPECT_EQ(l[i].radiance.b, m.eval(dirs[i]).b);
    }
  }
  std::vector<EnvMap::Lookup> wrong(3);
  EXPECT_THROW(m.lookup(std::vector<Vec3<double>>(2), false, wrong), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::render
