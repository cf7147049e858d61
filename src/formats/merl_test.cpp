// MERL: SHA-256, the material table, bin indices against an independent acos-based reference,
// validation errors, lookups (nearest and trilinear), writer round trip.
#include "halfback/formats/merl.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <random>
#include <set>
#include <sstream>

#include "core/batch_engine.hpp"
#include "formats/binary_io.hpp"
#include "formats/isa_versions.hpp"
#include "formats/merl_kernel.hpp"
#include "formats/merl_reference.hpp"
#include "support/allocation_probe.hpp"
#include "support/every_isa.hpp"
#include "support/test_brdfs.hpp"
#include "support/test_support.hpp"

namespace halfback {
namespace {

using test::TempDir;
constexpr double kPi = std::numbers::pi;

std::span<const std::byte> bytes_of(const std::string& s) {
  return {reinterpret_cast<const std::byte*>(s.data()), s.size()};
}

// --------------------------------------------------------------------------------------------
// The material table
// --------------------------------------------------------------------------------------------

TEST(MerlMaterials, EmbeddedTable) {
  const auto table = merl_materials();
  ASSERT_EQ(table.size(), 100u);
  std::set<std::string_view> names, hashes;
  for (const auto& m : table) {
    EXPECT_EQ(m.size, merl::kFileBytes) << m.name;
    EXPECT_EQ(m.sha256.size(), 64u) << m.name;
    names.insert(m.name);
    hashes.insert(m.sha256);
  }
  EXPECT_EQ(names.size(), 100u);
  EXPECT_EQ(hashes.size(), 100u);
  const MerlMaterial* gold = nullptr;
  for (const auto& m : table)
    if (m.name == "gold-metallic-paint") gold = &m;
  ASSERT_NE(gold, nullptr);
  EXPECT_EQ(find_merl_material(gold->sha256), gold);
  EXPECT_EQ(find_merl_material(std::string(64, '0')), nullptr);
}

TEST(MerlMaterials, TableMatchesSharedTsv) {
  HALFBACK_REQUIRE_SHARED(dir, "merl");
  std::ifstream in(dir / "merl_sha256.tsv");
  std::string line;
  std::getline(in, line);
  std::size_t rows = 0;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::istringstream ss(line);
    std::string name, sha;
    std::uint64_t size;
    ss >> name >> sha >> size;
    const MerlMaterial* m = find_merl_material(sha);
    ASSERT_NE(m, nullptr) << name;
    EXPECT_EQ(m->name, name);
    EXPECT_EQ(m->size, size);
    ++rows;
  }
  EXPECT_EQ(rows, merl_materials().size());
}

// --------------------------------------------------------------------------------------------
// Synthetic files
// --------------------------------------------------------------------------------------------

// A file image: header, then values(channel, flat index).
template <class F>
std::string merl_image(F&& values) {
  std::string s(merl::kFileBytes, '\0');
  auto* p = reinterpret_cast<std::byte*>(s.data());
  io_detail::store_le<std::int32_t>(p, 90);
  io_detail::store_le<std::int32_t>(p + 4, 90);
  io_detail::store_le<std::int32_t>(p + 8, 180);
  for (int c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < merl::kBins; ++i)
      io_detail::store_le<double>(p + 12 + 8 * (c * merl::kBins + i), values(c, i));
  return s;
}

// Each bin stores its own indices: red = θh index, green = θd index, blue = φd index.
const std::string& index_image() {
  static const std::string image = merl_image([](int c, std::size_t i) -> double {
    const std::size_t pd = i % 180, td = (i / 180) % 90, th = i / (180 * 90);
    return c == 0 ? double(th) : c == 1 ? double(td) : double(pd);
  });
  return image;
}

merl::BinIndex decode(const Rgb& v) {
  return {static_cast<int>(std::lround(v.r / merl::kScale[0])),
          static_cast<int>(std::lround(v.g / merl::kScale[1])),
          static_cast<int>(std::lround(v.b / merl::kScale[2]))};
}

// Distance of a continuous bin coordinate to the nearest bin boundary (an integer).
double to_boundary(double x) {
  return std::abs(x - std::round(x));
}

TEST(Merl, IndicesMatchIndependentReference) {
  TempDir tmp;
  const auto path = tmp / "index.binary";
  test::write_bytes(path, index_image().data(), index_image().size());
  const MerlBrdf brdf(read_merl(path));
  EXPECT_FALSE(brdf.data().material.has_value());
  EXPECT_EQ(brdf.data().missing, (std::array<std::size_t, 3>{0, 0, 0}));

  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  std::size_t checked = 0, boundary = 0, fold = 0;
  auto check = [&](const Vec3<double>& wi, const Vec3<double>& wo) {
    const merl_reference::V3 in{wi.x, wi.y, wi.z}, out{wo.x, wo.y, wo.z};
    const auto a = merl_reference::half_diff(in, out);
    const merl::BinIndex ref{merl_reference::theta_h_index(a.theta_h),
                             merl_reference::theta_d_index(a.theta_d),
                             merl_reference::phi_d_index(a.phi_d)};
    const merl::BinIndex got = decode(brdf.eval(DirPair<double>{wi, wo}));
    const merl::BinIndex direct = merl::bin_of(DirPair<double>{wi, wo});
    EXPECT_EQ(got.theta_h, direct.theta_h);
    EXPECT_EQ(got.theta_d, direct.theta_d);
    EXPECT_EQ(got.phi_d, direct.phi_d);
    ++checked;
    if (got.theta_h == ref.theta_h && got.theta_d == ref.theta_d && got.phi_d == ref.phi_d) return;
    // A different bin is only acceptable on a bin boundary, where the reference's acos and
    // halfback's atan2 may round to different sides. On the φd = 0 ≡ π boundary (every in-plane
    // pair) the reference's rotations leave a ±1e-16 residue in dy whose sign picks bin 0 or 179;
    // halfback's dy is exactly 0 there and gives bin 0 (and 179 for φd = π, as the reference).
    const double eps = 1e-7;
    const double xp = merl_reference::phi_d_coordinate(a.phi_d);
    if (got.theta_h == ref.theta_h && got.theta_d == ref.theta_d && (xp < eps || xp > 180 - eps) &&
        (got.phi_d == 0 || got.phi_d == 179)) {
      ++fold;
      return;
    }
    ++boundary;
    if (got.theta_h != ref.theta_h) {
      EXPECT_LT(to_boundary(merl_reference::theta_h_coordinate(a.theta_h)), eps);
    }
    if (got.theta_d != ref.theta_d) {
      EXPECT_LT(to_boundary(merl_reference::theta_d_coordinate(a.theta_d)), eps);
    }
    if (got.phi_d != ref.phi_d) {
      const double x = merl_reference::phi_d_coordinate(a.phi_d);
      EXPECT_TRUE(to_boundary(x) < eps || x > 180 - eps || x < eps) << x;
    }
  };
  // Uniform pairs, pairs near the specular peak (small θh), in-plane pairs, grazing pairs.
  for (int n = 0; n < 100000; ++n)
    check(test::uniform_hemisphere(rng), test::uniform_hemisphere(rng));
  for (int n = 0; n < 20000; ++n) {
    const double ti = std::acos(u(rng)), pi = 2 * kPi * u(rng);
    const Vec3<double> wi = test::direction(ti, pi);
    const Vec3<double> mirror{-wi.x, -wi.y, wi.z};
    const double dt = 0.05 * u(rng) * u(rng), dp = 2 * kPi * u(rng);
    const Vec3<double> wo =
        test::direction(std::min(ti + dt * std::cos(dp), kPi / 2), pi + kPi + dt * std::sin(dp));
    check(wi, n % 2 ? mirror : wo);
  }
  for (int n = 0; n < 20000; ++n) {
    const double ti = kPi / 2 * u(rng), to = kPi / 2 * u(rng);
    check(test::direction(ti, 0), test::direction(to, n % 2 ? 0 : kPi));
  }
  for (int n = 0; n < 20000; ++n)
    check(test::direction(kPi / 2 * (1 - 1e-3 * u(rng)), 2 * kPi * u(rng)),
          test::uniform_hemisphere(rng));
  EXPECT_EQ(checked, 160000u);
  EXPECT_LE(boundary, 20u) << "bins differing from the reference (all on boundaries)";
  EXPECT_LE(fold, 10000u);  // at most half of the in-plane pairs
  std::cout << "[ info ] of " << checked << " pairs, " << boundary
            << " on a θh/θd/φd bin boundary and " << fold
            << " in-plane ones on the φd = 0 ≡ π boundary got the neighbouring bin\n";
}

TEST(Merl, BinFormulasAtKnownPoints) {
  // θh index is non-linear: bin i starts at θh = (i/90)² · 90°.
  EXPECT_EQ(merl::bin_of(0.0, 0, 0).theta_h, 0);
  EXPECT_EQ(merl::bin_of(std::pow(1.0 / 90, 2) * kPi / 2 * 0.999, 0, 0).theta_h, 0);
  EXPECT_EQ(merl::bin_of(std::pow(1.0 / 90, 2) * kPi / 2 * 1.001, 0, 0).theta_h, 1);
  EXPECT_EQ(merl::bin_of(std::pow(45.5 / 90, 2) * kPi / 2, 0, 0).theta_h, 45);
  EXPECT_EQ(merl::bin_of(kPi / 2, 0, 0).theta_h, 89);  // clamped
  EXPECT_EQ(merl::bin_of(0, kPi / 4, 0).theta_d, 45);
  EXPECT_EQ(merl::bin_of(0, kPi / 2, 0).theta_d, 89);  // clamped
  // φd folded by reciprocity: φd and φd ± π share a bin; negative (reference) and [0, 2π) (core)
  // conventions agree.
  for (double p : {0.1, 1.0, 2.0, 3.0}) {
    EXPECT_EQ(merl::bin_of(0, 0, p).phi_d, merl::bin_of(0, 0, p + kPi).phi_d) << p;
    EXPECT_EQ(merl::bin_of(0, 0, p).phi_d, merl::bin_of(0, 0, p - kPi).phi_d) << p;
  }
  EXPECT_EQ(merl::bin_of(0, 0, kPi / 2).phi_d, 90);
  EXPECT_EQ(merl::bin_of(0, 0, kPi).phi_d, 179);  // as the reference (180 clamped)
  EXPECT_EQ(merl::bin_of(0, 0, std::nan("")).phi_d, 0);
  // Bin centres map back to their bins.
  for (int th = 0; th < 90; th += 7)
    for (int td = 0; td < 90; td += 11)
      for (int pd = 0; pd < 180; pd += 13) {
        const auto c = merl::bin_centre(th, td, pd);
        const auto b = merl::bin_of(c[0], c[1], c[2]);
        EXPECT_EQ(b.theta_h, th);
        EXPECT_EQ(b.theta_d, td);
        EXPECT_EQ(b.phi_d, pd);
      }
}

TEST(Merl, ValuesAndScalesAreTheReferences) {
  // Arbitrary stored values: the lookup must give exactly stored × (1.0/1500.0) etc., as the
  // reference computes them, for the reference's bin.
  const std::string image = merl_image([](int c, std::size_t i) {
    return std::sin(0.37 * double(i) + c) * 1000.0 + 1001.0 + 1e-3 * double(c);
  });
  const MerlBrdf brdf(parse_merl(bytes_of(image), "values"));
  std::vector<double> values(3 * merl::kBins);
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] =
        io_detail::load_le<double>(reinterpret_cast<const std::byte*>(image.data()) + 12 + 8 * i);
  std::mt19937_64 rng(3);
  for (int n = 0; n < 2000; ++n) {
    const auto wi = test::uniform_hemisphere(rng), wo = test::uniform_hemisphere(rng);
    const auto b = merl::bin_of(DirPair<double>{wi, wo});
    const std::size_t i = merl::bin(b.theta_h, b.theta_d, b.phi_d);
    const Rgb v = brdf.eval(DirPair<double>{wi, wo});
    EXPECT_EQ(v.r, values[i] * (1.0 / 1500.0));
    EXPECT_EQ(v.g, values[i + merl::kBins] * (1.15 / 1500.0));
    EXPECT_EQ(v.b, values[i + 2 * merl::kBins] * (1.66 / 1500.0));
  }
}

