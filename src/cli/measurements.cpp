#include "measurements.hpp"

#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <optional>
#include <string_view>

#include "command.hpp"
#include "halfback/util/format_error.hpp"

namespace halfback::cli {

std::vector<Rgb> read_measurements(const std::string& path, std::size_t rows,
                                   std::size_t& measured) {
  const std::unique_ptr<CsvStreamReader> in = open_csv_input(path);
  const auto column = [&](std::string_view name) -> std::optional<std::size_t> {
    for (std::size_t c = 0; c < in->header().size(); ++c)
      if (in->header()[c] == name) return c;
    return std::nullopt;
  };
  const auto row = column("row"), r = column("r"), g = column("g"), b = column("b"),
             v = column("value");
  if (!row || !((r && g && b) || v))
    throw FormatError(path, "header", "expected the columns row and r, g, b (or row and value)");
  std::vector<Rgb> values(rows, Rgb{NAN, NAN, NAN});
  std::vector<std::uint8_t> seen(rows, 0);
  measured = 0;
  CsvTable t;
  while (in->read_block(t, kBlockRows, {.allow_non_finite = true})) {
    for (std::size_t k = 0; k < t.rows(); ++k) {
      const double x = t.columns[*row][k];
      if (!(x >= 0 && x < double(rows) && x == std::floor(x)))
        throw FormatError(path, fmt::format("line {}", t.lines[k]),
                          fmt::format("row {} is not a row of the plan (0 … {})", x, rows - 1));
      const auto i = std::size_t(x);
      if (seen[i]++)
        throw FormatError(path, fmt::format("line {}", t.lines[k]),
                          fmt::format("row {} is given twice", i));
      const Rgb c = v ? Rgb{t.columns[*v][k], t.columns[*v][k], t.columns[*v][k]}
                      : Rgb{t.columns[*r][k], t.columns[*g][k], t.columns[*b][k]};
      if (c.r < 0 || c.g < 0 || c.b < 0)  // NaN (not measured) passes
        throw FormatError(path, fmt::format("line {}", t.lines[k]),
                          fmt::format("row {}: the value is negative ({:g}, {:g}, {:g}): a "
                                      "reflectance is not (clamp noise below 0 to 0, or leave "
                                      "the row out)",
                                      i, c.r, c.g, c.b));
      if (std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b)) {
        values[i] = c;
        ++measured;
      }
    }
  }
  return values;
}

}  // namespace halfback::cli
