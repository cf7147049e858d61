#include "halfback/study/table.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <sstream>
#include <stdexcept>

#include "halfback/util/csv.hpp"

namespace halfback::study {

namespace {

bool holds_kind(const Cell& cell, ColumnKind kind) {
  switch (kind) {
    case ColumnKind::text:
      return std::holds_alternative<std::string>(cell);
    case ColumnKind::integer:
      return std::holds_alternative<std::int64_t>(cell);
    case ColumnKind::real:
      break;
  }
  return std::holds_alternative<double>(cell);
}

std::string cell_text(const Cell& cell, NumberText numbers) {
  if (const auto* s = std::get_if<std::string>(&cell)) return csv_text_field(*s);
  if (const auto* i = std::get_if<std::int64_t>(&cell)) return fmt::format("{}", *i);
  const double v = std::get<double>(cell);
  return numbers == NumberText::exact ? format_csv_number(v) : fmt::format("{:.6g}", v);
}

// The cell of `column` that `field` spells, or what is wrong with it.
std::variant<Cell, std::string> parse_cell(const std::string& field, const Column& column) {
  if (column.kind == ColumnKind::text) {
    if (column.choices.empty() ||
        std::find(column.choices.begin(), column.choices.end(), field) != column.choices.end())
      return Cell{field};
    return fmt::format("unknown {} '{}'", column.name, field);
  }
  if (column.kind == ColumnKind::integer) {
    std::int64_t v = 0;
    const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), v);
    if (ec == std::errc() && end == field.data() + field.size()) return Cell{v};
  } else if (double v = 0; parse_csv_number(field, v, false).empty()) {
    return Cell{v};
  }
  return fmt::format("'{}' is not a number", field);
}

}  // namespace

std::size_t MetricTable::column(std::string_view column_name) const {
  for (std::size_t c = 0; c < columns.size(); ++c)
    if (columns[c].name == column_name) return c;
  throw std::logic_error(fmt::format("table {}: no column '{}'", name, column_name));
}

void MetricTable::add(Row row) {
  bool fits = row.size() == columns.size();
  for (std::size_t c = 0; fits && c < row.size(); ++c) fits = holds_kind(row[c], columns[c].kind);
  if (!fits)
    throw std::logic_error(fmt::format("table {}: a row that does not fit its columns", name));
  rows.push_back(std::move(row));
}

const std::string& MetricTable::text(const Row& row, std::string_view column_name) const {
  return std::get<std::string>(row[column(column_name)]);
}

std::int64_t MetricTable::integer(const Row& row, std::string_view column_name) const {
  return std::get<std::int64_t>(row[column(column_name)]);
}

double MetricTable::real(const Row& row, std::string_view column_name) const {
  return std::get<double>(row[column(column_name)]);
}

std::string csv_header(const MetricTable& table) {
  std::string line = "brdf";
  for (const Column& c : table.columns) (line += ',') += csv_text_field(c.name);
  return line + "\n";
}

std::string csv_rows(const MetricTable& table, std::string_view brdf, NumberText numbers) {
  const std::string label = csv_text_field(brdf);
  std::string text;
  for (const Row& row : table.rows) {
    text += label;
    for (const Cell& cell : row) (text += ',') += cell_text(cell, numbers);
    text += "\n";
  }
  return text;
}

std::string read_csv_rows(MetricTable& table, std::string_view text, const std::string& source) {
  std::istringstream in{std::string(text)};
  std::string line;
  const std::string header = csv_header(table);
  if (!std::getline(in, line) || line + "\n" != header)
    throw std::runtime_error(fmt::format("{}: table {}: the header is not '{}'", source, table.name,
                                         header.substr(0, header.size() - 1)));
  std::string brdf;
  for (std::size_t n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    const std::string where = fmt::format("{}: table {}, line {}", source, table.name, n);
    std::vector<std::string> fields;
    try {
      fields = split_csv_line(line);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(fmt::format("{}: {}", where, e.what()));
    }
    if (fields.size() != table.columns.size() + 1)
      throw std::runtime_error(fmt::format("{}: {} fields, expected {}", where, fields.size(),
                                           table.columns.size() + 1));
    if (table.rows.empty()) brdf = fields[0];
    if (fields[0] != brdf)
      throw std::runtime_error(
          fmt::format("{}: a row of '{}' among those of '{}'", where, fields[0], brdf));
    Row row;
    for (std::size_t c = 0; c < table.columns.size(); ++c) {
      auto cell = parse_cell(fields[c + 1], table.columns[c]);
      if (const auto* problem = std::get_if<std::string>(&cell))
        throw std::runtime_error(fmt::format("{}: {}", where, *problem));
      row.push_back(std::move(std::get<Cell>(cell)));
    }
    table.rows.push_back(std::move(row));
  }
  return brdf;
}

}  // namespace halfback::study