TEST(Merl, NegativeBinsAndHorizon) {
  // Unmeasured (negative) bins are missing: NaN (never a negative ρ), and they are counted.
  const std::string image = merl_image([](int c, std::size_t i) {
    const std::size_t th = i / (180 * 90);
    return th >= 80 ? -1.0 : 1500.0 * (c + 1);
  });
  const MerlData data = parse_merl(bytes_of(image), "neg");
  EXPECT_EQ(data.missing[0], std::size_t(10) * 90 * 180);
  const MerlBrdf brdf(data);
  const auto c = merl::bin_centre(85, 2, 10);
  const Solved<double> s = inverse<HalfDiff>(Tuple4<double>{c[0], 0.0, c[1], c[2]});
  ASSERT_TRUE(s.in_domain);
  const Rgb v = brdf.eval(s.pair);
  EXPECT_TRUE(std::isnan(v.r) && std::isnan(v.g) && std::isnan(v.b)) << v.r;
  // A measured bin keeps the reference's value, bit for bit.
  const auto m = merl::bin_centre(40, 2, 10);
  const Solved<double> sm = inverse<HalfDiff>(Tuple4<double>{m[0], 0.0, m[1], m[2]});
  EXPECT_EQ(brdf.eval(sm.pair).b, 4500.0 * (1.66 / 1500.0));
  // Below the horizon: 0 (the interface's contract); NaN in, NaN out.
  const Rgb below = brdf.eval(DirPair<double>{{0, 0, 1}, {1, 0, -0.1}});
  EXPECT_EQ(below, (Rgb{0, 0, 0}));
  EXPECT_TRUE(std::isnan(brdf.eval(DirPair<double>{{0, 0, std::nan("")}, {0, 0, 1}}).r));
  EXPECT_NE(brdf.description().find("unmeasured"), std::string::npos);
}

