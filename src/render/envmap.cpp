#include "halfback/render/envmap.hpp"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfEnvmap.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <fmt/format.h>
#include <stb_image.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "halfback/util/bounded_read.hpp"
#include "halfback/util/format_error.hpp"

namespace halfback::render {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr long long kMaxPixels = 1LL << 28;  // 268 M pixels: 3 GiB of floats

std::string describe_value(float v) {
  if (std::isnan(v)) return "NaN";
  if (std::isinf(v)) return v > 0 ? "+Inf" : "-Inf";
  std::ostringstream s;
  s << v;
  return s.str();
}

// The first bad pixel and the number of bad values, or an empty string when all are valid.
std::string check_pixels(int width, std::span<const float> rgb) {
  std::size_t bad = 0, first = 0;
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    const float v = rgb[i];
    if (!(std::isfinite(v) && v >= 0)) {
      if (bad++ == 0) first = i;
    }
  }
  if (bad == 0) return {};
  const std::size_t pixel = first / 3;
  const char channel = "RGB"[first % 3];
  std::ostringstream s;
  s << bad << " invalid value" << (bad > 1 ? "s" : "") << " (radiance must be finite and >= 0); "
    << "first at pixel (x=" << pixel % std::size_t(width) << ", y=" << pixel / std::size_t(width)
    << ") channel " << channel << ": " << describe_value(rgb[first]);
  return s.str();
}

// Measured radiance carries noise: negative values no further below 0 than kEnvNoiseFraction of the
// map's largest value are set to 0 (counted); larger ones are left for check_pixels to refuse.
std::size_t clamp_noise(std::vector<float>& rgb) {
  float largest = 0;
  for (float v : rgb)
    if (std::isfinite(v)) largest = std::max(largest, v);
  const float floor = -float(kEnvNoiseFraction) * largest;
  std::size_t clamped = 0;
  for (float& v : rgb)
    if (v < 0 && v >= floor) {
      v = 0;
      ++clamped;
    }
  return clamped;
}

// A file's first bytes are read into this much at most before its format is known; a Radiance
// header must end within it, an OpenEXR header within kMaxExrHeader.
constexpr std::size_t kHeadBytes = std::size_t(1) << 16;
constexpr std::uint64_t kMaxExrHeader = std::uint64_t(1) << 24;

using Bytes = std::vector<std::byte>;

unsigned char byte_at(const Bytes& b, std::size_t i) {
  return static_cast<unsigned char>(b[i]);
}

// The size a header declares, checked before anything is allocated from it: pixels, the limit on
// their number, and the 2:1 shape of a latitude-longitude map.
void check_map_size(const std::string& file, const std::string& field, long long w, long long h) {
  if (w <= 0 || h <= 0)
    throw FormatError(file, field, "zero-size image: an environment map needs pixels");
  if (w > kMaxPixels / h)
    throw FormatError(file, field,
                      "image too large: " + std::to_string(w) + " x " + std::to_string(h) +
                          " pixels, more than the limit of " + std::to_string(kMaxPixels));
  if (std::abs(w - 2 * h) > 1)
    throw FormatError(file, "size",
                      std::to_string(w) + " x " + std::to_string(h) +
                          " is not a latitude-longitude map (width must be twice the height)");
}

bool is_exr(const Bytes& b) {
  return b.size() >= 4 && byte_at(b, 0) == 0x76 && byte_at(b, 1) == 0x2f && byte_at(b, 2) == 0x31 &&
         byte_at(b, 3) == 0x01;
}

bool is_radiance(const Bytes& b) {
  return b.size() >= 2 && byte_at(b, 0) == '#' && byte_at(b, 1) == '?';
}

// Walks the scanlines of Radiance pixel data (flat RGBE, or the run-length encoding of each
// channel), checks that they are complete (stb_image reads past a truncated file as zeros), and
// returns where they end.
std::size_t radiance_data_end(const std::string& file, std::span<const unsigned char> d,
                              std::size_t width, std::size_t height) {
  auto truncated = [&](std::size_t y) {
    throw FormatError(file, "Radiance data",
                      "truncated: the pixel data ends in scanline " + std::to_string(y) + " of " +
                          std::to_string(height));
  };
  std::size_t pos = 0;
  for (std::size_t y = 0; y < height; ++y) {
    const bool rle = width >= 8 && width < 32768 && pos + 4 <= d.size() && d[pos] == 2 &&
                     d[pos + 1] == 2 && !(d[pos + 2] & 0x80);
    if (!rle) {  // flat pixels from here to the end of the image
      if (d.size() - std::min(pos, d.size()) < 4 * width * (height - y)) truncated(y);
      return pos + 4 * width * (height - y);
    }
    if ((std::size_t(d[pos + 2]) << 8 | d[pos + 3]) != width)
      throw FormatError(file, "Radiance data",
                        "scanline " + std::to_string(y) + " has the wrong length");
    pos += 4;
    for (int channel = 0; channel < 4; ++channel)
      for (std::size_t x = 0; x < width;) {
        if (pos >= d.size()) truncated(y);
        std::size_t count = d[pos++];
        if (count > 128) {
          count -= 128;
          pos += 1;
        } else {
          pos += count;
        }
        if (count == 0 || x + count > width)
          throw FormatError(file, "Radiance data",
                            "bad run-length encoding in scanline " + std::to_string(y));
        if (pos > d.size()) truncated(y);
        x += count;
      }
  }
  return pos;
}

// Where a Radiance file's pixels start and how many there are: the header lines up to an empty
// one, then the resolution line ("-Y H +X W"), parsed here so that a zero-size image gets its own
// message rather than stb's generic one. `b` holds the file's first bytes, of `size`.
struct RadianceLayout {
  std::size_t data_start = 0;
  long long width = 0, height = 0;
};

