// The per-BRDF parts of the study: exact round trips of the tables, the settings and the part
// files, and the merge of results from several runs.
#include "halfback/study/parts.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>

#include "fake_results.hpp"
#include "halfback/loader/load.hpp"
#include "support/test_support.hpp"

namespace halfback::study {
namespace {

using acquire::Design;
using acquire::DesignProfile;
using acquire::ErrorSpace;
using acquire::kDesigns;
using acquire::learn_warps;
using acquire::Spacing;

using fakes::FakeParam;

// A made-up result with numbers that "%.6g" would round (so a lossy round trip shows).
BrdfResult fake(const std::string& label, bool isotropic, double k) {
  fakes::FakeBrdf b;
  b.label = label;
  b.isotropic = isotropic;
  b.seconds = 1.0 / 3;
  for (Space s : fakes::builtin_params()) {
    FakeParam p;
    p.space = s;
    p.azimuthal = k * std::numbers::pi / 100;
    p.separability_2d = {k / 7, k / 11, k / 13, 0};
    p.separability_3d = {k / 17, k / 19};
    for (Design d : kDesigns)
      for (std::size_t n : {1000u, 10000u})
        p.gonio.push_back({d, n, n - 3, k * std::exp(-double(n) / 7777)});
    p.gonio.push_back({Design::regular, 1000, 997, k / 37, Spacing::learned});
    p.gonio.push_back({Design::regular, 1000, 996, k / 41, Spacing::merl});
    p.images.push_back({Design::stratified, 997, "a \"quoted\", env", k / 3, k / 9, k / 27, k / 43,
                        k / 47, 1 - k / 53});
    if (!isotropic) {
      p.azimuthal_4d = k / 23;
      p.separability_4d = {k / 29};
      p.gonio_4d = {{Design::regular, 1000, 999, k / 31}};
    }
    b.params.push_back(p);
    k *= 1.1;
  }
  return fakes::to_result(b);
}

// The same label, parameterizations and tables: every cell equal (the same doubles, exactly).
void expect_same(const BrdfResult& a, const BrdfResult& b) {
  EXPECT_EQ(a.label, b.label);
  EXPECT_EQ(a.isotropic, b.isotropic);
  EXPECT_EQ(a.seconds, b.seconds);
  EXPECT_EQ(a.params, b.params);
  ASSERT_EQ(a.tables.size(), b.tables.size());
  for (std::size_t t = 0; t < a.tables.size(); ++t) {
    EXPECT_EQ(a.tables[t].name, b.tables[t].name);
    EXPECT_EQ(a.tables[t].columns, b.tables[t].columns);
    EXPECT_TRUE(a.tables[t].rows == b.tables[t].rows) << a.tables[t].name;
  }
}

const std::vector<Space> kParams = fakes::builtin_params();

TEST(StudyParts, TablesRoundTripExactly) {
  for (bool iso : {true, false}) {
    const BrdfResult b = fake("ggx:alpha=0.2,f0=0.9", iso, 0.123456789);
    expect_same(from_tables(to_tables(b), kParams, "test"), b);
  }
}

TEST(StudyParts, MalformedTablesNameTheProblem) {
  StudyTables t = to_tables(fake("x", true, 1));
  t["gonio"] += "x,hybrid,regular,10,abc,3,10,own\n";
  try {
    from_tables(t, kParams, "src");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("src: table gonio, line 26: 'abc' is not a number"),
              std::string::npos)
        << e.what();
  }
  t = to_tables(fake("x", true, 1));
  t["gonio"] += "x,hybrid,regular,10,0.5,3,10,sqrt\n";
  EXPECT_THROW(from_tables(t, kParams, "src"), std::runtime_error);
  t = to_tables(fake("x", true, 1));
  t.erase("image");
  EXPECT_THROW(from_tables(t, kParams, "src"), std::runtime_error);
  t = to_tables(fake("x", true, 1));
  t["azimuthal"] = "brdf,param,error\n";
  EXPECT_THROW(from_tables(t, kParams, "src"), std::runtime_error);
}

TEST(StudyParts, SettingsRoundTrip) {
  StudySettings s;
  s.quick = true;
  s.budgets = {100, 300};
  s.seed = 7;
  s.max_theta = 80.5;
  s.environments = {"sky", "studio"};
  s.space = "nielsen";
  s.designs = {"merl", "own", "learned"};
  StudyConfig c = make_config(s);
  c.learned_from = "3 profiles, 0123456789abcdef";
  const std::string text = describe_config(c);
  const StudyConfig back = config_from_description(text, "test");
  EXPECT_EQ(describe_config(back), text);
  EXPECT_EQ(back.budgets, (std::vector<std::size_t>{100, 300}));
  EXPECT_EQ(back.image_budget, 300u);  // the middle budget, as --image-budget's default
  EXPECT_EQ(back.max_theta_deg, 80.5);
  ASSERT_EQ(back.environments.size(), 2u);
  EXPECT_EQ(back.environments[1].label, "studio (built-in)");
  EXPECT_EQ(back.space, ErrorSpace::nielsen);
  EXPECT_EQ(back.spacings, (std::vector<Spacing>{Spacing::merl, Spacing::own, Spacing::learned}));
  EXPECT_EQ(back.learned_from, c.learned_from);
  // A quick run stays one through its parts (a merge's report warns as the run's own does); a
  // full run's settings have no such line.
  EXPECT_TRUE(back.quick);
  EXPECT_NE(text.find("\nquick = 1\n"), std::string::npos);
  s.quick = false;
  EXPECT_EQ(describe_config(make_config(s)).find("quick"), std::string::npos);
  EXPECT_FALSE(config_from_description(describe_config(make_config(s)), "test").quick);
  s.quick = true;
  // A setting that changes the results changes the description.
  s.seed = 8;
  EXPECT_NE(describe_config(make_config(s)), text);
  s.designs = {"own", "sqrt"};
  EXPECT_THROW(make_config(s), std::invalid_argument);
  s.designs = {"own", "own"};
  EXPECT_THROW(make_config(s), std::invalid_argument);
  s.designs = {"own"};
  s.space = "sqrt";
  EXPECT_THROW(make_config(s), std::invalid_argument);
  EXPECT_THROW(config_from_description("space = log\n", "f"), std::runtime_error);
}

TEST(StudyParts, PartFilesAndTheirMerge) {
  const test::TempDir tmp;
  const auto a = tmp.path() / "a", b = tmp.path() / "b";
  for (const auto& d : {a, b}) std::filesystem::create_directories(parts_dir(d));
  StudyConfig c;
  c.params = kParams;  // those of the fakes
  c.budgets = {1000, 10000};
  const std::string settings = describe_config(c);
  for (const auto& d : {a, b}) {
    std::ofstream(parts_dir(d) / "settings.txt") << settings;
  }
  BrdfResult first = fake("first", true, 1), second = fake("second", false, 2);
  render::Image im{4, 4, std::vector<float>(48)};
  for (std::size_t i = 0; i < im.rgb.size(); ++i) im.rgb[i] = float(i) / 7;
  first.example_images.assign(5, im);
  // Written in the reverse of their order: the merge follows `order`, not the file names.
  write_part(parts_dir(a), part_key("zz"), first, 0);
  write_part(parts_dir(a), part_key("aa"), second, 1);
  write_part(parts_dir(b), part_key("third"), fake("third", true, 3), 0);
  const MergedParts m = read_parts({a, b});
  ASSERT_EQ(m.results.size(), 3u);
  expect_same(m.results[0], first);
  expect_same(m.results[1], second);
  EXPECT_EQ(m.results[2].label, "third");
  ASSERT_EQ(m.results[0].example_images.size(), 5u);
  EXPECT_EQ(m.results[0].example_images[4].rgb, im.rgb);
  EXPECT_EQ(describe_config(m.config), settings);

  EXPECT_NE(part_key("ggx:alpha=0.2"), part_key("ggx:alpha=0.3"));
  EXPECT_THROW(read_parts({a, a}), std::runtime_error);  // every BRDF twice
  std::ofstream(parts_dir(b) / "settings.txt") << settings << "\n# other\n";
  StudyConfig other = c;
  other.seed = 2;
  std::ofstream(parts_dir(b) / "settings.txt") << describe_config(other);
  EXPECT_THROW(read_parts({a, b}), std::runtime_error);
}

// Profiles of three models on a small grid (cheap, yet not uniform).
std::vector<LabeledProfile> model_profiles(const StudyConfig& c) {
  std::vector<LabeledProfile> out;
  for (const char* spec : {"ggx:alpha=0.1", "ggx:alpha=0.4", "lambert"})
    out.push_back(study_profile(*load_brdf(spec), spec, c));
  return out;
}

TEST(StudyParts, ProfilesRoundTripExactly) {
  StudyConfig c;
  c.profile_grid = {8, 8, 8};
  const LabeledProfile p = model_profiles(c)[0];
  const LabeledProfile back = profile_from_text(profile_text(p), "test");
  EXPECT_EQ(back.label, p.label);
  ASSERT_EQ(back.profile.spaces.size(), p.profile.spaces.size());
  for (std::size_t i = 0; i < p.profile.spaces.size(); ++i) {
    EXPECT_EQ(back.profile.spaces[i].space, p.profile.spaces[i].space);
    EXPECT_EQ(back.profile.spaces[i].demand, p.profile.spaces[i].demand);  // the same doubles
  }
  EXPECT_THROW(profile_from_text("space = hybrid\n", "f"), std::runtime_error);
  std::string cut = profile_text(p);
  cut.resize(cut.rfind('\n', cut.size() - 2) + 1);  // the last axis line removed
  EXPECT_THROW(profile_from_text(cut, "f"), std::runtime_error);
}

TEST(StudyParts, LearnedWarpsLeaveTheirBrdfOut) {
  StudyConfig c;
  c.profile_grid = {8, 8, 8};
  std::vector<LabeledProfile> profiles = model_profiles(c);
  StudyConfig a = c;
  set_learned(a, profiles, "lambert");
  ASSERT_EQ(a.learned.size(), c.params.size());
  EXPECT_EQ(a.learned,
            learn_warps(std::vector<DesignProfile>{profiles[0].profile, profiles[1].profile,
                                                   profiles[2].profile},
                        2));
  EXPECT_EQ(a.learned_from, learned_fingerprint(profiles));
  // Another profile for the held-out BRDF: the same warps, another fingerprint (the run differs).
  profiles[2] = study_profile(*load_brdf("ggx:alpha=0.7"), "lambert", c);
  StudyConfig b = c;
  set_learned(b, profiles, "lambert");
  EXPECT_EQ(b.learned, a.learned);
  EXPECT_NE(b.learned_from, a.learned_from);
  // ... but another BRDF's warps change.
  StudyConfig d = c, e = c;
  set_learned(d, profiles, "ggx:alpha=0.1");
  profiles[2] = model_profiles(c)[2];
  set_learned(e, profiles, "ggx:alpha=0.1");
  EXPECT_NE(d.learned, e.learned);
  EXPECT_THROW(set_learned(d, profiles, "ggx:alpha=0.9"), std::invalid_argument);
  // One BRDF has none to learn from: no learned warps (the learned design has no rows).
  set_learned(d, std::span(profiles).first(1), "ggx:alpha=0.1");
  EXPECT_TRUE(d.learned.empty());
}

}  // namespace
}  // namespace halfback::study