// --------------------------------------------------------------------------------------------
// Validation
// --------------------------------------------------------------------------------------------

TEST(MerlErrors, SizeHeaderAndValues) {
  const std::string good = merl_image([](int, std::size_t) { return 1.0; });
  EXPECT_NO_THROW(parse_merl(bytes_of(good), "good"));

  std::string truncated = good.substr(0, good.size() - 1);
  EXPECT_FORMAT_ERROR(parse_merl(bytes_of(truncated), "t.binary"), "t.binary", "file size",
                      "34992011 bytes", "truncated");
  std::string oversized = good + "x";
  EXPECT_FORMAT_ERROR(parse_merl(bytes_of(oversized), "o.binary"), "o.binary", "file size",
                      "trailing data");
  EXPECT_FORMAT_ERROR(parse_merl(bytes_of(std::string("abc")), "tiny"), "tiny", "header",
                      "too short");

  std::string bad_dim = good;
  io_detail::store_le<std::int32_t>(reinterpret_cast<std::byte*>(bad_dim.data()) + 8, 360);
  EXPECT_FORMAT_ERROR(parse_merl(bytes_of(bad_dim), "d.binary"), "d.binary",
                      "header dimension 3 (phi_d)", "is 360, expected 180");
  std::string bad_dim1 = good;
  io_detail::store_le<std::int32_t>(reinterpret_cast<std::byte*>(bad_dim1.data()), -5);
  EXPECT_FORMAT_ERROR(parse_merl(bytes_of(bad_dim1), "d1"), "header dimension 1 (theta_h)",
                      "is -5");

  auto poke = [&](int channel, int th, int td, int pd, double v) {
    std::string s = good;
    io_detail::store_le<double>(reinterpret_cast<std::byte*>(s.data()) + 12 +
                                    8 * (channel * merl::kBins + merl::bin(th, td, pd)),
                                v);
    return s;
  };
  EXPECT_FORMAT_ERROR(parse_merl(bytes_of(poke(0, 1, 2, 3, std::nan(""))), "n.binary"), "n.binary",
                      "red value at bin (theta_h 1, theta_d 2, phi_d 3)", "is NaN");
  EXPECT_FORMAT_ERROR(parse_merl(bytes_of(poke(2, 89, 89, 179, INFINITY)), "i"),
                      "blue value at bin (theta_h 89, theta_d 89, phi_d 179)", "is infinite");
  EXPECT_FORMAT_ERROR(parse_merl(bytes_of(poke(1, 0, 0, 0, -INFINITY)), "i"), "green value",
                      "is infinite");
  // Finite but absurd (1e308, or a big-endian file read as little-endian): named, not integrated
  // into an infinite albedo. The bound is on ρ, so the largest accepted stored value is per
  // channel.
  EXPECT_FORMAT_ERROR(parse_merl(bytes_of(poke(0, 4, 5, 6, 1e308)), "huge"),
                      "red value at bin (theta_h 4, theta_d 5, phi_d 6)", "is 1e+308",
                      "above the bound of 1e+10 sr⁻¹", "little-endian");
  const double largest_blue = merl::kMaxRho / merl::kScale[2];
  EXPECT_NO_THROW(parse_merl(bytes_of(poke(2, 4, 5, 6, 0.999 * largest_blue)), "edge"));
  EXPECT_FORMAT_ERROR(parse_merl(bytes_of(poke(2, 4, 5, 6, largest_blue * 1.001)), "edge"),
                      "blue value");
}

TEST(MerlErrors, Files) {
  TempDir tmp;
  EXPECT_FORMAT_ERROR(read_merl(tmp / "missing.binary"), "missing.binary", "file");
  // A wrong size is diagnosed from the header without reading the file.
  const std::string head = merl_image([](int, std::size_t) { return 1.0; }).substr(0, 1000);
  test::write_bytes(tmp / "short.binary", head.data(), head.size());
  EXPECT_FORMAT_ERROR(read_merl(tmp / "short.binary"), "short.binary", "file size", "1000 bytes",
                      "truncated");
  const std::string text = "#DIM 3 1\n";
  test::write_bytes(tmp / "alta.binary", text.data(), text.size());
  EXPECT_FORMAT_ERROR(read_merl(tmp / "alta.binary"), "alta.binary", "header", "too short");
  EXPECT_FORMAT_ERROR(read_merl(tmp.path()), "not a regular file");
}

// --------------------------------------------------------------------------------------------
// Trilinear lookup
// --------------------------------------------------------------------------------------------

// A smooth, isotropic, reciprocal test function of the stored coordinates.
double smooth(double th, double td, double pd) {
  return 1.0 + 0.5 * std::cos(th) * std::cos(td) + 0.2 * std::cos(2 * pd) * std::sin(th);
}

