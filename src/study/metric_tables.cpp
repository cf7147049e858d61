#include "halfback/study/metric_tables.hpp"

namespace halfback::study {

std::span<const TableDef> study_tables() {
  static const TableDef kTables[] = {
      {azimuthal_table}, {separability_table}, {gonio_table}, {budget_table, derive_budget},
      {image_table},     {sampling_table},     {fit_table},
  };
  return kTables;
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
