#include "halfback/util/csv.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <locale.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <deque>
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

namespace {

// %.17g exactly as printf writes it (std::to_chars with a precision is specified so; tested
// against fmt's "{:.17g}" on 8 million values): twice as fast as fmt, and it keeps fmt's float
// formatting engine out of this file (docs/performance.md, "Building").
std::string_view format_17g(double value, std::array<char, 32>& digits) {
  const auto end = std::to_chars(digits.data(), digits.data() + digits.size(), value,
                                 std::chars_format::general, 17)
                       .ptr;
  return {digits.data(), std::size_t(end - digits.data())};
}

}  // namespace

std::string format_csv_number(double value) {
  if (std::isnan(value)) return "nan";
  std::array<char, 32> digits;
  return std::string(format_17g(value, digits));
}

// ---------------------------------------------------------------------------------------------

namespace {

void check_names(const std::vector<std::string>& header, const std::string& source,
                 std::size_t header_line) {
  std::unordered_set<std::string_view> seen;
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i].empty())
      throw CsvError(source, header_line, "",
                     fmt::format("header: the name of column {} is empty", i + 1));
    if (!seen.insert(header[i]).second)
      throw CsvError(source, header_line, "",
                     fmt::format("header: duplicate column name '{}'", shown(header[i])));
  }
}

void require_names(const std::vector<std::string>& header, const std::string& source,
                   std::size_t header_line, std::span<const std::string_view> expected,
                   std::string_view note) {
  bool same = expected.size() == header.size();
  for (std::size_t i = 0; same && i < expected.size(); ++i) same = expected[i] == header[i];
  if (same) return;
  std::string problem = fmt::format("header does not match: expected '{}', found '{}'",
                                    join(expected), shown(join(header)));
  if (!note.empty()) problem += fmt::format("; {}", note);
  throw CsvError(source, header_line, "", std::move(problem));
}

// The header line split into names; throws CsvError for a blank or malformed one.
std::vector<std::string> parse_header(std::string_view line, const std::string& source,
                                      std::size_t header_line) {
  if (is_blank_line(line))
    throw CsvError(source, header_line, "", "the header row is empty (expected column names)");
  std::vector<std::string_view> fields;
  std::deque<std::string> scratch;
  if (std::string problem = split_fields(line, fields, scratch); !problem.empty())
    throw CsvError(source, header_line, "", "header: " + problem);
  return {fields.begin(), fields.end()};
}

}  // namespace

// The data lines after the header, one at a time, into rows of a table. Blank lines are held
// until a data line shows that they are inside the data (then each is a bad row); blank lines at
// the end are allowed. emit() adds one row at a time, so a reader can stop at any row count.
class CsvRowParser {
 public:
  CsvRowParser(const std::vector<std::string>& header, const std::string& source,
               const CsvReadOptions& options)
      : header_(header), source_(source), options_(options), values_(header.size()) {}

  void take(std::string_view line, std::size_t line_no) {
    if (is_blank_line(line)) {
      if (blanks_++ == 0) first_blank_ = line_no;
      return;
    }
    inside_blanks_ = blanks_;
    inside_first_ = first_blank_;
    blanks_ = 0;
    held_.assign(line);
    held_line_ = line_no;
    holding_ = true;
  }

  bool pending() const { return inside_blanks_ > 0 || holding_; }

  // Adds the next pending row to `table`: a blank line inside the data, or the held line.
  void emit(CsvTable& table) {
    if (inside_blanks_ > 0) {
      const std::size_t line = inside_first_++;
      --inside_blanks_;
      bad_row(table, line, "",
              "empty line inside the data (blank lines are allowed only at the end)");
      push_nan_row(table, line);
      return;
    }
    holding_ = false;
    row(table, held_, held_line_);
  }

 private:
  void bad_row(CsvTable& table, std::size_t line, std::string column, std::string problem) {
    if (!options_.keep_bad_rows) throw CsvError(source_, line, std::move(column), problem);
    CsvRowProblem p;
    p.row = table.rows();
    p.line = line;
    p.message = CsvError::location(source_, line, column) + problem;
    p.column = std::move(column);
    p.problem = std::move(problem);
    table.problems.push_back(std::move(p));
  }
  static void push_nan_row(CsvTable& table, std::size_t line) {
    for (auto& c : table.columns) c.push_back(kNaN);
    table.lines.push_back(line);
  }

