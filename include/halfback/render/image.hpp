// Rendered images: linear RGB float arrays, tone mapping, and the file writers (linear OpenEXR,
// tone-mapped 8-bit sRGB PNG). Files are written safely through halfback::AtomicFile (a temporary
// file beside the target, renamed over it), so a reader never sees a partial image.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace halfback::render {

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // width × height × 3, row-major, row 0 at the top; linear radiance
  const float* pixel(int x, int y) const { return &rgb[3 * (std::size_t(y) * width + x)]; }
};

struct ToneMapOptions {
  double exposure = 0;  // stops: values are scaled by 2^exposure first
  bool filmic = false;  // ACES filmic curve (Narkowicz 2015 fit) instead of a plain clamp
};

// 8-bit sRGB, width × height × 3. NaN becomes 0.
std::vector<std::uint8_t> tonemap_srgb8(const Image& image, const ToneMapOptions& options);

// Throw std::runtime_error (std::system_error for I/O) naming the file on failure. write_image
// picks the format from the extension (.exr or .png, case-insensitive) and throws
// std::invalid_argument for any other.
void write_exr(const std::filesystem::path& path, const Image& image);
void write_png(const std::filesystem::path& path, const Image& image,
               const ToneMapOptions& options);
void write_image(const std::filesystem::path& path, const Image& image,
                 const ToneMapOptions& options);

// Reads an RGB OpenEXR file (e.g. one written by write_exr) as an Image.
Image read_exr(const std::filesystem::path& path);

}  // namespace halfback::render
