// Grouped horizontal bar charts (the plots of `halfback study`): one group of bars per row label,
// one bar per series, lengths on a shared linear axis from 0.
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

}  // namespace halfback::figure
