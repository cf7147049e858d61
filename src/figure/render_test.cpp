#include "halfback/figure/render.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "halfback/figure/color.hpp"
#include "halfback/figure/scene.hpp"
#include "support/test_support.hpp"

namespace halfback::figure {
namespace {

namespace fs = std::filesystem;

// The number of entries of a directory (a save must leave no temporary file behind).
std::size_t entries(const fs::path& dir) {
  return std::size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

std::string read(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

Scene sample_scene() {
  Scene s;
  s.width = 100;
  s.height = 60;
  s.title = "a test & <scene>";
  s.rect(10, 10, 30, 20, Color{1, 0, 0}, std::nullopt);
  s.line({50, 10}, {90, 50}, Stroke{kBlack, 1.0, {2, 1}});
  s.add(CircleItem{{70, 30}, 5, Color{0, 0, 1}, Stroke{kBlack, 0.5}});
  ImageItem im;
  im.x = 10;
  im.y = 40;
  im.width = 4;
  im.height = 2;
  im.px_width = 8;
  im.px_height = 4;
  for (std::size_t k = 0; k < 32; ++k) {
    const std::uint8_t c[4] = {0, 200, 0, 255};
    im.rgba.insert(im.rgba.end(), c, c + 4);
  }
  s.add(std::move(im));
  s.text({50, 55}, "‖h\u0304‖ θ_h and θ_{d}^2", 8, HAlign::centre, VAlign::baseline);
  return s;
}

TEST(Markup, Runs) {
  EXPECT_EQ(parse_markup("θ_h"), (std::vector<TextRun>{{"θ", 0}, {"h", -1}}));
  EXPECT_EQ(parse_markup("x_{ab}^2 y"),
            (std::vector<TextRun>{{"x", 0}, {"ab", -1}, {"2", 1}, {" y", 0}}));
  EXPECT_EQ(parse_markup("a\\_b"), (std::vector<TextRun>{{"a_b", 0}}));
  // A subscript character with its combining mark: h̄ as one subscript.
  EXPECT_EQ(parse_markup("x_h\u0304!"),
            (std::vector<TextRun>{{"x", 0}, {"h\u0304", -1}, {"!", 0}}));
  // A multi-byte character as subscript.
  EXPECT_EQ(parse_markup("ω_ο"), (std::vector<TextRun>{{"ω", 0}, {"ο", -1}}));
  EXPECT_EQ(plain_text("φ_k − φ_h"), "φk − φh");
  EXPECT_EQ(plain_text("trailing_"), "trailing_");
}

TEST(Colour, ViridisAnchors) {
  // The published map at 0, 1/4, 1/2, 3/4, 1: #440154, #3b528b, #21918c, #5ec962, #fde725.
  const std::array<std::array<int, 3>, 5> anchors{{{0x44, 0x01, 0x54},
                                                   {0x3b, 0x52, 0x8b},
                                                   {0x21, 0x91, 0x8c},
                                                   {0x5e, 0xc9, 0x62},
                                                   {0xfd, 0xe7, 0x25}}};
  for (std::size_t k = 0; k < anchors.size(); ++k) {
    const Color c = viridis(0.25 * double(k));
    // The fit is within 3.3/255 of the table; the hex anchors add up to 1/255 of rounding.
    EXPECT_NEAR(c.r * 255, anchors[k][0], 5.0) << k;
    EXPECT_NEAR(c.g * 255, anchors[k][1], 5.0) << k;
    EXPECT_NEAR(c.b * 255, anchors[k][2], 5.0) << k;
  }
  // Perceptually ordered: lightness (approximated by luminance) increases monotonically.
  double previous = -1;
  for (int k = 0; k <= 100; ++k) {
    const Color c = viridis(k / 100.0);
    const double y = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
    EXPECT_GT(y, previous);
    previous = y;
  }
  EXPECT_EQ(coordinate_colour(0.25, 1.5), (Color{0.25, 1.0, 0.0, 1.0}));
  EXPECT_EQ(to_byte(0.5), 128);
  EXPECT_EQ(to_byte(std::nan("")), 0);
  EXPECT_NEAR(srgb_encode(0.5), 0.7354, 1e-4);
}

TEST(Render, PngContent) {
  const Scene s = sample_scene();
  const Raster r = decode_png(render(s, Format::png, {2.0}));
  ASSERT_EQ(r.width, 200u);
  ASSERT_EQ(r.height, 120u);
  EXPECT_EQ(r.pixel(50, 40), (std::array<std::uint8_t, 4>{255, 0, 0, 255}));    // red rect
  EXPECT_EQ(r.pixel(5, 5), (std::array<std::uint8_t, 4>{255, 255, 255, 255}));  // background
  EXPECT_EQ(r.pixel(140, 60), (std::array<std::uint8_t, 4>{0, 0, 255, 255}));   // circle fill
  EXPECT_EQ(r.pixel(22, 82), (std::array<std::uint8_t, 4>{0, 200, 0, 255}));    // image
  // rasterize() draws what the PNG holds.
  const Raster direct = rasterize(s, 2.0);
  EXPECT_EQ(direct.rgba, r.rgba);
}

TEST(Render, LinesAreAntiAliased) {
  Scene s;
  s.width = s.height = 20;
  s.line({0, 10.25}, {20, 10.25}, Stroke{kBlack, 1.0});  // covers y in [9.75, 10.75]
  const Raster r = rasterize(s, 1.0);
  // Row 9 is covered by a quarter, row 10 by three quarters: grey levels, not black and white.
  const int row9 = r.pixel(10, 9)[0], row10 = r.pixel(10, 10)[0];
  EXPECT_GT(row9, 150);
  EXPECT_LT(row9, 230);
  EXPECT_GT(row10, 30);
  EXPECT_LT(row10, 100);
  EXPECT_EQ(r.pixel(10, 12)[0], 255);
}

TEST(Render, SvgHasRealTextAndPaths) {
  const std::string svg = render(sample_scene(), Format::svg);
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("<title>a test &amp; &lt;scene&gt;</title>"), std::string::npos);
  EXPECT_NE(svg.find("<text"), std::string::npos);
  EXPECT_NE(svg.find("‖h\u0304‖ θ"), std::string::npos);  // the text itself, not glyph outlines
  EXPECT_NE(svg.find("<tspan dy=\"1.76\" font-size=\"5.6\">h</tspan>"), std::string::npos);
  EXPECT_NE(svg.find("<path d=\"M50 10 L90 50\""), std::string::npos);
  EXPECT_NE(svg.find("stroke-dasharray=\"2 1\""), std::string::npos);
  EXPECT_NE(svg.find("<circle cx=\"70\" cy=\"30\" r=\"5\""), std::string::npos);
  EXPECT_NE(svg.find("data:image/png;base64,iVBORw0KGgo"), std::string::npos);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
}

TEST(Render, Pdf) {
  const std::string pdf = render(sample_scene(), Format::pdf);
  EXPECT_EQ(pdf.rfind("%PDF-", 0), 0u);
  EXPECT_NE(pdf.find("/FontFile"), std::string::npos);  // embedded font: real text
  EXPECT_NE(pdf.find("%%EOF"), std::string::npos);
}

TEST(Save, WritesEachFormatAtomically) {
  const test::TempDir dir;
  for (const char* name : {"a.png", "b.SVG", "c.pdf"}) {
    save(sample_scene(), dir.path() / name);
    EXPECT_GT(fs::file_size(dir.path() / name), 100u);
  }
  EXPECT_EQ(entries(dir.path()), 3u);  // no temporary files left
  EXPECT_EQ(read(dir.path() / "b.SVG").rfind("<?xml", 0), 0u);
  // Overwriting replaces the file whole.
  save(sample_scene(), dir.path() / "a.png");
  EXPECT_EQ(decode_png(read(dir.path() / "a.png")).width, 200u);
}

TEST(Save, BadPathsFailCleanly) {
  const test::TempDir dir;
  const Scene s = sample_scene();
  // Unknown format: nothing written.
  try {
    save(s, dir.path() / "figure.jpg");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(".png, .svg or .pdf"), std::string::npos);
  }
  // Missing directory.
  const fs::path missing = dir.path() / "no-such-dir" / "f.png";
  try {
    save(s, missing);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("No such file"), std::string::npos) << e.what();
  }
  // Parent is a regular file.
  std::ofstream(dir.path() / "plain") << "x";
  EXPECT_THROW(save(s, dir.path() / "plain" / "f.svg"), std::runtime_error);
  // Target is a directory: the rename fails, the temporary file is removed.
  fs::create_directories(dir.path() / "d.pdf" / "inner");
  EXPECT_THROW(save(s, dir.path() / "d.pdf"), std::runtime_error);
  EXPECT_EQ(entries(dir.path()), 2u);  // "plain" and the directory "d.pdf": nothing else
  EXPECT_TRUE(fs::is_directory(dir.path() / "d.pdf" / "inner"));
}

}  // namespace
}  // namespace halfback::figure
