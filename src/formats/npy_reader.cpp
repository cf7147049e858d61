// A strict reader of NumPy .npy files holding float32 arrays (the neural BRDFs' NumPy form).
//
// Format (NumPy's "format.py"): the magic "\x93NUMPY", a major and minor version byte, the header
// length (uint16 little-endian for version 1, uint32 for versions 2 and 3), the header (a Python
// dict literal, ASCII or UTF-8, padded with spaces, ended by '\n'), then the raw data.
#include <cctype>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include "formats/binary_io.hpp"
#include "halfback/formats/nbrdf.hpp"
#include "halfback/util/format_error.hpp"

namespace halfback {
namespace {

// The dict literal {'descr': '<f4', 'fortran_order': False, 'shape': (6, 21), } as NumPy writes
// it: single- or double-quoted keys, a string, a bool and a tuple of integers. Anything else in
// the header is an error.
class HeaderParser {
 public:
  HeaderParser(std::string_view text, std::string_view file) : text_(text), file_(file) {}

  struct Header {
    std::optional<std::string> descr;
    std::optional<bool> fortran_order;
    std::optional<std::vector<std::size_t>> shape;
  };

  Header parse() {
    Header h;
    expect('{');
    while (true) {
      skip_space();
      if (peek() == '}') break;
      const std::string key = quoted();
      expect(':');
      if (key == "descr" && !h.descr)
        h.descr = quoted();
      else if (key == "fortran_order" && !h.fortran_order)
        h.fortran_order = boolean();
      else if (key == "shape" && !h.shape)
        h.shape = tuple();
      else
        fail("unexpected or repeated key '" + key + "'");
      skip_space();
      if (peek() != ',') break;
      ++pos_;
    }
    expect('}');
    skip_space();
    if (pos_ != text_.size()) fail("text after the dict");
    return h;
  }

 private:
  [[noreturn]] void fail(const std::string& problem) const {
    throw FormatError(std::string(file_), "npy header",
                      problem + " at offset " + std::to_string(pos_) + " of the header");
  }
  char peek() const { return pos_ < text_.size() ? text_[pos_] : '\0'; }
  void skip_space() {
    while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\t')) ++pos_;
  }
  void expect(char c) {
    skip_space();
    if (peek() != c) fail(std::string("expected '") + c + "'");
    ++pos_;
  }
  std::string quoted() {
    skip_space();
    const char q = peek();
    if (q != '\'' && q != '"') fail("expected a quoted string");
    const std::size_t end = text_.find(q, pos_ + 1);
    if (end == std::string_view::npos) fail("unterminated string");
    std::string s(text_.substr(pos_ + 1, end - pos_ - 1));
    pos_ = end + 1;
    return s;
  }
  bool boolean() {
    skip_space();
    for (const auto& [word, value] : {std::pair{"True", true}, std::pair{"False", false}}) {
      const std::string_view w(word);
      if (text_.substr(pos_, w.size()) == w) {
        pos_ += w.size();
        return value;
      }
    }
    fail("expected True or False");
  }
  std::vector<std::size_t> tuple() {
    expect('(');
    std::vector<std::size_t> dims;
    while (true) {
      skip_space();
      if (peek() == ')') break;
      if (!std::isdigit(static_cast<unsigned char>(peek()))) fail("expected a dimension");
      std::size_t d = 0;
      while (std::isdigit(static_cast<unsigned char>(peek()))) {
        if (d > (std::numeric_limits<std::uint32_t>::max() - 9) / 10) fail("dimension too large");
        d = d * 10 + std::size_t(text_[pos_++] - '0');
      }
      dims.push_back(d);
      if (dims.size() > 8) fail("more than 8 dimensions");
      skip_space();
      if (peek() != ',') break;
      ++pos_;
    }
    expect(')');
    return dims;
  }

  std::string_view text_, file_;
  std::size_t pos_ = 0;
};

constexpr std::string_view kNpyMagic{"\x93NUMPY", 6};

}  // namespace

NpyArray parse_npy_float32(std::span<const std::byte> bytes, std::string_view name) {
  const std::string file(name);
  const auto* p = bytes.data();
  if (bytes.size() < 10 || std::string_view(reinterpret_cast<const char*>(p), 6) != kNpyMagic)
    throw FormatError(file, "magic", "not a NumPy .npy file (no \\x93NUMPY signature)");
  const int major = int(p[6]);
  if (major < 1 || major > 3)
    throw FormatError(file, "version", "unknown .npy version " + std::to_string(major));
  const std::size_t prefix = major == 1 ? 10 : 12;
  if (bytes.size() < prefix) throw FormatError(file, "header", "truncated before the header");
  const std::size_t header_len = major == 1 ? io_detail::load_le<std::uint16_t>(p + 8)
                                            : io_detail::load_le<std::uint32_t>(p + 8);
  if (header_len > bytes.size() - prefix)
    throw FormatError(
        file, "header",
        "header length " + std::to_string(header_len) + " runs past the end of the file");
  std::string_view text(reinterpret_cast<const char*>(p + prefix), header_len);
  if (text.empty() || text.back() != '\n')
    throw FormatError(file, "header", "does not end with a newline");
  text.remove_suffix(1);
  while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
  const auto header = HeaderParser(text, file).parse();
  if (!header.descr || !header.fortran_order || !header.shape)
    throw FormatError(file, "npy header", "needs the keys 'descr', 'fortran_order' and 'shape'");
  if (*header.descr != "<f4")
    throw FormatError(file, "dtype",
                      "'" + *header.descr + "', expected little-endian float32 ('<f4')");
  if (*header.fortran_order)
    throw FormatError(file, "fortran_order", "True; only C-order arrays are read");
  std::size_t count = 1;
  for (const std::size_t d : *header.shape) {
    if (d != 0 && count > (bytes.size() / 4 + 1) / d)
      throw FormatError(file, "shape", "more values than the file holds");
    count *= d;
  }
  const std::size_t data_bytes = bytes.size() - prefix - header_len;
  if (data_bytes != count * 4)
    throw FormatError(file, "data",
                      std::to_string(data_bytes) + " bytes, the shape needs " +
                          std::to_string(count * 4) +
                          (data_bytes < count * 4 ? " (truncated)" : " (trailing bytes)"));
  NpyArray array{*header.shape, std::vector<float>(count)};
  const std::byte* data = p + prefix + header_len;
  for (std::size_t i = 0; i < count; ++i) array.values[i] = io_detail::load_le<float>(data + 4 * i);
  return array;
}

NpyArray read_npy_float32(const std::filesystem::path& path) {
  // A neural BRDF's arrays are a few KB; 64 MB is far beyond any plausible one.
  const std::string bytes = io_detail::read_file_bytes(path, std::uintmax_t(64) << 20);
  return parse_npy_float32(io_detail::as_bytes(bytes), path.string());
}

}  // namespace halfback
