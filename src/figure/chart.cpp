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
  const double left = l.label_width, top = 48, legend = 18 * double(ns) + 10;
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

}  // namespace halfback::figure
