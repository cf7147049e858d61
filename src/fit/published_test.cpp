// The reader of the published fits (Ngan et al. 2005, as BBM distributes them).
#include "halfback/fit/published.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "halfback/fit/fit.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/util/format_error.hpp"
#include "support/test_support.hpp"

namespace halfback::fit {
namespace {

// A published line as a halfback spec: BBM's models by the registry's names, its parameters in
// lower case, [r, g, b] as NAME_r/_g/_b, values exact; a model halfback lacks is named.
TEST(PublishedFits, SpecOfALine) {
  const auto fits = parse_published_fits(
      "m = Aggregate(Lambertian(albedo = [0.0143, 0.033, 0.0639]), "
      "NganAshikhminShirley(albedo = [0.0366, 0.0241, 0.0147], fresnelReflectance = 0.0949, "
      "sharpness = 11600.0))\n"
      "n = NganLafortune(albedo = 0.5, Cxy = -0.577, Cz = 0.577, sharpness = 4060.0)\n"
      "o = Aggregate(Lambertian(albedo = 0.1), Phong(sharpness = 2))\n"
      "p = NganWard(albedo = [1, 2], roughness = 0.1)\n",
      "t.fit");
  ASSERT_EQ(fits.size(), 4u);
  EXPECT_EQ(spec_of(fits[0]),
            "lambert:albedo_r=0.0143,albedo_g=0.033,albedo_b=0.0639+ashikhmin-shirley:"
            "albedo_r=0.0366,albedo_g=0.0241,albedo_b=0.0147,f0=0.0949,sharpness=11600");
  EXPECT_EQ(model_of(fits[0]), "lambert+ashikhmin-shirley");
  EXPECT_EQ(spec_of(fits[1]), "lafortune:albedo=0.5,cxy=-0.577,cz=0.577,sharpness=4060");
  EXPECT_EQ(model_of(fits[1]), "lafortune");
  const auto refused = [](const PublishedFit& f, const std::string& words) {
    try {
      (void)spec_of(f);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what()).find(words) != std::string::npos;
    }
    return false;
  };
  EXPECT_TRUE(refused(fits[2], "o: halfback has no model for BBM's 'Phong'"));
  EXPECT_TRUE(refused(fits[3], "p: NganWard's 'albedo' has 2 values (one or three)"));
  EXPECT_THROW((void)model_of(fits[2]), std::invalid_argument);
  // Every line of the shared files maps (the models themselves: the loader's tests).
  HALFBACK_REQUIRE_SHARED(dir, "fits");
  for (const char* name : {"ngan_ashikhminshirley", "ngan_blinnphong", "ngan_cooktorrance",
                           "ngan_he", "ngan_lafortune", "ngan_ward", "ngan_wardduer"}) {
    for (const PublishedFit& f : read_published_fits(dir / (std::string(name) + ".fit"))) {
      EXPECT_NE(spec_of(f).find("lambert:albedo_r="), std::string::npos) << f.material;
      EXPECT_EQ(model_of(f).substr(0, 8), "lambert+") << f.material;
    }
  }
}

TEST(PublishedFits, ReadsAnAggregateLine) {
  const auto fits = parse_published_fits(
      "# comment\n\nblue-acrylic = Aggregate(Lambertian(albedo = [0.0143, 0.033, 0.0639]), "
      "NganCookTorrance(albedo = [0.0291, 0.0193, 0.0118], eta = 0.117, roughness = 1.37e-2))\r\n"
      "x = NganLafortune(Cxy = -0.577, sharpness = 4060.0)\n",
      "t.fit");
  ASSERT_EQ(fits.size(), 2u);
  EXPECT_EQ(fits[0].material, "blue-acrylic");
  EXPECT_EQ(fits[0].line, 3u);
  ASSERT_EQ(fits[0].lobes.size(), 2u);
  EXPECT_EQ(fits[0].lobes[0].model, "Lambertian");
  EXPECT_EQ(fits[0].lobes[0].params[0].second, (std::vector<double>{0.0143, 0.033, 0.0639}));
  EXPECT_EQ(fits[0].lobes[1].model, "NganCookTorrance");
  EXPECT_EQ(fits[0].lobes[1].params[2].first, "roughness");
  EXPECT_EQ(fits[0].lobes[1].params[2].second, (std::vector<double>{0.0137}));
  ASSERT_EQ(fits[1].lobes.size(), 1u);
  EXPECT_EQ(fits[1].lobes[0].params[0].second, (std::vector<double>{-0.577}));
}

void expect_error(const std::string& text, const std::string& words) {
  try {
    parse_published_fits(text, "bad.fit");
    ADD_FAILURE() << text << ": no error; expected " << words;
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    EXPECT_EQ(e.file(), "bad.fit");
  }
}

TEST(PublishedFits, MalformedLinesAreErrorsNamingTheLineAndColumn) {
  expect_error("a = Aggregate(Lambertian(albedo = [0.1, 0.2, 0.3])",
               "line 1, column 51: expected ')'");
  expect_error("# c\na = Ward(alpha = )", "line 2, column 18: expected a finite number");
  expect_error("a = Ward(alpha = nan)", "finite number");
  expect_error("a = Ward(alpha = 1e999)", "finite number");
  expect_error("a Ward(alpha = 1)", "expected '='");
  expect_error("a = Ward(alpha = 1, alpha = 2)", "parameter 'alpha' repeated");
  expect_error("a = Ward(alpha = 1) junk", "unexpected text");
  expect_error("a = Ward(alpha = [0.1, 0.2)", "expected ']'");
  expect_error("a = Ward(alpha = 1)\na = Ward(alpha = 2)", "line 2: material 'a' repeated");
  EXPECT_THROW(read_published_fits("/nonexistent/x.fit"), FormatError);
}

// docs/reliability/readers.md, "A reader reads what the file's header declares, and nothing more":
// the file is read line by line; the zeros of a file extended past its end are binary data, refused
// at the first line holding one.
TEST(PublishedFits, BinaryDataIsRefusedUnread) {
  test::TempDir tmp;
  const std::string text = "a = Ward(alpha = 1)\n";
  test::write_bytes(tmp / "x.fit", text.data(), text.size());
  EXPECT_EQ(read_published_fits(tmp / "x.fit").size(), 1u);
  std::filesystem::resize_file(tmp / "x.fit", std::uintmax_t(1) << 20);
  EXPECT_FORMAT_ERROR(read_published_fits(tmp / "x.fit"), "x.fit", "line 2",
                      "a NUL byte at column 1");
  std::filesystem::resize_file(tmp / "x.fit", std::uintmax_t(1) << 30);
  EXPECT_FORMAT_ERROR(read_published_fits(tmp / "x.fit"), "x.fit", "file size",
                      "1073741824 bytes is more than this format allows");
}

TEST(PublishedFits, EveryFileOfTheSharedData) {
  HALFBACK_REQUIRE_SHARED(dir, "fits");
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().extension() != ".fit") continue;
    ++files;
    const auto fits = read_published_fits(e.path());
    SCOPED_TRACE(e.path().string());
    // Ngan et al.'s sets: 86 materials; Löw et al.'s and Bagher et al.'s: all 100.
    const bool ngan = e.path().filename().string().starts_with("ngan_");
    EXPECT_EQ(fits.size(), ngan ? 86u : 100u);
    for (const PublishedFit& f : fits) {
      ASSERT_EQ(f.lobes.size(), 2u) << f.material;
      EXPECT_EQ(f.lobes[0].model, "Lambertian");
      EXPECT_EQ(f.lobes[0].params.at(0).second.size(), 3u);
      // Every fit is a spec of the registry's models, within their bounds, finite at a pair.
      BrdfPtr b;
      ASSERT_NO_THROW(b = load_brdf(spec_of(f))) << f.material;
      const Rgb v = b->eval({{0.3, 0.1, std::sqrt(0.9)}, {-0.2, 0.1, std::sqrt(0.95)}});
      EXPECT_TRUE(std::isfinite(v.r) && std::isfinite(v.g) && std::isfinite(v.b)) << f.material;
    }
  }
  EXPECT_EQ(files, 14u);  // Ngan: 7 models; Löw: 6 sets; Bagher: 1
}