RadianceLayout radiance_layout(const std::string& file, std::span<const unsigned char> b,
                               std::uint64_t size) {
  std::size_t i = 0;
  bool blank = false;
  while (i < b.size() && !blank) {  // header lines up to an empty one
    const std::size_t start = i;
    while (i < b.size() && b[i] != '\n') ++i;
    blank = (i == start);
    ++i;
  }
  if (!blank)
    throw FormatError(file, "Radiance header",
                      b.size() < size ? "no blank line ends the header within its first " +
                                            std::to_string(b.size()) + " bytes"
                                      : std::string("no blank line ends the header"));
  std::string line;
  while (i < b.size() && b[i] != '\n' && line.size() < 100) line.push_back(char(b[i++]));
  ++i;  // the data starts after the resolution line
  std::istringstream s(line);
  std::string a1, a2;
  long long n1 = -1, n2 = -1;
  s >> a1 >> n1 >> a2 >> n2;
  if (!s || a1.size() != 2 || a2.size() != 2)
    throw FormatError(file, "Radiance resolution line", "cannot parse '" + line + "'");
  if (n1 <= 0 || n2 <= 0)
    throw FormatError(file, "Radiance resolution line",
                      "zero-size image ('" + line + "'): an environment map needs pixels");
  if (a1 != "-Y" || a2 != "+X")
    throw FormatError(file, "Radiance resolution line",
                      "unsupported orientation '" + line + "' (expected -Y H +X W)");
  check_map_size(file, "Radiance resolution line", n2, n1);
  return {std::min(i, b.size()), n2, n1};
}

struct Loaded {
  int width = 0, height = 0;
  std::vector<float> rgb;
};

// The header, then the size check (a file larger than its pixels can take is refused unread),
// then the pixel data, whose end must be the file's.
Loaded load_radiance(BoundedFile& in, Bytes bytes) {
  const std::string& file = in.name();
  const auto head = [&] {
    return std::span(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
  };
  const RadianceLayout layout = radiance_layout(file, head(), in.size());
  const auto w = std::uint64_t(layout.width), h = std::uint64_t(layout.height);
  // A run-length encoded scanline takes at most 4 + 8w bytes (2 bytes a pixel and channel).
  const std::uint64_t most = h * (4 + 8 * w), after = in.size() - layout.data_start;
  if (after > most)
    throw FormatError(file, "file size",
                      fmt::format("{} × {} pixels take at most {} bytes after the {}-byte header, "
                                  "the file has {} bytes after it: at least {} bytes of trailing "
                                  "data",
                                  w, h, most, layout.data_start, after, after - most));
  if (in.size() > std::uint64_t(std::numeric_limits<int>::max()))
    throw FormatError(file, "file", "too large");
  in.extend(bytes, in.size(), "Radiance data");
  const std::size_t end = radiance_data_end(file, head().subspan(layout.data_start), w, h);
  require_declared_size(
      file, layout.data_start + end, in.size(),
      fmt::format("{} × {} RGBE pixels after a {}-byte header", w, h, layout.data_start));
  if (!stbi_is_hdr_from_memory(head().data(), int(bytes.size())))
    throw FormatError(file, "Radiance header",
                      "not a Radiance HDR file (expected '#?RADIANCE' or '#?RGBE')");
  int width = 0, height = 0, comp = 0;
  float* data = stbi_loadf_from_memory(head().data(), int(bytes.size()), &width, &height, &comp, 3);
  if (!data) {
    const char* why = stbi_failure_reason();
    throw FormatError(file, "Radiance data",
                      std::string("cannot decode: ") + (why ? why : "unknown error"));
  }
  Loaded out;
  out.width = width;
  out.height = height;
  out.rgb.assign(data, data + std::size_t(width) * std::size_t(height) * 3);
  stbi_image_free(data);
  return out;
}

// Lines per chunk of a scanline OpenEXR file, by compression (the OpenEXR file layout).
int exr_lines_per_chunk(Imf::Compression c) {
  switch (c) {
    case Imf::ZIP_COMPRESSION:
    case Imf::PXR24_COMPRESSION:
      return 16;
    case Imf::PIZ_COMPRESSION:
    case Imf::B44_COMPRESSION:
    case Imf::B44A_COMPRESSION:
    case Imf::DWAA_COMPRESSION:
      return 32;
    case Imf::DWAB_COMPRESSION:
      return 256;
    default:
      return 1;
  }
}

// Checks, before OpenEXR or this reader allocate anything from the header's sizes, that a
// single-part scanline file holds the chunks its header declares and nothing after them. Its
// chunks follow the offset table (8 bytes a chunk) one after the other, each an int32 y, an int32
// data size and the data; they are walked as OpenEXR walks them when the table is incomplete,
// which also covers files whose table was left zero, reading 8 bytes a chunk. Tiled, deep and
// multi-part files, and headers this walk cannot follow, are left to OpenEXR and to the
// incremental decoding. `b` holds the file's first bytes; it grows to hold the whole header.
void check_exr_chunks(BoundedFile& in, Bytes& b) {
  const std::string& file = in.name();
  if (b.size() < 8 || (byte_at(b, 5) & 0x1a) != 0) return;  // tiled, deep or multi-part
  // Makes b hold the file's first `end` bytes; false past the end of the file.
  auto have = [&](std::uint64_t end) {
    if (end <= b.size()) return true;
    if (end > in.size()) return false;
    if (end > kMaxExrHeader)
      throw FormatError(file, "OpenEXR header",
                        fmt::format("longer than the limit of {} bytes", kMaxExrHeader));
    in.extend(b, std::min<std::uint64_t>(in.size(), std::max<std::uint64_t>(end, 2 * b.size())),
              "OpenEXR header");
    return true;
  };
  auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = v << 8 | byte_at(b, at + std::size_t(i));
    return v;
  };
  std::size_t pos = 8;
  long long height = -1, width = -1;
  auto compression = Imf::NUM_COMPRESSION_METHODS;
  while (have(pos + 1) && b[pos] != std::byte{0}) {  // attributes: name\0 type\0 size value
    const std::size_t name = pos;
    for (int strings = 0; strings < 2; ++strings) {
      while (have(pos + 1) && b[pos] != std::byte{0}) ++pos;
      ++pos;
    }
    if (!have(pos + 4)) return;
    const std::uint32_t size = u32(pos);
    pos += 4;
    if (!have(pos + std::uint64_t(size))) return;
    const std::string_view key(reinterpret_cast<const char*>(&b[name]));
    if (key == "dataWindow" && size == 16) {
      width = (long long)std::int32_t(u32(pos + 8)) - std::int32_t(u32(pos)) + 1;
      height = (long long)std::int32_t(u32(pos + 12)) - std::int32_t(u32(pos + 4)) + 1;
    } else if (key == "compression" && size == 1 &&
               byte_at(b, pos) < Imf::NUM_COMPRESSION_METHODS) {
      compression = Imf::Compression(byte_at(b, pos));
    }
    pos += size;
  }
  if (!have(pos + 1) || height < 0 || compression == Imf::NUM_COMPRESSION_METHODS) return;
  check_map_size(file, "dataWindow", width, height);
  const int lines = exr_lines_per_chunk(compression);
  const auto chunks = std::uint64_t((height + lines - 1) / lines);
  std::uint64_t found = 0;
  std::uint64_t at = std::uint64_t(pos) + 1 + 8 * chunks;  // after the offset table
  const std::uint64_t size = in.size();
  std::array<std::byte, 8> chunk_head;
  while (found < chunks && at + 8 <= size) {
    in.read_at(at, chunk_head, "OpenEXR chunk");
    std::uint32_t data_size = 0;
    for (int i = 7; i >= 4; --i) data_size = data_size << 8 | std::uint8_t(chunk_head[i]);
    if (data_size > size - at - 8) break;
    at += 8 + data_size;
    ++found;
  }
  if (found < chunks)
    throw FormatError(file, "dataWindow",
                      "the file is too short for its header: " + std::to_string(width) + " x " +
                          std::to_string(height) + " pixels in " + std::to_string(chunks) +
                          " chunks, the file (" + std::to_string(size) + " bytes) holds " +
                          std::to_string(found));
  require_declared_size(file, at, size,
                        fmt::format("{} × {} pixels in {} chunks", width, height, chunks));
}

