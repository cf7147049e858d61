// The table of metric 2, the separability (metric_tables.hpp).
#include "halfback/study/metric_tables.hpp"
#include "table_columns.hpp"

namespace halfback::study {

MetricTable separability_table() {
  return {"separability",
          {columns::parameterization(), columns::integer("rank"), columns::real("error"),
           columns::integer("dims")},
          {}};
}

void add_separability(MetricTable& table, Space space, const std::vector<int>& ranks,
                      const std::vector<double>& errors, int dims) {
  for (std::size_t i = 0; i < errors.size() && i < ranks.size(); ++i)
    table.add({std::string(name_of(space)), std::int64_t(ranks[i]), errors[i], std::int64_t(dims)});
}

std::vector<double> separability_errors(const BrdfResult& result, Space space, int dims) {
  const MetricTable& t = result.table("separability");
  std::vector<double> errors;
  for (const Row* row : rows_of(t, space))
    if (t.integer(*row, "dims") == dims) errors.push_back(t.real(*row, "error"));
  return errors;
}

}  // namespace halfback::study
