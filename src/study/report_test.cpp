// The study's files: CSV columns, the budget table, the report and its HTML version.
#include "halfback/study/report.hpp"

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>

#include "fake_results.hpp"
#include "halfback/figure/plot.hpp"
#include "report_internal.hpp"
#include "support/test_support.hpp"

namespace halfback::study {
namespace {

using acquire::Design;
using acquire::Spacing;

std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

using fakes::FakeBrdf;
using fakes::FakeParam;
using fakes::to_result;

// A made-up result whose numbers the files must repeat; parameterization i has k = ks[i].
FakeBrdf fake_numbers(const std::string& label, bool isotropic,
                      const std::vector<double>& ks = {1, 2, 3, 4}) {
  FakeBrdf b;
  b.label = label;
  b.isotropic = isotropic;
  const std::vector<Space> params = fakes::builtin_params();
  for (std::size_t i = 0; i < params.size(); ++i) {
    const double k = ks[i];
    FakeParam p;
    p.space = params[i];
    p.azimuthal = 0.1 * k;
    p.separability_2d = {0.2 * k, 0.1 * k, 0.05 * k, 0.01 * k};
    p.separability_3d = p.separability_2d;
    // E = 0.5 k (N / 1000)^(-2/3): reaches 0.02 (k = 1) at N = 1000 · 25^(3/2) = 125000.
    for (Design d : {Design::regular, Design::stratified})
      for (std::size_t n : {1000u, 1000000u})
        p.gonio.push_back({d, n, n, 0.5 * k * std::pow(n / 1000.0, -2.0 / 3)});
    p.images.push_back(
        {Design::regular, 1000, "sky", 0.03 * k, 1.5 * k, 3 * k, 0.1 * k, 0.2 * k, 0.4 * k});
    if (!isotropic) {
      p.azimuthal_4d = 0.3 * k;
      p.separability_4d = p.separability_2d;
      p.gonio_4d = p.gonio;
    }
    b.params.push_back(p);
  }
  return b;
}

BrdfResult fake(const std::string& label, bool isotropic) {
  return to_result(fake_numbers(label, isotropic));
}

// The settings the fakes were "studied" with (the report reads budgets and environments).
StudyConfig config_of_fakes() {
  StudyConfig c;
  c.budgets = {1000, 1000000};
  c.image_budget = 1000;
  c.environments.push_back({"sky", nullptr});  // only its label is used by the report
  return c;
}

// The network fitted to a measured file: the same material, its parameterizations' numbers in
// the reverse order (so that its lowest errors are spherical's where the file's are halfdiff's).
BrdfResult network_of(const BrdfResult& file) {
  return to_result(fake_numbers("nbrdf:" + file.label.substr(file.label.find(':') + 1),
                                file.isotropic, {4, 3, 2, 1}));
}

// The renderings' column heads are parameterization names, some wider than a rendering: the
// columns are spaced so that no two heads overlap (by the layout's width estimate), and each
// rendering sits under its head.
TEST(Report, RenderingColumnsFitTheirHeads) {
  FakeBrdf b;
  b.label = "a";
  b.isotropic = true;
  for (Space s : {space_of<RectifiedHybrid>, space_of<StereoHalfDiff>, space_of<HalfDiff>}) {
    FakeParam p;
    p.space = s;
    b.params.push_back(p);
  }
  BrdfResult r = to_result(b);
  const render::Image grey{8, 8, std::vector<float>(8 * 8 * 3, 0.5f)};
  r.example_images.assign(r.params.size() + 1, grey);
  const figure::Scene sc = report::examples_chart({r}, config_of_fakes());
  std::vector<const figure::TextItem*> heads;
  std::vector<double> images;
  double first_row_y = -1;
  for (const figure::Item& item : sc.items) {
    if (const auto* t = std::get_if<figure::TextItem>(&item);
        t && t->halign == figure::HAlign::centre)
      heads.push_back(t);
    if (const auto* i = std::get_if<figure::ImageItem>(&item)) {
      if (first_row_y < 0) first_row_y = i->y;
      if (i->y == first_row_y) images.push_back(i->x);  // the renderings, not their differences
    }
  }
  ASSERT_EQ(heads.size(), 4u);  // BRDF, then the three parameterizations
  ASSERT_EQ(images.size(), 4u);
  for (std::size_t k = 0; k + 1 < heads.size(); ++k) {
    const double half_widths = (figure::approx_text_width(heads[k]->text, heads[k]->size) +
                                figure::approx_text_width(heads[k + 1]->text, heads[k + 1]->size)) /
                               2;
    EXPECT_GE(heads[k + 1]->at.x - heads[k]->at.x, half_widths) << heads[k + 1]->text;
    EXPECT_GE(images[k + 1] - images[k], heads[k + 1]->at.x - heads[k]->at.x - 1e-9);
  }
}

// A whole-data study renders every BRDF: the figure shows at most kMaxExampleRows of them, the
// first and the last among them, spread evenly, and says so (176 rows were 51 040 pixels tall,
// above an image's 32 767, and the whole report failed after the last BRDF).
TEST(Report, RenderingsOfManyBrdfsShowASpreadOfThem) {
  std::vector<BrdfResult> results;
  const render::Image grey{8, 8, std::vector<float>(8 * 8 * 3, 0.5f)};
  for (int k = 0; k < 176; ++k) {
    BrdfResult r = fake(fmt::format("brdf{}", k), true);
    r.example_images.assign(r.params.size() + 1, grey);
    results.push_back(std::move(r));
  }
  const figure::Scene sc = report::examples_chart(results, config_of_fakes());
  std::vector<std::string> labels;
  bool said = false;
  for (const figure::Item& item : sc.items)
    if (const auto* t = std::get_if<figure::TextItem>(&item)) {
      if (t->text.rfind("brdf", 0) == 0) labels.push_back(t->text);
      said = said || t->text.find("24 of the 176 BRDFs") != std::string::npos;
    }
  ASSERT_EQ(labels.size(), report::kMaxExampleRows);
  EXPECT_EQ(labels.front(), "brdf0");
  EXPECT_EQ(labels.back(), "brdf175");
  EXPECT_TRUE(
      std::is_sorted(labels.begin(), labels.end(), [](const std::string& a, const std::string& b) {
        return std::stoi(a.substr(4)) < std::stoi(b.substr(4));
      }));
  EXPECT_EQ(std::set<std::string>(labels.begin(), labels.end()).size(), labels.size());
  EXPECT_TRUE(said);
  EXPECT_LT(sc.height * 2, 32767);
}

TEST(Report, FilesRepeatTheResults) {
  const test::TempDir tmp;
  const std::filesystem::path& dir = tmp.path();
  StudyConfig c;
  c.budgets = {1000, 1000000};
  c.image_budget = 1000;
  c.environments.push_back({"sky", nullptr});  // only its label is used by the report
  BrdfResult with_images = fake("a,b", true);
  render::Image grey{8, 8, std::vector<float>(8 * 8 * 3, 0.5f)};
  with_images.example_images.assign(with_images.params.size() + 1, grey);
  const StudyOutput out = write_study(dir, {with_images, fake("aniso", false)}, c, 1.5);
  for (const char* f :
       {"azimuthal.csv", "separability.csv", "gonio.csv", "budget.csv", "image.csv", "report.md",
        "report.html", "gonio.png", "gonio.svg", "gonio4d.png", "image.png", "azimuthal.svg"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  const std::string az = slurp(dir / "azimuthal.csv");
  EXPECT_EQ(az.rfind("brdf,parameterization,error,dims\n", 0), 0u);
  EXPECT_NE(az.find("\"a,b\",halfdiff,0.1,3\n"), std::string::npos);  // quoted label
  EXPECT_NE(az.find("aniso,ortho,0.6,4\n"), std::string::npos);
  const std::string sep = slurp(dir / "separability.csv");
  EXPECT_EQ(sep.rfind("brdf,parameterization,rank,error,dims\n", 0), 0u);
  EXPECT_NE(sep.find("aniso,hybrid,8,0.03,4\n"), std::string::npos);
  const std::string gon = slurp(dir / "gonio.csv");
  EXPECT_EQ(gon.rfind("brdf,parameterization,design,samples,error,", 0), 0u);
  EXPECT_NE(gon.find("aniso,spherical,stratified,1000000,0.02,4,1000000,own\n"), std::string::npos);
  const std::string bud = slurp(dir / "budget.csv");
  EXPECT_NE(bud.find("aniso,halfdiff,regular,3,0.02,125000,reached,own\n"), std::string::npos)
      << bud;
  EXPECT_NE(bud.find("aniso,halfdiff,regular,3,0.01,353553,reached,own\n"), std::string::npos);
  EXPECT_NE(bud.find("aniso,halfdiff,regular,3,0.05,31623,reached,own\n"), std::string::npos);
  // ortho (k = 2) reaches 0.05 at 1000 · 20^(3/2); spherical (k = 4) is 0.02 at 10^6.
  EXPECT_NE(bud.find("aniso,ortho,stratified,4,0.05,89443,reached,own\n"), std::string::npos);
  EXPECT_NE(bud.find("aniso,spherical,regular,3,0.01,,not_reached,own\n"), std::string::npos);
  EXPECT_NE(slurp(dir / "image.csv").find("aniso,ortho,regular,1000,sky,0.06,3,6,0.2,0.4,0.8\n"),
            std::string::npos);
  // The report counts halfdiff (the lowest numbers) as the winner everywhere.
  EXPECT_NE(out.markdown.find("halfdiff 2, ortho 0, hybrid 0, spherical 0"), std::string::npos);
  EXPECT_NE(out.markdown.find("| a,b | 0.1000 |"), std::string::npos);
  // ortho (k = 2) needs 1000 · 2^(3/2) measurements to reach halfdiff's error at 1000.
  EXPECT_NE(out.markdown.find("| a,b (0.5) | ×1.00 | ×2.83 |"), std::string::npos) << out.markdown;
  const std::string html = slurp(dir / "report.html");
  EXPECT_NE(html.find("<img alt=\"Virtual gonio-reflectometer\" src=\"data:image/png;base64,"),
            std::string::npos);
  EXPECT_EQ(html.find("](gonio.png)"), std::string::npos);
}

TEST(Report, DesignsSectionComparesBestAgainstBest) {
  // In the own design halfdiff wins (k = 1); in the learned design hybrid's error is a tenth of
  // its own, below halfdiff's, and the angle design is worse for everyone.
  const test::TempDir tmp;
  StudyConfig c;
  c.budgets = {1000, 1000000};
  c.image_budget = 1000;
  std::vector<FakeBrdf> fakes{fake_numbers("x", true), fake_numbers("y", true)};
  for (FakeBrdf& b : fakes)
    for (FakeParam& p : b.params) {
      const std::vector<GonioPoint> own = p.gonio;
      for (const GonioPoint& g : own) {
        if (g.design != Design::regular) continue;
        const double learned = p.space == space_of<Hybrid> ? 0.1 : 1.0;
        p.gonio.push_back({g.design, g.budget, g.samples, g.error * 2, Spacing::angle});
        p.gonio.push_back({g.design, g.budget, g.samples, g.error * learned, Spacing::learned});
      }
    }
  const StudyOutput out = write_study(tmp.path(), {to_result(fakes[0]), to_result(fakes[1])}, c, 1);
  const std::string& md = out.markdown;
  EXPECT_NE(md.find("## 3b. Designs"), std::string::npos);
  // hybrid (k = 3) at N = 1000: 1.5 own, 3 angle, 0.15 learned; its best is learned.
  EXPECT_NE(md.find("| hybrid | 1.5000 | 1.5000 | 3.0000 | **0.1500** | learned |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| halfdiff | **0.5000** | 0.5000 | 1.0000 | 0.5000 | own regular |"),
            std::string::npos);
  EXPECT_NE(md.find("changes, from halfdiff to hybrid"), std::string::npos);
  EXPECT_NE(md.find("2 of 2 BRDFs change their best parameterization"), std::string::npos);
  // The angle design doubles ortho's (k = 2) and hybrid's (k = 3) errors at N = 1000.
  EXPECT_NE(md.find("ortho 1.0000 → 2.0000 (×2.00); hybrid 1.5000 → 3.0000 (×2.00)"),
            std::string::npos)
      << md;
  // Without the own design, best against best only.
  StudyConfig no_own = c;
  std::vector<BrdfResult> without;
  for (FakeBrdf b : fakes) {
    for (FakeParam& p : b.params)
      std::erase_if(p.gonio, [](const GonioPoint& g) { return g.spacing == Spacing::own; });
    without.push_back(to_result(b));
  }
  const test::TempDir tmp2;
  const std::string md2 = write_study(tmp2.path(), without, no_own, 1).markdown;
  EXPECT_NE(md2.find("Lowest error, best against best (BRDFs): halfdiff 0, ortho 0, hybrid 2"),
            std::string::npos)
      << md2;
  EXPECT_NE(slurp(tmp.path() / "gonio.csv").find("x,hybrid,regular,1000,0.15,3,1000,learned\n"),
            std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(tmp.path() / "designs.png"));
}

TEST(Report, OnlyWhatWasComputedIsWrittenAndLinked) {
  // Anisotropic BRDFs only: the 4D gonio-reflectometer still gets its CSV files; no example
  // renderings: no renderings plot, and no link to one.
  const test::TempDir tmp;
  const std::filesystem::path& dir = tmp.path();
  StudyConfig c;
  c.budgets = {1000, 1000000};
  c.image_budget = 1000;
  c.environments.push_back({"sky", nullptr});
  FakeBrdf b = fake_numbers("aniso", false);
  for (FakeParam& p : b.params) p.gonio.clear();
  const StudyOutput out = write_study(dir, {to_result(b)}, c, 1);
  EXPECT_TRUE(std::filesystem::exists(dir / "gonio.csv"));
  EXPECT_NE(slurp(dir / "gonio.csv").find("aniso,hybrid,regular,1000,"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir / "gonio4d.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "gonio.png"));  // no 3D curve to draw
  EXPECT_FALSE(std::filesystem::exists(dir / "renderings.png"));
  EXPECT_EQ(out.markdown.find("](gonio.png)"), std::string::npos);
  EXPECT_EQ(out.markdown.find("](renderings.png)"), std::string::npos);
  EXPECT_NE(out.markdown.find("](gonio4d.png)"), std::string::npos);
}

// Nielsen et al.'s rows give their table (the grid's measurements for the same error, from its
// curve) and, with the sequential design's rows, the strategies chart; without them, neither.
TEST(Report, NielsenTableAndStrategiesChart) {
  const test::TempDir tmp;
  StudyConfig c = config_of_fakes();
  c.nielsen_counts = {1, 10, 100};
  std::vector<BrdfResult> results;
  for (const char* label : {"a", "b"}) {
    FakeBrdf b = fake_numbers(label, true);
    FakeParam& halfdiff = b.params[0];  // k = 1: the regular grid's error 0.5 (N / 1000)^(-2/3)
    ASSERT_EQ(halfdiff.space, space_of<HalfDiff>);
    for (std::size_t n : {1u, 10u, 100u})
      halfdiff.gonio.push_back({Design::nielsen, n, n, n == 100 ? 0.1 : 0.5});
    for (std::size_t n : {1000u, 1000000u})
      halfdiff.gonio.push_back({Design::sequential, n, n, 0.25 * std::pow(n / 1000.0, -2.0 / 3)});
    results.push_back(to_result(b));
  }
  const std::string md = write_study(tmp.path(), results, c, 1).markdown;
  // 0.5 (N / 1000)^(-2/3) = 0.1 at N = 1000 · 5^(3/2) = 11180; 0.5 is the grid's at 1000.
  EXPECT_NE(md.find("| models | 100 | 2 | 0.1000 | 11180 | 2 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| models | 1 | 2 | 0.5000 | < smallest | 0 |"), std::string::npos) << md;
  EXPECT_TRUE(std::filesystem::exists(tmp.path() / "strategies.png"));
  EXPECT_NE(md.find("](strategies.png)"), std::string::npos);
  const test::TempDir plain;
  const std::string md2 =
      write_study(plain.path(), {fake("a", true), fake("b", true)}, config_of_fakes(), 1).markdown;
  EXPECT_FALSE(std::filesystem::exists(plain.path() / "strategies.png"));
  EXPECT_EQ(md2.find("Nielsen"), std::string::npos);
}

TEST(Report, MarkdownToHtml) {
  const test::TempDir tmp;
  const std::filesystem::path& dir = tmp.path();
  {
    std::ofstream f(dir / "x.png", std::ios::binary);
    f << "Man";  // base64 "TWFu"
  }
  const std::string html = markdown_to_html(
      "# T <1>\n\nsome `a|b` and **bold**\ntext & more\n\n| h | k |\n|---|---|\n| 1 \\| 2 | 3 |\n\n"
      "* one\n* two\n\n![pic](x.png)\n\n![gone](missing.png)\n",
      dir, "t");
  EXPECT_NE(html.find("<h1>T &lt;1&gt;</h1>"), std::string::npos);
  EXPECT_NE(html.find("<p>some <code>a|b</code> and <strong>bold</strong> text &amp; more</p>"),
            std::string::npos);
  EXPECT_NE(html.find("<tr><th>h</th><th>k</th></tr>"), std::string::npos);
  EXPECT_NE(html.find("<tr><td>1 | 2</td><td>3</td></tr>"), std::string::npos);
  EXPECT_NE(html.find("<li>two</li>"), std::string::npos);
  EXPECT_NE(html.find("src=\"data:image/png;base64,TWFu\""), std::string::npos);
  EXPECT_NE(html.find("<a href=\"missing.png\">gone</a>"), std::string::npos);
}

// A measured file and the network fitted to it, side by side (section 5): the file's lowest
// errors are halfdiff's, the network's spherical's (its values in the reverse order).
TEST(Report, FilesBesideTheirNetworks) {
  const test::TempDir tmp;
  const StudyConfig c = config_of_fakes();
  const BrdfResult file = fake("rgl:felt_rgb", true), network = network_of(file);
  const StudyOutput out = write_study(tmp.path(), {file, fake("lambert", true), network}, c, 1.0);
  const std::string& md = out.markdown;
  EXPECT_NE(md.find("## 5. Measured files and their neural BRDFs"), std::string::npos) << md;
  EXPECT_NE(md.find("| felt_rgb | halfdiff / spherical | halfdiff / spherical | halfdiff / "
                    "spherical | halfdiff / spherical |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("azimuthal 0 of 1, separability 0 of 1, gonio 0 of 1, image 0 of 1"),
            std::string::npos)
      << md;
  // The gonio errors at the reference budget, file then network: 0.5 k at N = 1000.
  EXPECT_NE(md.find("| rgl:felt_rgb | 0.5000 | 1.0000 | 1.5000 | 2.0000 |"), std::string::npos);
  EXPECT_NE(md.find("| nbrdf:felt_rgb | 2.0000 | 1.5000 | 1.0000 | 0.5000 |"), std::string::npos);
  // Without a pair, no section.
  EXPECT_EQ(write_study(tmp.path(), {file}, c, 1.0).markdown.find("## 5."), std::string::npos);
}

TEST(Report, SummaryGroupsTheBrdfsByKind) {
  // A file where halfdiff wins, its network where spherical wins (the parameterizations' numbers
  // reversed), and a model like the file: per kind and over all, the medians and the wins.
  const test::TempDir tmp;
  const StudyConfig c = config_of_fakes();
  const BrdfResult file = fake("rgl:felt_rgb", true), network = network_of(file);
  const StudyOutput out = write_study(tmp.path(), {file, fake("ggx", true), network}, c, 1.0);
  const std::string& md = out.markdown;
  const std::size_t summary = md.find("## Summary"), azimuthal = md.find("## 1.");
  ASSERT_LT(summary, azimuthal) << md;
  const std::string s = md.substr(summary, azimuthal - summary);
  for (const char* row :
       {"| RGL files | 1 | **0.1000** (1) | 0.2000 (0) | 0.3000 (0) | 0.4000 (0) |",
        "| models | 1 | **0.1000** (1) |",
        "| neural BRDFs | 1 | 0.4000 (0) | 0.3000 (0) | 0.2000 (0) | **0.1000** (1) |",
        "| all | 3 | **0.1000** (2) | 0.2000 (0) | 0.3000 (0) | 0.4000 (1) |",
        // the gonio-reflectometer at N = 1000: 0.5 k
        "| all | 3 | **0.5000** (2) | 1.0000 (0) | 1.5000 (0) | 2.0000 (1) |"})
    EXPECT_NE(s.find(row), std::string::npos) << row << "\n" << s;
  EXPECT_LT(s.find("| RGL files"), s.find("| models"));  // kinds in the order they first appear
  EXPECT_TRUE(std::filesystem::exists(tmp.path() / "summary.png"));
  EXPECT_NE(s.find("![Summary](summary.png)"), std::string::npos);
}

// The summary and header of the report's odd cases: an embedded material is a kind of its own,
// not a model; one BRDF is "1 BRDF"; a parameterization that never reaches E* on most BRDFs has
// no multiple for a median ("×inf" before).
TEST(Report, SummaryKindsCountsAndUnreachedMedians) {
  const test::TempDir tmp;
  const StudyOutput one = write_study(tmp.path(), {fake("embedded:gold-metallic-paint3", true)},
                                      config_of_fakes(), 1.0);
  EXPECT_NE(one.markdown.find("| embedded materials | 1 |"), std::string::npos) << one.markdown;
  EXPECT_EQ(one.markdown.find("| models |"), std::string::npos);
  EXPECT_NE(one.markdown.find("Definitions: docs/study.md. 1 BRDF in"), std::string::npos);
  EXPECT_EQ(one.markdown.find("1 BRDFs"), std::string::npos);
  // E* is halfdiff's error at 1000 (k = 1, E* = 0.5); ortho (k = 2000) needs 1000 · 2000^1.5
  // measurements, past the largest budget (10^6), on both BRDFs.
  const std::vector<double> ks{1, 2000, 3, 4};
  const StudyOutput two = write_study(
      tmp.path(), {to_result(fake_numbers("x", true, ks)), to_result(fake_numbers("y", true, ks))},
      config_of_fakes(), 1.0);
  EXPECT_EQ(two.markdown.find("×inf"), std::string::npos) << two.markdown;
  EXPECT_NE(two.markdown.find("Median over the BRDFs: halfdiff ×1, ortho not reached (2 of 2 not "
                              "reached)"),
            std::string::npos)
      << two.markdown;
}

// The report's first section answers "which parameterization for what" on its BRDFs: per use,
// the winner, the runner-up and the margin, and the winner per kind.
TEST(Report, AnswersSectionComesFirst) {
  const test::TempDir tmp;
  // halfdiff has k = 1, ortho k = 2: every error of ortho is twice halfdiff's.
  const std::string md =
      write_study(tmp.path(), {fake("x", true), fake("nbrdf:y", true)}, config_of_fakes(), 1.0)
          .markdown;
  const std::size_t answers = md.find("## Answers"), summary = md.find("## Summary");
  ASSERT_NE(answers, std::string::npos) << md;
  EXPECT_LT(answers, summary);
  EXPECT_NE(
      md.find("| compactness: dropping the azimuth | **halfdiff** 0.1 | ortho 0.2 | ×2.00 | 2 "
              "of 2 | models (1): halfdiff ×2.00; neural BRDFs (1): halfdiff ×2.00 |"),
      std::string::npos)
      << md.substr(answers, summary - answers);
  EXPECT_NE(md.find("| interpolation from a gonio-reflectometer (regular grid) | **halfdiff**"),
            std::string::npos);
}

// Under each reconstruction's rendering, its difference from the BRDF's: black where they agree
// (the common noise cancels), brighter with the relative difference, white from 50 % on.
TEST(Report, RenderingsShowTheirDifferenceImages) {
  FakeBrdf b;
  b.label = "a";
  for (Space s : {space_of<HalfDiff>, space_of<Hybrid>}) {
    FakeParam p;
    p.space = s;
    b.params.push_back(p);
  }
  BrdfResult r = to_result(b);
  const render::Image grey{4, 4, std::vector<float>(4 * 4 * 3, 0.5f)};
  render::Image brighter = grey;
  for (float& v : brighter.rgb) v = 0.5f * 1.25f;  // 25 % above: half the full scale
  r.example_images = {grey, grey, brighter};
  const figure::Scene sc = report::examples_chart({r}, config_of_fakes());
  std::vector<const figure::ImageItem*> images;
  for (const figure::Item& item : sc.items)
    if (const auto* i = std::get_if<figure::ImageItem>(&item)) images.push_back(i);
  ASSERT_EQ(images.size(), 5u);  // the BRDF, two reconstructions, two differences
  // In the order drawn: BRDF, halfdiff, (its difference), hybrid, (its difference).
  const figure::ImageItem& same = *images[2];
  const figure::ImageItem& off = *images[4];
  EXPECT_GT(same.y, images[1]->y);  // below its rendering
  EXPECT_EQ(same.x, images[1]->x);
  for (std::size_t p = 0; p < 16; ++p) {
    EXPECT_EQ(same.rgba[4 * p], 0);  // no difference: black
    // 25 % of the mean is half the full scale: u = 1.5 on the 0-3 ramp (red full, green half).
    EXPECT_EQ(off.rgba[4 * p], 255);
    EXPECT_NEAR(off.rgba[4 * p + 1], 128, 1);
    EXPECT_EQ(off.rgba[4 * p + 2], 0);
  }
}

}  // namespace
}  // namespace halfback::study
