// Building blocks of the figures: panels mapping data to the page, rasters of sampled fields,
// isolines, axes with ticks, colour bars and the hatching of invalid regions.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/figure/contour.hpp"
#include "halfback/figure/field.hpp"
#include "halfback/figure/scene.hpp"

namespace halfback::figure {

struct Rect {
  double x = 0, y = 0, w = 0, h = 0;
};

// A panel: the data rectangle [x0, x1] × [y0, y1] drawn in `rect` (y up in data, down on the
// page). With `pixels_per_point` it also fixes the panel's raster: one sample per output pixel.
struct PanelMap {
  Rect rect;
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;

  Point to_page(double x, double y) const {
    return {rect.x + (x - x0) / (x1 - x0) * rect.w, rect.y + (y1 - y) / (y1 - y0) * rect.h};
  }
  Point to_data(Point page) const {
    return {x0 + (page.x - rect.x) / rect.w * (x1 - x0),
            y1 - (page.y - rect.y) / rect.h * (y1 - y0)};
  }
  // Raster size at `pixels_per_point`, and the grid of its pixel centres in data coordinates
  // (row 0 of the grid is the bottom row of the raster).
  std::size_t raster_width(double pixels_per_point) const;
  std::size_t raster_height(double pixels_per_point) const;
  Grid raster_grid(double pixels_per_point) const;
};

// Rounds a length to the nearest half point, so that at 2 px/pt panels start on whole pixels.
double snap(double v);

// The raster of a panel: colour(i, j) for every node of `grid` (j = 0 at the bottom), drawn over
// the panel rectangle without interpolation.
ImageItem raster(const PanelMap& panel, const Grid& grid,
                 const std::function<Color(std::size_t i, std::size_t j)>& colour);

// The hatching of regions that are not data: 45° stripes of `light` and `dark`, `period` pixels
// wide, a function of the raster pixel so that it is crisp at any size.
Color hatch(std::size_t i, std::size_t j, const Color& light, const Color& dark,
            std::size_t period = 8);

// Polylines in data coordinates, drawn on the panel.
void draw_polylines(Scene& scene, const PanelMap& panel, const std::vector<Polyline>& lines,
                    const Stroke& stroke);

struct AxisSpec {
  std::string title;                // markup
  std::vector<double> ticks;        // data values
  std::vector<std::string> labels;  // one per tick (empty: no labels)
};

// Frame, ticks (outside the panel), tick labels and axis titles. `x_labels` / `y_labels` say
// whether this panel shows the tick labels and title of that axis.
// A black frame around a rectangle.
void draw_frame(Scene& scene, const Rect& rect, double width = 0.7);

void draw_axes(Scene& scene, const PanelMap& panel, const AxisSpec& x, const AxisSpec& y,
               bool x_labels = true, bool y_labels = true, double font_size = 8.5);

// Evenly spaced ticks lo, lo + step, … ≤ hi (with a little tolerance at hi).
std::vector<double> ticks(double lo, double hi, double step);

// A vertical colour bar: `colour(t)` for t in [0, 1] bottom to top, ticks at t values.
void draw_colour_bar(Scene& scene, const Rect& rect, const std::function<Color(double)>& colour,
                     const std::vector<double>& tick_t, const std::vector<std::string>& labels,
                     const std::string& title, double pixels_per_point, double font_size = 8.5);

// A rough width of a text in points (0.6 em per character, scripts smaller), for layout where
// the font is not at hand; DejaVu Sans averages about 0.55–0.6 em.
double approx_text_width(std::string_view markup, double font_size);

// Splits a text at spaces into lines of at most `width` points (by approx_text_width); a word
// longer than the width gets a line of its own.
std::vector<std::string> wrap_text(std::string_view markup, double width, double font_size);

// A short horizontal line sample followed by a label (legends).
void draw_legend_line(Scene& scene, Point at, const Stroke& stroke, const std::string& label,
                      double font_size = 9, const Color& text_colour = kBlack);

}  // namespace halfback::figure
