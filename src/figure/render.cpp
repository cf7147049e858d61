#include "halfback/figure/render.hpp"

#include "halfback/util/atomic_file.hpp"
#include "halfback/util/text_encoding.hpp"

#include <cairo-pdf.h>
#include <cairo.h>
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <memory>
#include <numbers>
#include <stdexcept>

namespace halfback::figure {
namespace {

constexpr const char* kFontFamily = "DejaVu Sans";

// ---------------------------------------------------------------------------------------------
// Cairo helpers
// ---------------------------------------------------------------------------------------------
struct SurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDeleter {
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};
using SurfacePtr = std::unique_ptr<cairo_surface_t, SurfaceDeleter>;
using ContextPtr = std::unique_ptr<cairo_t, ContextDeleter>;

void check(cairo_status_t status, const char* what) {
  if (status != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error(fmt::format("{}: {}", what, cairo_status_to_string(status)));
}

cairo_status_t append_to_string(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

// Straight-alpha RGBA -> Cairo ARGB32 (premultiplied, native endian).
SurfacePtr image_surface(const ImageItem& im) {
  if (im.rgba.size() != 4 * im.px_width * im.px_height)
    throw std::invalid_argument(
        fmt::format("image: {} bytes for {}x{} pixels", im.rgba.size(), im.px_width, im.px_height));
  SurfacePtr s(
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, int(im.px_width), int(im.px_height)));
  check(cairo_surface_status(s.get()), "image surface");
  cairo_surface_flush(s.get());
  unsigned char* data = cairo_image_surface_get_data(s.get());
  const int stride = cairo_image_surface_get_stride(s.get());
  for (std::size_t y = 0; y < im.px_height; ++y) {
    auto* row = reinterpret_cast<std::uint32_t*>(data + std::ptrdiff_t(y) * stride);
    for (std::size_t x = 0; x < im.px_width; ++x) {
      const std::uint8_t* p = &im.rgba[4 * (y * im.px_width + x)];
      const std::uint32_t a = p[3];
      auto pre = [a](std::uint32_t c) { return (c * a + 127) / 255; };
      row[x] = (a << 24) | (pre(p[0]) << 16) | (pre(p[1]) << 8) | pre(p[2]);
    }
  }
  cairo_surface_mark_dirty(s.get());
  return s;
}

void set_colour(cairo_t* cr, const Color& c) {
  cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a);
}

void path_of(cairo_t* cr, const PathItem& p) {
  cairo_new_path(cr);
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    if (i == 0)
      cairo_move_to(cr, p.points[i].x, p.points[i].y);
    else
      cairo_line_to(cr, p.points[i].x, p.points[i].y);
  }
  if (p.closed) cairo_close_path(cr);
}

void fill_and_stroke(cairo_t* cr, const std::optional<Color>& fill,
                     const std::optional<Stroke>& stroke) {
  if (fill) {
    set_colour(cr, *fill);
    if (stroke)
      cairo_fill_preserve(cr);
    else
      cairo_fill(cr);
  }
  if (stroke) {
    set_colour(cr, stroke->color);
    cairo_set_line_width(cr, stroke->width);
    cairo_set_dash(cr, stroke->dash.data(), int(stroke->dash.size()), 0);
    cairo_stroke(cr);
  }
  cairo_new_path(cr);
}

void draw_text(cairo_t* cr, const TextItem& t) {
  const auto runs = parse_markup(t.text);
  cairo_save(cr);
  cairo_select_font_face(cr, kFontFamily, CAIRO_FONT_SLANT_NORMAL,
                         t.bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  double width = 0;
  for (const TextRun& r : runs) {
    cairo_set_font_size(cr, t.size * (r.script == 0 ? 1.0 : kScriptScale));
    cairo_text_extents_t e;
    cairo_text_extents(cr, r.text.c_str(), &e);
    width += e.x_advance;
  }
  cairo_translate(cr, t.at.x, t.at.y);
  cairo_rotate(cr, -t.angle * std::numbers::pi / 180.0);
  double x = t.halign == HAlign::left ? 0.0 : t.halign == HAlign::centre ? -0.5 * width : -width;
  const double y = baseline_offset(t.valign) * t.size;
  set_colour(cr, t.color);
  for (const TextRun& r : runs) {
    cairo_set_font_size(cr, t.size * (r.script == 0 ? 1.0 : kScriptScale));
    const double shift = r.script < 0 ? kSubShift : r.script > 0 ? kSuperShift : 0.0;
    cairo_move_to(cr, x, y + shift * t.size);
    cairo_text_extents_t e;
    cairo_text_extents(cr, r.text.c_str(), &e);
    cairo_show_text(cr, r.text.c_str());
    x += e.x_advance;
  }
  cairo_restore(cr);
}

void draw_scene(cairo_t* cr, const Scene& scene) {
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  set_colour(cr, scene.background);
  cairo_paint(cr);
  for (const Item& item : scene.items) {
    if (const auto* p = std::get_if<PathItem>(&item)) {
      if (p->points.empty()) continue;
      path_of(cr, *p);
      fill_and_stroke(cr, p->fill, p->stroke);
    } else if (const auto* c = std::get_if<CircleItem>(&item)) {
      cairo_new_path(cr);
      cairo_arc(cr, c->centre.x, c->centre.y, c->radius, 0, 2 * std::numbers::pi);
      cairo_close_path(cr);
      fill_and_stroke(cr, c->fill, c->stroke);
    } else if (const auto* im = std::get_if<ImageItem>(&item)) {
      if (im->px_width == 0 || im->px_height == 0) continue;
      SurfacePtr s = image_surface(*im);
      cairo_save(cr);
      cairo_translate(cr, im->x, im->y);
      cairo_scale(cr, im->width / double(im->px_width), im->height / double(im->px_height));
      cairo_set_source_surface(cr, s.get(), 0, 0);
      cairo_pattern_set_filter(cairo_get_source(cr),
                               im->smooth ? CAIRO_FILTER_GOOD : CAIRO_FILTER_NEAREST);
      cairo_pattern_set_extend(cairo_get_source(cr), CAIRO_EXTEND_PAD);
      cairo_rectangle(cr, 0, 0, double(im->px_width), double(im->px_height));
      cairo_fill(cr);
      cairo_restore(cr);
    } else if (const auto* t = std::get_if<TextItem>(&item)) {
      draw_text(cr, *t);
    }
  }
  check(cairo_status(cr), "drawing the figure");
}

SurfacePtr raster_surface(const Scene& scene, double scale) {
  if (!(scale > 0) || !(scene.width > 0) || !(scene.height > 0))
    throw std::invalid_argument(
        fmt::format("figure of {}x{} pt at scale {}", scene.width, scene.height, scale));
  check_raster_size(scene.width, scene.height, scale, "a smaller scale");
  const int w = int(std::ceil(scene.width * scale)), h = int(std::ceil(scene.height * scale));
  SurfacePtr s(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w, h));
  check(cairo_surface_status(s.get()), "PNG surface");
  ContextPtr cr(cairo_create(s.get()));
  cairo_scale(cr.get(), scale, scale);
  draw_scene(cr.get(), scene);
  cairo_surface_flush(s.get());
  return s;
}

Raster raster_of(cairo_surface_t* s) {
  Raster r;
  r.width = std::size_t(cairo_image_surface_get_width(s));
  r.height = std::size_t(cairo_image_surface_get_height(s));
  r.rgba.resize(4 * r.width * r.height);
  const unsigned char* data = cairo_image_surface_get_data(s);
  const int stride = cairo_image_surface_get_stride(s);
  const cairo_format_t format = cairo_image_surface_get_format(s);
  for (std::size_t y = 0; y < r.height; ++y) {
    const auto* row = reinterpret_cast<const std::uint32_t*>(data + std::ptrdiff_t(y) * stride);
    for (std::size_t x = 0; x < r.width; ++x) {
      const std::uint32_t v = row[x];
      const std::uint32_t a = format == CAIRO_FORMAT_RGB24 ? 255 : v >> 24;
      auto un = [a](std::uint32_t c) {
        return a == 0 ? 0u : std::min(255u, (c * 255 + a / 2) / a);
      };
      std::uint8_t* p = &r.rgba[4 * (y * r.width + x)];
      p[0] = std::uint8_t(un((v >> 16) & 255));
      p[1] = std::uint8_t(un((v >> 8) & 255));
      p[2] = std::uint8_t(un(v & 255));
      p[3] = std::uint8_t(a);
    }
  }
  return r;
}

std::string png_of_surface(cairo_surface_t* s) {
  std::string out;
  check(cairo_surface_write_to_png_stream(s, append_to_string, &out), "PNG encoding");
  return out;
}

std::string render_pdf(const Scene& scene) {
  std::string out;
  {
    SurfacePtr s(
        cairo_pdf_surface_create_for_stream(append_to_string, &out, scene.width, scene.height));
    check(cairo_surface_status(s.get()), "PDF surface");
    if (!scene.title.empty())
      cairo_pdf_surface_set_metadata(s.get(), CAIRO_PDF_METADATA_TITLE, scene.title.c_str());
    cairo_pdf_surface_set_metadata(s.get(), CAIRO_PDF_METADATA_CREATOR, "halfback");
    ContextPtr cr(cairo_create(s.get()));
    draw_scene(cr.get(), scene);
    cr.reset();
    cairo_surface_finish(s.get());
    check(cairo_surface_status(s.get()), "PDF output");
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// SVG, written directly
// ---------------------------------------------------------------------------------------------
std::string hex(const Color& c) {
  return fmt::format("#{:02x}{:02x}{:02x}", to_byte(c.r), to_byte(c.g), to_byte(c.b));
}

std::string num(double v) {
  if (std::abs(v) < 5e-4) return "0";
  std::string s = fmt::format("{:.3f}", v);
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

std::string paint_attributes(const std::optional<Color>& fill,
                             const std::optional<Stroke>& stroke) {
  std::string a;
  if (fill) {
    a += fmt::format(" fill=\"{}\"", hex(*fill));
    if (fill->a < 1) a += fmt::format(" fill-opacity=\"{}\"", num(fill->a));
  } else {
    a += " fill=\"none\"";
  }
  if (stroke) {
    a += fmt::format(" stroke=\"{}\" stroke-width=\"{}\"", hex(stroke->color), num(stroke->width));
    if (stroke->color.a < 1) a += fmt::format(" stroke-opacity=\"{}\"", num(stroke->color.a));
    if (!stroke->dash.empty()) {
      a += " stroke-dasharray=\"";
      for (std::size_t i = 0; i < stroke->dash.size(); ++i) {
        if (i) a += ' ';
        a += num(stroke->dash[i]);
      }
      a += "\"";
    }
  }
  return a;
}

std::string render_svg(const Scene& scene) {
  std::string out;
  out += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out += fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:xlink=\"http://www.w3.org/1999/xlink\" "
      "width=\"{0}pt\" height=\"{1}pt\" viewBox=\"0 0 {0} {1}\" version=\"1.1\">\n",
      num(scene.width), num(scene.height));
  if (!scene.title.empty()) out += fmt::format("<title>{}</title>\n", escape_xml(scene.title));
  out += fmt::format(
      "<g stroke-linejoin=\"round\" stroke-linecap=\"round\" font-family=\"{}, Verdana, "
      "sans-serif\">\n",
      kFontFamily);
  out += fmt::format("<rect x=\"0\" y=\"0\" width=\"{}\" height=\"{}\" fill=\"{}\"/>\n",
                     num(scene.width), num(scene.height), hex(scene.background));
  for (const Item& item : scene.items) {
    if (const auto* p = std::get_if<PathItem>(&item)) {
      if (p->points.empty()) continue;
      std::string d;
      for (std::size_t i = 0; i < p->points.size(); ++i)
        d += fmt::format("{}{} {}", i == 0 ? "M" : (i == 1 ? " L" : " "), num(p->points[i].x),
                         num(p->points[i].y));
      if (p->closed) d += " Z";
      out += fmt::format("<path d=\"{}\"{}/>\n", d, paint_attributes(p->fill, p->stroke));
    } else if (const auto* c = std::get_if<CircleItem>(&item)) {
      out += fmt::format("<circle cx=\"{}\" cy=\"{}\" r=\"{}\"{}/>\n", num(c->centre.x),
                         num(c->centre.y), num(c->radius), paint_attributes(c->fill, c->stroke));
    } else if (const auto* im = std::get_if<ImageItem>(&item)) {
      if (im->px_width == 0 || im->px_height == 0) continue;
      SurfacePtr s = image_surface(*im);
      const std::string png = png_of_surface(s.get());
      out += fmt::format(
          "<image x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" preserveAspectRatio=\"none\"{} "
          "xlink:href=\"data:image/png;base64,{}\"/>\n",
          num(im->x), num(im->y), num(im->width), num(im->height),
          im->smooth ? "" : " style=\"image-rendering:pixelated\"", base64_encode(png));
    } else if (const auto* t = std::get_if<TextItem>(&item)) {
      const char* anchor = t->halign == HAlign::left     ? "start"
                           : t->halign == HAlign::centre ? "middle"
                                                         : "end";
      std::string attrs = fmt::format(" x=\"{}\" y=\"{}\" font-size=\"{}\" fill=\"{}\"",
                                      num(t->at.x), num(t->at.y), num(t->size), hex(t->color));
      if (t->halign != HAlign::left) attrs += fmt::format(" text-anchor=\"{}\"", anchor);
      if (t->bold) attrs += " font-weight=\"bold\"";
      if (t->angle != 0)
        attrs += fmt::format(" transform=\"rotate({} {} {})\"", num(-t->angle), num(t->at.x),
                             num(t->at.y));
      // The baseline offset of the alignment is a dy on the first run, in the rotated frame.
      std::string body;
      double shift = baseline_offset(t->valign) * t->size;  // pending dy
      double current = 0;                                   // script shift now in effect
      for (const TextRun& r : parse_markup(t->text)) {
        const double target = (r.script < 0   ? kSubShift
                               : r.script > 0 ? kSuperShift
                                              : 0.0) *
                              t->size;
        const double dy = shift + target - current;
        shift = 0;
        current = target;
        std::string ta;
        if (dy != 0) ta += fmt::format(" dy=\"{}\"", num(dy));
        if (r.script != 0) ta += fmt::format(" font-size=\"{}\"", num(t->size * kScriptScale));
        body += ta.empty() ? escape_xml(r.text)
                           : fmt::format("<tspan{}>{}</tspan>", ta, escape_xml(r.text));
      }
      out += fmt::format("<text xml:space=\"preserve\"{}>{}</text>\n", attrs, body);
    }
  }
  out += "</g>\n</svg>\n";
  return out;
}

}  // namespace

std::optional<Format> format_from_path(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".png") return Format::png;
  if (ext == ".svg") return Format::svg;
  if (ext == ".pdf") return Format::pdf;
  return std::nullopt;
}

std::string_view extension_of(Format f) {
  switch (f) {
    case Format::png:
      return "png";
    case Format::svg:
      return "svg";
    case Format::pdf:
      break;
  }
  return "pdf";
}

std::string render(const Scene& scene, Format format, const RenderOptions& options) {
  switch (format) {
    case Format::png: {
      SurfacePtr s = raster_surface(scene, options.png_scale);
      return png_of_surface(s.get());
    }
    case Format::svg:
      return render_svg(scene);
    case Format::pdf:
      break;
  }
  return render_pdf(scene);
}

Raster rasterize(const Scene& scene, double scale) {
  SurfacePtr s = raster_surface(scene, scale);
  return raster_of(s.get());
}

namespace {
struct PngReader {
  std::string_view data;
  std::size_t pos = 0;
};
cairo_status_t read_png(void* closure, unsigned char* out, unsigned int length) {
  auto* r = static_cast<PngReader*>(closure);
  if (r->data.size() - r->pos < length) return CAIRO_STATUS_READ_ERROR;
  std::memcpy(out, r->data.data() + r->pos, length);
  r->pos += length;
  return CAIRO_STATUS_SUCCESS;
}
}  // namespace

Raster decode_png(std::string_view png) {
  PngReader reader{png};
  SurfacePtr s(cairo_image_surface_create_from_png_stream(read_png, &reader));
  check(cairo_surface_status(s.get()), "decoding PNG");
  return raster_of(s.get());
}

void check_raster_size(double width, double height, double scale, std::string_view hint) {
  const double w = std::ceil(width * scale), h = std::ceil(height * scale);
  if (!(w <= kMaxRasterSide && h <= kMaxRasterSide))
    throw FigureSizeError(fmt::format(
        "the figure would be {:.0f} x {:.0f} pixels ({:.0f} x {:.0f} pt at {:g} pixels per point), "
        "above the {} pixels per side an image can have: ask for {}",
        w, h, width, height, scale, kMaxRasterSide, hint));
}

void save(const Scene& scene, const std::filesystem::path& path, const RenderOptions& options) {
  const auto format = format_from_path(path);
  if (!format)
    throw std::invalid_argument(
        fmt::format("cannot tell the figure format of '{}': use a .png, .svg or .pdf file name",
                    path.string()));
  // Fail on an unwritable destination before rendering; nothing is left behind on error.
  AtomicFile out(path);
  out.write(render(scene, *format, options));
  out.commit();
}

}  // namespace halfback::figure