TEST(MerlTrilinear, BinCentresWrapAndMissing) {
  MerlData data;
  data.values.resize(3 * merl::kBins);
  for (int th = 0; th < 90; ++th)
    for (int td = 0; td < 90; ++td)
      for (int pd = 0; pd < 180; ++pd) {
        const auto c = merl::bin_centre(th, td, pd);
        for (int ch = 0; ch < 3; ++ch)
          data.values[ch * merl::kBins + merl::bin(th, td, pd)] =
              smooth(c[0], c[1], c[2]) * (ch + 1);
      }
  const MerlBrdf near(data), tri(data, {MerlLookup::trilinear});
  auto pair_at = [](double th, double td, double pd) {
    const Solved<double> s = inverse<HalfDiff>(Tuple4<double>{th, 0.0, td, pd});
    return s;
  };
  // At bin centres both lookups give the bin value.
  for (int th : {0, 1, 20, 60}) {
    for (int td : {0, 5, 40}) {
      for (int pd : {0, 90, 179}) {
        const auto c = merl::bin_centre(th, td, pd);
        const auto s = pair_at(c[0], c[1], c[2]);
        if (!s.in_domain) continue;
        const Rgb a = near.eval(s.pair), b = tri.eval(s.pair);
        EXPECT_NEAR(b.r, a.r, 1e-12 * std::abs(a.r)) << th << " " << td << " " << pd;
        EXPECT_NEAR(b.b, a.b, 1e-12 * std::abs(a.b));
      }
    }
  }
  // Between centres the trilinear lookup follows the smooth function much more closely.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  double err_near = 0, err_tri = 0;
  for (int n = 0; n < 5000; ++n) {
    const double th = 1.2 * u(rng), td = 0.3 * u(rng), pd = 2 * kPi * u(rng);
    const auto s = pair_at(th, td, pd);
    if (!s.in_domain) continue;
    const double want = smooth(th, td, pd) * merl::kScale[0];
    err_near = std::max(err_near, std::abs(near.eval(s.pair).r - want) / want);
    err_tri = std::max(err_tri, std::abs(tri.eval(s.pair).r - want) / want);
  }
  EXPECT_LT(err_tri, 2e-3);
  EXPECT_LT(err_tri, err_near / 5);
  // φd wrap: φd = ε and φd = π - ε are neighbours (0 ≡ π), and φd ↔ φd + π is the same point.
  for (double th : {0.3, 0.9}) {
    const double eps = 1e-9;
    const Rgb a = tri.eval(pair_at(th, 0.2, eps).pair),
              b = tri.eval(pair_at(th, 0.2, kPi - eps).pair);
    const Rgb c = tri.eval(pair_at(th, 0.2, kPi + eps).pair);
    EXPECT_NEAR(a.r, b.r, 1e-9 * a.r);
    EXPECT_NEAR(a.r, c.r, 1e-9 * a.r);
  }
  // Near θh = 0: continuous, and equal to the θh-bin-0 layer interpolated in θd, φd.
  {
    const Rgb at0 = tri.eval(pair_at(0.0, 0.2, 1.0).pair);
    const Rgb tiny = tri.eval(pair_at(1e-7, 0.2, 1.0).pair);
    EXPECT_NEAR(at0.r, tiny.r, 1e-9 * at0.r);
    EXPECT_TRUE(std::isfinite(at0.r));
  }
  // Missing corners are skipped and the remaining weights renormalized: a constant function with
  // holes stays constant.
  MerlData holes;
  holes.values.assign(3 * merl::kBins, 1500.0);
  for (int td = 0; td < 90; td += 2)
    for (int pd = 0; pd < 180; pd += 3)
      for (int ch = 0; ch < 3; ++ch) holes.values[ch * merl::kBins + merl::bin(30, td, pd)] = -1;
  const MerlBrdf with_holes(holes, {MerlLookup::trilinear});
  for (int n = 0; n < 2000; ++n) {
    const double th = std::pow((29.5 + u(rng)) / 90, 2) * kPi / 2, td = kPi / 2 * u(rng) * 0.5;
    const auto s = pair_at(th, td, kPi * u(rng));
    if (!s.in_domain) continue;
    EXPECT_NEAR(with_holes.eval(s.pair).r, 1.0, 1e-12);
  }
  // All 8 corners missing: missing (NaN), not the negative stored value.
  MerlData empty;
  empty.values.assign(3 * merl::kBins, -2.0);
  const MerlBrdf all_missing(empty, {MerlLookup::trilinear});
  EXPECT_TRUE(std::isnan(all_missing.eval(pair_at(0.5, 0.3, 1.0).pair).g));
}

// --------------------------------------------------------------------------------------------
// Writer
// --------------------------------------------------------------------------------------------

// An analytic isotropic, reciprocal BRDF defined here: a diffuse term and a lobe around the
// specular direction, coloured.
class TestLobe final : public Brdf {
 public:
  std::string name() const override { return "test-lobe"; }
  std::string description() const override { return "test lobe"; }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& p) const override {
    if (p.wi.z < 0 || p.wo.z < 0) return {};
    const double hx = p.wi.x + p.wo.x, hy = p.wi.y + p.wo.y, hz = p.wi.z + p.wo.z;
    const double cos_h = hz / std::sqrt(hx * hx + hy * hy + hz * hz);
    const double lobe = std::pow(cos_h, 50.0) * 10.0;
    return {0.2 + lobe, 0.3 + 0.5 * lobe, 0.1 + 0.25 * lobe};
  }
};

// --------------------------------------------------------------------------------------------
// Batch evaluation (SIMD conversion, prefetched reads)
// --------------------------------------------------------------------------------------------

// Pairs of every kind the batch path must handle: uniform, near the specular peak, in the plane
// of incidence, grazing; and rows it leaves to eval(): NaN, below the horizon, not unit length.
std::vector<DirPair<double>> batch_pairs() {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<DirPair<double>> p;
  for (int n = 0; n < 20000; ++n)
    p.push_back({test::uniform_hemisphere(rng), test::uniform_hemisphere(rng)});
  for (int n = 0; n < 3000; ++n) {
    const Vec3<double> wi = test::uniform_hemisphere(rng);
    p.push_back({wi, {-wi.x, -wi.y, wi.z}});
    p.push_back({test::direction(kPi / 2 * u(rng), 0), test::direction(kPi / 2 * u(rng), kPi)});
    p.push_back({test::direction(kPi / 2 * (1 - 1e-3 * u(rng)), 2 * kPi * u(rng)),
                 test::uniform_hemisphere(rng)});
  }
  const double nan = std::nan("");
  p.push_back({{0, 0, nan}, {0, 0, 1}});
  p.push_back({{0.6, 0, 0.8}, {nan, 0, 1}});
  p.push_back({{0, 0, 1}, {1, 0, -0.1}});
  p.push_back({{0.6, 0, -1e-9}, {0, 0.6, 0.8}});  // below by less than the tolerance
  p.push_back({{0.66, 0, 0.88}, {0, 0.6, 0.8}});  // not unit: eval() takes it as given
  p.push_back({{1, 0, 0}, {0, 1, 0}});            // both at the horizon
  std::shuffle(p.begin(), p.end(), rng);          // special rows inside SIMD vectors and blocks
  return p;
}

// The same double, sign of zero included (any NaN equals any NaN).
bool same_bits(double a, double b) {
  return a == b ? std::signbit(a) == std::signbit(b) : std::isnan(a) && std::isnan(b);
}

bool same_value(double a, double b) {
  return a == b || (std::isnan(a) && std::isnan(b));
}

TEST(MerlBatch, NearestIsEvalButOnBinBoundaries) {
  const MerlBrdf brdf(parse_merl(bytes_of(index_image()), "index"));
  const auto pairs = batch_pairs();
  std::vector<Rgb> batch(pairs.size());
  brdf.eval_batch(pairs, batch);
  std::size_t differ = 0, fold = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const Rgb one = brdf.eval(pairs[i]);
    if (same_value(one.r, batch[i].r) && same_value(one.g, batch[i].g) &&
        same_value(one.b, batch[i].b))
      continue;
    // The SIMD conversion's atan2 may round to the other side of a bin boundary than libm's; the
    // point must then be on that boundary (within 1e-7 of a bin edge, by the reference's formulas).
    const auto& [wi, wo] = pairs[i];
    const auto a = merl_reference::half_diff({wi.x, wi.y, wi.z}, {wo.x, wo.y, wo.z});
    const merl::BinIndex got = decode(batch[i]), want = decode(one);
    const double eps = 1e-7;
    const double xp = merl_reference::phi_d_coordinate(a.phi_d);
    // In the plane of incidence φd is 0 ≡ π: bins 0 and 179 are the same boundary, which the
    // reference itself picks by the sign of a rounding residue (IndicesMatchIndependentReference).
    if (got.theta_h == want.theta_h && got.theta_d == want.theta_d &&
        (xp < eps || xp > 180 - eps) && (got.phi_d == 0 || got.phi_d == 179)) {
      ++fold;
      continue;
    }
    ++differ;
    if (got.theta_h != want.theta_h) {
      EXPECT_LT(to_boundary(merl_reference::theta_h_coordinate(a.theta_h)), eps) << i;
    }
    if (got.theta_d != want.theta_d) {
      EXPECT_LT(to_boundary(merl_reference::theta_d_coordinate(a.theta_d)), eps) << i;
    }
    if (got.phi_d != want.phi_d) {
      EXPECT_LT(to_boundary(xp), eps) << i << " " << xp;
    }
  }
  EXPECT_LE(differ, 20u) << "of " << pairs.size();
  EXPECT_LE(fold, 1500u);  // at most half of the 3000 in-plane pairs
  std::cout << "[ info ] of " << pairs.size() << " pairs, " << differ << " on a bin boundary and "
            << fold
            << " in-plane ones on the φd = 0 ≡ π boundary got the neighbouring bin in the batch\n";
  EXPECT_THROW(brdf.eval_batch(pairs, std::span<Rgb>(batch).first(3)), std::invalid_argument);
}

