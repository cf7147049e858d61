#include "halfback/util/csv.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <locale.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <iterator>
#include <limits>
#include <system_error>
#include <unordered_set>

namespace halfback {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

bool is_blank_line(std::string_view s) {
  return trim(s).empty();
}

// The offending text for a message: at most 40 characters, control bytes escaped.
std::string shown(std::string_view text) {
  constexpr std::size_t kMax = 40;
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < kMax; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7f)
      out += fmt::format("\\x{:02x}", c);
    else
      out += static_cast<char>(c);
  }
  if (text.size() > kMax) out += "...";
  return out;
}

std::string join(std::span<const std::string_view> names) {
  std::string s;
  for (auto n : names) {
    if (!s.empty()) s += ',';
    s += n;
  }
  return s;
}

std::string join(std::span<const std::string> names) {
  std::string s;
  for (const auto& n : names) {
    if (!s.empty()) s += ',';
    s += n;
  }
  return s;
}

// Walks the lines of a text: LF or CRLF ends, the last line possibly without one.
struct LineCursor {
  std::string_view text;
  std::size_t pos = 0;
  std::size_t line = 0;  // number of the line last returned

  bool next(std::string_view& out) {
    if (pos >= text.size()) return false;
    std::size_t end = text.find('\n', pos);
    const std::size_t stop = end == std::string_view::npos ? text.size() : end;
    out = text.substr(pos, stop - pos);
    if (!out.empty() && out.back() == '\r') out.remove_suffix(1);
    pos = end == std::string_view::npos ? text.size() : end + 1;
    ++line;
    return true;
  }
};

// Splits a line into fields. Returns a problem, or an empty string. Unescaped quoted fields live
// in `scratch` (a deque: growing it does not move the strings the views point into).
std::string split_fields(std::string_view line, std::vector<std::string_view>& fields,
                         std::deque<std::string>& scratch) {
  fields.clear();
  scratch.clear();
  const std::size_t n = line.size();
  std::size_t i = 0;
  while (true) {
    while (i < n && is_blank(line[i])) ++i;
    if (i < n && line[i] == '"') {
      const std::size_t start = ++i;
      bool doubled = false;
      while (true) {
        if (i >= n) return "unterminated quoted field";
        if (line[i] == '"') {
          if (i + 1 < n && line[i + 1] == '"') {
            doubled = true;
            i += 2;
            continue;
          }
          break;
        }
        ++i;
      }
      const std::string_view raw = line.substr(start, i - start);
      ++i;  // the closing quote
      while (i < n && is_blank(line[i])) ++i;
      if (i < n && line[i] != ',') return "unexpected text after a closing quote";
      if (doubled) {
        std::string& s = scratch.emplace_back();
        for (std::size_t k = 0; k < raw.size(); ++k) {
          s += raw[k];
          if (raw[k] == '"') ++k;  // "" -> "
        }
        fields.push_back(s);
      } else {
        fields.push_back(raw);
      }
    } else {
      std::size_t comma = line.find(',', i);
      if (comma == std::string_view::npos) comma = n;
      fields.push_back(trim(line.substr(i, comma - i)));
      i = comma;
    }
    if (i >= n) break;
    ++i;  // the comma
  }
  return {};
}

