// A metric's results as a table (docs/study.md, "Output"): a name, typed columns and rows of
// cells. One BRDF's table holds its rows; the study's CSV file NAME.csv is the tables of every BRDF
// one after the other, each row led by the BRDF's label (the "brdf" column, which the files add).
// Generic code (part files, Python's dicts, CSV files, merges) works on any such table; the
// metrics' own files (metric_tables.hpp) say which columns a table has and what its rows mean.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace halfback::study {

enum class ColumnKind { text, integer, real };

struct Column {
  std::string name;
  ColumnKind kind = ColumnKind::real;
  std::vector<std::string> choices;  // a text column's only values (a design's name); empty: any
  friend bool operator==(const Column&, const Column&) = default;
};

// A cell holds the alternative of its column's kind: std::string, std::int64_t or double.
using Cell = std::variant<std::string, std::int64_t, double>;
using Row = std::vector<Cell>;

struct MetricTable {
  std::string name;             // the CSV file NAME.csv, the part file's section [NAME]
  std::vector<Column> columns;  // after "brdf"
  std::vector<Row> rows;

  // The index of a column; std::logic_error when the table has none of that name (a bug).
  std::size_t column(std::string_view column_name) const;
  // Appends a row; std::logic_error when its cells do not match the columns' number and kinds.
  void add(Row row);
  // Typed cells (the column's kind must be the one asked for).
  const std::string& text(const Row& row, std::string_view column_name) const;
  std::int64_t integer(const Row& row, std::string_view column_name) const;
  double real(const Row& row, std::string_view column_name) const;
};

// How the real cells of a table's text are written: `exact` in shortest round-trip form (part
// files and Python's tables, which are read back), `rounded` to 6 significant digits (the CSV
// files people read). Integers are written as integers, text as a CSV field (quoted if needed).
enum class NumberText { exact, rounded };

// "brdf,COLUMN,...\n".
std::string csv_header(const MetricTable& table);
// The rows as CSV lines, each led by the BRDF's label.
std::string csv_rows(const MetricTable& table, std::string_view brdf, NumberText numbers);

// Reads the text csv_header() + csv_rows() wrote into `table`, whose name and columns say what to
// expect; returns the label of the BRDF its rows are led by ("" without rows). Throws
// std::runtime_error naming `source`, the table and the line on another header, a row of another
// length or another BRDF, or a cell that is not of its column's kind or not one of its choices.
std::string read_csv_rows(MetricTable& table, std::string_view text, const std::string& source);

}  // namespace halfback::study