TEST(MerlBatch, NearestKeepsTheStoredValuesAndMissingBins) {
  // Arbitrary values (some unmeasured): a batch value is exactly stored × scale of the bin that
  // eval() finds, or NaN for an unmeasured bin.
  const std::string image = merl_image([](int c, std::size_t i) {
    return i % 97 == 5 ? -1.0 : std::sin(0.37 * double(i) + c) * 1000.0 + 1001.0;
  });
  const MerlBrdf brdf(parse_merl(bytes_of(image), "values"));
  const auto pairs = batch_pairs();
  std::vector<Rgb> batch(pairs.size());
  brdf.eval_batch(pairs, batch);
  // Rows whose value differs must be in-plane pairs on the φd = 0 ≡ π fold (above), whose bin
  // the last ulp of φd decides: the SIMD azimuth and std::atan2 round differently there.
  std::size_t fold = 0, other = 0, nan = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const Rgb one = brdf.eval(pairs[i]);
    if (std::isnan(batch[i].g)) ++nan;
    if (same_value(one.g, batch[i].g)) continue;
    const double phi_d = std::fmod(HalfDiff::forward(pairs[i])[3], kPi);
    ++(std::min(phi_d, kPi - phi_d) < 1e-9 ? fold : other);
  }
  EXPECT_LE(other, 20u);   // on a θh or θd bin boundary (none measured)
  EXPECT_LE(fold, 1500u);  // at most half of the 3000 in-plane pairs (565 measured)
  EXPECT_GT(nan, 50u);     // unmeasured bins and NaN rows
}

TEST(MerlBatch, TrilinearFollowsEval) {
  MerlData data;
  data.values.resize(3 * merl::kBins);
  for (std::size_t i = 0; i < merl::kBins; ++i)
    for (int ch = 0; ch < 3; ++ch)
      data.values[ch * merl::kBins + i] =
          i % 211 == 3 ? -1.0 : 2.0 + std::sin(1e-3 * double(i) + ch);
  const MerlBrdf tri(data, {MerlLookup::trilinear});
  const auto pairs = batch_pairs();
  std::vector<Rgb> batch(pairs.size());
  tri.eval_batch(pairs, batch);
  // The coordinates differ by a few ulps at most (the SIMD atan2 within 2.4 ulp): so do the values,
  // which are continuous in them.
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const Rgb one = tri.eval(pairs[i]);
    for (auto [a, b] : {std::pair{one.r, batch[i].r}, {one.g, batch[i].g}, {one.b, batch[i].b}}) {
      if (std::isnan(a) || a == 0) {
        EXPECT_TRUE(same_value(a, b)) << i << " " << a << " " << b;
      } else {
        EXPECT_NEAR(b, a, 1e-9 * std::abs(a)) << i;
      }
    }
  }
}

// Pairs at given (θh, θd, φd), φh random: the ends of the clamped axes and the φd wrap, where the
// trilinear cell's corners are chosen differently from the interior.
std::vector<DirPair<double>> pairs_at_the_ends() {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<DirPair<double>> p;
  const double eps = 1e-9, top = kPi / 2;
  for (double th : {0.0, 1e-12, 0.5 * std::pow(0.5 / 90, 2) * top, 0.3, top * (1 - 1e-4)})
    for (double td : {0.0, 1e-12, 0.25 / 90 * top, 0.4, top * (89.6 / 90)})
      for (double pd : {0.0, eps, 0.5 / 180 * kPi, kPi - eps, kPi, kPi + eps, 2 * kPi - eps}) {
        const Solved<double> s = inverse<HalfDiff>(Tuple4<double>{th, 2 * kPi * u(rng), td, pd});
        if (s.in_domain && s.pair.wi.z >= 0 && s.pair.wo.z >= 0) p.push_back(s.pair);
      }
  return p;
}

TEST(MerlBatch, TrilinearAtTheEndsWithHolesAndWithoutData) {
  MerlData data;
  data.values.resize(3 * merl::kBins);
  for (std::size_t i = 0; i < merl::kBins; ++i)
    for (int ch = 0; ch < 3; ++ch)
      data.values[ch * merl::kBins + i] = 2.0 + std::sin(1e-3 * double(i) + ch);
  const MerlBrdf tri(data, {MerlLookup::trilinear});
  const auto ends = pairs_at_the_ends();
  ASSERT_GT(ends.size(), 100u);
  std::vector<Rgb> batch(ends.size());
  tri.eval_batch(ends, batch);
  for (std::size_t i = 0; i < ends.size(); ++i) {
    const Rgb one = tri.eval(ends[i]);
    EXPECT_NEAR(batch[i].r, one.r, 1e-9 * std::abs(one.r)) << i;
    EXPECT_NEAR(batch[i].b, one.b, 1e-9 * std::abs(one.b)) << i;
  }
  // A constant with holes stays constant through the batch's renormalized weights; a table with
  // no measured bin gives missing values (NaN), not its negative stored ones.
  MerlData holes;
  holes.values.assign(3 * merl::kBins, 1500.0);
  for (std::size_t i = 0; i < merl::kBins; i += 3) holes.values[merl::kBins + i] = -1;  // green
  const MerlBrdf with_holes(holes, {MerlLookup::trilinear});
  MerlData empty;
  empty.values.assign(3 * merl::kBins, -2.0);
  const MerlBrdf no_data(empty, {MerlLookup::trilinear});
  auto pairs = batch_pairs();
  pairs.insert(pairs.end(), ends.begin(), ends.end());
  std::vector<Rgb> a(pairs.size()), b(pairs.size());
  with_holes.eval_batch(pairs, a);
  no_data.eval_batch(pairs, b);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const bool nan = std::isnan(pairs[i].wi.z + pairs[i].wi.x + pairs[i].wi.y + pairs[i].wo.x +
                                pairs[i].wo.y + pairs[i].wo.z);
    if (nan || pairs[i].wi.z < 0 || pairs[i].wo.z < 0) continue;
    ++checked;
    EXPECT_NEAR(a[i].r, 1.0, 1e-12) << i;
    EXPECT_NEAR(a[i].g, 1.15, 1e-12) << i;
    EXPECT_TRUE(std::isnan(b[i].r) && std::isnan(b[i].g) && std::isnan(b[i].b)) << i;
  }
  EXPECT_GT(checked, 20000u);
}

