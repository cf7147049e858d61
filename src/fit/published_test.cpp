// The reader of the published fits (Ngan et al. 2005, as BBM distributes them).
#include "halfback/fit/published.hpp"

#include <gtest/gtest.h>

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

// Issue 35, class C (docs/reliability-round3-readers.md): the file is read line by line; the zeros
// of a file extended past its end are binary data, refused at the first line holding one.
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
    EXPECT_EQ(fits.size(), 86u);  // 88 lines: two comments and 86 materials
    for (const PublishedFit& f : fits) {
      ASSERT_EQ(f.lobes.size(), 2u) << f.material;
      EXPECT_EQ(f.lobes[0].model, "Lambertian");
      EXPECT_EQ(f.lobes[0].params.at(0).second.size(), 3u);
    }
  }
  EXPECT_EQ(files, 7u);
}

}  // namespace
}  // namespace halfback::fit
