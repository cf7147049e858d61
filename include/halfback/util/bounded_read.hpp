// Reading input files within bounds (docs/reliability/readers.md, "A reader reads what the file's
// header declares, and nothing more").
//
// The rule for every reader: learn the file's size before anything else, read the header, work
// out from it the size the file must have, refuse a file of any other size (truncated, or
// trailing data: require_declared_size), and only then read the rest. Nothing is read or
// allocated beyond what the header declares, so a small file extended to gigabytes (`truncate -s`)
// costs no more than the small one. Text formats, which declare no size, are read line by line
// with a bound on the line (TextLines), and a NUL byte, which no text holds, ends them with an
// error.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace halfback {

// A regular file opened for reading at offsets, its size known. Errors are FormatError naming the
// file.
class BoundedFile {
 public:
  // FormatError(path, "file", ...) when it is not a regular file or cannot be opened.
  explicit BoundedFile(const std::filesystem::path& path);

  const std::string& name() const noexcept { return name_; }
  std::uint64_t size() const noexcept { return size_; }

  // Reads bytes [offset, offset + out.size()); FormatError(name, what, "truncated: ...") when the
  // file ends first.
  void read_at(std::uint64_t offset, std::span<std::byte> out, std::string_view what);
  // Grows `buffer`, which holds the file's first bytes, to its first `end` bytes (a header read as
  // far as it goes).
  void extend(std::vector<std::byte>& buffer, std::uint64_t end, std::string_view what);
  // The file's first min(n, size()) bytes.
  std::vector<std::byte> head(std::size_t n);

 private:
  std::string name_;
  std::uint64_t size_ = 0;
  std::ifstream in_;
};

// The size check of every binary reader: FormatError(file, "file size", ...) unless `found` (the
// file's size) is `declared` (what its header declares; `layout` says how, e.g. "12-byte header +
// 3 × 90·90·180 float64"). The message names both counts: "the header declares 658952 bytes (...),
// the file has 1500000000: 1499341048 bytes of trailing data" or "...: truncated".
void require_declared_size(const std::string& file, std::uint64_t declared, std::uint64_t found,
                           std::string_view layout = {});

// A text file read line by line: a line longer than `max_line` bytes, a NUL byte (binary data,
// such as the zeros of a file extended past its end) or a file larger than `max_bytes` is a
// FormatError naming the file and the line.
class TextLines {
 public:
  static constexpr std::size_t kDefaultMaxLine = std::size_t{1} << 20;

  TextLines(const std::filesystem::path& path, std::uint64_t max_bytes,
            std::size_t max_line = kDefaultMaxLine);

  // The next line without its '\n'; false at the end of the file.
  bool next(std::string_view& line);
  std::size_t line_number() const noexcept { return line_; }
  const std::string& name() const noexcept { return file_.name(); }

 private:
  bool fill();

  BoundedFile file_;
  std::size_t max_line_;
  std::uint64_t read_ = 0;  // bytes read from the file so far
  std::string buffer_;
  std::size_t pos_ = 0, line_ = 0;
};

// The text rule on a line held in memory: FormatError(file, "line N", ...) when it holds a NUL
// byte. TextLines applies it to every line; readers of text in memory call it themselves.
void require_text_line(const std::string& file, std::size_t line_number, std::string_view line);

}  // namespace halfback
