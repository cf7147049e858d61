// Bar charts: bar lengths are the values on the drawn axis; bad input is refused.
#include "halfback/figure/chart.hpp"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace halfback::figure
