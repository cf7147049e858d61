// The "tensor_file" container of the RGL material database (see include/halfback/formats/rgl.hpp
// and docs/formats.md), read from the layout of the published files:
//   char[12] "tensor_file\0" | u8 major | u8 minor | u32 field count | field table | arrays
//   field: u16 name length | name | u16 ndim | u8 dtype | u64 offset | u64 shape[ndim]
// All integers little-endian; arrays are stored C-order at their byte offsets.
#include <algorithm>
#include <cstring>
#include <limits>
#include <set>

#include "binary_io.hpp"
#include "halfback/formats/rgl.hpp"
#include "halfback/util/format_error.hpp"

namespace halfback {

namespace {

using io_detail::load_le;
using io_detail::store_le;

constexpr char kMagic[12] = {'t', 'e', 'n', 's', 'o', 'r', '_', 'f', 'i', 'l', 'e', '\0'};
constexpr std::size_t kPreambleBytes = 12 + 2 + 4;
constexpr std::size_t kMinEntryBytes =
    2 + 1 + 2 + 1 + 8;  // name length, 1-char name, ndim, dtype, offset
constexpr std::size_t kMaxDims = 16;
constexpr std::uint64_t kMaxFileBytes = std::uint64_t(1) << 32;  // 4 GiB: far above any material

bool valid_name_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-' || c == '.';
}

}  // namespace

std::string_view name_of(TensorDtype dtype) {
  static constexpr std::string_view kNames[] = {"invalid", "uint8",   "int8",    "uint16",
                                                "int16",   "uint32",  "int32",   "uint64",
                                                "int64",   "float16", "float32", "float64"};
  const auto i = static_cast<std::size_t>(dtype);
  return i < std::size(kNames) ? kNames[i] : "invalid";
}

std::size_t size_of(TensorDtype dtype) {
  switch (dtype) {
    case TensorDtype::uint8:
    case TensorDtype::int8:
      return 1;
    case TensorDtype::uint16:
    case TensorDtype::int16:
    case TensorDtype::float16:
      return 2;
    case TensorDtype::uint32:
    case TensorDtype::int32:
    case TensorDtype::float32:
      return 4;
    case TensorDtype::uint64:
    case TensorDtype::int64:
    case TensorDtype::float64:
      return 8;
  }
  return 0;
}

std::uint64_t TensorField::count() const {
  std::uint64_t n = 1;
  for (auto s : shape) n *= s;  // checked against overflow at parse time
  return n;
}

const TensorField* TensorFile::find(std::string_view name) const {
  for (const auto& f : fields)
    if (f.name == name) return &f;
  return nullptr;
}