  void row(CsvTable& table, std::string_view line, std::size_t line_no) {
    const std::size_t ncols = header_.size();
    if (std::string problem = split_fields(line, fields_, scratch_); !problem.empty()) {
      bad_row(table, line_no, "", std::move(problem));
      push_nan_row(table, line_no);
      return;
    }
    if (fields_.size() != ncols) {
      std::string problem =
          fmt::format("expected {} fields ({}), found {}", ncols,
                      join(std::span<const std::string>(header_)), fields_.size());
      if (fields_.size() == ncols + 1 && fields_.back().empty()) problem += " (a trailing comma?)";
      bad_row(table, line_no, "", std::move(problem));
      push_nan_row(table, line_no);
      return;
    }
    bool row_ok = true;
    for (std::size_t c = 0; c < ncols; ++c) {
      std::string problem = parse_csv_number(fields_[c], values_[c], options_.allow_non_finite);
      if (!problem.empty()) {
        values_[c] = kNaN;
        if (row_ok) bad_row(table, line_no, header_[c], std::move(problem));
        row_ok = false;
      }
    }
    for (std::size_t c = 0; c < ncols; ++c) table.columns[c].push_back(values_[c]);
    table.lines.push_back(line_no);
  }

  const std::vector<std::string>& header_;
  const std::string& source_;
  CsvReadOptions options_;
  std::vector<std::string_view> fields_;
  std::deque<std::string> scratch_;
  std::vector<double> values_;
  std::size_t blanks_ = 0, first_blank_ = 0;  // blank lines not yet known to be inside the data
  std::size_t inside_blanks_ = 0, inside_first_ = 0;  // blank lines inside the data, to emit
  std::string held_;                                  // the data line after them
  std::size_t held_line_ = 0;
  bool holding_ = false;
};

CsvReader::CsvReader(std::string_view text, std::string source)
    : text_(text), source_(std::move(source)) {
  if (text_.substr(0, 3) == "\xEF\xBB\xBF") text_.remove_prefix(3);  // UTF-8 byte-order mark
  if (text_.find_first_not_of(" \t\r\n\v\f") == std::string_view::npos)
    throw CsvError(source_, 0, "", "the input is empty (expected a header row)");
  LineCursor cursor{text_};
  std::string_view line;
  cursor.next(line);
  header_line_ = cursor.line;
  header_ = parse_header(line, source_, header_line_);
  pos_ = cursor.pos;
}

void CsvReader::check_names() const {
  halfback::check_names(header_, source_, header_line_);
}

void CsvReader::require_header(std::span<const std::string_view> expected,
                               std::string_view note) const {
  require_names(header_, source_, header_line_, expected, note);
}

CsvTable CsvReader::read_rows(const CsvReadOptions& options) {
  check_names();
  CsvTable table;
  table.header = header_;
  table.columns.assign(header_.size(), {});
  CsvRowParser parser(header_, source_, options);
  LineCursor cursor{text_, pos_, header_line_};
  std::string_view line;
  while (true) {
    if (parser.pending()) {
      parser.emit(table);
    } else if (cursor.next(line)) {
      parser.take(line, cursor.line);
    } else {
      break;
    }
  }
  return table;
}

// ---------------------------------------------------------------------------------------------

CsvStreamReader::CsvStreamReader(const std::filesystem::path& path) : source_(path.string()) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0)
    throw std::system_error(errno, std::generic_category(), "cannot read '" + source_ + "'");
  owns_fd_ = true;
  start();
}

CsvStreamReader::CsvStreamReader(int fd, std::string source)
    : source_(std::move(source)), fd_(fd), owns_fd_(false) {
  start();
}

CsvStreamReader::~CsvStreamReader() {
  if (owns_fd_) ::close(fd_);
}

// Reads more bytes into the buffer; false at the end of the input.
bool CsvStreamReader::fill() {
  if (eof_) return false;
  if (pos_ > 0) {  // drop the lines already returned
    buffer_.erase(0, pos_);
    pos_ = 0;
  }
  char chunk[1 << 16];
  while (true) {
    const ssize_t n = ::read(fd_, chunk, sizeof chunk);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::system_error(errno, std::generic_category(),
                              source_ == "<stdin>" ? std::string("cannot read standard input")
                                                   : "cannot read '" + source_ + "'");
    }
    if (n == 0) {
      eof_ = true;
      return false;
    }
    buffer_.append(chunk, static_cast<std::size_t>(n));
    return true;
  }
}

