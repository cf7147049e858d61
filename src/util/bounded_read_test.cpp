// docs/reliability/readers.md, "A reader reads what the file's header declares, and nothing more":
// reads bounded by what a file declares; the size check's message; text read line by line, a NUL
// byte or an overlong line refused.
#include "halfback/util/bounded_read.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "halfback/util/format_error.hpp"

namespace halfback {
namespace {

namespace fs = std::filesystem;

// A file of the test's own, removed after it.
class TempFile {
 public:
  explicit TempFile(const std::string& content)
      : path_(fs::temp_directory_path() /
              ("halfback-bounded-" + std::to_string(::getpid()) + "-" + std::to_string(++count_))) {
    std::ofstream(path_, std::ios::binary) << content;
  }
  ~TempFile() {
    std::error_code ec;
    fs::remove(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
  static inline int count_ = 0;
};

std::string error_of(auto&& f) {
  try {
    f();
  } catch (const FormatError& e) {
    return e.what();
  }
  return "no error";
}

TEST(BoundedRead, DeclaredSizeMessageNamesBothCounts) {
  EXPECT_NO_THROW(require_declared_size("f", 10, 10));
  EXPECT_EQ(error_of([] { require_declared_size("f.bsdf", 658952, 1500000000, "its fields"); }),
            "f.bsdf: file size: the header declares 658952 bytes (its fields), the file has "
            "1500000000 bytes: 1499341048 bytes of trailing data");
  EXPECT_EQ(error_of([] { require_declared_size("f", 8, 9); }),
            "f: file size: the header declares 8 bytes, the file has 9 bytes: 1 byte of "
            "trailing data");
  EXPECT_EQ(error_of([] { require_declared_size("f", 8, 3); }),
            "f: file size: the header declares 8 bytes, the file has 3 bytes: truncated");
}

TEST(BoundedRead, ReadsAtOffsetsAndNeverPastTheEnd) {
  const TempFile f("0123456789");
  BoundedFile in(f.path());
  EXPECT_EQ(in.size(), 10u);
  std::vector<std::byte> head = in.head(4);
  ASSERT_EQ(head.size(), 4u);
  EXPECT_EQ(char(head[3]), '3');
  in.extend(head, 7, "header");
  EXPECT_EQ(char(head[6]), '6');
  std::array<std::byte, 2> two{};
  in.read_at(8, two, "x");
  EXPECT_EQ(char(two[1]), '9');
  // Past the end: refused before anything is allocated.
  EXPECT_NE(error_of([&] { in.extend(head, std::uint64_t(1) << 40, "data"); }).find("truncated"),
            std::string::npos);
  EXPECT_EQ(head.size(), 7u);
  EXPECT_NE(error_of([&] { in.read_at(9, two, "x"); }).find("truncated"), std::string::npos);
  EXPECT_NE(error_of([] { BoundedFile("/nonexistent/halfback"); }).find("/nonexistent/halfback"),
            std::string::npos);
}

TEST(BoundedRead, TextLinesSplitAndRefuseBinaryData) {
  const TempFile f("a\nbb\r\n\nlast");
  TextLines lines(f.path(), 100);
  std::vector<std::string> got;
  for (std::string_view l; lines.next(l);) got.emplace_back(l);
  EXPECT_EQ(got, (std::vector<std::string>{"a", "bb\r", "", "last"}));

  // The zeros of a file extended past its end: refused at the first, naming the line.
  const TempFile sparse(std::string("#DIM 3 1\n1 2 3 4\n") + std::string(100000, '\0'));
  TextLines s(sparse.path(), 1 << 20);
  std::string_view l;
  ASSERT_TRUE(s.next(l));
  ASSERT_TRUE(s.next(l));
  const std::string e = error_of([&] { s.next(l); });
  EXPECT_NE(e.find("line 3: a NUL byte at column 1"), std::string::npos) << e;

  const TempFile longline(std::string(5000, 'x') + "\n");
  TextLines t(longline.path(), 1 << 20, 4096);
  EXPECT_NE(error_of([&] { t.next(l); }).find("line 1: longer than the limit of 4096 bytes"),
            std::string::npos);
  EXPECT_NE(error_of([&] { TextLines(longline.path(), 100); }).find("more than this format"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              require_text_line("m", 7, std::string("ab\0c", 4));
            }).find("m: line 7: a NUL byte at column 3"),
            std::string::npos);
}

}  // namespace
}  // namespace halfback
