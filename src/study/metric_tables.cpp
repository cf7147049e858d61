#include "halfback/study/metric_tables.hpp"

#include "halfback/study/metric.hpp"

namespace halfback::study {

std::vector<TableDef> study_tables() {
  std::vector<TableDef> tables;
  for (const Metric* m : study_metrics())
    for (const TableDef& def : m->tables()) tables.push_back(def);
  return tables;
}

std::vector<MetricTable> stored_tables() {
  std::vector<MetricTable> tables;
  for (const TableDef& def : study_tables())
    if (!def.derive) tables.push_back(def.columns());
  return tables;
}

std::vector<const Row*> rows_of(const MetricTable& table, Space space) {
  std::vector<const Row*> rows;
  for (const Row& row : table.rows)
    if (table.text(row, "parameterization") == name_of(space)) rows.push_back(&row);
  return rows;
}

}  // namespace halfback::study