TensorFile parse_tensor_file(std::vector<std::byte> bytes, std::string_view name_view) {
  const std::string name(name_view);
  const std::uint64_t size = bytes.size();
  TensorFile tf;
  tf.name = name;
  tf.storage = std::move(bytes);
  const std::byte* base = tf.storage.data();

  if (size < sizeof(kMagic) || std::memcmp(base, kMagic, sizeof(kMagic)) != 0)
    throw FormatError(name, "magic",
                      "does not start with \"tensor_file\\0\" (not an RGL tensor file)");
  if (size < kPreambleBytes)
    throw FormatError(name, "header", "truncated: " + std::to_string(size) + " bytes");
  tf.version_major = static_cast<std::uint8_t>(base[12]);
  tf.version_minor = static_cast<std::uint8_t>(base[13]);
  if (tf.version_major != 1 || tf.version_minor != 0)
    throw FormatError(name, "version",
                      "is " + std::to_string(tf.version_major) + "." +
                          std::to_string(tf.version_minor) + ", only 1.0 is supported");
  const auto n_fields = load_le<std::uint32_t>(base + 14);
  if (n_fields == 0) throw FormatError(name, "field count", "is 0");
  if (n_fields > (size - kPreambleBytes) / kMinEntryBytes)
    throw FormatError(name, "field count",
                      std::to_string(n_fields) + " fields cannot fit in a " + std::to_string(size) +
                          "-byte file");

  std::uint64_t pos = kPreambleBytes;
  auto need = [&](std::uint64_t n, const std::string& what) {
    if (n > size - pos)
      throw FormatError(name, what, "truncated: the field table runs past the end of the file");
  };
  std::set<std::string, std::less<>> names;
  tf.fields.reserve(n_fields);
  for (std::uint32_t k = 0; k < n_fields; ++k) {
    const std::string entry = "field table entry " + std::to_string(k);
    need(2, entry);
    const auto len = load_le<std::uint16_t>(base + pos);
    pos += 2;
    if (len == 0) throw FormatError(name, entry, "has an empty name");
    need(len, entry);
    TensorField f;
    f.name.assign(reinterpret_cast<const char*>(base + pos), len);
    pos += len;
    if (!std::all_of(f.name.begin(), f.name.end(), valid_name_char))
      throw FormatError(name, entry, "name has characters outside [A-Za-z0-9_.-]");
    const std::string field = "field '" + f.name + "'";
    if (!names.insert(f.name).second) throw FormatError(name, field, "appears twice");
    need(2 + 1 + 8, field);
    const auto ndim = load_le<std::uint16_t>(base + pos);
    pos += 2;
    const auto dtype = static_cast<std::uint8_t>(base[pos]);
    pos += 1;
    f.offset = load_le<std::uint64_t>(base + pos);
    pos += 8;
    if (dtype < 1 || dtype > 11)
      throw FormatError(name, field, "unknown dtype code " + std::to_string(dtype));
    f.dtype = static_cast<TensorDtype>(dtype);
    if (ndim > kMaxDims)
      throw FormatError(name, field,
                        "has " + std::to_string(ndim) + " dimensions (at most " +
                            std::to_string(kMaxDims) + " supported)");
    need(8 * std::uint64_t(ndim), field);
    f.shape.resize(ndim);
    for (auto& s : f.shape) {
      s = load_le<std::uint64_t>(base + pos);
      pos += 8;
    }
    tf.fields.push_back(std::move(f));
  }
  const std::uint64_t table_end = pos;

  for (auto& f : tf.fields) {
    const std::string field = "field '" + f.name + "'";
    // Byte size, with overflow checks: every factor must keep the product within the file.
    std::uint64_t bytes_needed = size_of(f.dtype);
    for (auto s : f.shape) {
      if (s != 0 && bytes_needed > size / s)
        throw FormatError(name, field, "shape is larger than the file");
      bytes_needed *= s;
    }
    if (f.offset < table_end)
      throw FormatError(name, field,
                        "data offset " + std::to_string(f.offset) +
                            " lies inside the header (which ends at " + std::to_string(table_end) +
                            ")");
    if (f.offset > size || bytes_needed > size - f.offset)
      throw FormatError(name, field,
                        "truncated data: needs " + std::to_string(bytes_needed) +
                            " bytes at offset " + std::to_string(f.offset) + ", the file has " +
                            std::to_string(size) + " bytes");
    f.bytes = std::span<const std::byte>(base + f.offset, static_cast<std::size_t>(bytes_needed));
  }
  return tf;
}

TensorFile read_tensor_file(const std::filesystem::path& path) {
  const std::string s = io_detail::read_file_bytes(path, kMaxFileBytes);
  std::vector<std::byte> bytes(s.size());
  if (!s.empty()) std::memcpy(bytes.data(), s.data(), s.size());
  return parse_tensor_file(std::move(bytes), path.string());
}

std::vector<std::byte> serialize_tensor_file(std::span<const TensorFieldData> fields) {
  std::uint64_t header = kPreambleBytes;
  for (const auto& f : fields) header += 2 + f.name.size() + 2 + 1 + 8 + 8 * f.shape.size();
  auto align8 = [](std::uint64_t x) { return (x + 7) / 8 * 8; };
  std::vector<std::uint64_t> offsets;
  std::uint64_t end = align8(header);
  for (const auto& f : fields) {
    offsets.push_back(end);
    end = align8(end + f.data.size());
  }
  std::vector<std::byte> out(end);
  std::memcpy(out.data(), kMagic, sizeof(kMagic));
  out[12] = std::byte{1};
  out[13] = std::byte{0};
  store_le<std::uint32_t>(out.data() + 14, static_cast<std::uint32_t>(fields.size()));
  std::uint64_t pos = kPreambleBytes;
  for (std::size_t k = 0; k < fields.size(); ++k) {
    const auto& f = fields[k];
    store_le<std::uint16_t>(out.data() + pos, static_cast<std::uint16_t>(f.name.size()));
    pos += 2;
    std::memcpy(out.data() + pos, f.name.data(), f.name.size());
    pos += f.name.size();
    store_le<std::uint16_t>(out.data() + pos, static_cast<std::uint16_t>(f.shape.size()));
    pos += 2;
    out[pos] = static_cast<std::byte>(f.dtype);
    pos += 1;
    store_le<std::uint64_t>(out.data() + pos, offsets[k]);
    pos += 8;
    for (auto s : f.shape) {
      store_le<std::uint64_t>(out.data() + pos, s);
      pos += 8;
    }
    if (!f.data.empty()) std::memcpy(out.data() + offsets[k], f.data.data(), f.data.size());
  }
  return out;
}

}  // namespace halfback
