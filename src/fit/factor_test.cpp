// Factored models (fit/factor.hpp, formats/factored.hpp): exact where the BRDF is exactly of the
// model's form, better with more terms, the file's exact round trip through the loader, and the
// errors of bad input.
#include "halfback/fit/factor.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "halfback/brdf/rho_bound.hpp"

#include "halfback/loader/load.hpp"
#include "halfback/util/format_error.hpp"
#include "support/test_support.hpp"

namespace halfback::fit {
namespace {

// ρ_c = exp(k_c f(θh) g(θd)) − 1 with smooth f, g: exactly one separable term in log(1 + ρ) in
// halfdiff, in each channel.
class SeparableInHalfdiff final : public Brdf {
 public:
  std::string name() const override { return "separable"; }
  std::string description() const override { return name(); }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& p) const override {
    if (!(p.wi.z > 0 && p.wo.z > 0)) return {};
    const Vec3<double> h{p.wi.x + p.wo.x, p.wi.y + p.wo.y, p.wi.z + p.wo.z};
    const double len = std::sqrt(h.x * h.x + h.y * h.y + h.z * h.z);
    const double th = std::acos(std::clamp(h.z / len, -1.0, 1.0));
    const double td =
        std::acos(std::clamp((p.wi.x * h.x + p.wi.y * h.y + p.wi.z * h.z) / len, -1.0, 1.0));
    const double x = (1 + std::cos(2 * th)) * (0.5 + 0.2 * std::sin(td));
    return {std::expm1(x), std::expm1(0.5 * x), std::expm1(0.25 * x)};
  }
};

DirPair<double> pair_at(double ti, double pi, double to, double po) {
  return {{std::sin(ti) * std::cos(pi), std::sin(ti) * std::sin(pi), std::cos(ti)},
          {std::sin(to) * std::cos(po), std::sin(to) * std::sin(po), std::cos(to)}};
}

TEST(Factor, ConstantIsExactInEveryParameterization) {
  const BrdfPtr lambert = load_brdf("lambert:albedo_r=0.6,albedo_g=0.3,albedo_b=0.1");
  for (const char* name : {"halfdiff", "hybrid", "spherical"}) {
    const FactorResult r =
        factor_brdf(*lambert, *space_from_name(name), {.rank = 1, .counts = {8, 8, 8}});
    EXPECT_LT(r.relative_error, 1e-9) << name;
    const FactoredBrdf f(r.model);
    const Rgb v = f.eval(pair_at(0.3, 0.1, 1.1, 2.5));
    EXPECT_NEAR(v.r, 0.6 / std::numbers::pi, 1e-9) << name;
    EXPECT_NEAR(v.b, 0.1 / std::numbers::pi, 1e-9) << name;
  }
}

// One term suffices where the BRDF is separable (halfdiff, to the interpolation between cell
// centres), not in the spherical coordinates; more terms never fit worse.
TEST(Factor, SeparableWhereTheParameterizationSeparatesIt) {
  const SeparableInHalfdiff b;
  const FactorOptions one{.rank = 1, .counts = {32, 32, 16}};
  const double halfdiff = factor_brdf(b, space_of<HalfDiff>, one).relative_error;
  const double spherical = factor_brdf(b, space_of<Spherical>, one).relative_error;
  EXPECT_LT(halfdiff, 1e-6);
  EXPECT_GT(spherical, 100 * halfdiff);
  double previous = 1e300;
  for (std::size_t rank : {1, 2, 4}) {
    const double e =
        factor_brdf(b, space_of<Spherical>, {.rank = rank, .counts = {16, 16, 16}}).relative_error;
    EXPECT_LE(e, previous * (1 + 1e-9)) << rank;
    previous = e;
  }
}

TEST(Factor, FileRoundTripsThroughTheLoader) {
  const test::TempDir dir;
  const FactorResult r = factor_brdf(*load_brdf("lambert:albedo=0.2+ggx:alpha=0.3,f0=0.5"),
                                     space_of<Hybrid>, {.rank = 3, .counts = {12, 10, 8}});
  const auto path = dir.path() / "ggx.json";
  write_factored(path, r.model);
  const BrdfPtr back = load_brdf(path.string());
  const FactoredBrdf direct(r.model);
  EXPECT_EQ(back->description(), direct.description());
  for (double ti : {0.1, 0.7, 1.3})
    for (double to : {0.2, 0.9, 1.4}) {
      const DirPair<double> p = pair_at(ti, 0.3, to, 2.9);
      const Rgb a = direct.eval(p), b = back->eval(p);
      EXPECT_EQ(a.r, b.r);
      EXPECT_EQ(a.g, b.g);
      EXPECT_EQ(a.b, b.b);
    }
  EXPECT_EQ(r.model.numbers(), 3u * 3 * (12 + 10 + 8) + 3);
}

// Where no data constrained a product of factors, the model stays within the data's range: never
// above the largest value it was fitted to, in any channel (the clamp of formats/factored.hpp).
TEST(Factor, NeverAboveTheDataItWasFittedTo) {
  const BrdfPtr b = load_brdf("ggx:alpha=0.05,f0=0.9");
  for (const char* name : {"rectified-hybrid", "spherical", "hybrid"}) {
    const FactorResult r =
        factor_brdf(*b, *space_from_name(name), {.rank = 1, .counts = {16, 16, 8}});
    const FactoredBrdf f(r.model);
    for (double ti = 0.05; ti < 1.55; ti += 0.1)
      for (double to = 0.05; to < 1.55; to += 0.1)
        for (double po : {0.0, 1.0, 2.0, 3.1}) {
          const Rgb v = f.eval(pair_at(ti, 0, to, po));
          ASSERT_LE(v.r, std::expm1(r.model.max_log[0]) * (1 + 1e-12)) << name;
          ASSERT_GE(v.r, 0) << name;
        }
  }
}

TEST(Factor, BadInputIsRefusedByName) {
  const BrdfPtr ggx = load_brdf("ggx:alpha=0.3");
  EXPECT_THROW(factor_brdf(*ggx, space_of<Hybrid>, {.rank = 0}), std::invalid_argument);
  EXPECT_THROW(factor_brdf(*ggx, space_of<Hybrid>, {.counts = {0, 8, 8}}), std::invalid_argument);
  EXPECT_THROW(factor_brdf(*load_brdf("ggx:alpha_x=0.1,alpha_y=0.3"), space_of<Hybrid>),
               std::invalid_argument);
  EXPECT_THROW(factor_brdf(*ggx, Space::dirs), std::invalid_argument);
  const test::TempDir dir;
  const FactorResult r = factor_brdf(*ggx, space_of<Hybrid>, {.rank = 1, .counts = {4, 4, 4}});
  const auto path = dir.path() / "f.json";
  write_factored(path, r.model);
  std::ifstream in(path);
  const std::string good((std::istreambuf_iterator<char>(in)), {});
  const auto refused = [&](std::string text, const char* field) {
    const auto bad = dir.path() / "bad.json";
    std::ofstream(bad) << text;
    try {
      (void)read_factored(bad);
      ADD_FAILURE() << "accepted: " << text.substr(0, 200);
    } catch (const FormatError& e) {
      EXPECT_EQ(e.field().substr(0, std::string(field).size()), field) << e.what();
    }
  };
  const auto replaced = [&](const std::string& from, const std::string& to) {
    std::string t = good;
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return t.replace(at, from.size(), to);
  };
  refused(good.substr(0, good.size() / 2), "file");  // truncated: not JSON
  refused(replaced("\"version\": 1", "\"version\": 2"), "version");
  refused(replaced("\"hybrid\"", "\"nosuch\""), "parameterization");
  refused(replaced("\"rank\": 1", "\"rank\": 2"), "factors.r");
  refused(replaced("\"rank\": 1", "\"rank\": 0"), "rank");
  refused(replaced("\"counts\": [", "\"counts\": [5000, "), "counts");
  refused(replaced("\"max_log\": [", "\"max_log\": [-1, "), "max_log");
  refused(replaced("\"a\": [", "\"a\": [1, "), "factors.r[0].a");
  refused(replaced("\"phi\": [", "\"phi\": [\"x\", "), "factors.r[0].phi");
}

// The bound on ρ (brdf/rho_bound.hpp) holds for factored files: ρ_c ≤ exp(M_c) − 1, so a file
// whose max_log can exceed kMaxRho is refused naming the field (1000 made ρ infinite, 30 made it
// 1.07e13); a max_log at the bound is accepted and its values stay within it.
TEST(FactoredFile, MaxLogAboveTheRhoBoundIsRefusedNamingTheField) {
  FactoredModel m;
  m.counts = {2, 2, 2};
  for (auto& terms : m.channels) terms.push_back({{800, 800}, {1, 1}, {1, 1}});
  const double at_bound = std::log1p(kMaxRho);
  m.max_log = {at_bound, at_bound, at_bound};
  const std::string good = factored_text(m);
  const FactoredBrdf f(parse_factored(good, "good.json"));
  const Rgb v = f.eval({{0.3, 0.1, std::sqrt(0.9)}, {-0.2, 0.4, std::sqrt(0.8)}});
  EXPECT_TRUE(std::isfinite(v.r) && v.r <= kMaxRho * (1 + 1e-12)) << v.r;
  for (const char* max_log : {"30", "1000", "1e300"}) {
    std::string text = good;  // the first channel's max_log replaced
    const auto open = text.find('[', text.find("\"max_log\""));
    ASSERT_NE(open, std::string::npos);
    text.replace(open + 1, text.find(',', open) - open - 1, max_log);
    try {
      (void)parse_factored(text, "big.json");
      ADD_FAILURE() << "accepted max_log " << max_log;
    } catch (const FormatError& e) {
      EXPECT_EQ(e.field(), "max_log[0]") << e.what();
      EXPECT_NE(e.problem().find("above the bound"), std::string::npos) << e.what();
    }
  }
  m.max_log[1] = 30;
  EXPECT_THROW((void)factored_text(m), std::invalid_argument);  // nor is one written
}

// The largest counts a factored file may have (4096 an axis) load: a factored BRDF makes no grid
// of its cells (4096³ points would be above a resampled grid's limit, which made the file a
// usage error blamed on the command line).
TEST(FactoredFile, LargestCountsLoad) {
  FactoredModel m;
  m.counts = {4096, 4096, 4096};
  for (auto& terms : m.channels)
    terms.push_back({std::vector<double>(4096, 0.5), std::vector<double>(4096, 1.0),
                     std::vector<double>(4096, 1.0)});
  m.max_log = {1, 1, 1};
  const test::TempDir dir;
  write_factored(dir.path() / "big.json", m);
  const BrdfPtr b = load_brdf((dir.path() / "big.json").string());
  const Rgb v = b->eval({{0, 0, 1}, {0, 0, 1}});
  EXPECT_NEAR(v.r, std::expm1(0.5), 1e-12);
}

// A BRDF that is NaN somewhere inside the domain: refused, naming the point.
class NanAtNormalIncidence final : public Brdf {
 public:
  std::string name() const override { return "nan"; }
  std::string description() const override { return name(); }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& p) const override {
    return p.wi.z > 0.99 ? Rgb{NAN, 0, 0} : Rgb{0.1, 0.1, 0.1};
  }
};

TEST(Factor, NotFiniteBrdfIsRefused) {
  try {
    (void)factor_brdf(NanAtNormalIncidence(), space_of<Spherical>, {.counts = {16, 4, 4}});
    ADD_FAILURE() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace halfback::fit
