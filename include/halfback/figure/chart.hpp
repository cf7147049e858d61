// The plots of `halfback study`: grouped horizontal bar charts (one group of bars per row label,
// one bar per series, lengths on a shared linear axis from 0), and small multiples of log-log
// line plots (error against sample budget, one panel per BRDF).
#pragma once

#include <string>
#include <vector>

#include "halfback/figure/scene.hpp"

namespace halfback::figure {

struct BarChart {
  std::string title, x_label;
  std::vector<std::string> rows;    // group labels, top to bottom (plain text, drawn as written)
  std::vector<std::string> series;  // legend entries, one colour each
  std::vector<std::vector<double>> values;  // rows × series, finite and >= 0
};

struct BarChartLayout {
  double bar_height = 5, group_gap = 6, plot_width = 360, label_width = 250;
};

// Throws std::invalid_argument for mismatched sizes, no rows or series, or a negative or
// non-finite value.
Scene bar_chart(const BarChart& chart, const BarChartLayout& layout = {});

// Log-log line plots. Series of the same `colour` index share a colour; `dashed` draws the line
// dashed (e.g. one design against another). Every x and y must be finite and > 0.
struct LineSeries {
  std::string name;  // legend entry (plain text); the legend lists the series of the first panel
  int colour = 0;
  bool dashed = false;
  std::vector<double> x, y;
};
struct LogLogPanel {
  std::string title;  // plain text
  std::vector<LineSeries> series;
};
struct LogLogChart {
  std::string title, x_label, y_label;
  std::vector<LogLogPanel> panels;  // laid out row by row, `columns` per row
  int columns = 4;
  double panel_width = 170, panel_height = 120;
  // x on a linear axis from 0 to the panel's largest x instead (e.g. the fraction of BRDFs of a
  // sorted curve); y stays logarithmic.
  bool linear_x = false;
};

// Each panel's axes span the decades around its own values (x: from 0 with linear_x). Throws
// std::invalid_argument for no panels, a series with mismatched or no points, or a value that is
// not finite and > 0.
Scene loglog_chart(const LogLogChart& chart);

}  // namespace halfback::figure
