#include "halfback/util/bounded_read.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <system_error>

#include "halfback/util/format_error.hpp"

namespace halfback {

BoundedFile::BoundedFile(const std::filesystem::path& path) : name_(path.string()) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw FormatError(name_, "file", ec ? ec.message() : "not a regular file");
  size_ = std::filesystem::file_size(path, ec);
  if (ec) throw FormatError(name_, "file", "cannot get its size: " + ec.message());
  in_.open(path, std::ios::binary);
  if (!in_) throw FormatError(name_, "file", "cannot open for reading");
}

void BoundedFile::read_at(std::uint64_t offset, std::span<std::byte> out, std::string_view what) {
  if (offset > size_ || out.size() > size_ - offset)
    throw FormatError(name_, std::string(what),
                      fmt::format("truncated: needs bytes {} to {}, the file has {} bytes", offset,
                                  offset + out.size(), size_));
  if (out.empty()) return;
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(offset));
  in_.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(out.size()));
  if (static_cast<std::size_t>(in_.gcount()) != out.size())
    throw FormatError(name_, std::string(what),
                      fmt::format("read error after {} of {} bytes at offset {}", in_.gcount(),
                                  out.size(), offset));
}

void BoundedFile::extend(std::vector<std::byte>& buffer, std::uint64_t end, std::string_view what) {
  if (end <= buffer.size()) return;
  const std::size_t start = buffer.size();
  if (end > size_)  // checked before resizing: nothing is allocated beyond the file
    throw FormatError(name_, std::string(what),
                      fmt::format("truncated: needs {} bytes, the file has {}", end, size_));
  buffer.resize(static_cast<std::size_t>(end));
  read_at(start, std::span(buffer).subspan(start), what);
}

std::vector<std::byte> BoundedFile::head(std::size_t n) {
  std::vector<std::byte> bytes(static_cast<std::size_t>(std::min<std::uint64_t>(n, size_)));
  read_at(0, bytes, "file");
  return bytes;
}

void require_declared_size(const std::string& file, std::uint64_t declared, std::uint64_t found,
                           std::string_view layout) {
  if (found == declared) return;
  const std::string how = layout.empty() ? std::string() : fmt::format(" ({})", layout);
  throw FormatError(
      file, "file size",
      found > declared
          ? fmt::format("the header declares {} bytes{}, the file has {} bytes: {} "
                        "byte{} of trailing data",
                        declared, how, found, found - declared, found - declared == 1 ? "" : "s")
          : fmt::format("the header declares {} bytes{}, the file has {} bytes: "
                        "truncated",
                        declared, how, found));
}

void require_text_line(const std::string& file, std::size_t line_number, std::string_view line) {
  const std::size_t nul = line.find('\0');
  if (nul != std::string_view::npos)
    throw FormatError(file, fmt::format("line {}", line_number),
                      fmt::format("a NUL byte at column {}: binary data, not text (a file "
                                  "extended past its end, or not a text file)",
                                  nul + 1));
}

TextLines::TextLines(const std::filesystem::path& path, std::uint64_t max_bytes,
                     std::size_t max_line)
    : file_(path), max_line_(max_line) {
  if (file_.size() > max_bytes)
    throw FormatError(file_.name(), "file size",
                      fmt::format("{} bytes is more than this format allows ({} bytes)",
                                  file_.size(), max_bytes));
}

bool TextLines::fill() {
  if (read_ >= file_.size()) return false;
  buffer_.erase(0, pos_);
  pos_ = 0;
  constexpr std::size_t kChunk = std::size_t{1} << 16;
  const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, file_.size() - read_));
  const std::size_t old = buffer_.size();
  buffer_.resize(old + n);
  file_.read_at(read_, std::as_writable_bytes(std::span(buffer_).subspan(old)), "file");
  read_ += n;
  return true;
}

bool TextLines::next(std::string_view& line) {
  std::size_t scanned = pos_;  // bytes before it hold no '\n' nor NUL
  std::size_t end = std::string::npos;
  while (true) {
    const std::size_t stop = buffer_.find_first_of(std::string_view("\n\0", 2), scanned);
    if (stop != std::string::npos) {
      if (buffer_[stop] == '\0')
        require_text_line(file_.name(), line_ + 1, std::string_view(buffer_).substr(pos_));
      end = stop;
      break;
    }
    if (buffer_.size() - pos_ > max_line_)
      throw FormatError(file_.name(), fmt::format("line {}", line_ + 1),
                        fmt::format("longer than the limit of {} bytes", max_line_));
    scanned = buffer_.size() - pos_;
    if (!fill()) break;  // fill() moved the unread bytes to the front
  }
  if (end == std::string::npos) {
    if (pos_ >= buffer_.size()) return false;
    end = buffer_.size();
  }
  if (end - pos_ > max_line_)
    throw FormatError(file_.name(), fmt::format("line {}", line_ + 1),
                      fmt::format("longer than the limit of {} bytes", max_line_));
  line = std::string_view(buffer_).substr(pos_, end - pos_);
  pos_ = end == buffer_.size() ? end : end + 1;
  ++line_;
  return true;
}

}  // namespace halfback