// Decodes the pixels in bands of scanlines, growing the output as the bands decode, so that a
// header claiming more pixels than the file holds fails at its first missing chunk, having
// allocated about what the file really contains (plus an initial reserve in proportion to the
// file's size).
void read_exr_pixels(Imf::InputFile& in, bool rgb, Loaded& out, std::size_t file_bytes) {
  const Imath::Box2i dw = in.header().dataWindow();
  const std::size_t w = std::size_t(out.width), line = 3 * w;
  const std::size_t total = line * std::size_t(out.height);
  out.rgb.reserve(std::min(total, 64 * file_bytes / sizeof(float)));  // a small multiple
  // Whole chunks (16 lines at least), so that no chunk is decompressed twice.
  const int band = std::max(16, exr_lines_per_chunk(in.header().compression()));
  for (long long y = dw.min.y; y <= dw.max.y; y += band) {
    const int last = int(std::min<long long>(dw.max.y, y + band - 1));
    out.rgb.resize(line * std::size_t(last - dw.min.y + 1), 0.0f);
    // The frame buffer's base points at pixel (0, 0) of the coordinate system, so that the data
    // window's first pixel lands at index 0.
    char* base = reinterpret_cast<char*>(out.rgb.data()) -
                 (std::ptrdiff_t(dw.min.x) + std::ptrdiff_t(dw.min.y) * std::ptrdiff_t(w)) * 3 *
                     std::ptrdiff_t(sizeof(float));
    const std::size_t xs = 3 * sizeof(float), ys = w * xs;
    Imf::FrameBuffer fb;
    if (rgb) {
      fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
      fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
      fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
    } else {
      fb.insert("Y", Imf::Slice(Imf::FLOAT, base, xs, ys));
    }
    in.setFrameBuffer(fb);
    in.readPixels(int(y), last);
  }
  if (!rgb)
    for (std::size_t i = 0; i < out.rgb.size(); i += 3)
      out.rgb[i + 1] = out.rgb[i + 2] = out.rgb[i];
}

Loaded load_openexr(BoundedFile& file_in, Bytes head) {
  const std::string& file = file_in.name();
  check_exr_chunks(file_in, head);
  try {
    Imf::InputFile in(file.c_str());
    const Imf::Header& header = in.header();
    if (Imf::hasEnvmap(header) && Imf::envmap(header) == Imf::ENVMAP_CUBE)
      throw FormatError(file, "envmap attribute",
                        "a cube map; only latitude-longitude maps are supported");
    const Imath::Box2i dw = header.dataWindow();
    const long long w = (long long)dw.max.x - dw.min.x + 1, h = (long long)dw.max.y - dw.min.y + 1;
    check_map_size(file, "dataWindow", w, h);
    const Imf::ChannelList& channels = header.channels();
    const bool rgb =
        channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B");
    const bool grey = !rgb && channels.findChannel("Y");
    if (!rgb && !grey) {
      std::string names;
      for (auto it = channels.begin(); it != channels.end(); ++it)
        names += (names.empty() ? "" : ", ") + std::string(it.name());
      throw FormatError(file, "channels",
                        "needs R, G, B (or Y) channels; the file has: " +
                            (names.empty() ? std::string("none") : names));
    }
    Loaded out;
    out.width = int(w);
    out.height = int(h);
    read_exr_pixels(in, rgb, out, std::size_t(file_in.size()));
    return out;
  } catch (const FormatError&) {
    throw;
  } catch (const std::exception& e) {
    throw FormatError(file, "OpenEXR", e.what());
  }
}

}  // namespace

