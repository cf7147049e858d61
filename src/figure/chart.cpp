#include "halfback/figure/chart.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "halfback/figure/plot.hpp"

namespace halfback::figure {

namespace {

// Distinct colours for up to 8 series (colour-blind friendly, after Okabe & Ito).
const Color kSeries[] = {{0.0, 0.45, 0.70},  {0.90, 0.60, 0.0},  {0.0, 0.62, 0.45},
                         {0.80, 0.47, 0.65}, {0.35, 0.70, 0.90}, {0.84, 0.37, 0.0},
                         {0.95, 0.90, 0.25}, {0.3, 0.3, 0.3}};

}  // namespace

Scene bar_chart(const BarChart& c, const BarChartLayout& l) {
  if (c.rows.empty() || c.series.empty())
    throw std::invalid_argument("bar chart: no rows or no series");
  if (c.values.size() != c.rows.size())
    throw std::invalid_argument("bar chart: one row of values per row label");
  double max = 0;
  for (const auto& row : c.values) {
    if (row.size() != c.series.size())
      throw std::invalid_argument("bar chart: one value per series in every row");
    for (double v : row) {
      if (!std::isfinite(v) || v < 0)
        throw std::invalid_argument(fmt::format("bar chart: value {} is not finite and >= 0", v));
      max = std::max(max, v);
    }
  }
  if (max <= 0) max = 1;
  // Axis end: the next "nice" number (1, 2 or 5 times a power of ten) above the largest value.
  const double p10 = std::pow(10.0, std::floor(std::log10(max)));
  const double end = max <= p10       ? p10
                     : max <= 2 * p10 ? 2 * p10
                     : max <= 5 * p10 ? 5 * p10
                                      : 10 * p10;
  const double step = end / 5;

  const std::size_t ns = c.series.size();
  const double group = double(ns) * l.bar_height + l.group_gap;
  // The row labels are right-aligned before the bars: the margin widens for a longer label.
  double left = l.label_width;
  for (const std::string& row : c.rows)
    left = std::max(left, snap(12 + approx_text_width(escape_markup(row), 8.5)));
  const double top = 48, legend = 18 * double(ns) + 10;
  Scene sc;
  sc.title = c.title;
  sc.width = snap(left + l.plot_width + 40);
  sc.height = snap(top + double(c.rows.size()) * group + 40 + legend);
  sc.text({12, 24}, escape_markup(c.title), 13, HAlign::left, VAlign::baseline, kBlack, 0, true);

  const double plot_h = double(c.rows.size()) * group;
  auto x_of = [&](double v) { return left + l.plot_width * v / end; };
  const Stroke grid{{0.85, 0.85, 0.85}, 0.5}, axis{kBlack, 0.7};
  for (int k = 0; k <= 5; ++k) {
    const double x = x_of(step * k);
    sc.line({x, top}, {x, top + plot_h}, k == 0 ? axis : grid);
    sc.text({x, top + plot_h + 12}, fmt::format("{:g}", step * k), 8.5, HAlign::centre);
  }
  sc.text({left + l.plot_width / 2, top + plot_h + 26}, escape_markup(c.x_label), 9.5,
          HAlign::centre);
  for (std::size_t r = 0; r < c.rows.size(); ++r) {
    const double y0 = top + double(r) * group + l.group_gap / 2;
    sc.text({left - 6, y0 + double(ns) * l.bar_height / 2}, escape_markup(c.rows[r]), 8.5,
            HAlign::right, VAlign::middle);
    for (std::size_t s = 0; s < ns; ++s)
      sc.rect(left, y0 + double(s) * l.bar_height, x_of(c.values[r][s]) - left, l.bar_height,
              kSeries[s % std::size(kSeries)], std::nullopt);
  }
  for (std::size_t s = 0; s < ns; ++s) {
    const double y = top + plot_h + 44 + 18 * double(s);
    sc.rect(left, y - 8, 14, 10, kSeries[s % std::size(kSeries)], std::nullopt);
    sc.text({left + 20, y}, escape_markup(c.series[s]), 9.5);
  }
  return sc;
}

namespace {

// Decade bounds [10^lo, 10^hi] around positive values (at least one decade wide).
std::pair<int, int> decades(double min, double max) {
  int lo = int(std::floor(std::log10(min) + 1e-9)), hi = int(std::ceil(std::log10(max) - 1e-9));
  if (hi <= lo) hi = lo + 1;
  return {lo, hi};
}

void check_series(const LineSeries& s) {
  if (s.x.empty() || s.x.size() != s.y.size())
    throw std::invalid_argument(fmt::format(
        "log-log chart: series '{}' needs as many x as y values, at least one", s.name));
  for (std::size_t i = 0; i < s.x.size(); ++i)
    if (!(std::isfinite(s.x[i]) && s.x[i] > 0 && std::isfinite(s.y[i]) && s.y[i] > 0))
      throw std::invalid_argument(
          fmt::format("log-log chart: series '{}' has a point ({}, {}) that is not finite and > 0",
                      s.name, s.x[i], s.y[i]));
}

}  // namespace

Scene loglog_chart(const LogLogChart& c) {
  if (c.panels.empty()) throw std::invalid_argument("log-log chart: no panels");
  if (c.columns < 1) throw std::invalid_argument("log-log chart: columns must be >= 1");
  bool any = false;
  for (const LogLogPanel& p : c.panels)
    for (const LineSeries& s : p.series) {
      check_series(s);
      any = true;
    }
  if (!any) throw std::invalid_argument("log-log chart: no points");

  const auto cols = std::size_t(c.columns);
  const std::size_t rows = (c.panels.size() + cols - 1) / cols;
  const double margin_left = 52, gap_x = 30, gap_y = 58, top = 44;
  const double cell_w = c.panel_width + gap_x, cell_h = c.panel_height + gap_y;
  const LogLogPanel& first = c.panels.front();
  // Legend entries as wide as the longest name (~0.58 em a glyph at 8.5 pt, after the 28-pixel
  // swatch), at least 150 pixels; as many a row as the panels' width holds, 1 to 4.
  std::size_t longest = 0;
  for (const LineSeries& s : first.series) longest = std::max(longest, plain_text(s.name).size());
  const double entry_w = std::max(150.0, 28 + 8.5 * 0.58 * double(longest) + 14);
  const double panels_w = double(std::min(cols, c.panels.size())) * cell_w;
  const std::size_t per_row = std::clamp<std::size_t>(
      std::size_t(panels_w / entry_w), 1, std::min<std::size_t>(4, first.series.size()));
  const double legend = 16 * double((first.series.size() + per_row - 1) / per_row) + 10;
  Scene sc;
  sc.title = c.title;
  // Wide enough for the panels, the legend and the title (~0.62 em a glyph).
  const double title_w = 24 + 13 * 0.62 * double(plain_text(c.title).size());
  const double legend_w = margin_left + entry_w * double(per_row);
  sc.width = snap(std::max({margin_left + panels_w + 10, legend_w + 10, title_w}));
  sc.height = snap(top + double(rows) * cell_h + legend + 10);
  sc.text({12, 24}, escape_markup(c.title), 13, HAlign::left, VAlign::baseline, kBlack, 0, true);
  const Stroke grid{{0.88, 0.88, 0.88}, 0.5}, axis{kBlack, 0.7};

  for (std::size_t k = 0; k < c.panels.size(); ++k) {
    const LogLogPanel& p = c.panels[k];
    const double x0 = margin_left + double(k % cols) * cell_w,
                 y0 = top + 16 + double(k / cols) * cell_h;
    const double w = c.panel_width, h = c.panel_height;
    double xmin = INFINITY, xmax = 0, ymin = INFINITY, ymax = 0;
    for (const LineSeries& s : p.series) {
      for (double x : s.x) xmin = std::min(xmin, x), xmax = std::max(xmax, x);
      for (double y : s.y) ymin = std::min(ymin, y), ymax = std::max(ymax, y);
    }
    // Plain variables, not structured bindings: Clang 14 cannot capture those in the lambdas.
    const std::pair<int, int> xd = p.series.empty() ? std::pair{0, 1} : decades(xmin, xmax);
    const std::pair<int, int> yd = p.series.empty() ? std::pair{-1, 0} : decades(ymin, ymax);
    const int xlo = xd.first, xhi = xd.second, ylo = yd.first, yhi = yd.second;
    const bool linear = c.linear_x;
    const double xspan = xmax > 0 ? xmax : 1;
    auto px = [&](double x) {
      return linear ? x0 + w * x / xspan : x0 + w * (std::log10(x) - xlo) / double(xhi - xlo);
    };
    auto py = [&](double y) { return y0 + h - h * (std::log10(y) - ylo) / double(yhi - ylo); };
    sc.text({x0 + w / 2, y0 - 6}, escape_markup(p.title), 8.5, HAlign::centre);
    // Grid lines at the decades, and at 2 and 5 times them when the axis spans one decade.
    if (linear)
      for (int q = 0; q <= 4; ++q) {
        const double x = x0 + w * q / 4.0;
        sc.line({x, y0}, {x, y0 + h}, grid);
        sc.text({x, y0 + h + 11}, fmt::format("{:g}", xspan * q / 4.0), 7.5, HAlign::centre);
      }
    else
      for (int d = xlo; d <= xhi; ++d) {
        const double x = px(std::pow(10.0, d));
        sc.line({x, y0}, {x, y0 + h}, grid);
        sc.text({x, y0 + h + 11}, fmt::format("10^{{{}}}", d), 7.5, HAlign::centre);
      }
    for (int d = ylo; d <= yhi; ++d) {
      const double y = py(std::pow(10.0, d));
      sc.line({x0, y}, {x0 + w, y}, grid);
      sc.text({x0 - 3, y}, fmt::format("10^{{{}}}", d), 7.5, HAlign::right, VAlign::middle);
      if (yhi - ylo == 1 && d < yhi)
        for (double m : {2.0, 5.0}) {
          const double ym = py(m * std::pow(10.0, d));
          sc.line({x0, ym}, {x0 + w, ym}, grid);
          sc.text({x0 - 3, ym}, fmt::format("{:g}", m * std::pow(10.0, d)), 6.5, HAlign::right,
                  VAlign::middle);
        }
    }
    sc.rect(x0, y0, w, h, std::nullopt, axis);
    for (const LineSeries& s : p.series) {
      const Color col = kSeries[std::size_t(std::max(s.colour, 0)) % std::size(kSeries)];
      Stroke line{col, 1.1};
      if (s.dashed) line.dash = {3.5, 2};
      PathItem path;
      for (std::size_t i = 0; i < s.x.size(); ++i) path.points.push_back({px(s.x[i]), py(s.y[i])});
      path.stroke = line;
      sc.add(path);
      for (const Point& q : path.points)
        sc.add(CircleItem{q, 1.6, s.dashed ? std::optional<Color>(kWhite) : col, Stroke{col, 0.8}});
    }
    if (k % cols == 0)
      sc.text({x0 - 38, y0 + h / 2}, escape_markup(c.y_label), 8, HAlign::centre, VAlign::middle,
              kBlack, 90);
    if (k / cols == rows - 1 || k + cols >= c.panels.size())
      sc.text({x0 + w / 2, y0 + h + 24}, escape_markup(c.x_label), 8, HAlign::centre);
  }
  const double ly = top + double(rows) * cell_h + 8;
  for (std::size_t s = 0; s < first.series.size(); ++s) {
    const LineSeries& ser = first.series[s];
    const double x = margin_left + double(s % per_row) * entry_w, y = ly + 16 * double(s / per_row);
    const Color col = kSeries[std::size_t(std::max(ser.colour, 0)) % std::size(kSeries)];
    Stroke line{col, 1.1};
    if (ser.dashed) line.dash = {3.5, 2};
    sc.line({x, y - 3}, {x + 22, y - 3}, line);
    sc.text({x + 28, y}, escape_markup(ser.name), 8.5);
  }
  return sc;
}

}  // namespace halfback::figure
