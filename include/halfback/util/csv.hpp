// Numeric CSV: a header row of column names, then one row of numbers per line.
//
// Reading is strict and every error says where: "SOURCE:LINE: column NAME: PROBLEM (text 'abc')".
// Accepted: LF or CRLF line ends, a missing final newline, blank lines at the end of the file,
// spaces and tabs around fields, a UTF-8 byte-order mark, RFC 4180 quoted fields on one line
// ("1.5", "a ""b"""), numbers in any form std::from_chars accepts plus a leading '+' (so %.17g
// text round-trips exactly; values too small for a double read as ±0). Rejected: an empty input
// (no header), an empty or duplicate column name, a row with the wrong number of fields, an empty
// field, text that is not a number, out-of-range numbers such as 1e999, blank lines followed by
// more rows, and, unless allowed, nan and inf in any spelling. A header with no rows is a valid,
// empty table.
//
// Writing uses "{:.17g}" (exact round trip) and prints every NaN as `nan`.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace halfback {

// A read error. what() is "SOURCE:LINE: column NAME: PROBLEM", without the parts that do not
// apply (line 0: the whole input; empty column: the whole row).
class CsvError : public std::runtime_error {
 public:
  CsvError(std::string source, std::size_t line, std::string column, std::string problem);

  const std::string& source() const noexcept { return source_; }
  std::size_t line() const noexcept { return line_; }
  const std::string& column() const noexcept { return column_; }
  const std::string& problem() const noexcept { return problem_; }

  // "SOURCE:LINE: column NAME: " (the prefix of what()).
  static std::string location(std::string_view source, std::size_t line, std::string_view column);

 private:
  std::string source_;
  std::size_t line_;
  std::string column_, problem_;
};

struct CsvReadOptions {
  // Accept nan / inf / infinity (any case, optional sign, "nan(...)") as values.
  bool allow_non_finite = false;
  // Instead of throwing on a bad row (wrong field count, empty field, not a number, not allowed
  // non-finite value, blank line inside the data), keep it: its values are NaN where they could
  // not be read and the problem is listed in CsvTable::problems.
  bool keep_bad_rows = false;
};

struct CsvRowProblem {
  std::size_t row = 0;   // index of the row in the table
  std::size_t line = 0;  // 1-based line in the source
  std::string column;    // the column, or empty for a whole-row problem
  std::string problem;   // as in CsvError::problem()
  std::string message;   // the full message, as CsvError::what() would be
};

struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<double>> columns;  // header.size() columns of rows() values each
  std::vector<std::size_t> lines;            // 1-based source line of each row
  std::vector<CsvRowProblem> problems;       // keep_bad_rows: the first problem of each bad row
  std::size_t rows() const noexcept { return lines.size(); }
};

// Reads CSV text in two steps, so that the caller can check the header before the rows.
class CsvReader {
 public:
  // `text` must outlive the reader; `source` names it in messages (a file name, "<stdin>").
  // Reads the header; throws CsvError when there is none or a quoted name is malformed. (Empty
  // and duplicate names are reported by read_rows(), so that require_header() can say first
  // that the header is not the expected one.)
  CsvReader(std::string_view text, std::string source);

  const std::vector<std::string>& header() const noexcept { return header_; }
  std::size_t header_line() const noexcept { return header_line_; }
  const std::string& source() const noexcept { return source_; }

  // Throws CsvError unless the header is exactly `expected` (same names, same order): "header
  // does not match: expected 'a,b,c', found 'a,c'" followed by `note` when given.
  void require_header(std::span<const std::string_view> expected, std::string_view note = {}) const;

  // Reads every row (one column per header entry). Throws CsvError for an empty or duplicate
  // column name, and on the first bad row unless options.keep_bad_rows. Call once.
  CsvTable read_rows(const CsvReadOptions& options = {});

 private:
  void check_names() const;

  std::string_view text_;
  std::string source_;
  std::vector<std::string> header_;
  std::size_t header_line_ = 1;
  std::size_t pos_ = 0;  // start of the first data line
};