// --------------------------------------------------------------------------------------------

EnvMap::EnvMap(int width, int height, std::vector<float> rgb, std::string name, EnvOptions options)
    : width_(width),
      height_(height),
      rgb_(std::move(rgb)),
      name_(std::move(name)),
      options_(options) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument(name_ + ": zero-size image (" + std::to_string(width) + " x " +
                                std::to_string(height) + ")");
  if ((long long)width * height > kMaxPixels)
    throw std::invalid_argument(name_ + ": image too large");
  if (rgb_.size() != std::size_t(width) * std::size_t(height) * 3)
    throw std::invalid_argument(name_ + ": " + std::to_string(rgb_.size()) + " values for " +
                                std::to_string(width) + " x " + std::to_string(height) +
                                " RGB pixels");
  if (const std::string bad = check_pixels(width, rgb_); !bad.empty())
    throw std::invalid_argument(name_ + ": " + bad);
  if (!std::isfinite(options.exposure) || std::abs(options.exposure) > 64)
    throw std::invalid_argument(name_ + ": exposure must be a finite number of stops in [-64, 64]");
  if (!std::isfinite(options.rotation_deg))
    throw std::invalid_argument(name_ + ": rotation must be finite");
  scale_ = std::exp2(options.exposure);
  const double rot = options.rotation_deg * kPi / 180;
  cos_rot_ = std::cos(rot);
  sin_rot_ = std::sin(rot);

  // Pixel probability ∝ luminance × solid angle; within a pixel, uniform in solid angle.
  row_solid_angle_.resize(std::size_t(height));
  row_cos_.resize(std::size_t(height) + 1);
  for (int r = 0; r <= height; ++r) row_cos_[std::size_t(r)] = std::cos(kPi * double(r) / height);
  col_edge_.resize(std::size_t(width));
  for (int c = 0; c < width; ++c) {
    const double phi = 2 * kPi * c / width - kPi;
    col_edge_[std::size_t(c)] = {std::cos(phi), std::sin(phi)};
  }
  // The row of cos θ = 1 − 2k / n at the top of each of n = 4 × height buckets in cos θ.
  row_guide_.resize(4 * std::size_t(height));
  for (std::size_t k = 0, r = 0; k < row_guide_.size(); ++k) {
    const double c = 1 - 2 * double(k) / double(row_guide_.size());
    while (r + 1 < std::size_t(height) && !(c > row_cos_[r + 1])) ++r;
    row_guide_[k] = std::uint32_t(r);
  }
  const double dphi = 2 * kPi / width;
  for (std::size_t r = 0; r < std::size_t(height); ++r)
    row_solid_angle_[r] = dphi * (row_cos_[r] - row_cos_[r + 1]);
  row_inverse_solid_angle_.resize(row_solid_angle_.size());
  for (std::size_t r = 0; r < row_solid_angle_.size(); ++r)
    row_inverse_solid_angle_[r] = 1 / row_solid_angle_[r];
  std::vector<double> weights(std::size_t(width) * std::size_t(height));
  for (std::size_t i = 0; i < weights.size(); ++i) {
    const float* p = &rgb_[3 * i];
    weights[i] = Rgb{p[0], p[1], p[2]}.luminance() * row_solid_angle_[i / std::size_t(width)];
  }
  distribution_ = Distribution2D(std::size_t(height), std::size_t(width), weights);
  // MIS compensation: the luminance above its solid-angle mean.
  double mean = 0;
  for (double w : weights) mean += w;
  mean /= 4 * kPi;
  std::vector<double> compensated(weights.size());
  double total = 0;
  for (std::size_t i = 0; i < weights.size(); ++i) {
    const double omega = row_solid_angle_[i / std::size_t(width)];
    compensated[i] = std::max(0.0, weights[i] - mean * omega);
    total += compensated[i];
  }
  compensated_ = total > 0 ? Distribution2D(std::size_t(height), std::size_t(width), compensated)
                           : distribution_;
  const double power = mean * 4 * kPi;
  residual_ = power > 0 ? std::clamp(1 - total / power, 0.0, 1.0) : 1.0;
}

EnvMap EnvMap::constant(const Rgb& radiance, EnvOptions options) {
  std::ostringstream name;
  name << "constant:" << radiance.r << "," << radiance.g << "," << radiance.b;
  return EnvMap(1, 1, {float(radiance.r), float(radiance.g), float(radiance.b)}, name.str(),
                options);
}