// A list of lists is read row by row (Bagher et al.'s complex index); rows of different lengths
// are refused, naming the line and the column.
TEST(PublishedFits, NestedListsAreReadRowByRow) {
  // Bagher et al.'s pair of Fresnel rows becomes F0 and F1 per channel.
  const auto bagher = parse_published_fits(
      "m = Bagher(albedo = [1, 1, 1], eta = [[6.5, 0.25, 0.5], [5.5, 0.125, 0.25]], K = [1, 2, "
      "3])\n",
      "bagher");
  EXPECT_EQ(spec_of(bagher[0]),
            "bagher-sgd:albedo_r=1,albedo_g=1,albedo_b=1,f0_r=6.5,f0_g=0.25,f0_b=0.5,f1_r=5.5,"
            "f1_g=0.125,f1_b=0.25,kscale_r=1,kscale_g=2,kscale_b=3");
  const auto fits = parse_published_fits(
      "m = Bagher(eta = [[1.5, 2, 3], [0.1, 0.2, 0.3]], K = [1, 2, 3])\n", "nested");
  ASSERT_EQ(fits.size(), 1u);
  EXPECT_EQ(fits[0].lobes[0].params[0].second, (std::vector<double>{1.5, 2, 3, 0.1, 0.2, 0.3}));
  EXPECT_THROW(parse_published_fits("m = Bagher(eta = [[1, 2], [3]])\n", "ragged"), FormatError);
}

// The small version of scripts/fit-published.sh: for one material of Löw et al.'s Cook–Torrance
// E2 set and of Ngan et al.'s Ward set, halfback's fit of the same model under the set's
// published loss (bbm-low-e2, bbm-ngan) on coarse BBM grids, from the published parameters, is at
// least as good as the published parameters on the neural BRDF of the material.
TEST(PublishedFits, HalfbacksFitIsAtLeastAsGoodUnderThePublishedLoss) {
  HALFBACK_REQUIRE_SHARED(fits, "fits");
  HALFBACK_REQUIRE_SHARED(nbrdf, "nbrdf/merl_nbrdf");
  struct Case {
    const char* file;
    Loss loss;
    BbmGrid grid;
  };
  for (const Case& c : {Case{"low_cooktorrance_E2.fit", Loss::bbm_low_e2, {18, 10, 1, 10}},
                        Case{"ngan_ward.fit", Loss::bbm_ngan, {12, 6, 12, 6}}}) {
    SCOPED_TRACE(c.file);
    const PublishedFit f = read_published_fits(fits / c.file).at(0);
    const BrdfPtr target = load_brdf((nbrdf / (f.material + ".h5")).string());
    const std::string published = spec_of(f);
    FitOptions o;
    o.loss = c.loss;
    o.grid = c.grid;
    o.starts = {published};
    const FitResult r = fit(*target, model_of(f), o);
    const double before = loss_of(*target, *load_brdf(published), c.loss, 1, 0, c.grid);
    EXPECT_GT(before, 0);
    EXPECT_LE(r.loss_value, before) << f.material << ": " << r.spec;
    // And the fit improves on it: the published parameters are not its optimum on this target.
    EXPECT_LT(r.loss_value, 0.9 * before) << f.material;
  }
}

}  // namespace
}  // namespace halfback::fit
