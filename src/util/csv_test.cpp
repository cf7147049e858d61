#include "halfback/util/csv.hpp"

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
