// Rendering a Scene to PNG, SVG or PDF, and writing figure files safely.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/figure/scene.hpp"

namespace halfback::figure {

enum class Format { png, svg, pdf };

// From the extension (.png, .svg, .pdf, any case); nullopt for anything else.
std::optional<Format> format_from_path(const std::filesystem::path& path);
std::string_view extension_of(Format f);  // "png", "svg", "pdf"

struct RenderOptions {
  // Pixels per point of PNG output. Figures sample their rasters at this density (their
  // `pixels_per_point` option), so 2 draws one field sample per output pixel.
  double png_scale = 2.0;
};

// Cairo's image surfaces have at most this many pixels per side.
inline constexpr int kMaxRasterSide = 32767;
// A figure that its options make larger than an image can be (a usage error for the CLI).
class FigureSizeError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};
// Throws FigureSizeError when a page of width × height points at `scale` pixels per point is
// wider or taller than kMaxRasterSide pixels; `hint` says what makes the page smaller. Figures
// call it with their layout, before sampling any raster, so an oversized request costs nothing.
void check_raster_size(double width, double height, double scale, std::string_view hint);

// The file content of the scene in the given format (binary for PNG and PDF).
std::string render(const Scene& scene, Format format, const RenderOptions& options = {});

// An 8-bit RGBA image (straight alpha, row 0 at the top), for tests and inspection.
struct Raster {
  std::size_t width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
  std::array<std::uint8_t, 4> pixel(std::size_t x, std::size_t y) const {
    const std::size_t k = 4 * (y * width + x);
    return {rgba[k], rgba[k + 1], rgba[k + 2], rgba[k + 3]};
  }
};

// The scene drawn at `scale` pixels per point, as the PNG writer draws it.
Raster rasterize(const Scene& scene, double scale);
// Decodes a PNG file's content; throws std::runtime_error when it is not a PNG.
Raster decode_png(std::string_view png);

// Renders the scene in the format named by the path's extension and writes it atomically: to a
// temporary file in the same directory, renamed over `path` once complete, so a failure leaves no
// partial file. Throws std::invalid_argument for an unknown extension and std::runtime_error
// (naming the path and the reason) when the file cannot be written.
void save(const Scene& scene, const std::filesystem::path& path, const RenderOptions& options = {});

}  // namespace halfback::figure
