// Writers of resampled tables (halfback/brdf/resample.hpp): OpenEXR, NumPy .npy and .npz.
//
// .npy is NumPy's format 1.0: the magic "\x93NUMPY", version 1.0, a little-endian uint16 header
// length, a Python dict literal (descr, fortran_order, shape) padded with spaces to a multiple of
// 64 bytes and ended by '\n', then the raw C-order data. .npz is a zip archive of .npy members,
// written here "stored" (no compression), with the CRC-32 of each member.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStdIO.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "halfback/formats/table_file.hpp"
#include "halfback/util/atomic_file.hpp"

namespace halfback {

namespace {

// JSON string literal of UTF-8 text.
std::string json_string(std::string_view s) {
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20)
          out += fmt::format("\\u{:04x}", static_cast<unsigned char>(c));
        else
          out += c;
    }
  }
  return out + "\"";
}

std::string shape_text(const GridSpec& g) {
  std::string s;
  for (const GridAxis& a : g.axes) s += fmt::format("{}{}", s.empty() ? "" : " ", a.count);
  return s;
}

// ---- .npy ----

template <class T>
void append_le(std::string& out, T value) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
  out.append(reinterpret_cast<const char*>(bytes), sizeof(T));
}

std::string npy_header(std::string_view descr, const std::vector<std::size_t>& shape) {
  std::string dims;
  for (std::size_t d : shape) dims += fmt::format("{}, ", d);
  if (shape.size() > 1) dims.resize(dims.size() - 2);  // (n,) keeps its comma; (a, b) does not
  if (shape.empty()) dims.clear();
  std::string dict =
      fmt::format("{{'descr': '{}', 'fortran_order': False, 'shape': ({}), }}", descr, dims);
  const std::size_t prefix = 10;  // magic (6) + version (2) + header length (2)
  const std::size_t total = (prefix + dict.size() + 1 + 63) / 64 * 64;
  dict.append(total - prefix - dict.size() - 1, ' ');
  dict += '\n';
  std::string out("\x93NUMPY\x01\x00", 8);
  append_le<std::uint16_t>(out, std::uint16_t(dict.size()));
  return out + dict;
}

std::string npy_float64(const std::vector<double>& values, const std::vector<std::size_t>& shape) {
  std::string out = npy_header("<f8", shape);
  out.reserve(out.size() + 8 * values.size());
  for (double v : values) append_le(out, v);
  return out;
}

std::string npy_bool(const std::vector<std::uint8_t>& values,
                     const std::vector<std::size_t>& shape) {
  std::string out = npy_header("|b1", shape);
  for (std::uint8_t v : values) out += char(v ? 1 : 0);
  return out;
}

// A 0-d or 1-d array of unicode strings ('<Un': UTF-32 little-endian, n code points each).
std::vector<char32_t> utf32(std::string_view s) {
  std::vector<char32_t> cps;
  for (std::size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    const int len = c < 0x80 ? 1 : c < 0xE0 ? 2 : c < 0xF0 ? 3 : 4;
    char32_t cp = len == 1 ? c : len == 2 ? (c & 0x1F) : len == 3 ? (c & 0x0F) : (c & 0x07);
    for (int j = 1; j < len && i + j < s.size(); ++j)
      cp = (cp << 6) | (static_cast<unsigned char>(s[i + j]) & 0x3F);
    cps.push_back(cp);
    i += std::size_t(len);
  }
  return cps;
}

std::string npy_strings(const std::vector<std::string>& items, bool scalar) {
  std::vector<std::vector<char32_t>> cps;
  std::size_t width = 1;
  for (const auto& s : items) {
    cps.push_back(utf32(s));
    width = std::max(width, cps.back().size());
  }
  std::string out =
      npy_header(fmt::format("<U{}", width),
                 scalar ? std::vector<std::size_t>{} : std::vector<std::size_t>{items.size()});
  for (const auto& c : cps)
    for (std::size_t j = 0; j < width; ++j)
      append_le<std::uint32_t>(out, j < c.size() ? std::uint32_t(c[j]) : 0u);
  return out;
}

// ---- .npz (zip, stored) ----

