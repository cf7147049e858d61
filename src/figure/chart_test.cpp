// Bar charts and log-log plots: marks are the values on the drawn axes; bad input is refused.
#include "halfback/figure/chart.hpp"

#include <gtest/gtest.h>

#include "halfback/figure/plot.hpp"
#include "halfback/figure/render.hpp"

namespace halfback::figure {
namespace {

TEST(BarChart, BarLengthsAreTheValuesOnTheAxis) {
  BarChart c;
  c.title = "t_1";
  c.x_label = "error";
  c.rows = {"a", "b"};
  c.series = {"x", "y", "z"};
  c.values = {{0.1, 0.35, 0.0}, {0.2, 0.05, 0.3}};
  const BarChartLayout l;
  const Scene sc = bar_chart(c, l);
  // The axis ends at 0.5 (the next 1-2-5 step above 0.35): a bar of value v is v/0.5 of the plot.
  std::vector<double> widths;
  for (const Item& item : sc.items)
    if (const auto* p = std::get_if<PathItem>(&item))
      if (p->fill && p->points.size() == 4 && p->points[0].x == l.label_width &&
          p->points[2].y - p->points[0].y == l.bar_height)
        widths.push_back(p->points[1].x - p->points[0].x);
  ASSERT_EQ(widths.size(), 6u);
  const double expected[] = {0.1, 0.35, 0.0, 0.2, 0.05, 0.3};
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(widths[k], l.plot_width * expected[k] / 0.5, 1e-9) << k;
  bool title = false;
  for (const Item& item : sc.items)
    if (const auto* t = std::get_if<TextItem>(&item)) title |= plain_text(t->text) == "t_1";
  EXPECT_TRUE(title);
  EXPECT_FALSE(render(sc, Format::svg).empty());
}

// A row label longer than the layout's label width widens the margin: every right-aligned label
// starts inside the page by the layout's width estimate (a study's "dupuy-jakob:per-material"
// lost its first letter), and the bars start where the margin ends.
TEST(BarChart, LongRowLabelsFitTheMargin) {
  BarChart c;
  c.title = "t";
  c.x_label = "error";
  c.rows = {"halfdiff", "dupuy-jakob:per-material, a long row label"};
  c.series = {"x"};
  c.values = {{0.1}, {0.2}};
  BarChartLayout l;
  l.label_width = 110;
  const Scene sc = bar_chart(c, l);
  double bars_start = -1;
  for (const Item& item : sc.items) {
    if (const auto* t = std::get_if<TextItem>(&item); t && t->halign == HAlign::right) {
      EXPECT_GE(t->at.x - approx_text_width(t->text, t->size), 0.0) << t->text;
    }
    if (const auto* p = std::get_if<PathItem>(&item);
        p && p->fill && p->points.size() == 4 && p->points[2].y - p->points[0].y == l.bar_height)
      bars_start = p->points[0].x;
  }
  EXPECT_GT(bars_start, l.label_width);
}

TEST(BarChart, BadInput) {
  BarChart c;
  EXPECT_THROW(bar_chart(c), std::invalid_argument);
  c.rows = {"a"};
  c.series = {"x"};
  c.values = {{-1}};
  EXPECT_THROW(bar_chart(c), std::invalid_argument);
  c.values = {{NAN}};
  EXPECT_THROW(bar_chart(c), std::invalid_argument);
  c.values = {{1, 2}};
  EXPECT_THROW(bar_chart(c), std::invalid_argument);
}

TEST(LogLogChart, PointsArePlacedOnTheDecadeAxes) {
  LogLogChart c;
  c.title = "errors";
  c.panels.push_back({"p_1",
                      {{"hybrid", 0, false, {1e3, 1e4}, {0.1, 0.01}},
                       {"ortho", 1, true, {1e3, 1e5}, {0.05, 0.02}}}});
  c.panels.push_back({"p2", {{"hybrid", 0, false, {1e3, 1e5}, {0.3, 0.2}}}});
  const Scene sc = loglog_chart(c);
  // The first series of the first panel spans the panel's x decades [3, 5] (the second series
  // reaches 10^5) and its y decades [-2, -1] corner to corner.
  std::vector<const PathItem*> lines;
  for (const Item& item : sc.items)
    if (const auto* p = std::get_if<PathItem>(&item))
      if (p->stroke && !p->fill && !p->closed && p->points.size() >= 2 && p->stroke->width == 1.1)
        lines.push_back(p);
  ASSERT_GE(lines.size(), 3u);
  const PathItem& h = *lines[0];
  EXPECT_NEAR(h.points[1].x - h.points[0].x, c.panel_width / 2, 1e-9);
  EXPECT_NEAR(h.points[1].y - h.points[0].y, c.panel_height, 1e-9);
  EXPECT_TRUE(lines[1]->stroke->dash.size() == 2);
  bool title = false;
  for (const Item& item : sc.items)
    if (const auto* t = std::get_if<TextItem>(&item)) title |= plain_text(t->text) == "p_1";
  EXPECT_TRUE(title);
  EXPECT_FALSE(render(sc, Format::svg).empty());
}

TEST(LogLogChart, BadInput) {
  LogLogChart c;
  EXPECT_THROW(loglog_chart(c), std::invalid_argument);
  c.panels.push_back({"p", {{"s", 0, false, {1, 2}, {1}}}});
  EXPECT_THROW(loglog_chart(c), std::invalid_argument);
  c.panels[0].series[0].y = {1, 0};
  EXPECT_THROW(loglog_chart(c), std::invalid_argument);
  c.panels[0].series[0].y = {1, NAN};
  EXPECT_THROW(loglog_chart(c), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::figure