TEST(MerlBatch, SameResultWhateverTheSplit) {
  // Rows land in other SIMD lanes, blocks and threads when the batch starts elsewhere: their
  // values must not change.
  const MerlBrdf brdf(parse_merl(bytes_of(index_image()), "index"), {MerlLookup::trilinear});
  const auto pairs = batch_pairs();
  std::vector<Rgb> whole(pairs.size()), parts(pairs.size());
  brdf.eval_batch(pairs, whole);
  const std::span<const DirPair<double>> p(pairs);
  const std::span<Rgb> o(parts);
  for (auto [b, e] :
       {std::pair<std::size_t, std::size_t>{0, 3}, {3, 1001}, {1001, 12346}, {12346, pairs.size()}})
    brdf.eval_batch(p.subspan(b, e - b), o.subspan(b, e - b));
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    EXPECT_TRUE(same_value(whole[i].r, parts[i].r) && same_value(whole[i].g, parts[i].g) &&
                same_value(whole[i].b, parts[i].b))
        << i;
  }
}

// The block loops (vectorized across rows, in the version simd_isa() names) against the one-row
// formulas eval() uses: the same bins, cells and blends, bit for bit, on coordinates of every kind
// (inside, on bin edges, at both ends, the φd fold and wrap, negative, NaN, infinite), in every
// lane position and block length.
void expect_block_loops_are_the_one_row_formulas() {
  using namespace merl_kernel;
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(0, 1);
  const double nan = std::nan(""), inf = HUGE_VAL, top = kPi / 2;
  const std::vector<double> special = {0.0,     -0.0, 1e-300,          -1e-12,        top,
                                       top * 2, kPi,  2 * kPi - 1e-15, 7.0,           nan,
                                       inf,     -inf, top / 90 * 37,   kPi / 180 * 91};
  alignas(64) double q[3][kBlock];
  alignas(64) std::uint8_t apart[kBlock];
  std::uint32_t bins[kBlock];
  Cells cells;
  for (std::size_t m : {std::size_t(1), std::size_t(7), std::size_t(61), kBlock}) {
    for (int round = 0; round < 20; ++round) {
      for (std::size_t i = 0; i < m; ++i) {
        for (int a = 0; a < 3; ++a)
          q[a][i] =
              u(rng) < 0.2 ? special[rng() % special.size()] : (a == 2 ? 2 * kPi : top) * u(rng);
        apart[i] = u(rng) < 0.1;
      }
      nearest_bins(q[0], q[1], q[2], apart, m, 0xffffffffu, bins);
      merl_kernel::cells(q[0], q[1], q[2], m, cells);
      for (std::size_t i = 0; i < m; ++i) {
        EXPECT_EQ(bins[i], apart[i] ? 0xffffffffu : nearest_bin(q[0][i], q[1][i], q[2][i])) << i;
        const Cell one = cell_of(q[0][i], q[1][i], q[2][i]), block = cells[i];
        EXPECT_EQ(block.base, one.base) << q[0][i] << " " << q[1][i] << " " << q[2][i];
        EXPECT_EQ(block.phi_step, one.phi_step);
        for (int a = 0; a < 3; ++a) EXPECT_TRUE(same_bits(block.t[a], one.t[a])) << a;
        // All 8 corners in the table.
        EXPECT_LT(one.base + kThetaHStep + kThetaDStep + std::max(one.phi_step, 0), merl::kBins);
        EXPECT_GE(std::int64_t(one.base) + one.phi_step, 0);
      }
      // The blends, on a table with unmeasured bins: the block's rows against blend() of each cell.
      static const std::vector<merl::BinValues> table = [] {
        std::vector<merl::BinValues> t(merl::kBins);
        for (std::size_t i = 0; i < merl::kBins; ++i)
          for (int ch = 0; ch < 3; ++ch)
            t[i].rgb[ch] = (i + ch) % 13 == 0 ? -1.0 : 1.0 + std::sin(0.01 * double(i) + ch);
        return t;
      }();
      std::vector<Rgb> out(m);
      blend_rows(table.data(), cells, 0, m, out.data());
      for (std::size_t i = 0; i < m; ++i) {
        const Rgb one = blend(table.data(), cells[i]);
        EXPECT_TRUE(same_bits(out[i].r, one.r) && same_bits(out[i].g, one.g) &&
                    same_bits(out[i].b, one.b))
            << i;
      }
    }
  }
}

// The block loops against the one-row formulas, bit for bit, in the version of every instruction
// set (isa_versions.hpp: what HALFBACK_ISA=scalar, sse2, avx2 or avx512 runs).
TEST(MerlKernel, BlockLoopsAreTheOneRowFormulas) {
  EXPECT_GE(test::under_every_isa([](SimdIsa) { expect_block_loops_are_the_one_row_formulas(); }),
            1u);
}

// The blend kernels, each of them (the AVX-512 one where the CPU has it, the portable loop
// always, in the version of each instruction set), against blend() of each row, bit for bit: every
// block length from 1 to kBlock (all tails of the 8-row lane groups), a start inside the block,
// cells of every kind (the φd wrap, the clamped ends, unmeasured corners, corners missing in one
// channel or all three, a cell with none measured: NaN).
TEST(MerlKernel, BlendKernelsAreBlendBitForBit) {
  test::under_every_isa([&](SimdIsa) {
    using namespace merl_kernel;
    static const std::vector<merl::BinValues> table = [] {
      std::vector<merl::BinValues> t(merl::kBins);
      for (std::size_t i = 0; i < merl::kBins; ++i)
        for (int ch = 0; ch < 3; ++ch)
          t[i].rgb[ch] = (i + ch) % 13 == 0 || i % 97 < 9 ? -1.0
                         : i % 89 == 5                    ? 0.0  // measured zeros count
                         : i % 89 == 6                    ? -0.0
                                                          : 1.0 + std::sin(0.01 * double(i) + ch);
      return t;
    }();
    std::mt19937_64 rng(37);
    std::uniform_real_distribution<double> u(0, 1);
    const double nan = std::nan(""), top = kPi / 2;
    const std::vector<double> special = {0.0, -0.0, 1e-300, -1e-12, top, 2 * top, kPi, 7.0, nan};
    alignas(64) double q[3][kBlock];
    Cells cells;
    using Kernel = void (*)(const merl::BinValues*, const Cells&, std::size_t, std::size_t, Rgb*);
    std::vector<std::pair<const char*, Kernel>> kernels = {{"portable", blend_rows_portable},
                                                           {"dispatched", blend_rows}};
    if (avx512_kernels()) kernels.push_back({"avx512", blend_rows_avx512});
    std::size_t rows = 0;
    for (std::size_t m = 1; m <= kBlock; m += m < 40 ? 1 : 23) {
      for (std::size_t i = 0; i < m; ++i)
        for (int a = 0; a < 3; ++a)
          q[a][i] = u(rng) < 0.15  ? special[rng() % special.size()]
                    : u(rng) < 0.1 ? (a == 2 ? kPi * (1 - 1e-4 * u(rng)) : top * 1e-5 * u(rng))
                                   : (a == 2 ? 2 * kPi : top) * u(rng);
      merl_kernel::cells(q[0], q[1], q[2], m, cells);
      const std::size_t begin = m > 9 ? m % 5 : 0;
      for (const auto& [name, kernel] : kernels) {
        std::vector<Rgb> out(m, Rgb{-7, -7, -7});
        kernel(table.data(), cells, begin, m, out.data());
        for (std::size_t i = 0; i < m; ++i) {
          const Rgb one = i < begin ? Rgb{-7, -7, -7} : blend(table.data(), cells[i]);
          ASSERT_TRUE(same_bits(out[i].r, one.r) && same_bits(out[i].g, one.g) &&
                      same_bits(out[i].b, one.b))
              << name << " m " << m << " row " << i << ": " << out[i].r << " " << one.r;
        }
      }
      rows += m;
    }
    EXPECT_GT(rows, 2000u);
  });
}