EnvMap EnvMap::from_spec(std::string_view spec, EnvOptions options) {
  if (spec == "default" || spec == "sky") return default_sky(options);
  if (spec == "studio") return studio(options);
  if (spec == "sunset") return sunset(options);
  constexpr std::string_view prefix = "constant:";
  if (spec.substr(0, prefix.size()) == prefix) {
    std::vector<double> v;
    std::string_view rest = spec.substr(prefix.size());
    while (true) {
      const std::size_t comma = rest.find(',');
      const std::string_view item = rest.substr(0, comma);
      double x = 0;
      const auto r = std::from_chars(item.data(), item.data() + item.size(), x);
      if (item.empty() || r.ec != std::errc() || r.ptr != item.data() + item.size())
        throw std::invalid_argument("environment '" + std::string(spec) + "': '" +
                                    std::string(item) + "' is not a number");
      if (!std::isfinite(x) || x < 0)
        throw std::invalid_argument("environment '" + std::string(spec) +
                                    "': radiance must be finite and >= 0");
      v.push_back(x);
      if (comma == std::string_view::npos) break;
      rest = rest.substr(comma + 1);
    }
    if (v.size() != 1 && v.size() != 3)
      throw std::invalid_argument("environment '" + std::string(spec) +
                                  "': expected constant:V or constant:R,G,B");
    return v.size() == 1 ? constant({v[0], v[0], v[0]}, options)
                         : constant({v[0], v[1], v[2]}, options);
  }
  const std::filesystem::path path{std::string(spec)};
  std::error_code ec;
  if (spec.empty() || !std::filesystem::exists(path, ec))
    throw std::invalid_argument(fmt::format(
        "environment '{}': neither a built-in ({}), constant:V or constant:R,G,B, nor an "
        "existing file",
        spec, fmt::join(builtin_names(), ", ")));
  return load(path, options);
}

EnvMap EnvMap::load(const std::filesystem::path& path, EnvOptions options) {
  const std::string file = path.string();
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw FormatError(file, "file", "is a directory, not an image");
  if (!std::filesystem::exists(path, ec))
    throw FormatError(file, "file", std::string("cannot open: ") + std::strerror(ENOENT));
  BoundedFile in(path);  // read as far as the header declares: a padded file is not read whole
  Bytes head = in.head(kHeadBytes);
  if (head.empty()) throw FormatError(file, "file", "empty file, not an HDR image");
  Loaded img;
  if (is_exr(head)) {
    img = load_openexr(in, std::move(head));
  } else if (is_radiance(head)) {
    img = load_radiance(in, std::move(head));
  } else {
    throw FormatError(file, "content",
                      "not an HDR image: expected a Radiance .hdr ('#?RADIANCE' header) or an "
                      "OpenEXR file");
  }
  if (img.width <= 0 || img.height <= 0)
    throw FormatError(file, "size", "zero-size image: an environment map needs pixels");
  if (std::abs(img.width - 2 * img.height) > 1)
    throw FormatError(file, "size",
                      std::to_string(img.width) + " x " + std::to_string(img.height) +
                          " is not a latitude-longitude map (width must be twice the height)");
  const std::size_t clamped = clamp_noise(img.rgb);
  if (const std::string bad = check_pixels(img.width, img.rgb); !bad.empty())
    throw FormatError(file, "pixels", bad);
  EnvMap map(img.width, img.height, std::move(img.rgb), file, options);
  map.noise_clamped_ = clamped;
  return map;
}

// --------------------------------------------------------------------------------------------

Vec3<double> EnvMap::map_direction(double u, double v) {
  const double theta = kPi * v, phi = 2 * kPi * u - kPi;
  const double st = std::sin(theta);
  return {st * std::sin(phi), std::cos(theta), -st * std::cos(phi)};
}

void EnvMap::map_coordinates(const Vec3<double>& d, double& u, double& v) {
  const double theta = std::atan2(std::sqrt(d.x * d.x + d.z * d.z), d.y);
  const double phi = std::atan2(d.x, -d.z);  // (−π, π]
  u = (phi + kPi) / (2 * kPi);
  if (!(u < 1)) u = 0;  // φ = π is the left edge again
  v = theta / kPi;
}

// The map is turned by +rotation about +y, so a world direction is looked up turned by −rotation.
// Inline: the loops of pixels_of vectorize with them.
[[gnu::always_inline]] inline Vec3<double> EnvMap::to_map(const Vec3<double>& w) const {
  return {cos_rot_ * w.x - sin_rot_ * w.z, w.y, sin_rot_ * w.x + cos_rot_ * w.z};
}
Vec3<double> EnvMap::to_world(const Vec3<double>& m) const {
  return {cos_rot_ * m.x + sin_rot_ * m.z, m.y, -sin_rot_ * m.x + cos_rot_ * m.z};
}

namespace {

// atan2(y, x) to within about 1e-5 rad (a minimax polynomial of atan on [0, 1], Abramowitz and
// Stegun 4.4.49's form), without a library call or a branch (loops over it vectorize): a first
// guess of a pixel, which the exact edge tests of EnvMap::place then correct.
[[gnu::always_inline]] inline double approx_atan2(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const double big = std::max(ax, ay), small = std::min(ax, ay);
  const double a = small / (big > 0 ? big : 1.0), a2 = a * a;
  const double r0 =
      a *
      (0.99986600 + a2 * (-0.33029950 + a2 * (0.18014100 + a2 * (-0.08513300 + a2 * 0.02083510))));
  const double r1 = kPi / 2 - r0, q1 = ay > ax ? r1 : r0;
  const double r2 = kPi - q1, q2 = x < 0 ? r2 : q1;
  return y < 0 ? -q2 : q2;
}

}  // namespace

// The guess: the bucket of cos θ in the rows' guide table, φ by approx_atan2 as a fractional
// column. No branches.
[[gnu::always_inline]] inline EnvMap::Guess EnvMap::guess(const Vec3<double>& d) const {
  const double rho2 = d.x * d.x + d.z * d.z, len = std::sqrt(rho2 + d.y * d.y);
  const double t = 0.5 * (1 - d.y / len);
  Guess g;
  g.rho2 = rho2;
  g.len = len;
  g.row = (t > 0 ? (t < 1 ? t : 1.0) : 0.0) * double(row_guide_.size());
  g.col = (approx_atan2(d.x, -d.z) + kPi) * (double(width_) / (2 * kPi));
  return g;
}

