// Environment maps: latitude–longitude radiance maps (Radiance .hdr or OpenEXR files, a built-in
// procedural sky, or a constant), looked up and importance sampled in world directions.
//
// World frame of the renderer (docs/render.md): +y is up, the camera looks along −z from +z, +x is
// to the right in the image. A map pixel (column c, row r) of a W×H map covers
//   φ ∈ [2π c/W − π, 2π (c+1)/W − π),   θ ∈ [π r/H, π (r+1)/H),
// θ the polar angle from +y (row 0 is the zenith) and φ the azimuth about +y, with
//   direction(θ, φ) = (sin θ sin φ, cos θ, −sin θ cos φ).
// So the centre of the map (φ = 0, θ = π/2) is −z, the direction the camera looks in, and is what
// the background shows behind the sphere; the left and right edges are +z, behind the camera; the
// map's right half (φ > 0) is to the right (+x). Lookups are nearest-pixel: the map is piecewise
// constant in direction, which is exactly the function the sampler importance samples.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/render/distribution.hpp"

namespace halfback::render {

// A negative pixel value of a map file no further below 0 than this fraction of the map's largest
// value is noise and read as 0 (EnvMap::noise_clamped()); a more negative one is refused
// (docs/formats.md, "Missing and negative measurements").
inline constexpr double kEnvNoiseFraction = 1e-3;

struct EnvOptions {
  double rotation_deg = 0;  // turns the environment about +y (counter-clockwise seen from above)
  double exposure = 0;      // radiance scale 2^exposure
};

class EnvMap {
 public:
  // `rgb` holds width × height × 3 linear radiance values, row 0 at the top (the zenith). Throws
  // std::invalid_argument when a dimension is 0, the size does not match, or a value is negative,
  // NaN or infinite (the message names `name`, the pixel and the channel).
  EnvMap(int width, int height, std::vector<float> rgb, std::string name, EnvOptions options = {});

  // A built-in ("sky", "studio", "sunset"; "default" is sky's older name, still taken),
  // "constant:V" or "constant:R,G,B", or a file name. Throws std::invalid_argument for a spec that
  // is none of these (no such file included) or a bad constant, and what load() throws for a
  // file.
  static EnvMap from_spec(std::string_view spec, EnvOptions options = {});
  // A Radiance .hdr or OpenEXR file, recognized by its content. Throws FormatError naming the file
  // and the problem: unreadable, not an HDR image, zero size, not 2:1, more pixels than the file
  // can hold (checked before the pixels are allocated), NaN/Inf/negative pixels beyond noise
  // (kEnvNoiseFraction).
  static EnvMap load(const std::filesystem::path& path, EnvOptions options = {});
  static EnvMap constant(const Rgb& radiance, EnvOptions options = {});
  // The built-in procedural environment (1024 × 512): a blue sky gradient, a small bright sun
  // disk (radius 1.5°, 40° above the horizon, behind the camera on its left) and a darker ground.
  static EnvMap default_sky(EnvOptions options = {});
  // Two more built-in environments (512 × 256), so that a material can be shown under three
  // lightings with no files (the paper's Figures 3-5): a dark studio with a large warm softbox
  // above the camera's left and a cool strip light behind the sphere on the right; and a sunset, a
  // low orange sun to the right under a sky going from orange at the horizon to deep blue.
  static EnvMap studio(EnvOptions options = {});
  static EnvMap sunset(EnvOptions options = {});
  // The names of the built-in environments (one name each, "sky" the default everywhere: the
  // CLI, Python, the explorer); from_spec() also takes "default" for sky.
  static std::vector<std::string> builtin_names();

  // Radiance arriving from world direction `dir` (unit), scaled by the exposure.
  Rgb eval(const Vec3<double>& dir) const;
  // eval() of each direction, equal to it (throws std::invalid_argument when the sizes differ).
  void eval(std::span<const Vec3<double>> dirs, std::span<Rgb> out) const;
  // Whether the directions (1 to 32) all fall in one map pixel, and then its radiance (eval()).
  bool uniform(std::span<const Vec3<double>> dirs, Rgb& radiance) const;