bool CsvStreamReader::next_line(std::string_view& out) {
  std::size_t end = buffer_.find('\n', pos_);
  while (end == std::string::npos) {
    const std::size_t unread = buffer_.size() - pos_;
    if (unread > kMaxLineBytes)
      throw CsvError(source_, line_ + 1, "",
                     fmt::format("the line is longer than the limit of {} bytes", kMaxLineBytes));
    if (!fill()) break;
    end = buffer_.find('\n', unread);  // fill() moved the unread bytes to the front
  }
  if (end == std::string::npos) {
    if (pos_ >= buffer_.size()) return false;
    end = buffer_.size();
  }
  out = std::string_view(buffer_).substr(pos_, end - pos_);
  if (!out.empty() && out.back() == '\r') out.remove_suffix(1);
  pos_ = end == buffer_.size() ? end : end + 1;
  ++line_;
  return true;
}

void CsvStreamReader::start() {
  while (buffer_.size() < 3 && fill()) {
  }
  if (std::string_view(buffer_).substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3;  // UTF-8 byte-order mark
  std::string_view line;
  // As CsvReader: an input of blank lines only is empty; a blank first line is an empty header.
  std::size_t first = 0;
  while (next_line(line)) {
    if (first == 0) first = line_;
    if (!is_blank_line(line)) {
      if (first != line_)
        throw CsvError(source_, first, "", "the header row is empty (expected column names)");
      header_ = parse_header(line, source_, line_);
      header_line_ = line_;
      return;
    }
  }
  throw CsvError(source_, 0, "", "the input is empty (expected a header row)");
}

void CsvStreamReader::require_header(std::span<const std::string_view> expected,
                                     std::string_view note) const {
  require_names(header_, source_, header_line_, expected, note);
}

bool CsvStreamReader::read_block(CsvTable& block, std::size_t max_rows,
                                 const CsvReadOptions& options) {
  if (!parser_) {
    check_names(header_, source_, header_line_);
    parser_ = std::make_unique<CsvRowParser>(header_, source_, options);
  }
  block.header = header_;
  block.columns.assign(header_.size(), {});
  block.lines.clear();
  block.problems.clear();
  std::string_view line;
  while (block.rows() < max_rows) {
    if (parser_->pending()) {
      parser_->emit(block);
    } else if (next_line(line)) {
      parser_->take(line, line_);
    } else {
      break;
    }
  }
  return block.rows() > 0;
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

std::string csv_header_line(std::span<const std::string> header) {
  fmt::memory_buffer buf;
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (c > 0) buf.push_back(',');
    append_name(buf, header[c]);
  }
  buf.push_back('\n');
  return fmt::to_string(buf);
}

void write_csv_rows(std::span<const std::span<const double>> columns, const CsvSink& sink,
                    std::size_t chunk_bytes) {
  const std::size_t rows = columns.empty() ? 0 : columns.front().size();
  for (const auto& c : columns)
    if (c.size() != rows) throw std::invalid_argument("write_csv: columns of different lengths");
  fmt::memory_buffer buf;
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (c > 0) buf.push_back(',');
      const double v = columns[c][r];
      std::array<char, 32> digits;
      buf.append(std::isnan(v) ? std::string_view("nan") : format_17g(v, digits));
    }
    buf.push_back('\n');
    if (buf.size() >= chunk_bytes) {
      sink(std::string_view(buf.data(), buf.size()));
      buf.clear();
    }
  }
  if (buf.size() > 0) sink(std::string_view(buf.data(), buf.size()));
}

void write_csv(std::span<const std::string> header,
               std::span<const std::span<const double>> columns, const CsvSink& sink,
               std::size_t chunk_bytes) {
  if (header.size() != columns.size())
    throw std::invalid_argument("write_csv: the header and the columns differ in number");
  const std::size_t rows = columns.empty() ? 0 : columns.front().size();
  for (const auto& c : columns)
    if (c.size() != rows) throw std::invalid_argument("write_csv: columns of different lengths");
  // The header goes out with the first chunk of rows (one write for a small table).
  std::string head = csv_header_line(header);
  bool sent = false;
  write_csv_rows(
      columns,
      [&](std::string_view rows_text) {
        if (!sent) {
          head += rows_text;
          sink(head);
          sent = true;
        } else {
          sink(rows_text);
        }
      },
      chunk_bytes);
  if (!sent) sink(head);
}

std::string to_csv(std::span<const std::string> header,
                   std::span<const std::span<const double>> columns) {
  std::string out;
  write_csv(header, columns, [&](std::string_view s) { out += s; });
  return out;
}

}  // namespace halfback