// The pixel of a direction, as map_coordinates() places it, from the guess: the row's and the
// column's edges tested exactly (cos θ against the rows' edges; the side of the columns' edge
// half-planes), moving a pixel when the guess was within approx_atan2's error of an edge. A
// direction the tests cannot place (on the axis, where every column meets) falls back to
// map_coordinates. Equal to it except within rounding of an edge.
std::size_t EnvMap::place(const Vec3<double>& d, const Guess& g, std::size_t& row,
                          std::size_t& col) const {
  const std::size_t w = std::size_t(width_), h = std::size_t(height_);
  auto exact = [&] {
    double u, v;
    map_coordinates(d, u, v);
    col = std::min(std::size_t(u * width_), w - 1);
    row = std::min(std::size_t(v * height_), h - 1);
    return row * w + col;
  };
  if (w < 8 || !(g.rho2 > 1e-300)) return exact();
  // Row r holds cos θ ∈ (row_cos_[r + 1], row_cos_[r]]; the guide gives the row of the bucket's
  // top in cos θ.
  const double len = g.len;
  const std::size_t buckets = row_guide_.size();
  std::size_t r = row_guide_[std::min(std::size_t(g.row), buckets - 1)];
  while (r > 0 && d.y > row_cos_[r] * len) --r;
  while (r + 1 < h && !(d.y > row_cos_[r + 1] * len)) ++r;
  // Column c holds the directions on or after its left edge and before the next one.
  std::size_t c = std::min(std::size_t(std::max(0.0, g.col)), w - 1);
  auto after = [&](std::size_t edge) {
    return d.x * col_edge_[edge].cos + d.z * col_edge_[edge].sin >= 0;
  };
  for (int step = 0;; ++step) {
    if (step == 3) return exact();
    if (!after(c)) {
      c = c == 0 ? w - 1 : c - 1;
    } else if (after(c + 1 == w ? 0 : c + 1)) {
      c = c + 1 == w ? 0 : c + 1;
    } else {
      break;
    }
  }
  row = r;
  col = c;
  return row * w + col;
}

std::size_t EnvMap::pixel_of(const Vec3<double>& d, std::size_t& row, std::size_t& col) const {
  return place(d, guess(d), row, col);
}

// The pixels of n world directions: all the map directions and guesses first, in a loop without
// branches that the compiler vectorizes, then the exact tests.
void EnvMap::pixels_of(const Vec3<double>* world, std::size_t n, Vec3<double>* map,
                       std::size_t* row, std::size_t* col, std::size_t* index) const {
  Guess g[kChunk];
  for (std::size_t i = 0; i < n; ++i) {
    map[i] = to_map(world[i]);
    g[i] = guess(map[i]);
  }
  for (std::size_t i = 0; i < n; ++i) index[i] = place(map[i], g[i], row[i], col[i]);
}

Rgb EnvMap::eval(const Vec3<double>& dir) const {
  std::size_t row, col;
  const std::size_t i = pixel_of(to_map(dir), row, col);
  const float* p = &rgb_[3 * i];
  return {p[0] * scale_, p[1] * scale_, p[2] * scale_};
}

EnvMap::Sample EnvMap::sample(double u1, double u2, bool compensated) const {
  return sample_in((compensated ? compensated_ : distribution_).sample(u1, u2));
}

void EnvMap::sample(std::span<const double> u1, std::span<const double> u2, bool compensated,
                    std::span<Sample> out) const {
  if (u1.size() != out.size() || u2.size() != out.size())
    throw std::invalid_argument("EnvMap::sample: the spans' sizes differ");
  Distribution2D::Sample cells[kChunk];
  const Distribution2D& d = compensated ? compensated_ : distribution_;
  for (std::size_t begin = 0; begin < out.size(); begin += kChunk) {
    const std::size_t n = std::min(kChunk, out.size() - begin);
    d.sample(u1.subspan(begin, n), u2.subspan(begin, n), std::span(cells, n));
    for (std::size_t i = 0; i < n; ++i) out[begin + i] = sample_in(cells[i]);
  }
}

EnvMap::Sample EnvMap::sample_in(const Distribution2D::Sample& cell) const {
  Sample s;
  if (cell.probability <= 0) return s;
  const double c0 = row_cos_[cell.row], c1 = row_cos_[cell.row + 1];
  const double cos_theta = std::clamp(c0 + (c1 - c0) * cell.remapped_row, -1.0, 1.0);
  const double sin_theta = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
  double sin_phi, cos_phi;
  column_sincos(cell.col, cell.remapped_col, sin_phi, cos_phi);
  const Vec3<double> m{sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi};
  s.dir = to_world(m);
  const float* p = &rgb_[3 * (cell.row * std::size_t(width_) + cell.col)];
  s.radiance = {p[0] * scale_, p[1] * scale_, p[2] * scale_};
  s.pdf = cell.probability * row_inverse_solid_angle_[cell.row];
  return s;
}

double EnvMap::pdf(const Vec3<double>& dir, bool compensated) const {
  std::size_t row, col;
  pixel_of(to_map(dir), row, col);
  return (compensated ? compensated_ : distribution_).probability(row, col) *
         row_inverse_solid_angle_[row];
}

// sin φ and cos φ of φ = 2π (col + t) / W − π: the column's left edge turned by δ = 2π t / W,
// whose sine and cosine are short series when the columns are narrow (δ < 0.1: the terms left out
// are below 1e-18).
void EnvMap::column_sincos(std::size_t col, double t, double& sin_phi, double& cos_phi) const {
  if (width_ < 64) {
    const double phi = 2 * kPi * (double(col) + t) / width_ - kPi;
    sin_phi = std::sin(phi);
    cos_phi = std::cos(phi);
    return;
  }
  const double d = 2 * kPi * t / width_, d2 = d * d;
  // Taylor coefficients ±1/n!, by Horner's rule.
  const double sd =
      d * (1 + d2 * (-1.0 / 6 + d2 * (1.0 / 120 + d2 * (-1.0 / 5040 + d2 * (1.0 / 362880)))));
  const double cd =
      1 + d2 * (-0.5 + d2 * (1.0 / 24 + d2 * (-1.0 / 720 + d2 * (1.0 / 40320 - d2 / 3628800))));
  const Edge& e = col_edge_[col];
  sin_phi = e.sin * cd + e.cos * sd;
  cos_phi = e.cos * cd - e.sin * sd;
}

