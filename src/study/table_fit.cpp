// The table of metric 6, fitting from a gonio-reflectometer's measurements (metric_tables.hpp).
#include "halfback/study/metric_tables.hpp"
#include "table_columns.hpp"

namespace halfback::study {

std::string_view name_of(FitWeights w) {
  return w == FitWeights::uniform ? "uniform" : "solid-angle";
}

std::optional<FitWeights> parse_fit_weights(std::string_view name) {
  for (FitWeights w : kFitWeights)
    if (name_of(w) == name) return w;
  return std::nullopt;
}

MetricTable fit_table() {
  std::vector<std::string> weights;
  for (FitWeights w : kFitWeights) weights.emplace_back(name_of(w));
  return {"fit",
          {columns::parameterization(),
           columns::design(),
           columns::integer("budget"),
           columns::integer("samples"),
           {"weights", ColumnKind::text, weights},
           columns::text("model"),
           columns::text("loss"),
           columns::real("whole_loss"),
           columns::real("layout_loss"),
           columns::real("excess"),
           columns::real("shape_change"),
           columns::text("spec")},
          {}};
}

void add_fit(MetricTable& table, Space space, const FitPoint& p) {
  table.add({std::string(name_of(space)), std::string(name_of(p.design)), std::int64_t(p.budget),
             std::int64_t(p.samples), std::string(name_of(p.weights)), p.model, p.loss,
             p.whole_loss, p.layout_loss, p.layout_loss / p.whole_loss - 1, p.shape_change,
             p.spec});
}

std::vector<FitPoint> fit_points(const BrdfResult& result, Space space) {
  const MetricTable& t = result.table("fit");
  std::vector<FitPoint> points;
  for (const Row* row : rows_of(t, space))
    points.push_back({columns::design_of(t, *row), std::size_t(t.integer(*row, "budget")),
                      std::size_t(t.integer(*row, "samples")),
                      parse_fit_weights(t.text(*row, "weights")).value(), t.text(*row, "model"),
                      t.text(*row, "loss"), t.real(*row, "whole_loss"), t.real(*row, "layout_loss"),
                      t.real(*row, "shape_change"), t.text(*row, "spec")});
  return points;
}

}  // namespace halfback::study