// ±0 when a number that from_chars found out of range is too small for a double, NaN when it is
// too large. strtod_l in the "C" locale tells which.
double underflow_value(std::string_view number) {
  static const locale_t c_locale = newlocale(LC_ALL_MASK, "C", locale_t{});
  const std::string copy(number);
  const double v = c_locale ? strtod_l(copy.c_str(), nullptr, c_locale) : HUGE_VAL;
  if (std::abs(v) < 1.0) return std::signbit(v) ? -0.0 : 0.0;
  return kNaN;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

CsvError::CsvError(std::string source, std::size_t line, std::string column, std::string problem)
    : std::runtime_error(location(source, line, column) + problem),
      source_(std::move(source)),
      line_(line),
      column_(std::move(column)),
      problem_(std::move(problem)) {}

std::string CsvError::location(std::string_view source, std::size_t line, std::string_view column) {
  std::string s(source);
  if (line > 0) s += fmt::format(":{}", line);
  s += ": ";
  if (!column.empty()) s += fmt::format("column {}: ", column);
  return s;
}

std::vector<std::string> split_csv_line(std::string_view line) {
  std::vector<std::string_view> fields;
  std::deque<std::string> scratch;
  if (std::string problem = split_fields(line, fields, scratch); !problem.empty())
    throw std::invalid_argument(problem);
  return {fields.begin(), fields.end()};
}

std::string parse_csv_number(std::string_view field, double& value, bool allow_non_finite) {
  field = trim(field);
  if (field.empty()) return "empty field";
  std::string_view s = field;
  if (s.front() == '+') {
    s.remove_prefix(1);
    if (s.empty() || s.front() == '+' || s.front() == '-')
      return fmt::format("'{}' is not a number", shown(field));
  }
  double v = 0;
  const char* end = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(s.data(), end, v);
  if (ec == std::errc::invalid_argument || ptr != end)
    return fmt::format("'{}' is not a number", shown(field));
  if (ec == std::errc::result_out_of_range) {
    v = underflow_value(s);
    if (std::isnan(v)) return fmt::format("'{}' is out of the range of a double", shown(field));
  }
  if (!allow_non_finite && !std::isfinite(v))
    return fmt::format("'{}' is not a finite number", shown(field));
  value = v;
  return {};
}

std::string format_csv_number(double value) {
  if (std::isnan(value)) return "nan";
  return fmt::format("{:.17g}", value);
}

// ---------------------------------------------------------------------------------------------

CsvReader::CsvReader(std::string_view text, std::string source)
    : text_(text), source_(std::move(source)) {
  if (text_.substr(0, 3) == "\xEF\xBB\xBF") text_.remove_prefix(3);  // UTF-8 byte-order mark
  if (text_.find_first_not_of(" \t\r\n\v\f") == std::string_view::npos)
    throw CsvError(source_, 0, "", "the input is empty (expected a header row)");
  LineCursor cursor{text_};
  std::string_view line;
  cursor.next(line);
  header_line_ = cursor.line;
  if (is_blank_line(line))
    throw CsvError(source_, header_line_, "", "the header row is empty (expected column names)");
  std::vector<std::string_view> fields;
  std::deque<std::string> scratch;
  if (std::string problem = split_fields(line, fields, scratch); !problem.empty())
    throw CsvError(source_, header_line_, "", "header: " + problem);
  header_.assign(fields.begin(), fields.end());
  pos_ = cursor.pos;
}

void CsvReader::check_names() const {
  std::unordered_set<std::string_view> seen;
  for (std::size_t i = 0; i < header_.size(); ++i) {
    if (header_[i].empty())
      throw CsvError(source_, header_line_, "",
                     fmt::format("header: the name of column {} is empty", i + 1));
    if (!seen.insert(header_[i]).second)
      throw CsvError(source_, header_line_, "",
                     fmt::format("header: duplicate column name '{}'", shown(header_[i])));
  }
}

void CsvReader::require_header(std::span<const std::string_view> expected,
                               std::string_view note) const {
  bool same = expected.size() == header_.size();
  for (std::size_t i = 0; same && i < expected.size(); ++i) same = expected[i] == header_[i];
  if (same) return;
  std::string problem = fmt::format("header does not match: expected '{}', found '{}'",
                                    join(expected), shown(join(header_)));
  if (!note.empty()) problem += fmt::format("; {}", note);
  throw CsvError(source_, header_line_, "", std::move(problem));
}

CsvTable CsvReader::read_rows(const CsvReadOptions& options) {
  check_names();
  const std::size_t ncols = header_.size();
  CsvTable table;
  table.header = header_;
  table.columns.assign(ncols, {});

  auto bad_row = [&](std::size_t line, std::string column, std::string problem) {
    if (!options.keep_bad_rows) throw CsvError(source_, line, std::move(column), problem);
    CsvRowProblem p;
    p.row = table.rows();
    p.line = line;
    p.message = CsvError::location(source_, line, column) + problem;
    p.column = std::move(column);
    p.problem = std::move(problem);
    table.problems.push_back(std::move(p));
  };
  auto push_nan_row = [&](std::size_t line) {
    for (auto& c : table.columns) c.push_back(kNaN);
    table.lines.push_back(line);
  };

  LineCursor cursor{text_, pos_, header_line_};
  std::string_view line;
  std::vector<std::string_view> fields;
  std::deque<std::string> scratch;
  std::vector<double> values(ncols);
  std::size_t first_blank = 0, blanks = 0;  // blank lines not yet known to be inside the data
  while (cursor.next(line)) {
    if (is_blank_line(line)) {
      if (blanks++ == 0) first_blank = cursor.line;
      continue;
    }
    for (std::size_t b = 0; b < blanks; ++b) {
      bad_row(first_blank + b, "",
              "empty line inside the data (blank lines are allowed only at the end)");
      push_nan_row(first_blank + b);
    }
    blanks = 0;

    if (std::string problem = split_fields(line, fields, scratch); !problem.empty()) {
      bad_row(cursor.line, "", std::move(problem));
      push_nan_row(cursor.line);
      continue;
    }
    if (fields.size() != ncols) {
      std::string problem = fmt::format("expected {} fields ({}), found {}", ncols,
                                        join(std::span<const std::string>(header_)), fields.size());
      if (fields.size() == ncols + 1 && fields.back().empty()) problem += " (a trailing comma?)";
      bad_row(cursor.line, "", std::move(problem));
      push_nan_row(cursor.line);
      continue;
    }
    bool row_ok = true;
    for (std::size_t c = 0; c < ncols; ++c) {
      std::string problem = parse_csv_number(fields[c], values[c], options.allow_non_finite);
      if (!problem.empty()) {
        values[c] = kNaN;
        if (row_ok) bad_row(cursor.line, header_[c], std::move(problem));
        row_ok = false;
      }
    }
    for (std::size_t c = 0; c < ncols; ++c) table.columns[c].push_back(values[c]);
    table.lines.push_back(cursor.line);
  }
  return table;
}

CsvTable read_csv(std::string_view text, std::string source,
                  std::span<const std::string_view> expected_header,
                  const CsvReadOptions& options) {
  CsvReader reader(text, std::move(source));
  if (!expected_header.empty()) reader.require_header(expected_header);
  return reader.read_rows(options);
}

std::string read_text_file(const std::filesystem::path& path) {
  auto fail = [&](int err) -> std::system_error {
    return std::system_error(err, std::generic_category(), "cannot read '" + path.string() + "'");
  };
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw fail(errno);
  std::string text;
  char buf[1 << 16];
  while (true) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      throw fail(err);
    }
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return text;
}

