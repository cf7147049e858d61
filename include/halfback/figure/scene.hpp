// A figure as a display list: paths, circles, raster images and text in page coordinates.
//
// Page coordinates are in points (1/72 in), origin at the top-left corner, y down. A Scene is
// built once and rendered by render.hpp to any output: PNG (a raster at some pixels per point),
// PDF (through Cairo: vector paths, embedded fonts, selectable text) and SVG (written directly, so
// that text stays <text> elements and isolines stay <path> elements).
//
// Text takes a small markup: `_x` or `_{...}` for a subscript, `^x` or `^{...}` for a
// superscript, `\_` and `\^` for the characters themselves. Everything else is UTF-8, combining
// characters included (‖h̄‖ is "‖h\u0304‖").
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "halfback/figure/color.hpp"
#include "halfback/figure/contour.hpp"

namespace halfback::figure {

struct Stroke {
  Color color;
  double width = 1.0;          // points
  std::vector<double> dash{};  // on/off lengths in points; empty: solid
};

struct PathItem {
  std::vector<Point> points;
  bool closed = false;
  std::optional<Color> fill;
  std::optional<Stroke> stroke;
};

struct CircleItem {
  Point centre;
  double radius = 1;
  std::optional<Color> fill;
  std::optional<Stroke> stroke;
};

// An RGBA raster (8 bits per channel, straight alpha, row 0 at the top) stretched over a
// rectangle. `smooth` = false draws its pixels as squares (no interpolation).
struct ImageItem {
  double x = 0, y = 0, width = 0, height = 0;
  std::size_t px_width = 0, px_height = 0;
  std::vector<std::uint8_t> rgba;
  bool smooth = false;
};

enum class HAlign { left, centre, right };
enum class VAlign { baseline, middle, top, bottom };

struct TextItem {
  Point at;
  std::string text;  // with the markup above
  double size = 10;  // points
  Color color{};
  HAlign halign = HAlign::left;
  VAlign valign = VAlign::baseline;
  double angle = 0;  // degrees, counter-clockwise, about `at`
  bool bold = false;
};

using Item = std::variant<PathItem, CircleItem, ImageItem, TextItem>;

struct Scene {
  double width = 0, height = 0;  // points
  Color background = kWhite;
  std::string title;  // document metadata (PDF title, SVG <title>)
  std::vector<Item> items;

  // Out of line: GCC 12 reports false -Wmaybe-uninitialized in the inlined vector growth.
  void add(Item item);
  void line(Point a, Point b, const Stroke& s) { add(PathItem{{a, b}, false, std::nullopt, s}); }
  void rect(double x, double y, double w, double h, std::optional<Color> fill,
            std::optional<Stroke> stroke) {
    add(PathItem{{{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}}, true, fill, stroke});
  }
  void text(Point at, std::string s, double size, HAlign h = HAlign::left,
            VAlign v = VAlign::baseline, Color c = {}, double angle = 0, bool bold = false) {
    add(TextItem{at, std::move(s), size, c, h, v, angle, bold});
  }
};

// Appends every item of `src` to `dst`, moved by `offset` (to compose figures from figures).
void append_scene(Scene& dst, const Scene& src, Point offset);

// A run of text at one script level: 0 normal, −1 subscript, +1 superscript.
struct TextRun {
  std::string text;
  int script = 0;
  friend bool operator==(const TextRun&, const TextRun&) = default;
};
std::vector<TextRun> parse_markup(std::string_view text);
// The text without markup (for SVG <title>s, alt texts, tests).
std::string plain_text(std::string_view text);
// Text from outside (a BRDF's name, a file name) made literal: every '_' and '^' escaped, so
// that "ilm_l3_37" is drawn as written, not with subscripts.
std::string escape_markup(std::string_view text);

// Font metrics shared by the backends: a script run is drawn at kScriptScale of the size, shifted
// by kSubShift / kSuperShift of the size; vertical alignment offsets the baseline by these
// fractions of the size (so PNG, PDF and SVG place text alike).
inline constexpr double kScriptScale = 0.7;
inline constexpr double kSubShift = 0.22, kSuperShift = -0.38;
double baseline_offset(VAlign v);  // in units of the font size, added to `at.y`

}  // namespace halfback::figure
