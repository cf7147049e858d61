// Tests of `halfback compare A B` (the binary at HALFBACK_CLI_PATH): values known by hand, a BRDF
// against itself, agreement with `halfback fit`'s reported loss, the figure, and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "halfback/figure/render.hpp"
#include "halfback/fit/fit.hpp"
#include "support/spawn.hpp"
#include "support/test_support.hpp"

// A named namespace: the test files are compiled as one unity translation unit.
namespace halfback::compare_cli_test {

namespace fs = std::filesystem;
using nlohmann::json;

struct Outcome {
  int status = -1;
  std::string out, err;
};

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class CompareCli : public testing::Test {
 protected:
  fs::path path(const std::string& name) const { return dir_.path() / name; }

  // Runs halfback with `args` in the test's folder.
  Outcome run(const std::vector<std::string>& args) const {
    std::vector<std::string> argv{HALFBACK_CLI_PATH};
    argv.insert(argv.end(), args.begin(), args.end());
    const test::Captured ran = test::run_captured(dir_.path(), std::move(argv));
    if (!ran.started) ADD_FAILURE() << "cannot run " << HALFBACK_CLI_PATH << ": " << ran.error;
    return {ran.status, ran.out, ran.err};
  }

  // The names in the test's folder (no leftover temporary files).
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_.path())) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  }

  json compare_json(const std::string& a, const std::string& b,
                    std::vector<std::string> more = {}) const {
    std::vector<std::string> args{"compare", a, b, "--json", "c.json", "--test-pairs", "20000"};
    args.insert(args.end(), more.begin(), more.end());
    const Outcome r = run(args);
    EXPECT_EQ(r.status, 0) << r.err;
    return json::parse(read_all(path("c.json")));
  }

  test::TempDir dir_;
};

TEST_F(CompareCli, ABrdfAgainstItselfIsZeroInEveryMeasure) {
  const json j = compare_json("lambert:albedo=0.3+ggx:alpha=0.2",
                              "lambert:albedo=0.3+ggx:alpha=0.2", {"--samples", "2000"});
  ASSERT_EQ(j["fit_losses"]["values"].size(), std::size(fit::kLosses));
  for (const auto& [name, v] : j["fit_losses"]["values"].items())
    EXPECT_EQ(v.get<double>(), 0) << name;
  ASSERT_EQ(j["study_errors"]["values"].size(), 5u);
  for (const auto& [name, v] : j["study_errors"]["values"].items())
    EXPECT_EQ(v.get<double>(), 0) << name;
  for (const json& row : j["albedo"]["rows"])
    for (const json& d : row["difference"]) EXPECT_EQ(d.get<double>(), 0);
}

// Two Lambertian BRDFs of albedo 0.5 and 0.6: ρ = a/π, grey, so the luminance is ρ too.
// - study, linear: the relative L² error of a constant ratio 1.2 is 0.2 on any test pairs;
//   log: ln(1 + 0.6/π)/ln(1 + 0.5/π) − 1; cbrt: 1.2^⅓ − 1 (likewise constant ratios);
// - fit, ngan: mean of w c² (m − t)² = (0.1/π)² · mean(w c²), and mean(w c²) estimates
//   ∫∫ cos²θi dωi dωo / (2π)² = (2π/3)(2π)/(2π)² = 1/3 (the layout's weights have mean 1);
//   low-e1: (0.1/π)² · mean(c²) over the layout, computed here from the library's layout;
// - albedo: 0.5 and 0.6 at every incidence (the cosine estimator of a constant ρ is exact).
TEST_F(CompareCli, TwoLambertiansGiveTheValuesComputedByHand) {
  const json j = compare_json("lambert:albedo=0.5", "lambert:albedo=0.6", {"--samples", "4000"});
  const double pi = std::numbers::pi, d2 = (0.1 / pi) * (0.1 / pi);
  const json& study = j["study_errors"]["values"];
  EXPECT_NEAR(study["linear"].get<double>(), 0.2, 1e-12);
  EXPECT_NEAR(study["log"].get<double>(), std::log1p(0.6 / pi) / std::log1p(0.5 / pi) - 1, 1e-12);
  EXPECT_NEAR(study["cbrt"].get<double>(), std::cbrt(1.2) - 1, 1e-12);
  const json& loss = j["fit_losses"]["values"];
  EXPECT_NEAR(loss["ngan"].get<double>(), d2 / 3, 0.02 * d2 / 3);  // quasi-Monte-Carlo
  const fit::Samples s = fit::halfdiff_samples(4000);
  double mean_c2 = 0;
  for (double c : s.cos_i) mean_c2 += c * c / double(s.cos_i.size());
  EXPECT_NEAR(loss["low-e1"].get<double>(), d2 * mean_c2, 1e-12 * d2);
  ASSERT_EQ(j["albedo"]["rows"].size(), 4u);
  for (const json& row : j["albedo"]["rows"])
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(row["reference"][k].get<double>(), 0.5, 1e-9);
      EXPECT_NEAR(row["difference"][k].get<double>(), 0.1, 1e-9);
    }
}

