// The tables of metric 3, the virtual gonio-reflectometer, and the budget table derived from it
// (metric_tables.hpp).
#include <fmt/format.h>

#include <cmath>

#include "halfback/study/metric_tables.hpp"
#include "table_columns.hpp"

namespace halfback::study {

using acquire::Design;
using acquire::kAllDesigns;
using acquire::kSpacings;
using acquire::samples_to_reach;
using acquire::Spacing;

MetricTable gonio_table() {
  return {"gonio",
          {columns::parameterization(), columns::design(), columns::integer("samples"),
           columns::real("error"), columns::integer("dims"), columns::integer("budget"),
           columns::spacing()},
          {}};
}

void add_gonio(MetricTable& table, Space space, const GonioPoint& p, int dims) {
  table.add({std::string(name_of(space)), std::string(name_of(p.design)), std::int64_t(p.samples),
             p.error, std::int64_t(dims), std::int64_t(p.budget), std::string(name_of(p.spacing))});
}

std::vector<GonioPoint> gonio_points(const BrdfResult& result, Space space, int dims) {
  const MetricTable& t = result.table("gonio");
  std::vector<GonioPoint> points;
  for (const Row* row : rows_of(t, space))
    if (t.integer(*row, "dims") == dims)
      points.push_back({columns::design_of(t, *row), std::size_t(t.integer(*row, "budget")),
                        std::size_t(t.integer(*row, "samples")), t.real(*row, "error"),
                        columns::spacing_of(t, *row)});
  return points;
}

GonioCurve gonio_curve(const std::vector<GonioPoint>& points, Design layout, Spacing spacing) {
  GonioCurve c;
  for (const GonioPoint& p : points)
    if (p.spacing == spacing && p.design == layout) {
      c.samples.push_back(double(p.samples));
      c.errors.push_back(p.error);
    }
  return c;
}

MetricTable budget_table() {
  return {"budget",
          {columns::parameterization(), columns::design(), columns::integer("dims"),
           columns::real("target_error"), columns::text("samples"), columns::text("note"),
           columns::spacing()},
          {}};
}

namespace {

// The rows of one parameterization's points of one form: per design, each target error.
void add_budget_rows(MetricTable& into, Space space, const std::vector<GonioPoint>& points,
                     int dims) {
  for (Spacing spacing : kSpacings)
    for (Design d : kAllDesigns) {
      const GonioCurve c = gonio_curve(points, d, spacing);
      if (c.samples.empty()) continue;
      for (double target : kTargetErrors) {
        const double s = samples_to_reach(c.samples, c.errors, target);
        const bool reached = s != 0 && !std::isinf(s);
        into.add({std::string(name_of(space)), std::string(name_of(d)), std::int64_t(dims), target,
                  reached ? fmt::format("{:.0f}", s) : std::string(),
                  std::string(s == 0    ? "below_range"
                              : reached ? "reached"
                                        : "not_reached"),
                  std::string(name_of(spacing))});
      }
    }
}

}  // namespace

void derive_budget(const BrdfResult& result, MetricTable& into) {
  for (Space space : result.params)
    for (int dims : {3, 4}) add_budget_rows(into, space, gonio_points(result, space, dims), dims);
}

}  // namespace halfback::study
