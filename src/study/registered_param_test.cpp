// A parameterization registered at run time is studied like the built-in ones: the default list
// takes it (before the spherical baseline), every table has its rows, the report its column, and
// the settings and part tables carry it. (The registration lasts for the process: each test of
// this executable runs in a process of its own, gtest_discover_tests.)
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>

#include "halfback/core/parameterization.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/study/parts.hpp"
#include "halfback/study/report.hpp"
#include "support/test_support.hpp"

namespace halfback::study {
namespace {

using acquire::Spacing;

// Hybrid under another name: the same maps, so the same numbers as hybrid's.
struct ToyHybrid : Hybrid {
  static constexpr std::string_view name = "toy-hybrid";
  static constexpr std::string_view summary = "hybrid under another name (a test's)";
};
static_assert(Parameterization<ToyHybrid>);

std::string read_file(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

// The error of the row "BRDF,PARAM,ERROR,..." of a CSV text (-1 when there is none).
double error_in(const std::string& csv, const std::string& row_start) {
  const std::size_t at = csv.find("\n" + row_start + ",");
  return at == std::string::npos ? -1 : std::stod(csv.substr(at + row_start.size() + 2));
}

TEST(StudyRegistered, ARegisteredParameterizationIsStudiedAndReported) {
  const Space toy = register_parameterization<ToyHybrid>();
  const std::vector<Space> params = default_studied();
  // The built-in ones studied by default, the toy registered last, the baseline at the end.
  const std::vector<Space> expected{
      space_of<HalfDiff>, space_of<Ortho>, space_of<Hybrid>, space_of<RectifiedHybrid>, toy,
      space_of<Spherical>};
  ASSERT_EQ(params, expected);
  EXPECT_FALSE(space_of<StereoHalfDiff>.param().studied_by_default());

  StudyConfig c;  // the default list, the toy included
  c.grid = {12, 12, 16};
  c.budgets = {300, 1000};
  c.test_pairs = 2000;
  c.image_budget = 1000;
  c.spacings = {Spacing::own, Spacing::angle};
  ASSERT_EQ(c.params, params);
  // Studied beside the paper's four only, to keep the test short.
  c.params = {space_of<HalfDiff>, space_of<Ortho>, space_of<Hybrid>, toy, space_of<Spherical>};
  const BrdfResult r = study_brdf(*load_brdf("ggx:alpha=0.3"), "ggx", c);
  EXPECT_EQ(r.params, c.params);

  const test::TempDir tmp;
  const StudyOutput out = write_study(tmp.path(), {r}, c, 1);
  const std::string az = read_file(tmp.path() / "azimuthal.csv");
  const std::string gonio = read_file(tmp.path() / "gonio.csv");
  ASSERT_GE(error_in(az, "ggx,toy-hybrid"), 0) << az;
  // The same maps: the same numbers as hybrid's, up to the rounding of another code path.
  EXPECT_NEAR(error_in(az, "ggx,toy-hybrid"), error_in(az, "ggx,hybrid"),
              1e-6 * error_in(az, "ggx,hybrid"));
  EXPECT_NE(gonio.find("\nggx,toy-hybrid,regular,"), std::string::npos) << gonio;
  EXPECT_NE(read_file(tmp.path() / "budget.csv").find("\nggx,toy-hybrid,"), std::string::npos);
  EXPECT_NE(out.markdown.find("| BRDF | halfdiff | ortho | hybrid | toy-hybrid | spherical |"),
            std::string::npos)
      << out.markdown;
  EXPECT_NE(out.markdown.find("| parameterization | own regular |"), std::string::npos);
  EXPECT_NE(out.markdown.find("| toy-hybrid |"), std::string::npos);
  EXPECT_NE(out.markdown.find("measured in all five"), std::string::npos);

  // The settings name it; the tables round-trip with it.
  const std::string settings = describe_config(c);
  EXPECT_EQ(settings.rfind("parameterizations = halfdiff,ortho,hybrid,toy-hybrid,spherical\n", 0),
            0u)
      << settings;
  EXPECT_EQ(config_from_description(settings, "test").params, c.params);
  const BrdfResult back = from_tables(to_tables(r), c.params, "test");
  ASSERT_EQ(back.tables.size(), r.tables.size());
  for (std::size_t t = 0; t < r.tables.size(); ++t)
    EXPECT_TRUE(back.tables[t].rows == r.tables[t].rows) << r.tables[t].name;
  // Tables of a run without it do not read as a run with it, nor the reverse.
  const std::vector<Space> builtin{space_of<HalfDiff>, space_of<Ortho>, space_of<Hybrid>,
                                   space_of<Spherical>};
  EXPECT_THROW(from_tables(to_tables(r), builtin, "test"), std::runtime_error);
  // A report of BRDFs studied with different parameterizations is refused.
  StudyConfig four = c;
  four.params = builtin;
  const BrdfResult other = study_brdf(*load_brdf("lambert"), "lambert", four);
  const test::TempDir tmp2;
  EXPECT_THROW(write_study(tmp2.path(), {r, other}, c, 1), std::invalid_argument);
  EXPECT_NO_THROW(write_study(tmp2.path(), {other}, four, 1));
}

TEST(StudyRegistered, ParameterizationsAreChosenByName) {
  StudySettings s;
  s.off = {"gonio"};
  s.params = {"hybrid", "halfdiff"};
  EXPECT_EQ(make_config(s).params, (std::vector<Space>{space_of<Hybrid>, space_of<HalfDiff>}));
  s.params = {"hybrid", "hybrid"};
  EXPECT_THROW(make_config(s), std::invalid_argument);
  s.params = {"dirs"};
  EXPECT_THROW(make_config(s), std::invalid_argument);
  s.params = {"never-registered"};
  try {
    make_config(s);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--params: 'never-registered' is not a parameterization"),
              std::string::npos)
        << e.what();
  }
  StudyConfig c;
  c.params = {space_of<Hybrid>, space_of<HalfDiff>};
  const std::string text = describe_config(c);
  EXPECT_EQ(config_from_description(text, "t").params, c.params);
  EXPECT_THROW(
      config_from_description(
          "parameterizations = never-registered\n" + text.substr(text.find('\n') + 1), "t"),
      std::runtime_error);
}

}  // namespace
}  // namespace halfback::study