// The loss a fit reports is compare's loss of the fitted spec against the target, on the same
// number of samples.
TEST_F(CompareCli, TheFitsLossIsComparesLoss) {
  const Outcome fit = run({"fit", "--brdf", "ggx:alpha=0.3", "--model", "lambert+beckmann",
                           "--samples", "1500", "-o", "fit.json"});
  ASSERT_EQ(fit.status, 0) << fit.err;
  const json f = json::parse(read_all(path("fit.json")));
  const json j = compare_json("ggx:alpha=0.3", f["spec"].get<std::string>(), {"--samples", "1500"});
  const double expected = f["loss"]["value"].get<double>();
  EXPECT_GT(expected, 0);
  EXPECT_NEAR(j["fit_losses"]["values"]["ngan"].get<double>(), expected, 1e-12 * expected);
}

TEST_F(CompareCli, WritesTheTableAndAValidPngFigure) {
  const Outcome r = run({"compare", "ggx:alpha=0.2", "beckmann:alpha=0.25", "--samples", "1000",
                         "--test-pairs", "5000", "-o", "cmp.png"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* word : {"ngan", "nielsen", "linear", "cbrt", "Directional albedo", "80°"})
    EXPECT_NE(r.out.find(word), std::string::npos) << word << " in\n" << r.out;
  const figure::Raster png = figure::decode_png(read_all(path("cmp.png")));
  EXPECT_GT(png.width, 500u);
  EXPECT_GT(png.height, 500u);
  EXPECT_EQ(entries(), std::vector<std::string>{"cmp.png"});
}

// Measured data without values at some pairs (an ALTA file of retro-reflection, measured at
// 16°-60° of incidence): the losses and the study's errors are over the pairs where it has values,
// and say how many; its albedo is missing where no ωo was measured and noted where only part was.
TEST_F(CompareCli, MeasuredDataIsComparedWhereItHasValues) {
  HALFBACK_REQUIRE_SHARED(alta, "alta");
  const std::string a = (alta / "retro-3M-jaune.dat").string();
  const Outcome r = run({"compare", a, "lambert:albedo=0.5", "--samples", "1000", "--test-pairs",
                         "2000", "--json", "c.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(read_all(path("c.json")));
  const std::size_t used = j["fit_losses"]["used"].get<std::size_t>();
  EXPECT_GT(used, 100u);
  EXPECT_LT(used, 1000u);
  for (const auto& [name, v] : j["fit_losses"]["values"].items()) {
    EXPECT_TRUE(std::isfinite(v.get<double>())) << name;
    EXPECT_GT(v.get<double>(), 0) << name;
  }
  for (const auto& [name, v] : j["study_errors"]["used"].items())
    EXPECT_LT(v.get<int>(), 2000) << name;
  const json& rows = j["albedo"]["rows"];
  EXPECT_TRUE(rows[0]["reference"][0].is_null());  // θi = 0°: nothing measured
  EXPECT_EQ(rows[0]["reference_measured"].get<double>(), 0);
  EXPECT_NE(r.out.find("not measured"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mean over the measured"), std::string::npos) << r.out;
}

TEST_F(CompareCli, BadInputIsRefusedWithoutLeavingAFile) {
  test::write_bytes(path("bad.binary"), "not a MERL file", 15);
  // A file that does not hold a BRDF: bad data, status 1; neither output is left.
  Outcome r = run({"compare", "lambert", "bad.binary", "-o", "c.png", "--json", "c.json"});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("bad.binary"), std::string::npos) << r.err;
  EXPECT_EQ(entries(), std::vector<std::string>{"bad.binary"});
  // A model that does not exist, an unknown option, a figure format that is none: status 2.
  r = run({"compare", "no-such-model:x=1", "lambert"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("no-such-model"), std::string::npos) << r.err;
  r = run({"compare", "lambert", "ggx", "--bogus"});
  EXPECT_EQ(r.status, 2) << r.err;
  r = run({"compare", "lambert", "ggx", "-o", "c.txt"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(".png, .svg or .pdf"), std::string::npos) << r.err;
  r = run({"compare", "lambert", "ggx", "-o", "c.png", "--json", "c.png"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(entries(), std::vector<std::string>{"bad.binary"});
  // An output that names an input: status 2, the input kept as it was.
  for (const char* option : {"-o", "--json"}) {
    const std::string target = option == std::string("-o") ? "in.png" : "in.json";
    test::write_bytes(path(target), "input", 5);
    r = run({"compare", target, "ggx", option, target});
    EXPECT_EQ(r.status, 2) << option << ": " << r.err;
    EXPECT_NE(r.err.find("never replaces an input"), std::string::npos) << r.err;
    EXPECT_EQ(read_all(path(target)), "input");
  }
}

}  // namespace halfback::compare_cli_test
