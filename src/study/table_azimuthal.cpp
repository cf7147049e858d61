// The table of metric 1, the azimuthal dependence (metric_tables.hpp).
#include <cmath>

#include "halfback/study/metric_tables.hpp"
#include "table_columns.hpp"

namespace halfback::study {

MetricTable azimuthal_table() {
  return {"azimuthal",
          {columns::parameterization(), columns::real("error"), columns::integer("dims")},
          {}};
}

void add_azimuthal(MetricTable& table, Space space, double error, int dims) {
  table.add({std::string(name_of(space)), error, std::int64_t(dims)});
}

double azimuthal_error(const BrdfResult& result, Space space, int dims) {
  const MetricTable& t = result.table("azimuthal");
  for (const Row* row : rows_of(t, space))
    if (t.integer(*row, "dims") == dims) return t.real(*row, "error");
  return NAN;
}

}  // namespace halfback::study
