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
#include <utility>

#include "formats/binary_io.hpp"
#include "halfback/formats/nbrdf.hpp"
#include "halfback/util/bounded_read.hpp"
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

namespace {

// A header longer than this is not a float32 array's (NumPy writes about 128 bytes; its own reader
// refuses more than 10000 by default).
constexpr std::size_t kMaxHeaderBytes = 65536;
// A neural BRDF's arrays are a few KB; 64 MB is far beyond any plausible one.
constexpr std::uint64_t kMaxNpyBytes = std::uint64_t(64) << 20;

// What the prefix and header declare: the shape, where the data starts and how many bytes it has.
struct Layout {
  std::vector<std::size_t> shape;
  std::size_t count = 0;         // values
  std::uint64_t data_start = 0;  // bytes before the data
  std::uint64_t declared_size() const { return data_start + 4 * std::uint64_t(count); }
};

// The prefix (magic, version, header length): the header's length and where it starts. `p` holds
// min(size, 12) bytes of a file of `size` bytes.
std::pair<std::size_t, std::size_t> parse_prefix(std::span<const std::byte> p, std::uint64_t size,
                                                 const std::string& file) {
  if (size < 10 || std::string_view(reinterpret_cast<const char*>(p.data()), 6) != kNpyMagic)
    throw FormatError(file, "magic", "not a NumPy .npy file (no \\x93NUMPY signature)");
  const int major = int(p[6]);
  if (major < 1 || major > 3)
    throw FormatError(file, "version", "unknown .npy version " + std::to_string(major));
  const std::size_t prefix = major == 1 ? 10 : 12;
  if (size < prefix) throw FormatError(file, "header", "truncated before the header");
  const std::size_t header_len = major == 1 ? io_detail::load_le<std::uint16_t>(p.data() + 8)
                                            : io_detail::load_le<std::uint32_t>(p.data() + 8);
  if (header_len > size - prefix)
    throw FormatError(
        file, "header",
        "header length " + std::to_string(header_len) + " runs past the end of the file");
  if (header_len > kMaxHeaderBytes)
    throw FormatError(file, "header",
                      "header length " + std::to_string(header_len) + " is above the limit of " +
                          std::to_string(kMaxHeaderBytes) + " bytes");
  return {prefix, header_len};
}

// The header dict (`text`, after the prefix) of a file of `size` bytes.
Layout parse_header(std::string_view text, std::size_t prefix, std::uint64_t size,
                    const std::string& file) {
  const std::size_t header_len = text.size();
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
  Layout layout{*header.shape, 1, prefix + header_len};
  for (const std::size_t d : layout.shape) {
    if (d != 0 && layout.count > (size / 4 + 1) / d)
      throw FormatError(file, "shape", "more values than the file holds");
    layout.count *= d;
  }
  return layout;
}

NpyArray decode(const Layout& layout, const std::byte* data) {
  NpyArray array{layout.shape, std::vector<float>(layout.count)};
  for (std::size_t i = 0; i < layout.count; ++i)
    array.values[i] = io_detail::load_le<float>(data + 4 * i);
  return array;
}

std::string layout_text(const Layout& layout) {
  return std::to_string(layout.data_start) + "-byte header + " + std::to_string(layout.count) +
         " float32";
}

}  // namespace

NpyArray parse_npy_float32(std::span<const std::byte> bytes, std::string_view name) {
  const std::string file(name);
  const auto [prefix, header_len] =
      parse_prefix(bytes.first(std::min<std::size_t>(bytes.size(), 12)), bytes.size(), file);
  const Layout layout = parse_header(
      std::string_view(reinterpret_cast<const char*>(bytes.data() + prefix), header_len), prefix,
      bytes.size(), file);
  require_declared_size(file, layout.declared_size(), bytes.size(), layout_text(layout));
  return decode(layout, bytes.data() + layout.data_start);
}

NpyArray read_npy_float32(const std::filesystem::path& path) {
  // The prefix, then the header, then the size check: only then the data.
  BoundedFile in(path);
  std::vector<std::byte> bytes = in.head(12);
  const auto [prefix, header_len] = parse_prefix(bytes, in.size(), in.name());
  in.extend(bytes, prefix + header_len, "header");
  const Layout layout = parse_header(
      std::string_view(reinterpret_cast<const char*>(bytes.data() + prefix), header_len), prefix,
      in.size(), in.name());
  require_declared_size(in.name(), layout.declared_size(), in.size(), layout_text(layout));
  if (in.size() > kMaxNpyBytes)
    throw FormatError(in.name(), "file size",
                      std::to_string(in.size()) +
                          " bytes is more than a neural BRDF's array may "
                          "have (" +
                          std::to_string(kMaxNpyBytes) + " bytes)");
  in.extend(bytes, layout.declared_size(), "data");
  return decode(layout, bytes.data() + layout.data_start);
}

}  // namespace halfback
