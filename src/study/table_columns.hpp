// Columns that several of the study's tables share (metric_tables.hpp), and reading a name back
// from a cell whose column's choices already held it to those names.
#pragma once

#include <string>
#include <vector>

#include "halfback/acquire/design.hpp"
#include "halfback/acquire/gonio.hpp"
#include "halfback/study/table.hpp"

namespace halfback::study::columns {

inline Column parameterization() {
  return {"parameterization", ColumnKind::text, {}};  // the study's own list (from_tables checks)
}

inline Column design() {
  std::vector<std::string> names;
  for (acquire::Design d : acquire::kAllDesigns) names.emplace_back(name_of(d));
  return {"design", ColumnKind::text, names};
}

inline Column spacing() {
  std::vector<std::string> names;
  for (acquire::Spacing s : acquire::kSpacings) names.emplace_back(name_of(s));
  return {"spacing", ColumnKind::text, names};
}

inline Column integer(std::string name) {
  return {std::move(name), ColumnKind::integer, {}};
}

inline Column real(std::string name) {
  return {std::move(name), ColumnKind::real, {}};
}

inline Column text(std::string name) {
  return {std::move(name), ColumnKind::text, {}};
}

inline acquire::Design design_of(const MetricTable& t, const Row& row) {
  return acquire::parse_design(t.text(row, "design")).value();
}

inline acquire::Spacing spacing_of(const MetricTable& t, const Row& row) {
  return acquire::parse_spacing(t.text(row, "spacing")).value();
}

}  // namespace halfback::study::columns