std::uint32_t crc32(std::string_view data) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (const char ch : data) c = table[(c ^ static_cast<unsigned char>(ch)) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

struct ZipMember {
  std::string name, data;
};

// The fields a local file header and its central directory entry share, from "version needed"
// to the name length: version 2.0, no flags, stored, DOS time and date 1980-01-01 00:00.
void append_entry_fields(std::string& out, std::uint32_t crc, std::uint32_t size,
                         std::size_t name_length) {
  append_le<std::uint16_t>(out, 20);    // version needed to extract
  append_le<std::uint16_t>(out, 0);     // flags
  append_le<std::uint16_t>(out, 0);     // method: stored
  append_le<std::uint16_t>(out, 0);     // time
  append_le<std::uint16_t>(out, 0x21);  // date
  append_le<std::uint32_t>(out, crc);
  append_le<std::uint32_t>(out, size);  // compressed
  append_le<std::uint32_t>(out, size);  // uncompressed
  append_le<std::uint16_t>(out, std::uint16_t(name_length));
}

std::string zip_stored(const std::vector<ZipMember>& members, const std::filesystem::path& path) {
  std::size_t total = 0;
  for (const ZipMember& m : members) total += 76 + 2 * m.name.size() + m.data.size();
  if (total >= 0xFFFFFFFFull)
    throw std::runtime_error(fmt::format(
        "cannot write '{}': the table is larger than the 4 GiB a plain zip (.npz) holds; use "
        ".exr or .npy",
        path.string()));
  std::string out, central;
  out.reserve(total);
  for (const ZipMember& m : members) {
    const std::uint32_t crc = crc32(m.data), size = std::uint32_t(m.data.size());
    const std::uint32_t offset = std::uint32_t(out.size());
    append_le<std::uint32_t>(out, 0x04034b50u);  // local file header
    append_entry_fields(out, crc, size, m.name.size());
    append_le<std::uint16_t>(out, 0);  // extra field length
    out += m.name;
    out += m.data;
    append_le<std::uint32_t>(central, 0x02014b50u);  // central directory entry
    append_le<std::uint16_t>(central, 20);           // version made by
    append_entry_fields(central, crc, size, m.name.size());
    for (int k = 0; k < 4; ++k) append_le<std::uint16_t>(central, 0);  // extra, comment, disk, attr
    append_le<std::uint32_t>(central, 0);                              // external attributes
    append_le<std::uint32_t>(central, offset);
    central += m.name;
  }
  const std::uint32_t central_offset = std::uint32_t(out.size());
  out += central;
  append_le<std::uint32_t>(out, 0x06054b50u);  // end of central directory
  append_le<std::uint16_t>(out, 0);
  append_le<std::uint16_t>(out, 0);
  append_le<std::uint16_t>(out, std::uint16_t(members.size()));
  append_le<std::uint16_t>(out, std::uint16_t(members.size()));
  append_le<std::uint32_t>(out, std::uint32_t(central.size()));
  append_le<std::uint32_t>(out, central_offset);
  append_le<std::uint16_t>(out, 0);
  return out;
}

std::vector<std::size_t> table_shape(const ResampledTable& t, bool with_channels) {
  std::vector<std::size_t> shape;
  for (const GridAxis& a : t.grid.axes) shape.push_back(a.count);
  if (with_channels) shape.push_back(3);
  return shape;
}

std::string npz_of(const ResampledTable& t, const std::filesystem::path& path) {
  std::vector<ZipMember> m;
  m.push_back({"rho.npy", npy_float64(t.rgb, table_shape(t, true))});
  m.push_back({"valid.npy", npy_bool(t.valid, table_shape(t, false))});
  std::vector<std::string> names;
  for (std::size_t a = 0; a < t.grid.axes.size(); ++a) {
    const GridAxis& ax = t.grid.axes[a];
    std::vector<double> p(ax.count);
    for (std::size_t i = 0; i < ax.count; ++i) p[i] = ax.position(i, t.grid.sampling);
    m.push_back({fmt::format("axis{}.npy", a), npy_float64(p, {ax.count})});
    names.push_back(ax.name);
  }
  m.push_back({"axis_names.npy", npy_strings(names, false)});
  m.push_back({"metadata.npy", npy_strings({table_metadata_json(t)}, true)});
  return zip_stored(m, path);
}

// ---- OpenEXR ----

std::string exr_of(const ResampledTable& t, const std::filesystem::path& path) {
  const GridSpec& g = t.grid;
  const std::size_t width = g.axes.back().count, height = g.points() / width;
  if (width > std::size_t(std::numeric_limits<int>::max()) ||
      height > std::size_t(std::numeric_limits<int>::max()))
    throw std::runtime_error(fmt::format(
        "cannot write '{}': the table is too large for an OpenEXR image", path.string()));
  std::vector<float> pixels(4 * g.points());
  for (std::size_t p = 0; p < g.points(); ++p) {
    for (int c = 0; c < 3; ++c) pixels[4 * p + c] = float(t.rgb[3 * p + c]);
    pixels[4 * p + 3] = t.valid[p] ? 1.f : 0.f;
  }
  try {
    Imf::StdOSStream stream;
    Imf::Header header{int(width), int(height)};
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const char* c : {"R", "G", "B", "valid"})
      header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    auto attr = [&](const std::string& name, const std::string& value) {
      header.insert("halfback:" + name, Imf::StringAttribute(value));
    };
    attr("parameterization", std::string(name_of(g.space)));
    attr("kind", std::string(name_of(g.kind)));
    attr("sampling", std::string(name_of(g.sampling)));
    attr("shape", shape_text(g));
    attr("layout", "row-major, last axis along x; the other axes run down the rows");
    if (g.kind == GridKind::slice) attr("slice_azimuth", fmt::format("{:.17g}", g.slice_azimuth));
    for (std::size_t a = 0; a < g.axes.size(); ++a) {
      const GridAxis& ax = g.axes[a];
      attr(fmt::format("axis{}", a), fmt::format("{} [{:.17g}, {:.17g}] {} {}", ax.name, ax.lo,
                                                 ax.hi, ax.count, name_of(g.sampling)));
    }
    attr("brdf", t.brdf_name);
    attr("brdf_description", t.brdf_description);
    attr("metadata", table_metadata_json(t));
    {
      // The OutputFile writes the scan-line offset table when it is destroyed: the stream is
      // complete only after this scope.
      Imf::OutputFile file(stream, header);
      Imf::FrameBuffer fb;
      char* base = reinterpret_cast<char*>(pixels.data());
      const std::size_t xs = 4 * sizeof(float), ys = xs * width;
      const char* names[] = {"R", "G", "B", "valid"};
      for (int c = 0; c < 4; ++c)
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
      file.setFrameBuffer(fb);
      file.writePixels(int(height));
    }
    return stream.str();
  } catch (const std::exception& e) {
    throw std::runtime_error(
        fmt::format("cannot write '{}': OpenEXR: {}", path.string(), e.what()));
  }
}

}  // namespace