// ---------------------------------------------------------------------------------------------

namespace {

void append_name(fmt::memory_buffer& buf, std::string_view name) {
  const bool quote = name.find_first_of(",\"\n\r") != std::string_view::npos ||
                     (!name.empty() && (is_blank(name.front()) || is_blank(name.back())));
  if (!quote) {
    buf.append(name);
    return;
  }
  buf.push_back('"');
  for (char c : name) {
    if (c == '"') buf.push_back('"');
    buf.push_back(c);
  }
  buf.push_back('"');
}

}  // namespace

std::string csv_text_field(std::string_view text) {
  fmt::memory_buffer buf;
  append_name(buf, text);
  return fmt::to_string(buf);
}

void write_csv(std::span<const std::string> header,
               std::span<const std::span<const double>> columns, const CsvSink& sink,
               std::size_t chunk_bytes) {
  if (header.size() != columns.size())
    throw std::invalid_argument("write_csv: the header and the columns differ in number");
  const std::size_t rows = columns.empty() ? 0 : columns.front().size();
  for (const auto& c : columns)
    if (c.size() != rows) throw std::invalid_argument("write_csv: columns of different lengths");

  fmt::memory_buffer buf;
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (c > 0) buf.push_back(',');
    append_name(buf, header[c]);
  }
  buf.push_back('\n');
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (c > 0) buf.push_back(',');
      const double v = columns[c][r];
      if (std::isnan(v))
        buf.append(std::string_view("nan"));
      else
        fmt::format_to(std::back_inserter(buf), "{:.17g}", v);
    }
    buf.push_back('\n');
    if (buf.size() >= chunk_bytes) {
      sink(std::string_view(buf.data(), buf.size()));
      buf.clear();
    }
  }
  if (buf.size() > 0) sink(std::string_view(buf.data(), buf.size()));
}

std::string to_csv(std::span<const std::string> header,
                   std::span<const std::span<const double>> columns) {
  std::string out;
  write_csv(header, columns, [&](std::string_view s) { out += s; });
  return out;
}

}  // namespace halfback
