#include "halfback/render/image.hpp"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStdIO.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "halfback/util/atomic_file.hpp"

namespace halfback::render {

namespace {

void check_image(const Image& image, const std::filesystem::path& path) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != std::size_t(image.width) * std::size_t(image.height) * 3)
    throw std::invalid_argument(path.string() + ": the image is empty or its size is inconsistent");
}

double srgb_encode(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
}

double aces_filmic(double x) {  // Narkowicz 2015, "ACES Filmic Tone Mapping Curve"
  x = std::max(0.0, x);
  return std::clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

std::string lower_extension(const std::filesystem::path& p) {
  std::string e = p.extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

}  // namespace

std::vector<std::uint8_t> tonemap_srgb8(const Image& image, const ToneMapOptions& o) {
  const double scale = std::exp2(o.exposure);
  std::vector<std::uint8_t> out(image.rgb.size());
  for (std::size_t i = 0; i < image.rgb.size(); ++i) {
    double v = double(image.rgb[i]);
    if (std::isnan(v)) v = 0;
    v *= scale;
    if (o.filmic) v = aces_filmic(v);
    out[i] = std::uint8_t(std::lround(255 * srgb_encode(v)));
  }
  return out;
}

void write_png(const std::filesystem::path& path, const Image& image, const ToneMapOptions& o) {
  check_image(image, path);
  const std::vector<std::uint8_t> pixels = tonemap_srgb8(image, o);
  std::vector<unsigned char> bytes;
  auto sink = [](void* ctx, void* data, int size) {
    auto* v = static_cast<std::vector<unsigned char>*>(ctx);
    const auto* p = static_cast<const unsigned char*>(data);
    v->insert(v->end(), p, p + size);
  };
  if (!stbi_write_png_to_func(sink, &bytes, image.width, image.height, 3, pixels.data(),
                              image.width * 3))
    throw std::runtime_error(path.string() + ": PNG encoding failed");
  write_file_atomically(
      path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

void write_exr(const std::filesystem::path& path, const Image& image) {
  check_image(image, path);
  std::ostringstream buffer;
  try {
    Imf::StdOSStream stream;
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    {
      // The OutputFile writes the scan-line offset table when it is destroyed: the stream is
      // complete only after this scope.
      Imf::OutputFile file(stream, header);
      Imf::FrameBuffer fb;
      char* base = const_cast<char*>(reinterpret_cast<const char*>(image.rgb.data()));
      const std::size_t xs = 3 * sizeof(float), ys = xs * std::size_t(image.width);
      fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
      fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
      fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
      file.setFrameBuffer(fb);
      file.writePixels(image.height);
    }
    buffer << stream.str();
  } catch (const std::exception& e) {
    throw std::runtime_error(path.string() + ": OpenEXR: " + e.what());
  }
  write_file_atomically(path, buffer.str());
}

void write_image(const std::filesystem::path& path, const Image& image, const ToneMapOptions& o) {
  const std::string ext = lower_extension(path);
  if (ext == ".exr") return write_exr(path, image);
  if (ext == ".png") return write_png(path, image, o);
  throw std::invalid_argument(path.string() +
                              ": unknown image type (the name must end in .png or .exr)");
}

Image read_exr(const std::filesystem::path& path) {
  try {
    Imf::InputFile in(path.c_str());
    const Imath::Box2i dw = in.header().dataWindow();
    Image image;
    image.width = dw.max.x - dw.min.x + 1;
    image.height = dw.max.y - dw.min.y + 1;
    image.rgb.assign(std::size_t(image.width) * std::size_t(image.height) * 3, 0.0f);
    char* base = reinterpret_cast<char*>(image.rgb.data()) -
                 (std::ptrdiff_t(dw.min.x) + std::ptrdiff_t(dw.min.y) * image.width) * 3 *
                     std::ptrdiff_t(sizeof(float));
    const std::size_t xs = 3 * sizeof(float), ys = xs * std::size_t(image.width);
    Imf::FrameBuffer fb;
    fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    return image;
  } catch (const std::exception& e) {
    throw std::runtime_error(path.string() + ": OpenEXR: " + e.what());
  }
}

}  // namespace halfback::render
