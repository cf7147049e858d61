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
#include "halfback/util/bounded_read.hpp"
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

namespace {

// Parses a tensor file from its first bytes, `storage`, reading more through `more(end)` (which
// grows `storage` to the file's first `end` bytes) only as far as the header and then the fields
// it declares go: the file's size is checked against the declared one before its data is read.
// `size` is the file's size.
template <class More>
TensorFile parse(std::vector<std::byte> storage, std::uint64_t size, const std::string& name,
                 More&& more) {
  TensorFile tf;
  tf.name = name;
  auto at = [&](std::uint64_t pos) { return storage.data() + pos; };
  more(storage, std::min<std::uint64_t>(size, kPreambleBytes));
  if (size < sizeof(kMagic) || std::memcmp(at(0), kMagic, sizeof(kMagic)) != 0)
    throw FormatError(name, "magic",
                      "does not start with \"tensor_file\\0\" (not an RGL tensor file)");
  if (size < kPreambleBytes)
    throw FormatError(name, "header", "truncated: " + std::to_string(size) + " bytes");
  tf.version_major = static_cast<std::uint8_t>(*at(12));
  tf.version_minor = static_cast<std::uint8_t>(*at(13));
  if (tf.version_major != 1 || tf.version_minor != 0)
    throw FormatError(name, "version",
                      "is " + std::to_string(tf.version_major) + "." +
                          std::to_string(tf.version_minor) + ", only 1.0 is supported");
  const auto n_fields = load_le<std::uint32_t>(at(14));
  if (n_fields == 0) throw FormatError(name, "field count", "is 0");
  if (n_fields > (size - kPreambleBytes) / kMinEntryBytes)
    throw FormatError(name, "field count",
                      std::to_string(n_fields) + " fields cannot fit in a " + std::to_string(size) +
                          "-byte file");

  std::uint64_t pos = kPreambleBytes;
  auto need = [&](std::uint64_t n, const std::string& what) {
    if (n > size - pos)
      throw FormatError(name, what, "truncated: the field table runs past the end of the file");
    more(storage, pos + n);
  };
  std::set<std::string, std::less<>> names;
  tf.fields.reserve(n_fields);
  for (std::uint32_t k = 0; k < n_fields; ++k) {
    const std::string entry = "field table entry " + std::to_string(k);
    need(2, entry);
    const auto len = load_le<std::uint16_t>(at(pos));
    pos += 2;
    if (len == 0) throw FormatError(name, entry, "has an empty name");
    need(len, entry);
    TensorField f;
    f.name.assign(reinterpret_cast<const char*>(at(pos)), len);
    pos += len;
    if (!std::all_of(f.name.begin(), f.name.end(), valid_name_char))
      throw FormatError(name, entry, "name has characters outside [A-Za-z0-9_.-]");
    const std::string field = "field '" + f.name + "'";
    if (!names.insert(f.name).second) throw FormatError(name, field, "appears twice");
    need(2 + 1 + 8, field);
    const auto ndim = load_le<std::uint16_t>(at(pos));
    pos += 2;
    const auto dtype = static_cast<std::uint8_t>(*at(pos));
    pos += 1;
    f.offset = load_le<std::uint64_t>(at(pos));
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
      s = load_le<std::uint64_t>(at(pos));
      pos += 8;
    }
    tf.fields.push_back(std::move(f));
  }
  const std::uint64_t table_end = pos;

  // The fields' extents, each checked against the file; the file ends with the last of them.
  std::uint64_t declared_end = table_end;
  std::vector<std::uint64_t> field_bytes;
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
    field_bytes.push_back(bytes_needed);
    declared_end = std::max(declared_end, f.offset + bytes_needed);
  }
  // The writers pad the last field to a multiple of 8 bytes with zeros; nothing else may follow.
  const std::uint64_t padded = (declared_end + 7) / 8 * 8;
  if (size > declared_end && size <= padded) {
    more(storage, size);
    if (std::any_of(at(declared_end), at(size), [](std::byte b) { return b != std::byte{0}; }))
      require_declared_size(name, declared_end, size, "the end of its last field");
  } else {
    require_declared_size(name, declared_end, size, "the end of its last field");
  }
  more(storage, size);
  tf.storage = std::move(storage);
  for (std::size_t k = 0; k < tf.fields.size(); ++k)
    tf.fields[k].bytes = std::span<const std::byte>(tf.storage.data() + tf.fields[k].offset,
                                                    static_cast<std::size_t>(field_bytes[k]));
  return tf;
}

}  // namespace

TensorFile parse_tensor_file(std::vector<std::byte> bytes, std::string_view name) {
  const std::uint64_t size = bytes.size();
  return parse(std::move(bytes), size, std::string(name),
               [](std::vector<std::byte>&, std::uint64_t) {});  // all in memory
}

TensorFile read_tensor_file(const std::filesystem::path& path) {
  BoundedFile file(path);
  if (file.size() > kMaxFileBytes)
    throw FormatError(file.name(), "file size",
                      std::to_string(file.size()) + " bytes is more than this format allows (" +
                          std::to_string(kMaxFileBytes) + " bytes)");
  return parse({}, file.size(), file.name(),
               [&](std::vector<std::byte>& storage, std::uint64_t end) {
                 file.extend(storage, end, "file");
               });
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