void EnvMap::eval(std::span<const Vec3<double>> dirs, std::span<Rgb> out) const {
  if (dirs.size() != out.size())
    throw std::invalid_argument("EnvMap::eval: the spans' sizes differ");
  Vec3<double> map[kChunk];
  std::size_t rows[kChunk], cols[kChunk], index[kChunk];
  for (std::size_t begin = 0; begin < out.size(); begin += kChunk) {
    const std::size_t n = std::min(kChunk, out.size() - begin);
    pixels_of(dirs.data() + begin, n, map, rows, cols, index);
    for (std::size_t i = 0; i < n; ++i) {
      const float* p = &rgb_[3 * index[i]];
      out[begin + i] = {p[0] * scale_, p[1] * scale_, p[2] * scale_};
    }
  }
}

bool EnvMap::uniform(std::span<const Vec3<double>> dirs, Rgb& radiance) const {
  Vec3<double> map[kChunk];
  std::size_t rows[kChunk], cols[kChunk], index[kChunk];
  if (dirs.empty() || dirs.size() > kChunk) return false;
  pixels_of(dirs.data(), dirs.size(), map, rows, cols, index);
  for (std::size_t i = 1; i < dirs.size(); ++i)
    if (index[i] != index[0]) return false;
  const float* p = &rgb_[3 * index[0]];
  radiance = {p[0] * scale_, p[1] * scale_, p[2] * scale_};
  return true;
}

void EnvMap::lookup(std::span<const Vec3<double>> dirs, bool compensated,
                    std::span<Lookup> out) const {
  if (dirs.size() != out.size())
    throw std::invalid_argument("EnvMap::lookup: the spans' sizes differ");
  // The pixels first, then their values: the loads of different directions overlap.
  Vec3<double> map[kChunk];
  std::size_t rows[kChunk], cols[kChunk], index[kChunk];
  const Distribution2D& d = compensated ? compensated_ : distribution_;
  for (std::size_t begin = 0; begin < out.size(); begin += kChunk) {
    const std::size_t n = std::min(kChunk, out.size() - begin);
    pixels_of(dirs.data() + begin, n, map, rows, cols, index);
    for (std::size_t i = 0; i < n; ++i) {
      const float* p = &rgb_[3 * index[i]];
      Lookup& l = out[begin + i];
      l.radiance = {p[0] * scale_, p[1] * scale_, p[2] * scale_};
      l.pdf = d.probability(rows[i], cols[i]) * row_inverse_solid_angle_[rows[i]];
    }
  }
}

EnvMap::Lookup EnvMap::lookup(const Vec3<double>& dir, bool compensated) const {
  std::size_t row, col;
  const std::size_t i = pixel_of(to_map(dir), row, col);
  const float* p = &rgb_[3 * i];
  Lookup l;
  l.radiance = {p[0] * scale_, p[1] * scale_, p[2] * scale_};
  l.pdf = (compensated ? compensated_ : distribution_).probability(row, col) *
          row_inverse_solid_angle_[row];
  return l;
}

// --------------------------------------------------------------------------------------------
// The built-in environment.

namespace {

// A procedural map: `radiance(d)` at the centre of every pixel, averaged over n × n sub-pixel
// samples where `edge(d)` says the pixel may straddle the boundary of a light.
template <class Radiance, class Edge>
std::vector<float> procedural_map(int W, int H, Radiance radiance, Edge edge, int n_edge = 4) {
  std::vector<float> rgb(std::size_t(W) * H * 3);
  for (int r = 0; r < H; ++r)
    for (int c = 0; c < W; ++c) {
      const Vec3<double> d = EnvMap::map_direction((c + 0.5) / W, (r + 0.5) / H);
      Rgb v{};
      const int n = edge(d) ? n_edge : 1;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const Rgb x =
              radiance(EnvMap::map_direction((c + (i + 0.5) / n) / W, (r + (j + 0.5) / n) / H));
          v += x;
        }
      float* p = &rgb[3 * (std::size_t(r) * W + std::size_t(c))];
      p[0] = float(v.r / (n * n));
      p[1] = float(v.g / (n * n));
      p[2] = float(v.b / (n * n));
    }
  return rgb;
}

// Elevation above the horizon and azimuth from +z (the camera's side) towards +x, in radians.
void elevation_azimuth(const Vec3<double>& d, double& elev, double& azim) {
  elev = std::asin(std::clamp(d.y, -1.0, 1.0));
  azim = std::atan2(d.x, d.z);
}

// Whether (elev, azim) is inside a rectangle of half-sizes (he, ha) around (e0, a0), with the
// azimuth difference wrapped to (−π, π].
bool in_rectangle(double elev, double azim, double e0, double a0, double he, double ha,
                  double margin = 0) {
  const double da = std::remainder(azim - a0, 2 * kPi);
  return std::abs(elev - e0) <= he + margin && std::abs(da) <= ha + margin;
}

}  // namespace

