// The values a laboratory measured at the rows of a plan (`halfback reconstruct`, and `halfback
// plan --pilot` for the sequential design's main stage; docs/acquisition.md).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "halfback/core/rgb.hpp"

namespace halfback::cli {

// A CSV with `row` and `r`, `g`, `b` (or one channel, `value`), a line per measured row in any
// order: the values of the plan's `rows` rows (NaN where a row is missing or not finite: not
// measured), and how many were measured. A row given twice or out of the plan, a negative value
// (−∞ included), or a header without those columns, is a FormatError naming the line. Read a block
// of rows at a time, as every CSV input: memory bounded by the plan's rows, not by the file.
std::vector<Rgb> read_measurements(const std::string& path, std::size_t rows,
                                   std::size_t& measured);

}  // namespace halfback::cli
