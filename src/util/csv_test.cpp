#include "halfback/util/csv.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <system_error>
#include <vector>

#include "support/test_support.hpp"

namespace halfback {
namespace {

using namespace std::string_literals;
constexpr std::array<std::string_view, 3> kAbc{"a", "b", "c"};

// Expects `f` to throw a CsvError and returns it.
template <class F>
CsvError csv_error(F&& f) {
  try {
    f();
  } catch (const CsvError& e) {
    return e;
  }
  ADD_FAILURE() << "no CsvError thrown";
  return CsvError("", 0, "", "");
}

TEST(CsvRead, HeaderAndRows) {
  const CsvTable t = read_csv("a,b,c\n1,2,3\n4.5,-6e-3,7\n", "t.csv", kAbc);
  ASSERT_EQ(t.header, (std::vector<std::string>{"a", "b", "c"}));
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.columns[0], (std::vector<double>{1, 4.5}));
  EXPECT_EQ(t.columns[1], (std::vector<double>{2, -6e-3}));
  EXPECT_EQ(t.columns[2], (std::vector<double>{3, 7}));
  EXPECT_EQ(t.lines, (std::vector<std::size_t>{2, 3}));
  EXPECT_TRUE(t.problems.empty());
}

TEST(CsvRead, LineEndingsBlanksAndByteOrderMark) {
  const std::vector<std::string> texts = {
      "a,b,c\r\n1,2,3\r\n4,5,6\r\n",            // CRLF
      "a,b,c\n1,2,3\n4,5,6",                    // no final newline
      "a,b,c\n1,2,3\n4,5,6\n\n  \n\t\r\n",      // blank lines at the end
      " a , b\t,c \n 1 ,\t2, 3\n4 , 5 , 6 \n",  // blanks around fields
      "\xEF\xBB\xBF"
      "a,b,c\n1,2,3\n4,5,6\n",                               // UTF-8 BOM
      "\"a\",\"b\",c\n\"1\", \"2\" ,3\n4,5,\"+6\"\r\n\r\n",  // quoted fields
  };
  for (const auto& text : texts) {
    SCOPED_TRACE(text);
    const CsvTable t = read_csv(text, "t.csv", kAbc);
    ASSERT_EQ(t.rows(), 2u);
    EXPECT_EQ(t.columns[0], (std::vector<double>{1, 4}));
    EXPECT_EQ(t.columns[2], (std::vector<double>{3, 6}));
    EXPECT_EQ(t.lines, (std::vector<std::size_t>{2, 3}));
  }
}

TEST(CsvRead, EmptyInputHasNoHeader) {
  for (const char* text : {"", "\n", "  \r\n\n"}) {
    const CsvError e = csv_error([&] { CsvReader r(text, "e.csv"); });
    EXPECT_EQ(e.line(), 0u);
    EXPECT_STREQ(e.what(), "e.csv: the input is empty (expected a header row)");
  }
  const CsvError e = csv_error([&] { CsvReader r("\n1,2\n", "e.csv"); });
  EXPECT_EQ(e.line(), 1u);
  EXPECT_STREQ(e.what(), "e.csv:1: the header row is empty (expected column names)");
}

TEST(CsvRead, HeaderOnlyIsAnEmptyTable) {
  for (const char* text : {"a,b,c", "a,b,c\n", "a,b,c\r\n\r\n"}) {
    const CsvTable t = read_csv(text, "h.csv", kAbc);
    EXPECT_EQ(t.header.size(), 3u);
    EXPECT_EQ(t.rows(), 0u);
    ASSERT_EQ(t.columns.size(), 3u);
    EXPECT_TRUE(t.columns[0].empty());
  }
}

TEST(CsvRead, MalformedHeader) {
  EXPECT_STREQ(csv_error([] { read_csv("a,,c\n", "h.csv"); }).what(),
               "h.csv:1: header: the name of column 2 is empty");
  EXPECT_STREQ(csv_error([] { read_csv("a,b,a\n", "h.csv"); }).what(),
               "h.csv:1: header: duplicate column name 'a'");
  // require_header() comes first: a header-less file is reported as a header mismatch.
  CsvReader r("1,1,2\n", "h.csv");
  EXPECT_EQ(csv_error([&] { r.require_header(kAbc); }).problem(),
            "header does not match: expected 'a,b,c', found '1,1,2'");
  EXPECT_STREQ(csv_error([] { CsvReader r("a,\"b\n", "h.csv"); }).what(),
               "h.csv:1: header: unterminated quoted field");
}

TEST(CsvRead, HeaderMismatchNamesExpectedAndFound) {
  CsvReader r("a,c\n1,2\n", "h.csv");
  const CsvError e = csv_error([&] { r.require_header(kAbc, "a hint"); });
  EXPECT_EQ(e.line(), 1u);
  EXPECT_STREQ(e.what(), "h.csv:1: header does not match: expected 'a,b,c', found 'a,c'; a hint");
  // Same names in another order is a mismatch too.
  CsvReader r2("c,b,a\n", "h.csv");
  EXPECT_THROW(r2.require_header(kAbc), CsvError);
  CsvReader r3("a,b,c\n", "h.csv");
  EXPECT_NO_THROW(r3.require_header(kAbc));
}

TEST(CsvRead, WrongFieldCountNamesTheLine) {
  const CsvError e2 = csv_error([] { read_csv("a,b,c\n1,2,3\n4,5\n7,8,9\n", "x.csv", kAbc); });
  EXPECT_EQ(e2.line(), 3u);
  EXPECT_STREQ(e2.what(), "x.csv:3: expected 3 fields (a,b,c), found 2");
  const CsvError e3 = csv_error([] { read_csv("a,b,c\n1,2,3,\n", "x.csv", kAbc); });
  EXPECT_STREQ(e3.what(), "x.csv:2: expected 3 fields (a,b,c), found 4 (a trailing comma?)");
}

TEST(CsvRead, TrailingBlankLineIsNotAnError) {
  EXPECT_NO_THROW(read_csv("a,b,c\n1,2,3\n\n", "x.csv", kAbc));
}

TEST(CsvRead, BlankLineInsideTheData) {
  const CsvError e = csv_error([] { read_csv("a\n1\n\n2\n", "x.csv"); });
  EXPECT_EQ(e.line(), 3u);
  EXPECT_STREQ(e.what(),
               "x.csv:3: empty line inside the data (blank lines are allowed only at the end)");
}

TEST(CsvRead, NotANumberNamesLineColumnAndText) {
  struct Case {
    const char* field;
    const char* problem;
  };
  const Case cases[] = {
      {"abc", "'abc' is not a number"},
      {"1.5x", "'1.5x' is not a number"},
      {"1e", "'1e' is not a number"},
      {"--1", "'--1' is not a number"},
      {"+-1", "'+-1' is not a number"},
      {"+", "'+' is not a number"},
      {"0x10", "'0x10' is not a number"},
      {"1 2", "'1 2' is not a number"},
      {"", "empty field"},
      {"  ", "empty field"},
      {"1e999", "'1e999' is out of the range of a double"},
      {"-1e999", "'-1e999' is out of the range of a double"},
      {"nan", "'nan' is not a finite number"},
      {"NaN", "'NaN' is not a finite number"},
      {"-nan", "'-nan' is not a finite number"},
      {"nan(0x1)", "'nan(0x1)' is not a finite number"},
      {"inf", "'inf' is not a finite number"},
      {"-Infinity", "'-Infinity' is not a finite number"},
      {"+INF", "'+INF' is not a finite number"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.field);
    const std::string text = "a,b,c\n1,2,3\n4,"s + c.field + ",6\n";
    const CsvError e = csv_error([&] { read_csv(text, "n.csv", kAbc); });
    EXPECT_EQ(e.line(), 3u);
    EXPECT_EQ(e.column(), "b");
    EXPECT_EQ(e.problem(), c.problem);
    EXPECT_EQ(std::string(e.what()), "n.csv:3: column b: "s + c.problem);
  }
}

TEST(CsvRead, OffendingTextIsEscapedAndShortened) {
  const std::string text = "a\n" + std::string("x\x01y") + "\n";
  EXPECT_EQ(csv_error([&] { read_csv(text, "c.csv"); }).problem(), "'x\\x01y' is not a number");
  const std::string long_field(100, 'z');
  EXPECT_EQ(csv_error([&] { read_csv("a\n" + long_field + "\n", "c.csv"); }).problem(),
            "'" + std::string(40, 'z') + "...' is not a number");
}

TEST(CsvRead, NumberSpellings) {
  double v = 0;
  EXPECT_EQ(parse_csv_number("+1.5", v, false), "");
  EXPECT_EQ(v, 1.5);
  EXPECT_EQ(parse_csv_number(" .5 ", v, false), "");
  EXPECT_EQ(v, 0.5);
  EXPECT_EQ(parse_csv_number("1.", v, false), "");
  EXPECT_EQ(v, 1.0);
  EXPECT_EQ(parse_csv_number("-0", v, false), "");
  EXPECT_TRUE(v == 0 && std::signbit(v));
  EXPECT_EQ(parse_csv_number("4.9406564584124654e-324", v, false), "");
  EXPECT_EQ(v, std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(parse_csv_number("1e-400", v, false), "");  // underflow: zero
  EXPECT_TRUE(v == 0 && !std::signbit(v));
  EXPECT_EQ(parse_csv_number("-1e-400", v, false), "");
  EXPECT_TRUE(v == 0 && std::signbit(v));
  EXPECT_EQ(parse_csv_number("1.7976931348623157e308", v, false), "");
  EXPECT_EQ(v, std::numeric_limits<double>::max());
  // Non-finite values where allowed.
  EXPECT_EQ(parse_csv_number("nan", v, true), "");
  EXPECT_TRUE(std::isnan(v));
  EXPECT_EQ(parse_csv_number("-inf", v, true), "");
  EXPECT_EQ(v, -std::numeric_limits<double>::infinity());
  EXPECT_EQ(parse_csv_number("Infinity", v, true), "");
  EXPECT_EQ(v, std::numeric_limits<double>::infinity());
}

TEST(CsvRead, AllowNonFinite) {
  CsvReadOptions options;
  options.allow_non_finite = true;
  const CsvTable t = read_csv("a,b\nnan,inf\n", "f.csv", {}, options);
  ASSERT_EQ(t.rows(), 1u);
  EXPECT_TRUE(std::isnan(t.columns[0][0]));
  EXPECT_TRUE(std::isinf(t.columns[1][0]));
}

TEST(CsvRead, KeepBadRows) {
  CsvReadOptions options;
  options.keep_bad_rows = true;
  const std::string text =
      "a,b,c\n"
      "1,2,3\n"     // line 2: ok
      "4,x,nan\n"   // line 3: b not a number (first problem), c NaN
      "7,8\n"       // line 4: wrong count
      "\n"          // line 5: blank inside the data
      "10,11,12\n"  // line 6: ok
      "13,\"14\n"   // line 7: unterminated quote
      "\n";         // line 8: trailing blank
  const CsvTable t = read_csv(text, "k.csv", kAbc, options);
  ASSERT_EQ(t.rows(), 6u);
  EXPECT_EQ(t.lines, (std::vector<std::size_t>{2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(t.columns[0][1], 4.0);  // the readable field of a bad row is kept
  EXPECT_TRUE(std::isnan(t.columns[1][1]));
  EXPECT_TRUE(std::isnan(t.columns[2][1]));
  for (std::size_t r : {2u, 3u, 5u})
    for (std::size_t c = 0; c < 3; ++c) EXPECT_TRUE(std::isnan(t.columns[c][r]));
  EXPECT_EQ(t.columns[2][4], 12.0);
  ASSERT_EQ(t.problems.size(), 4u);
  EXPECT_EQ(t.problems[0].row, 1u);
  EXPECT_EQ(t.problems[0].line, 3u);
  EXPECT_EQ(t.problems[0].column, "b");
  EXPECT_EQ(t.problems[0].message, "k.csv:3: column b: 'x' is not a number");
  EXPECT_EQ(t.problems[1].row, 2u);
  EXPECT_EQ(t.problems[1].message, "k.csv:4: expected 3 fields (a,b,c), found 2");
  EXPECT_EQ(t.problems[2].row, 3u);
  EXPECT_EQ(t.problems[2].line, 5u);
  EXPECT_EQ(t.problems[3].row, 5u);
  EXPECT_EQ(t.problems[3].message, "k.csv:7: unterminated quoted field");
}

TEST(CsvRead, SplitLine) {
  EXPECT_EQ(split_csv_line(" a , \"b,c\" ,\"d \"\"e\"\"\"\t"),
            (std::vector<std::string>{"a", "b,c", "d \"e\""}));
  EXPECT_EQ(split_csv_line(""), (std::vector<std::string>{""}));
  EXPECT_EQ(split_csv_line("a,"), (std::vector<std::string>{"a", ""}));
  EXPECT_THROW(split_csv_line("\"a\" b"), std::invalid_argument);
}

TEST(CsvRead, ReadTextFile) {
  const test::TempDir tmp;
  const std::filesystem::path& dir = tmp.path();
  const auto missing = dir / "missing.csv";
  try {
    read_text_file(missing);
    ADD_FAILURE() << "no exception";
  } catch (const std::system_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "cannot read '" + missing.string() + "': No such file or directory");
  }
  EXPECT_THROW(read_text_file(dir), std::system_error);  // a directory
}

// ---------------------------------------------------------------------------------------------

TEST(CsvWrite, FormatsSeventeenDigitsAndNan) {
  EXPECT_EQ(format_csv_number(0.1), "0.10000000000000001");
  EXPECT_EQ(format_csv_number(1.0), "1");
  EXPECT_EQ(format_csv_number(-0.0), "-0");
  EXPECT_EQ(format_csv_number(1e-5), "1.0000000000000001e-05");
  EXPECT_EQ(format_csv_number(std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(format_csv_number(-std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(format_csv_number(std::numeric_limits<double>::infinity()), "inf");
}

TEST(CsvWrite, TableText) {
  const std::vector<std::string> header{"x", "y,z", "w"};
  const std::vector<double> x{1, 2}, y{0.5, std::nan("")}, w{-3, 1e300};
  const std::vector<std::span<const double>> cols{x, y, w};
  EXPECT_EQ(to_csv(header, cols), "x,\"y,z\",w\n1,0.5,-3\n2,nan,1.0000000000000001e+300\n");
  EXPECT_EQ(to_csv(std::vector<std::string>{"a"}, std::vector<std::span<const double>>{{}}), "a\n");
  EXPECT_THROW(to_csv(std::vector<std::string>{"a"}, {}), std::invalid_argument);
  const std::vector<double> shorter{1};
  EXPECT_THROW(
      to_csv(std::vector<std::string>{"a", "b"}, std::vector<std::span<const double>>{x, shorter}),
      std::invalid_argument);
}

TEST(CsvWrite, ChunkedSinkGivesTheSameText) {
  std::vector<double> x(1000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::sqrt(double(i));
  const std::vector<std::string> header{"x"};
  const std::vector<std::span<const double>> cols{x};
  std::string chunked;
  int calls = 0;
  write_csv(
      header, cols,
      [&](std::string_view s) {
        chunked += s;
        ++calls;
      },
      256);
  EXPECT_GT(calls, 10);
  EXPECT_EQ(chunked, to_csv(header, cols));
}

// ---------------------------------------------------------------------------------------------
// CsvStreamReader: the same tables and errors as CsvReader, a block of rows at a time
// ---------------------------------------------------------------------------------------------

struct FdCloser {
  int fd;
  ~FdCloser() { ::close(fd); }
};

// The whole table of `text` read through a file in blocks of `block` rows (problems' rows made
// absolute), or the CsvError's message.
std::string stream_read(const std::string& text, std::size_t block, CsvTable& table,
                        const CsvReadOptions& options = {}) {
  test::TempDir dir;
  test::write_bytes(dir / "t.csv", text.data(), text.size());
  const int fd = ::open((dir / "t.csv").c_str(), O_RDONLY);
  const FdCloser closer{fd};
  try {
    CsvStreamReader reader(fd, "t.csv");
    table = {};
    table.header = reader.header();
    table.columns.assign(reader.header().size(), {});
    CsvTable part;
    while (reader.read_block(part, block, options)) {
      EXPECT_LE(part.rows(), block);
      for (CsvRowProblem p : part.problems) {
        p.row += table.rows();
        table.problems.push_back(p);
      }
      for (std::size_t c = 0; c < part.columns.size(); ++c)
        table.columns[c].insert(table.columns[c].end(), part.columns[c].begin(),
                                part.columns[c].end());
      table.lines.insert(table.lines.end(), part.lines.begin(), part.lines.end());
    }
  } catch (const CsvError& e) {
    return e.what();
  }
  return {};
}

std::string whole_read(const std::string& text, CsvTable& table,
                       const CsvReadOptions& options = {}) {
  try {
    CsvReader reader(text, "t.csv");
    table = reader.read_rows(options);
  } catch (const CsvError& e) {
    return e.what();
  }
  return {};
}

void expect_same_tables(const CsvTable& a, const CsvTable& b) {
  EXPECT_EQ(a.header, b.header);
  EXPECT_EQ(a.lines, b.lines);
  ASSERT_EQ(a.columns.size(), b.columns.size());
  for (std::size_t c = 0; c < a.columns.size(); ++c) {
    ASSERT_EQ(a.columns[c].size(), b.columns[c].size());
    for (std::size_t r = 0; r < a.columns[c].size(); ++r)
      EXPECT_EQ(std::bit_cast<std::uint64_t>(a.columns[c][r]),
                std::bit_cast<std::uint64_t>(b.columns[c][r]));
  }
  ASSERT_EQ(a.problems.size(), b.problems.size());
  for (std::size_t i = 0; i < a.problems.size(); ++i) {
    EXPECT_EQ(a.problems[i].row, b.problems[i].row);
    EXPECT_EQ(a.problems[i].line, b.problems[i].line);
    EXPECT_EQ(a.problems[i].problem, b.problems[i].problem);
  }
}

// Every rule of the reader at every block size: line ends, byte-order mark, blank lines at the
// end and inside the data (kept as bad rows across block boundaries), bad fields, empty inputs.
TEST(CsvStream, SameTablesAndErrorsAsTheWholeTextReader) {
  const std::vector<std::string> inputs{
      "a,b,c\n1,2,3\n4,5,6\n",
      "\xEF\xBB\xBF"
      "a,b,c\r\n1,2,3\r\n4,5,6",
      "a,b,c\n1,2,3\n\n\n",
      "a,b,c\n1,2,3\n\n\n4,5,6\n7,8,9\n",
      "a,b,c\n1,2,3\n4,x,6\n7,8\n1,2,3,\n\"1\",\"2\",3\n",
      "a,b,c\n",
      "a,b,c",
      "",
      "\n \n\t\n",
      "\n\na,b,c\n1,2,3\n",
      "a,a,c\n1,2,3\n",
      "a,,c\n1,2,3\n",
  };
  for (const std::string& text : inputs) {
    for (bool keep : {false, true}) {
      CsvReadOptions options;
      options.keep_bad_rows = keep;
      CsvTable whole, streamed;
      const std::string whole_error = whole_read(text, whole, options);
      for (std::size_t block : {1, 2, 3, 1000}) {
        SCOPED_TRACE("input '" + text + "', block " + std::to_string(block) +
                     (keep ? ", keep bad rows" : ""));
        const std::string stream_error = stream_read(text, block, streamed, options);
        EXPECT_EQ(stream_error, whole_error);
        if (whole_error.empty() && stream_error.empty()) expect_same_tables(streamed, whole);
      }
    }
  }
}

// Lines that cross the reader's 64 KiB chunks, many rows, and a line without an end past the
// limit (an error, not unbounded memory).
TEST(CsvStream, LongInputsAndTheLineLimit) {
  std::string text = "a,b,c\n";
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int r = 0; r < 20000; ++r)
    text += format_csv_number(u(rng)) + ", " + format_csv_number(u(rng)) + "," +
            format_csv_number(u(rng)) + "\n";
  CsvTable whole, streamed;
  ASSERT_EQ(whole_read(text, whole), "");
  ASSERT_EQ(stream_read(text, 4096, streamed), "");
  expect_same_tables(streamed, whole);

  const std::string endless = "a,b,c\n1,2," + std::string(CsvStreamReader::kMaxLineBytes, '3');
  const std::string error = stream_read(endless, 10, streamed);
  EXPECT_NE(error.find(":2: the line is longer than the limit of 1048576 bytes"), std::string::npos)
      << error;
}

TEST(CsvStream, MissingFileIsASystemError) {
  EXPECT_THROW(CsvStreamReader(std::filesystem::path("/nonexistent/t.csv")), std::system_error);
}

TEST(CsvRoundTrip, ExactForEveryDouble) {
  std::mt19937_64 rng(7);
  std::vector<double> a, b;
  // Random bit patterns (finite ones), and the extremes.
  while (a.size() < 20000) {
    const double v = std::bit_cast<double>(rng());
    if (std::isfinite(v)) a.push_back(v);
  }
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 20000; ++i) b.push_back(u(rng));
  for (double v :
       {0.0, -0.0, std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest(),
        std::numeric_limits<double>::min(), std::numeric_limits<double>::denorm_min(),
        -std::numeric_limits<double>::denorm_min(), 1.0, 0.1, 1.0 / 3.0}) {
    a.push_back(v);
    b.push_back(-v);
  }
  const std::vector<std::string> header{"a", "b"};
  const std::vector<std::span<const double>> cols{a, b};
  const std::string text = to_csv(header, cols);
  const CsvTable t = read_csv(text, "rt.csv");
  ASSERT_EQ(t.rows(), a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(std::bit_cast<std::uint64_t>(t.columns[0][i]), std::bit_cast<std::uint64_t>(a[i]))
        << a[i];
    ASSERT_EQ(std::bit_cast<std::uint64_t>(t.columns[1][i]), std::bit_cast<std::uint64_t>(b[i]))
        << b[i];
  }
}

}  // namespace
}  // namespace halfback
