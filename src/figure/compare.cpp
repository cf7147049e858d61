#include "halfback/figure/compare.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "halfback/brdf/albedo.hpp"
#include "halfback/figure/contour.hpp"
#include "halfback/figure/coordinates.hpp"
#include "halfback/figure/plot.hpp"
#include "halfback/figure/render.hpp"
#include "halfback/figure/slices.hpp"

namespace halfback::figure {

// A named namespace: the layer's files are compiled as one unity translation unit.
namespace compare_parts {

constexpr double kPi = std::numbers::pi;
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
// Where a measured BRDF has no value (NaN): a flat beige, apart from the hatching of the domain.
constexpr Color kNotMeasured = kBelowHorizonLight;

// Where things go, in points: rows A, B, log ratio; a column per azimuth; the albedo plot below.
struct Layout {
  double panel = 150, gap = 22, vgap = 50, left = 84, right = 100, top = 0;
  std::size_t cols = 0;
  double plot_height = 150;

  double row_y(std::size_t r) const { return top + double(r) * (panel + vgap); }
  double col_x(std::size_t c) const { return left + double(c) * (panel + gap); }
  double panels_right() const { return col_x(cols - 1) + panel; }
  double plot_y() const { return row_y(3) + 12; }
};

// One column: the slice's pairs and both BRDFs' luminances there (NaN outside the domain).
struct Column {
  PanelMap map;
  SliceSample sample;
  std::vector<double> y_ref, y_cmp;
};

std::vector<double> luminances(const Brdf& brdf, const SliceSample& s) {
  std::vector<DirPair<double>> pairs;
  std::vector<std::size_t> where;
  for (std::size_t k = 0; k < s.valid.size(); ++k)
    if (s.valid[k]) {
      pairs.push_back(s.pairs[k]);
      where.push_back(k);
    }
  std::vector<Rgb> rgb(pairs.size());
  brdf.eval_batch(pairs, rgb);
  std::vector<double> y(s.valid.size(), kNan);
  for (std::size_t m = 0; m < where.size(); ++m) y[where[m]] = rgb[m].luminance();
  return y;
}

double core_azimuth(double degrees) {
  double a = std::fmod(degrees, 360.0);
  if (a < 0) a += 360.0;
  return a >= 360.0 ? 0.0 : a * kPi / 180.0;
}

std::vector<Column> sample_columns(const CompareFigureOptions& o, const Layout& l) {
  const auto coords = iso_coordinates(o.param);
  std::vector<Column> cols;
  for (std::size_t c = 0; c < l.cols; ++c) {
    Column col;
    col.map =
        PanelMap{{l.col_x(c), l.row_y(0), l.panel, l.panel}, 0, coords[0].max, 0, coords[1].max};
    col.sample =
        sample_slice(o.param, third_coordinate_at(o.param, core_azimuth(o.azimuths_deg[c])),
                     col.map.raster_grid(o.pixels_per_point), o.threads);
    col.y_ref = luminances(*o.reference, col.sample);
    col.y_cmp = luminances(*o.compared, col.sample);
    cols.push_back(std::move(col));
  }
  return cols;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return kNan;
  const std::size_t k = std::min(v.size() - 1, std::size_t(p * double(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return v[k];
}

// The shared log10 luminance scale of A and B, as slices.hpp makes it: the 0.5 % and 99.5 %
// percentiles of the positive values, at most 7 decades.
void set_luminance_scale(CompareFigure& fig, const std::vector<Column>& cols) {
  std::vector<double> all;
  for (const Column& c : cols)
    for (const auto* ys : {&c.y_ref, &c.y_cmp})
      for (double y : *ys)
        if (y > 0 && std::isfinite(y)) all.push_back(std::log10(y));
  if (all.empty()) {
    fig.log_lo = -1;
    fig.log_hi = 0;
    return;
  }
  fig.log_hi = percentile(all, 0.995);
  fig.log_lo = std::max(percentile(all, 0.005), fig.log_hi - 7.0);
  if (!(fig.log_hi - fig.log_lo > 1e-6)) fig.log_lo = fig.log_hi - 1;
}

// log10(Y_B / Y_A): 0 where both are 0, ±∞ where one is; NaN where either is not finite.
double log_ratio(double ya, double yb) {
  if (!std::isfinite(ya) || !std::isfinite(yb)) return kNan;
  if (ya <= 0 && yb <= 0) return 0;
  if (ya <= 0) return std::numeric_limits<double>::infinity();
  if (yb <= 0) return -std::numeric_limits<double>::infinity();
  return std::log10(yb / ya);
}

// v rounded up to two significant digits, and at least 0.01 (a factor of 1.023).
double round_up(double v) {
  if (!(v > 0.01)) return 0.01;
  const double unit = std::pow(10.0, std::floor(std::log10(v)) - 1);
  return std::ceil(v / unit * (1 - 1e-12)) * unit;
}

// The log ratio's range: the 95th percentile of |log ratio| over every slice, rounded up, at
// most 3 (a factor of 1000): a narrow peak missed by B must not wash out the rest.
double ratio_range(const std::vector<Column>& cols) {
  std::vector<double> all;
  for (const Column& c : cols)
    for (std::size_t k = 0; k < c.y_ref.size(); ++k) {
      const double r = log_ratio(c.y_ref[k], c.y_cmp[k]);
      if (!std::isnan(r)) all.push_back(std::min(std::abs(r), 1e3));
    }
  return std::min(3.0, round_up(all.empty() ? 0 : percentile(all, 0.95)));
}

PanelMap moved_to_row(const PanelMap& m, const Layout& l, std::size_t row) {
  PanelMap out = m;
  out.rect.y = l.row_y(row);
  return out;
}

// The raster of one panel: `colour(k)` at the valid pixel k, hatching outside the domain.
void draw_raster(Scene& sc, const PanelMap& map, const SliceSample& s,
                 const std::function<Color(std::size_t)>& colour) {
  const Grid& g = s.grid;
  sc.add(raster(map, g, [&](std::size_t i, std::size_t j) -> Color {
    const std::size_t k = g.index(i, j);
    if (!s.valid[k]) return hatch(i, j, kInvalidLight, kInvalidDark);
    return colour(k);
  }));
}

// The domain boundary (exact, by bisection) and the axes of one panel.
void draw_panel_frame(Scene& sc, const CompareFigureOptions& o, const PanelMap& map,
                      const SliceSample& s, double azimuth_deg, bool first_column) {
  const double third = third_coordinate_at(o.param, core_azimuth(azimuth_deg));
  auto inside = [&](double x, double y) {
    return bool(o.param.param().inverse_iso({x, y, third}).in_domain);
  };
  draw_polylines(sc, map, region_boundary(s.grid, s.valid, inside), Stroke{kBlack, 0.8});
  const auto coords = iso_coordinates(o.param);
  const double deg = kPi / 180;
  AxisSpec ax{coords[0].label, ticks(0, coords[0].max, coords[0].angle ? 15 * deg : 0.2), {}};
  AxisSpec ay{coords[1].label, ticks(0, coords[1].max, coords[1].angle ? 15 * deg : 0.2), {}};
  for (double t : ax.ticks) ax.labels.push_back(format_coordinate(coords[0], t));
  for (double t : ay.ticks) ay.labels.push_back(format_coordinate(coords[1], t));
  draw_axes(sc, map, ax, ay, true, first_column, 8);
}

// Isolines of log10 luminance at the levels of the shared scale, as the slices draw them.
void draw_isolines(Scene& sc, const PanelMap& map, const SliceSample& s,
                   const std::vector<double>& y, const CompareFigure& fig) {
  ScalarField f(s.grid);
  f.valid = s.valid;
  for (std::size_t k = 0; k < y.size(); ++k)
    f.values[k] =
        !s.valid[k] || !std::isfinite(y[k]) ? kNan : (y[k] > 0 ? std::log10(y[k]) : fig.log_lo - 1);
  for (double level : log_levels(fig.log_lo, fig.log_hi, 10)) {
    const bool decade = std::abs(level - std::round(level)) < 1e-9;
    draw_polylines(sc, map, contour(f, level), Stroke{{1, 1, 1, 0.8}, decade ? 0.9 : 0.5});
  }
}

Color luminance_colour(double y, const CompareFigure& fig) {
  if (std::isnan(y)) return kNotMeasured;
  const double l = y > 0 ? std::log10(y) : fig.log_lo - 1;
  return viridis((l - fig.log_lo) / (fig.log_hi - fig.log_lo));
}

Color ratio_colour(double r, double range) {
  if (std::isnan(r)) return kNotMeasured;
  return diverging(0.5 + 0.5 * std::clamp(r / range, -1.0, 1.0));
}

void draw_rows(Scene& sc, const CompareFigureOptions& o, const CompareFigure& fig,
               const std::vector<Column>& cols, const Layout& l) {
  for (std::size_t c = 0; c < cols.size(); ++c) {
    const Column& col = cols[c];
    const PanelMap maps[3] = {col.map, moved_to_row(col.map, l, 1), moved_to_row(col.map, l, 2)};
    draw_raster(sc, maps[0], col.sample,
                [&](std::size_t k) { return luminance_colour(col.y_ref[k], fig); });
    draw_isolines(sc, maps[0], col.sample, col.y_ref, fig);
    draw_raster(sc, maps[1], col.sample,
                [&](std::size_t k) { return luminance_colour(col.y_cmp[k], fig); });
    draw_isolines(sc, maps[1], col.sample, col.y_cmp, fig);
    draw_raster(sc, maps[2], col.sample, [&](std::size_t k) {
      return ratio_colour(log_ratio(col.y_ref[k], col.y_cmp[k]), fig.ratio_range);
    });
    for (const PanelMap& m : maps) {
      draw_panel_frame(sc, o, m, col.sample, o.azimuths_deg[c], c == 0);
      sc.text({m.rect.x + 0.5 * l.panel, m.rect.y - 5},
              third_coordinate_title(o.param, o.azimuths_deg[c]), 9, HAlign::centre,
              VAlign::bottom);
    }
  }
  const char* names[3] = {"A (reference)", "B (compared)", "log₁₀ (B / A)"};
  for (std::size_t r = 0; r < 3; ++r)
    sc.text({14, l.row_y(r) + 0.5 * l.panel}, names[r], 10.5, HAlign::centre, VAlign::middle,
            kBlack, 90, true);
}

void draw_colour_bars(Scene& sc, const CompareFigureOptions& o, const CompareFigure& fig,
                      const Layout& l) {
  const double x = l.panels_right() + 22;
  std::vector<double> tick_t;
  std::vector<std::string> labels;
  const double span = fig.log_hi - fig.log_lo;
  for (double v : log_levels(fig.log_lo - 1e-6, fig.log_hi + 1e-6, 8)) {
    tick_t.push_back((v - fig.log_lo) / span);
    labels.push_back(power_of_ten_label(v));
  }
  if (tick_t.size() < 2) {  // less than a level inside the scale: label its ends
    tick_t = {0, 1};
    labels = {fmt::format("{:.3g}", std::pow(10.0, fig.log_lo)),
              fmt::format("{:.3g}", std::pow(10.0, fig.log_hi))};
  }
  draw_colour_bar(
      sc, {x, l.row_y(0) + 10, 14, l.row_y(1) + l.panel - l.row_y(0) - 20},
      [](double t) { return viridis(t); }, tick_t, labels, "luminance", o.pixels_per_point);
  const double m = fig.ratio_range;
  std::vector<std::string> ratio_labels;
  for (double v : {-m, -m / 2, 0.0, m / 2, m})
    ratio_labels.push_back(v == 0 ? "0"
                                  : (v < 0 ? fmt::format("−{:g}", -v) : fmt::format("+{:g}", v)));
  draw_colour_bar(
      sc, {x, l.row_y(2) + 10, 14, l.panel - 20}, [](double t) { return diverging(t); },
      {0, 0.25, 0.5, 0.75, 1}, ratio_labels, "log₁₀ B/A", o.pixels_per_point);
}

void sample_albedos(CompareFigure& fig, const CompareFigureOptions& o) {
  for (double deg = 0; deg <= 89 + 1e-9; deg += o.albedo_step_deg) {
    const double th = deg * kPi / 180;
    const Vec3<double> wi{std::sin(th), 0, std::cos(th)};
    auto y = [&](const Brdf& b) {
      const AlbedoEstimate a = directional_albedo(b, wi, o.albedo_samples);
      return a.measured > 0 ? a.mean.luminance() : kNan;
    };
    fig.albedo_theta_deg.push_back(deg);
    fig.albedo_reference.push_back(y(*o.reference));
    fig.albedo_compared.push_back(y(*o.compared));
  }
}

// A curve of the albedo plot: one polyline per run of finite values.
void draw_curve(Scene& sc, const PanelMap& map, const std::vector<double>& x,
                const std::vector<double>& y, const Stroke& stroke) {
  std::vector<Polyline> lines(1);
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (std::isfinite(y[k])) {
      lines.back().points.push_back({x[k], std::min(y[k], map.y1)});
    } else if (!lines.back().points.empty()) {
      lines.emplace_back();
    }
  }
  draw_polylines(sc, map, lines, stroke);
}

void draw_albedo_plot(Scene& sc, const CompareFigure& fig, const Layout& l) {
  double top = 0;
  for (const auto* ys : {&fig.albedo_reference, &fig.albedo_compared})
    for (double y : *ys)
      if (std::isfinite(y)) top = std::max(top, y);
  // Ticks 1, 2 or 5 × 10^k apart, about five of them, up to just above the largest value.
  const double raw = (top > 0 ? 1.1 * top : 1) / 5,
               unit = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10 * unit;
  for (double m : {5.0, 2.0, 1.0})
    if (m * unit >= raw) step = m * unit;
  top = step * std::ceil((top > 0 ? 1.1 * top : 1) / step - 1e-9);
  const double width = l.panels_right() - l.left;
  const PanelMap map{{l.left, l.plot_y(), width, l.plot_height}, 0, 90, 0, top};
  AxisSpec ax{"θ_i", ticks(0, 90, 15), {}};
  for (double t : ax.ticks) ax.labels.push_back(fmt::format("{:g}°", t));
  AxisSpec ay{"albedo (luminance)", ticks(0, top, step), {}};
  for (double t : ay.ticks) ay.labels.push_back(fmt::format("{:.3g}", t));
  const Stroke a{kBlack, 1.4}, b{{0.85, 0.2, 0.1}, 1.4, {5, 3}};
  draw_curve(sc, map, fig.albedo_theta_deg, fig.albedo_reference, a);
  draw_curve(sc, map, fig.albedo_theta_deg, fig.albedo_compared, b);
  draw_axes(sc, map, ax, ay, true, true, 8);
  draw_legend_line(sc, {l.panels_right() + 14, l.plot_y() + 14}, a, "A", 9);
  draw_legend_line(sc, {l.panels_right() + 14, l.plot_y() + 30}, b, "B", 9);
}

void check_options(const CompareFigureOptions& o) {
  if (!o.reference || !o.compared)
    throw std::invalid_argument("compare figure: both BRDFs must be given");
  if (o.azimuths_deg.empty()) throw std::invalid_argument("compare figure: no azimuth given");
  for (double a : o.azimuths_deg)
    if (!std::isfinite(a))
      throw std::invalid_argument("compare figure: the azimuths must be finite numbers");
  if (o.param == Space::dirs)
    throw std::invalid_argument("compare figure: 'dirs' is not a parameterization");
  if (!(o.albedo_step_deg > 0 && o.albedo_step_deg <= 45))
    throw std::invalid_argument("compare figure: the albedo step must be in (0°, 45°]");
  if (!(o.panel_size > 10) || !(o.pixels_per_point > 0))
    throw std::invalid_argument("compare figure: bad panel size or pixel density");
}

}  // namespace compare_parts

CompareFigure compare_figure(const CompareFigureOptions& o) {
  using namespace compare_parts;
  check_options(o);
  CompareFigure fig;
  Scene& sc = fig.scene;
  Layout l;
  l.panel = snap(o.panel_size);
  l.plot_height = l.panel;
  l.cols = o.azimuths_deg.size();
  sc.width = snap(l.panels_right() + l.right);
  sc.title = fmt::format("{} against {}", o.compared->name(), o.reference->name());
  const std::vector<std::string> heading =
      wrap_text(fmt::format("B = {} against A = {}", escape_markup(o.compared->name()),
                            escape_markup(o.reference->name())),
                sc.width - l.left - 8, 12);
  const std::vector<std::string> sub = wrap_text(
      "Slices of the isotropic forms at fixed relative azimuth, false colour of log₁₀ luminance "
      "on one scale for A and B (clipped at its 0.5 % and 99.5 % percentiles; white isolines at "
      "the levels of the colour bar); then the log ratio of B's luminance to A's (red: B "
      "brighter; clipped at the 95th percentile of its magnitude); hatched: outside the domain; "
      "beige: not measured. Below: the directional albedo of each.",
      sc.width - l.left - 12, 9);
  l.top = snap(50 + 15 * double(heading.size() - 1) + 12 * double(sub.size()));
  sc.height = snap(l.plot_y() + l.plot_height + 46);
  check_raster_size(sc.width, sc.height, o.pixels_per_point,
                    fmt::format("fewer azimuths ({} given) or a lower pixel density", l.cols));

  const std::vector<Column> cols = sample_columns(o, l);
  set_luminance_scale(fig, cols);
  fig.ratio_range = ratio_range(cols);
  sample_albedos(fig, o);

  for (std::size_t k = 0; k < heading.size(); ++k)
    sc.text({l.left, 20 + 15 * double(k)}, heading[k], 12, HAlign::left, VAlign::baseline, kBlack,
            0, true);
  for (std::size_t k = 0; k < sub.size(); ++k)
    sc.text({l.left, 36 + 15 * double(heading.size() - 1) + 12 * double(k)}, sub[k], 9);
  draw_rows(sc, o, fig, cols, l);
  draw_colour_bars(sc, o, fig, l);
  draw_albedo_plot(sc, fig, l);
  return fig;
}

}  // namespace halfback::figure