// The AVX-512 kernels run when the library's one instruction-set choice is AVX-512 (core/simd.hpp:
// the CPU's best, or HALFBACK_ISA's), and not when a lower set is forced.
TEST(MerlKernel, AvxKernelsFollowTheLibrarysInstructionSet) {
  using formats_isa::Version;
  for (SimdIsa isa : detail::kAllIsas) {
    if (!detail::set_batch_isa(isa)) continue;
    EXPECT_EQ(merl_kernel::avx512_kernels(), isa == SimdIsa::avx512) << simd_isa_name(isa);
    // So do the versions of the block loops (isa_versions.hpp).
    const Version v = isa == SimdIsa::avx512 ? Version::avx512
                      : isa == SimdIsa::avx2 ? Version::avx2
                                             : Version::baseline;
    EXPECT_EQ(formats_isa::version(), v) << simd_isa_name(isa);
  }
  detail::set_batch_isa(std::nullopt);
  EXPECT_EQ(merl_kernel::avx512_kernels(), simd_isa() == SimdIsa::avx512);
}

// rows_apart, each kernel (the portable loop in the version of each instruction set), against its
// definition, on rows of every kind at every lane position.
TEST(MerlKernel, RowsApartKernelsAgree) {
  test::under_every_isa([&](SimdIsa) {
    using namespace merl_kernel;
    std::mt19937_64 rng(41);
    std::uniform_real_distribution<double> u(-1, 1);
    const double nan = std::nan("");
    using Kernel = void (*)(const double*, const std::uint8_t*, std::size_t, std::uint8_t*);
    std::vector<std::pair<const char*, Kernel>> kernels = {{"portable", rows_apart_portable},
                                                           {"dispatched", rows_apart}};
    if (avx512_kernels()) kernels.push_back({"avx512", rows_apart_avx512});
    for (std::size_t m = 1; m <= kBlock; m += m < 20 ? 1 : 29) {
      std::vector<double> rows(6 * m);
      std::vector<std::uint8_t> valid(m), expected(m);
      for (std::size_t i = 0; i < m; ++i) {
        double* p = rows.data() + 6 * i;
        for (int c = 0; c < 6; ++c) p[c] = u(rng);
        const int kind = int(rng() % 8);
        if (kind == 0) p[2 + 3 * (rng() % 2)] = rng() % 2 ? -0.0 : 0.0;  // at the horizon: kept
        if (kind == 1) p[3] = -p[0], p[4] = -p[1];                    // ωi + ωo along the normal
        if (kind == 2) p[rng() % 6] = nan;                            // NaN compares false
        if (kind == 3) p[3] = -p[0];                                  // one component only
        if (kind >= 4) p[2] = std::abs(p[2]), p[5] = std::abs(p[5]);  // above
        valid[i] = rng() % 9 ? std::uint8_t(1 + rng() % 255) : 0;     // any non-zero is valid
        expected[i] =
            valid[i] == 0 || p[2] < 0 || p[5] < 0 || (p[0] + p[3] == 0 && p[1] + p[4] == 0);
      }
      for (const auto& [name, kernel] : kernels) {
        std::vector<std::uint8_t> apart(m + 8, 0xee);
        kernel(rows.data(), valid.data(), m, apart.data());
        for (std::size_t i = 0; i < m; ++i)
          ASSERT_EQ(apart[i], expected[i]) << name << " " << m << " " << i;
        EXPECT_EQ(apart[m], 0xee) << name << ": wrote past the end";
      }
    }
  });
}

TEST(MerlWriter, RoundTripAtBinCentres) {
  TempDir tmp;
  const auto path = tmp / "lobe.binary";
  const TestLobe model;
  write_merl(path, model);
  EXPECT_EQ(std::filesystem::file_size(path), merl::kFileBytes);
  // Only the written file remains (no temporary).
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(tmp.path()),
                          std::filesystem::directory_iterator{}),
            1);
  const MerlData back = read_merl(path);
  EXPECT_FALSE(back.material.has_value());
  EXPECT_EQ(back.sha256.size(), 64u);
  const MerlBrdf brdf(back);
  std::size_t valid = 0, invalid = 0;
  for (int th = 0; th < 90; th += 3)
    for (int td = 0; td < 90; td += 3)
      for (int pd = 0; pd < 180; pd += 7) {
        const auto c = merl::bin_centre(th, td, pd);
        const Solved<double> s = inverse<HalfDiff>(Tuple4<double>{c[0], 0.0, c[1], c[2]});
        const std::size_t i = merl::bin(th, td, pd);
        const std::optional<DirPair<double>> at = merl_bin_pair(th, td, pd);
        if (s.in_domain) {
          ASSERT_TRUE(at.has_value());
          EXPECT_EQ(at->wi.x, s.pair.wi.x);  // a valid centre is where the bin is tabulated
          EXPECT_EQ(at->wo.z, s.pair.wo.z);
        }
        if (!at) {
          ++invalid;
          EXPECT_EQ(back.values[i], -1.0);  // no valid pair in the bin: written as missing
          continue;
        }
        ++valid;
        const merl::BinIndex b = merl::bin_of(*at);  // the pair is looked up in its own bin
        EXPECT_EQ(merl::bin(b.theta_h, b.theta_d, b.phi_d), i) << th << " " << td << " " << pd;
        const Rgb want = model.eval(*at), got = brdf.eval(*at);
        EXPECT_NEAR(got.r, want.r, 1e-14 * want.r) << th << " " << td << " " << pd;
        EXPECT_NEAR(got.g, want.g, 1e-14 * want.g);
        EXPECT_NEAR(got.b, want.b, 1e-14 * want.b);
      }
  EXPECT_GT(valid, 1000u);
  EXPECT_GT(invalid, 100u);
  EXPECT_EQ(back.missing[0], back.missing[2]);
  // The in-memory tabulation is what was written.
  const MerlData table = tabulate_merl(model);
  EXPECT_EQ(table.values, back.values);
}