class CsvRowParser;

// Reads CSV from a file or a descriptor in blocks of rows, in memory bounded by the block size and
// the longest line: the same rules and messages as CsvReader, for inputs larger than memory.
class CsvStreamReader {
 public:
  static constexpr std::size_t kMaxLineBytes = std::size_t{1} << 20;  // longer: a CsvError

  // Opens `path` (std::system_error "cannot read 'PATH': REASON") and reads the header (CsvError
  // as CsvReader's constructor).
  explicit CsvStreamReader(const std::filesystem::path& path);
  // Reads from `fd`, which stays open; `source` names it in messages ("<stdin>").
  CsvStreamReader(int fd, std::string source);
  ~CsvStreamReader();
  CsvStreamReader(const CsvStreamReader&) = delete;
  CsvStreamReader& operator=(const CsvStreamReader&) = delete;

  const std::vector<std::string>& header() const noexcept { return header_; }
  std::size_t header_line() const noexcept { return header_line_; }
  const std::string& source() const noexcept { return source_; }
  void require_header(std::span<const std::string_view> expected, std::string_view note = {}) const;

  // Replaces `block` with the next rows, at most `max_rows` (CsvRowProblem::row counts from the
  // block's first row). Returns false, with an empty block, at the end of the input. Throws as
  // CsvReader::read_rows; `options` must be the same on every call.
  bool read_block(CsvTable& block, std::size_t max_rows, const CsvReadOptions& options = {});

 private:
  void start();
  bool fill();
  bool next_line(std::string_view& out);

  std::string source_;
  int fd_ = -1;
  bool owns_fd_ = false, eof_ = false;
  std::string buffer_;  // bytes read and not yet returned start at pos_
  std::size_t pos_ = 0;
  std::size_t line_ = 0;  // number of the line last returned
  std::vector<std::string> header_;
  std::size_t header_line_ = 1;
  std::unique_ptr<CsvRowParser> parser_;
};

// Reads `text`; when `expected_header` is not empty the header must match it exactly.
CsvTable read_csv(std::string_view text, std::string source,
                  std::span<const std::string_view> expected_header = {},
                  const CsvReadOptions& options = {});

// Reads a whole file into memory. Throws std::system_error ("cannot read 'PATH': REASON").
std::string read_text_file(const std::filesystem::path& path);

// Splits one line into fields (quoted fields unquoted, surrounding blanks removed). Throws
// std::invalid_argument on a malformed quoted field. For tests and for header-like text.
std::vector<std::string> split_csv_line(std::string_view line);

// Parses one field as a double like the reader does. Returns the problem, or an empty string.
std::string parse_csv_number(std::string_view field, double& value, bool allow_non_finite);

// "{:.17g}", except that every NaN prints as `nan`.
std::string format_csv_number(double value);

// A text field as written in a CSV file: quoted (RFC 4180) when it holds a comma, a quote, a
// line break or surrounding blanks, as it is otherwise.
std::string csv_text_field(std::string_view text);

// Receives the written text in chunks.
using CsvSink = std::function<void(std::string_view)>;

// Writes a header line and the rows of `columns` (all of the same length, one per header name)
// to `sink`, in chunks of about `chunk_bytes`. Names with a comma, a quote or surrounding blanks
// are quoted. Throws std::invalid_argument when the column count or lengths differ.
void write_csv(std::span<const std::string> header,
               std::span<const std::span<const double>> columns, const CsvSink& sink,
               std::size_t chunk_bytes = std::size_t{1} << 20);

// The pieces of write_csv, for writers that stream blocks of rows: the header line (with its
// newline), and rows without a header (columns of equal lengths, else std::invalid_argument).
std::string csv_header_line(std::span<const std::string> header);
void write_csv_rows(std::span<const std::span<const double>> columns, const CsvSink& sink,
                    std::size_t chunk_bytes = std::size_t{1} << 20);

// The same, as one string.
std::string to_csv(std::span<const std::string> header,
                   std::span<const std::span<const double>> columns);

}  // namespace halfback