std::string table_metadata_json(const ResampledTable& t) {
  const GridSpec& g = t.grid;
  std::string axes;
  for (const GridAxis& a : g.axes)
    axes += fmt::format("{}{{\"name\": {}, \"lo\": {:.17g}, \"hi\": {:.17g}, \"count\": {}}}",
                        axes.empty() ? "" : ", ", json_string(a.name), a.lo, a.hi, a.count);
  std::string s = fmt::format(
      "{{\"format\": \"halfback resampled table\", \"parameterization\": {}, \"kind\": {}, "
      "\"sampling\": {}, ",
      json_string(name_of(g.space)), json_string(name_of(g.kind)),
      json_string(name_of(g.sampling)));
  if (g.kind == GridKind::slice) s += fmt::format("\"slice_azimuth\": {:.17g}, ", g.slice_azimuth);
  s += fmt::format(
      "\"axes\": [{}], \"positions\": {}, \"order\": \"row-major, last axis fastest\", "
      "\"values\": \"rho (sr^-1, no cosine factor), RGB; NaN outside the domain\", "
      "\"brdf\": {}, \"brdf_description\": {}, \"valid_points\": {}}}",
      axes,
      json_string(g.sampling == GridSampling::centres
                      ? "cell centres: lo + (i + 0.5) (hi - lo) / count"
                      : "nodes: lo + i (hi - lo) / (count - 1)"),
      json_string(t.brdf_name), json_string(t.brdf_description), t.valid_count());
  return s;
}

std::optional<TableFormat> table_format_from_path(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".exr") return TableFormat::exr;
  if (ext == ".npz") return TableFormat::npz;
  if (ext == ".npy") return TableFormat::npy;
  return std::nullopt;
}

void write_table(const std::filesystem::path& path, const ResampledTable& t) {
  const auto format = table_format_from_path(path);
  if (!format)
    throw std::invalid_argument(fmt::format(
        "cannot tell the table format of '{}': use a .exr, .npz or .npy file name", path.string()));
  if (t.rgb.size() != 3 * t.grid.points() || t.valid.size() != t.grid.points())
    throw std::invalid_argument("write_table: the table's arrays do not match its grid");
  // The file is opened first, so that an unwritable destination fails before any encoding.
  AtomicFile out(path);
  switch (*format) {
    case TableFormat::exr:
      out.write(exr_of(t, path));
      break;
    case TableFormat::npz:
      out.write(npz_of(t, path));
      break;
    case TableFormat::npy:
      out.write(npy_float64(t.rgb, table_shape(t, true)));
      break;
  }
  out.commit();
}

}  // namespace halfback