EnvMap EnvMap::default_sky(EnvOptions options) {
  constexpr int W = 1024, H = 512;
  const double sun_elev = 40 * kPi / 180, sun_azim = 35 * kPi / 180;  // from +z towards −x
  const Vec3<double> sun{-std::cos(sun_elev) * std::sin(sun_azim), std::sin(sun_elev),
                         std::cos(sun_elev) * std::cos(sun_azim)};
  const double sun_radius = 1.5 * kPi / 180, cos_sun = std::cos(sun_radius);
  const double cos_edge = std::cos(sun_radius + 2 * kPi / H);
  const Rgb sun_radiance{1000, 940, 840};
  auto radiance = [&](const Vec3<double>& d) -> Rgb {
    const double cs = d.x * sun.x + d.y * sun.y + d.z * sun.z;
    Rgb v;
    if (d.y >= 0) {
      // Sky: a saturated blue at the zenith fading to a pale horizon, brighter towards the sun.
      const double t = std::pow(1 - d.y, 4);
      const double glow = std::pow(std::max(0.0, cs), 8);
      v = {0.09 + 0.31 * t + 0.25 * glow, 0.16 + 0.29 * t + 0.22 * glow,
           0.38 + 0.17 * t + 0.17 * glow};
    } else {
      // Ground: warm grey, darker towards the nadir.
      const double t = 0.55 + 0.45 * std::pow(1 + d.y, 2);
      v = {0.13 * t, 0.115 * t, 0.095 * t};
    }
    if (cs >= cos_sun) v += sun_radiance;
    return v;
  };
  // The sun disk's edge, supersampled 8 × 8.
  auto edge = [&](const Vec3<double>& d) {
    return d.x * sun.x + d.y * sun.y + d.z * sun.z > cos_edge;
  };
  return EnvMap(W, H, procedural_map(W, H, radiance, edge, 8), "sky", options);
}

EnvMap EnvMap::studio(EnvOptions options) {
  constexpr int W = 512, H = 256;
  constexpr double deg = kPi / 180, margin = 2 * kPi / H;
  struct Light {
    double e0, a0, he, ha;
    Rgb radiance;
  };
  // A key softbox above the camera, to its left; a strip light behind the sphere, to the right.
  const Light lights[] = {{40 * deg, -40 * deg, 14 * deg, 20 * deg, {9.0, 8.2, 7.0}},
                          {15 * deg, 150 * deg, 25 * deg, 5 * deg, {3.0, 4.0, 6.0}}};
  auto radiance = [&](const Vec3<double>& d) -> Rgb {
    double e, a;
    elevation_azimuth(d, e, a);
    for (const Light& l : lights)
      if (in_rectangle(e, a, l.e0, l.a0, l.he, l.ha)) return l.radiance;
    // Walls: a dim neutral grey, a little lighter above; the floor darker.
    const double t = d.y >= 0 ? 0.05 + 0.03 * d.y : 0.03 + 0.01 * (1 + d.y);
    return {t, t, t};
  };
  auto edge = [&](const Vec3<double>& d) {
    double e, a;
    elevation_azimuth(d, e, a);
    for (const Light& l : lights)
      if (in_rectangle(e, a, l.e0, l.a0, l.he, l.ha, margin)) return true;
    return false;
  };
  return EnvMap(W, H, procedural_map(W, H, radiance, edge), "studio", options);
}

EnvMap EnvMap::sunset(EnvOptions options) {
  constexpr int W = 512, H = 256;
  constexpr double deg = kPi / 180;
  const double sun_elev = 4 * deg, sun_azim = 110 * deg, sun_radius = 2 * deg;
  const Vec3<double> sun{std::cos(sun_elev) * std::sin(sun_azim), std::sin(sun_elev),
                         std::cos(sun_elev) * std::cos(sun_azim)};
  const double cos_sun = std::cos(sun_radius), cos_edge = std::cos(sun_radius + 2 * kPi / H);
  auto radiance = [&](const Vec3<double>& d) -> Rgb {
    const double cs = d.x * sun.x + d.y * sun.y + d.z * sun.z;
    if (cs >= cos_sun) return {400, 190, 70};
    if (d.y >= 0) {
      // From orange at the horizon to a deep blue at the zenith, with a glow around the sun.
      const double t = std::pow(std::max(0.0, d.y), 0.5);
      const double glow = std::pow(std::max(0.0, cs), 16);
      return {(1 - t) * 0.9 + t * 0.05 + 1.5 * glow, (1 - t) * 0.38 + t * 0.09 + 0.6 * glow,
              (1 - t) * 0.12 + t * 0.30 + 0.15 * glow};
    }
    const double t = 0.5 + 0.5 * std::pow(1 + d.y, 3);  // dark ground, lit near the horizon
    return {0.06 * t, 0.045 * t, 0.04 * t};
  };
  auto edge = [&](const Vec3<double>& d) {
    return d.x * sun.x + d.y * sun.y + d.z * sun.z >= cos_edge;
  };
  return EnvMap(W, H, procedural_map(W, H, radiance, edge), "sunset", options);
}

std::vector<std::string> EnvMap::builtin_names() {
  return {"sky", "studio", "sunset"};  // and "default", sky's older name (from_spec)
}

Environment load_environment(const std::string& spec) {
  auto map = std::make_shared<const EnvMap>(EnvMap::from_spec(spec));
  const auto builtins = EnvMap::builtin_names();
  std::string label;
  if (spec == "default" || std::find(builtins.begin(), builtins.end(), spec) != builtins.end())
    label = (spec == "default" ? std::string("sky") : spec) + " (built-in)";
  else if (spec.rfind("constant:", 0) == 0)
    label = spec;
  else
    label = std::filesystem::path(spec).stem().string();
  return {label, std::move(map)};
}

const std::vector<Environment>& default_environments() {
  static const std::vector<Environment> envs{load_environment("sky"), load_environment("studio"),
                                             load_environment("sunset")};
  return envs;
}

}  // namespace halfback::render