  struct Sample {
    Vec3<double> dir;  // world direction towards the light
    Rgb radiance;
    double pdf = 0;  // per unit solid angle; 0 when the map is black (no sample)
  };
  // A direction with probability proportional to the luminance of its pixel (times the pixel's
  // solid angle), uniform in solid angle within the pixel. u1, u2 in [0, 1).
  //
  // `compensated`: proportional to max(0, luminance − mean luminance) instead (MIS compensation,
  // Karlík et al. 2019): for use only beside a BRDF sampler in MIS, which covers the dim
  // directions that this density leaves out (pdf 0). The same as the plain density when the map
  // is constant.
  Sample sample(double u1, double u2, bool compensated = false) const;
  // sample() of each (u1[i], u2[i]), equal to it; the table lookups of different samples overlap.
  // Throws std::invalid_argument when the sizes differ.
  void sample(std::span<const double> u1, std::span<const double> u2, bool compensated,
              std::span<Sample> out) const;
  // The density of sample() at `dir`, per unit solid angle.
  double pdf(const Vec3<double>& dir, bool compensated = false) const;
  // eval(dir) and pdf(dir, compensated) from one lookup of the pixel (equal to both, bit for bit).
  struct Lookup {
    Rgb radiance;
    double pdf = 0;
  };
  Lookup lookup(const Vec3<double>& dir, bool compensated = false) const;
  // lookup() of each direction, equal to it (throws std::invalid_argument when the sizes differ).
  void lookup(std::span<const Vec3<double>> dirs, bool compensated, std::span<Lookup> out) const;

  // The share of the map's power (luminance × solid angle) that compensated sampling leaves to
  // the BRDF sampler: Σ min(L, L̄) ω / Σ L ω, L̄ the solid-angle mean of the luminance. 1 for a
  // constant (or black) map, small for a dark map with bright lights (the exposure does not
  // change it).
  double residual_fraction() const { return residual_; }

  int width() const { return width_; }
  int height() const { return height_; }
  const std::string& name() const { return name_; }
  const EnvOptions& options() const { return options_; }
  std::span<const float> pixels() const { return rgb_; }  // without the exposure scale
  // Tiny negative values of the file read as 0 (kEnvNoiseFraction); 0 for maps made in memory.
  std::size_t noise_clamped() const { return noise_clamped_; }

  // The map frame: direction of map coordinates (u, v) ∈ [0, 1]² and back (u ∈ [0, 1)).
  static Vec3<double> map_direction(double u, double v);
  static void map_coordinates(const Vec3<double>& dir, double& u, double& v);

 private:
  Vec3<double> to_map(const Vec3<double>& world) const;
  Vec3<double> to_world(const Vec3<double>& map) const;
  std::size_t pixel_of(const Vec3<double>& map_dir, std::size_t& row, std::size_t& col) const;
  // pixel_of in two steps: a guess without branches, then the exact edge tests.
  struct Guess {
    double rho2, len, row, col;  // x² + z², the length, the guide's bucket, the column
  };
  Guess guess(const Vec3<double>& map_dir) const;
  std::size_t place(const Vec3<double>& map_dir, const Guess& g, std::size_t& row,
                    std::size_t& col) const;
  static constexpr std::size_t kChunk = 32;  // directions per pass of the span lookups
  // pixel_of(to_map(world[i])) for n <= kChunk directions; map[i] = to_map(world[i]).
  void pixels_of(const Vec3<double>* world, std::size_t n, Vec3<double>* map, std::size_t* row,
                 std::size_t* col, std::size_t* index) const;

  int width_ = 0, height_ = 0;
  std::vector<float> rgb_;
  std::string name_;
  EnvOptions options_;
  double scale_ = 1, cos_rot_ = 1, sin_rot_ = 0;
  std::vector<double> row_solid_angle_;          // of one pixel of each row
  std::vector<double> row_inverse_solid_angle_;  // 1 / row_solid_angle_ (the pdfs multiply)
  std::vector<double> row_cos_;                  // cos θ of the rows' edges, height + 1 of them
  struct Edge {
    double cos = 1, sin = 0;
  };
  std::vector<std::uint32_t> row_guide_;  // the row at the top of each bucket of cos θ
  std::vector<Edge> col_edge_;            // of φ at each column's left edge
  Sample sample_in(const Distribution2D::Sample& cell) const;
  void column_sincos(std::size_t col, double t, double& sin_phi, double& cos_phi) const;
  Distribution2D distribution_, compensated_;
  std::size_t noise_clamped_ = 0;
  double residual_ = 1;
};

// An environment as figures and reports use it: a map shared by the renderings that light with
// it (each set of figures loads or builds it once), and the caption written under them.
struct Environment {
  std::string label;
  std::shared_ptr<const EnvMap> map;
};

// EnvMap::from_spec(spec) with its caption: "sky (built-in)", ..., a constant's spec, or a
// file's stem. Throws what from_spec throws.
Environment load_environment(const std::string& spec);
// The three built-ins, default (sky), studio and sunset; built once per process.
const std::vector<Environment>& default_environments();

}  // namespace halfback::render