// A written file has no holes: every valid pair, grazing ones included, finds a value (nearest
// and trilinear). The bins whose centre is below the horizon but which hold valid pairs were
// written as -1: 4-6 of 100 000 cosine-distributed pairs, and (θi = 89.9°, θo = 80°, Δφ = 90°),
// were NaN.
TEST(MerlWriter, EveryValidPairFindsAValue) {
  const MerlData table = tabulate_merl(TestLobe{});
  const double deg = kPi / 180;
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(0, 1);
  auto direction = [](double theta, double phi) {
    return Vec3<double>{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                        std::cos(theta)};
  };
  for (const MerlLookup lookup : {MerlLookup::nearest, MerlLookup::trilinear}) {
    const MerlBrdf brdf(table, {lookup});
    EXPECT_TRUE(brdf.eval({direction(89.9 * deg, 0), direction(80 * deg, 90 * deg)}).finite());
    std::size_t missing = 0;
    for (int n = 0; n < 200000; ++n) {
      // Half cosine-distributed, half with both directions within 5° of the horizon.
      const bool grazing = n % 2;
      const double ti = grazing ? (85 + 5 * u(rng)) * deg : std::acos(std::sqrt(u(rng)));
      const double to = grazing ? (85 + 5 * u(rng)) * deg : std::acos(std::sqrt(u(rng)));
      const DirPair<double> pair{direction(ti, 0), direction(to, 2 * kPi * u(rng))};
      if (!(pair.wi.z > 0 && pair.wo.z > 0)) continue;
      missing += !brdf.eval(pair).finite();
    }
    EXPECT_EQ(missing, 0u) << (lookup == MerlLookup::nearest ? "nearest" : "trilinear");
  }
}

// docs/reliability/readers.md, "Missing and negative measurements": a file with unmeasured bins
// (here every bin of θd ≥ 80°, as an instrument without grazing reach, and the bin of a grazing
// pair) gives, at a pair looked up there, a missing value (NaN), not the -1 mark times the scale
// (-0.000667); and no lookup anywhere gives a negative ρ.
TEST(MerlMissing, UnmeasuredBinsAreNaNNeverNegative) {
  MerlData table = tabulate_merl(TestLobe{});
  for (int th = 0; th < merl::kThetaH; ++th)
    for (int td = 80; td < merl::kThetaD; ++td)
      for (int pd = 0; pd < merl::kPhiD; ++pd)
        for (int c = 0; c < 3; ++c) table.values[c * merl::kBins + merl::bin(th, td, pd)] = -1;
  const double deg = kPi / 180;
  const DirPair<double> grazing{{std::sin(89.9 * deg), 0, std::cos(89.9 * deg)},
                                {0, std::sin(80 * deg), std::cos(80 * deg)}};
  const merl::BinIndex b = merl::bin_of(grazing);
  for (int c = 0; c < 3; ++c)
    table.values[c * merl::kBins + merl::bin(b.theta_h, b.theta_d, b.phi_d)] = -1;
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(0, 1);
  for (const MerlLookup lookup : {MerlLookup::nearest, MerlLookup::trilinear}) {
    const MerlBrdf brdf(table, {lookup});
    const Rgb at = brdf.eval(grazing);
    if (lookup == MerlLookup::nearest) {
      EXPECT_TRUE(std::isnan(at.r) && std::isnan(at.g) && std::isnan(at.b)) << at.r;
    }
    std::size_t missing = 0;
    for (int n = 0; n < 20000; ++n) {
      const double ti = std::acos(u(rng)), to = std::acos(u(rng)), dphi = 2 * kPi * u(rng);
      const Rgb v =
          brdf.eval({{std::sin(ti), 0, std::cos(ti)},
                     {std::sin(to) * std::cos(dphi), std::sin(to) * std::sin(dphi), std::cos(to)}});
      for (const double c : {v.r, v.g, v.b}) {
        EXPECT_FALSE(c < 0) << c;
        missing += std::isnan(c);
      }
    }
    if (lookup == MerlLookup::nearest) {
      EXPECT_GT(missing, 0u);  // some grazing pairs hit holes
    }
  }
}

TEST(MerlWriter, AtomicReplaceAndErrors) {
  TempDir tmp;
  const auto path = tmp / "x.binary";
  test::write_bytes(path, "old", 3);
  MerlData data;
  data.values.assign(3 * merl::kBins, 750.0);
  write_merl(path, data);
  EXPECT_EQ(read_merl(path).values[123], 750.0);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(tmp.path()),
                          std::filesystem::directory_iterator{}),
            1);
  EXPECT_FORMAT_ERROR(write_merl(tmp / "no-such-dir" / "y.binary", data), "y.binary", "write");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(tmp.path()),
                          std::filesystem::directory_iterator{}),
            1);
  // A BRDF whose values no MERL bin can hold is refused by name, and nothing is written.
  const test::FunctionBrdf spike(
      [](const DirPair<double>& p) { return p.wi.z > 0.999 && p.wo.z > 0.999 ? 1e12 : 1.0; });
  try {
    write_merl(tmp / "spike.binary", spike);
    ADD_FAILURE() << "no error for ρ = 1e12";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ρ = 1e+12 sr⁻¹ at θh"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(tmp / "spike.binary"));
  MerlData wrong;
  wrong.values.assign(10, 1.0);
  EXPECT_THROW(write_merl(path, wrong), std::invalid_argument);
  EXPECT_THROW(MerlBrdf{wrong}, std::invalid_argument);
}

// docs/reliability/readers.md, "Nothing is allocated from a size a file declares before the file is
// checked to hold it": the reader allocates from the sizes a file declares only after checking them
// against the file: a short file costs nothing, a whole one its own size plus the declared output
// (3 x 90 x 90 x 180 doubles).
TEST(MerlAllocation, BoundedByTheFileAndTheTable) {
  TempDir tmp;
  std::string head(12, '\0');
  const std::int32_t dims[3] = {90, 90, 180};
  std::memcpy(head.data(), dims, sizeof dims);
  test::write_bytes(tmp / "head.binary", head.data(), head.size());
  {
    test::AllocationProbe probe;
    EXPECT_FORMAT_ERROR(read_merl(tmp / "head.binary"), "head.binary", "truncated");
    EXPECT_LT(probe.growth(), 64u * 1024) << probe.growth();
  }
  const std::string image = merl_image([](int c, std::size_t i) { return double(c + i % 7); });
  test::write_bytes(tmp / "whole.binary", image.data(), image.size());
  test::AllocationProbe probe;
  const MerlData data = read_merl(tmp / "whole.binary", false);
  EXPECT_EQ(data.values.size(), 3 * merl::kBins);
  EXPECT_LT(probe.growth(), merl::kFileBytes + 3 * merl::kBins * sizeof(double) + (1u << 20))
      << probe.growth();
}

}  // namespace
}  // namespace halfback
