#include "halfback/figure/plot.hpp"

#include <algorithm>
#include <cmath>

namespace halfback::figure {

std::size_t PanelMap::raster_width(double ppp) const {
  return std::max<std::size_t>(1, std::size_t(std::lround(rect.w * ppp)));
}
std::size_t PanelMap::raster_height(double ppp) const {
  return std::max<std::size_t>(1, std::size_t(std::lround(rect.h * ppp)));
}
Grid PanelMap::raster_grid(double ppp) const {
  return Grid::pixel_centres(raster_width(ppp), raster_height(ppp), x0, x1, y0, y1);
}

double snap(double v) {
  return std::round(2.0 * v) / 2.0;
}

ImageItem raster(const PanelMap& panel, const Grid& grid,
                 const std::function<Color(std::size_t, std::size_t)>& colour) {
  ImageItem im;
  im.x = panel.rect.x;
  im.y = panel.rect.y;
  im.width = panel.rect.w;
  im.height = panel.rect.h;
  im.px_width = grid.nx;
  im.px_height = grid.ny;
  im.rgba.resize(4 * grid.nx * grid.ny);
  for (std::size_t j = 0; j < grid.ny; ++j) {
    const std::size_t row = grid.ny - 1 - j;  // data y up, image rows down
    for (std::size_t i = 0; i < grid.nx; ++i) {
      const Color c = colour(i, j);
      std::uint8_t* p = &im.rgba[4 * (row * grid.nx + i)];
      p[0] = to_byte(c.r);
      p[1] = to_byte(c.g);
      p[2] = to_byte(c.b);
      p[3] = to_byte(c.a);
    }
  }
  return im;
}

Color hatch(std::size_t i, std::size_t j, const Color& light, const Color& dark,
            std::size_t period) {
  // Stripes along the anti-diagonal of the image (rows run down): i + row is constant on them;
  // with j counted up, i - j is.
  const std::size_t k = (i + (std::size_t(1) << 30) - j) % period;
  return k < period / 4 ? dark : light;
}

void draw_polylines(Scene& scene, const PanelMap& panel, const std::vector<Polyline>& lines,
                    const Stroke& stroke) {
  for (const Polyline& l : lines) {
    if (l.points.size() < 2) continue;
    PathItem p;
    p.points.reserve(l.points.size());
    for (const Point& q : l.points) p.points.push_back(panel.to_page(q.x, q.y));
    p.closed = l.closed;
    p.stroke = stroke;
    scene.add(std::move(p));
  }
}

std::vector<double> ticks(double lo, double hi, double step) {
  std::vector<double> t;
  for (int k = 0;; ++k) {
    const double v = lo + k * step;
    if (v > hi + 1e-9 * std::abs(hi - lo)) break;
    t.push_back(std::min(v, hi));
  }
  return t;
}

void draw_frame(Scene& scene, const Rect& r, double width) {
  scene.rect(r.x, r.y, r.w, r.h, std::nullopt, Stroke{kBlack, width});
}

void draw_axes(Scene& scene, const PanelMap& panel, const AxisSpec& x, const AxisSpec& y,
               bool x_labels, bool y_labels, double fs) {
  const Rect& r = panel.rect;
  const Stroke frame{kBlack, 0.7};
  const double tick = 3.0;
  scene.rect(r.x, r.y, r.w, r.h, std::nullopt, frame);
  for (std::size_t k = 0; k < x.ticks.size(); ++k) {
    const Point p = panel.to_page(x.ticks[k], panel.y0);
    scene.line({p.x, r.y + r.h}, {p.x, r.y + r.h + tick}, frame);
    if (x_labels && k < x.labels.size())
      scene.text({p.x, r.y + r.h + tick + 1.5}, x.labels[k], fs, HAlign::centre, VAlign::top);
  }
  for (std::size_t k = 0; k < y.ticks.size(); ++k) {
    const Point p = panel.to_page(panel.x0, y.ticks[k]);
    scene.line({r.x - tick, p.y}, {r.x, p.y}, frame);
    if (y_labels && k < y.labels.size())
      scene.text({r.x - tick - 2, p.y}, y.labels[k], fs, HAlign::right, VAlign::middle);
  }
  if (x_labels && !x.title.empty())
    scene.text({r.x + 0.5 * r.w, r.y + r.h + tick + 3 + 1.25 * fs}, x.title, fs + 1.5,
               HAlign::centre, VAlign::top);
  if (y_labels && !y.title.empty())
    scene.text({r.x - tick - 2 - 2.6 * fs, r.y + 0.5 * r.h}, y.title, fs + 1.5, HAlign::centre,
               VAlign::bottom, kBlack, 90);
}

void draw_colour_bar(Scene& scene, const Rect& rect, const std::function<Color(double)>& colour,
                     const std::vector<double>& tick_t, const std::vector<std::string>& labels,
                     const std::string& title, double ppp, double fs) {
  PanelMap m{rect, 0, 1, 0, 1};
  const Grid g = Grid::pixel_centres(1, m.raster_height(ppp), 0, 1, 0, 1);
  ImageItem im = raster(m, g, [&](std::size_t, std::size_t j) { return colour(g.y(j)); });
  scene.add(std::move(im));
  const Stroke frame{kBlack, 0.7};
  scene.rect(rect.x, rect.y, rect.w, rect.h, std::nullopt, frame);
  for (std::size_t k = 0; k < tick_t.size(); ++k) {
    const double y = rect.y + (1 - tick_t[k]) * rect.h;
    scene.line({rect.x + rect.w, y}, {rect.x + rect.w + 3, y}, frame);
    if (k < labels.size())
      scene.text({rect.x + rect.w + 5, y}, labels[k], fs, HAlign::left, VAlign::middle);
  }
  if (!title.empty())
    scene.text({rect.x + 0.5 * rect.w, rect.y - 6}, title, fs + 0.5, HAlign::centre,
               VAlign::bottom);
}

double approx_text_width(std::string_view markup, double fs) {
  double w = 0;
  for (const TextRun& r : parse_markup(markup)) {
    std::size_t chars = 0;
    for (std::size_t i = 0; i < r.text.size(); ++i) {
      const auto b = static_cast<unsigned char>(r.text[i]);
      if ((b & 0xC0) == 0x80) continue;                  // continuation byte
      if (b == 0xCC && i + 1 < r.text.size()) continue;  // combining mark (U+0300–U+033F)
      ++chars;
    }
    w += 0.6 * fs * (r.script == 0 ? 1.0 : kScriptScale) * double(chars);
  }
  return w;
}

std::vector<std::string> wrap_text(std::string_view text, double width, double fs) {
  std::vector<std::string> lines;
  std::string line;
  std::size_t i = 0;
  while (i < text.size()) {
    const std::size_t space = text.find(' ', i);
    const std::size_t end = space == std::string_view::npos ? text.size() : space;
    const std::string_view word = text.substr(i, end - i);
    const std::string candidate = line.empty() ? std::string(word) : line + " " + std::string(word);
    if (!line.empty() && approx_text_width(candidate, fs) > width) {
      lines.push_back(line);
      line = std::string(word);
    } else {
      line = candidate;
    }
    i = end + 1;
  }
  if (!line.empty() || lines.empty()) lines.push_back(line);
  return lines;
}

void draw_legend_line(Scene& scene, Point at, const Stroke& stroke, const std::string& label,
                      double fs, const Color& text_colour) {
  scene.line({at.x, at.y}, {at.x + 22, at.y}, stroke);
  scene.text({at.x + 27, at.y}, label, fs, HAlign::left, VAlign::middle, text_colour);
}

}  // namespace halfback::figure
