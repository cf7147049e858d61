// RGL measured BRDFs (EPFL Realistic Graphics Lab; Dupuy & Jakob 2018, "An Adaptive
// Parameterization for Efficient Material Acquisition and Representation", ACM TOG 37(6)): the
// "tensor_file" container, the material it stores, and its evaluation. docs/formats.md describes
// the container, the fields, the warp and its inverse as implemented here.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/brdf/brdf.hpp"

namespace halfback {

// ---------------------------------------------------------------------------------------------
// The container: "tensor_file\0", version 1.0, a table of named n-dimensional little-endian
// arrays (name, dtype, shape, byte offset), then the arrays.
// ---------------------------------------------------------------------------------------------
enum class TensorDtype : std::uint8_t {
  uint8 = 1,
  int8,
  uint16,
  int16,
  uint32,
  int32,
  uint64,
  int64,
  float16,
  float32,
  float64
};
std::string_view name_of(TensorDtype dtype);
std::size_t size_of(TensorDtype dtype);

struct TensorField {
  std::string name;
  TensorDtype dtype{};
  std::vector<std::uint64_t> shape;
  std::uint64_t offset = 0;
  std::span<const std::byte> bytes;  // view into TensorFile::storage
  std::uint64_t count() const;       // product of the shape
};

struct TensorFile {
  std::string name;                // the file, for messages
  std::vector<std::byte> storage;  // the whole file
  std::uint8_t version_major = 0, version_minor = 0;
  std::vector<TensorField> fields;  // in file order
  const TensorField* find(std::string_view name) const;
};

// Parses the container strictly: magic, version 1.0, a field table that lies inside the file,
// non-empty unique names, known dtypes, shapes whose byte size (computed without overflow) fits in
// the file after the table. Nothing is allocated from a size read in the file before it has been
// checked against the file's size. Throws FormatError.
TensorFile parse_tensor_file(std::vector<std::byte> bytes, std::string_view name);
TensorFile read_tensor_file(const std::filesystem::path& path);
// Serializes fields (name, dtype, shape, little-endian data bytes) as a version 1.0 tensor file,
// each array 8-byte aligned. For tests and for writing synthetic materials.
struct TensorFieldData {
  std::string name;
  TensorDtype dtype;
  std::vector<std::uint64_t> shape;
  std::vector<std::byte> data;
};
std::vector<std::byte> serialize_tensor_file(std::span<const TensorFieldData> fields);

// ---------------------------------------------------------------------------------------------
// The material
// ---------------------------------------------------------------------------------------------
// Measured densities carry noise: a negative ndf, vndf or luminance value no further below 0 than
// this fraction of its field's largest value is read as 0 (and counted in facts()); a more negative
// one is refused. Real files have values down to -4e-10 where the maximum is of order 1
// (docs/formats.md, "Negative values").
inline constexpr double kRglNoiseFraction = 1e-3;

// The bound on ρ·cos θo that a material's tables imply, each table interpolated between its nodes
// (ρ·cos θo = rgb · ndf / (4 sigma)): the largest |rgb| times the largest ndf over 4 times the
// smallest sigma. The reader refuses a file, and the writer a BRDF's tables, where it is above
// the bound on ρ (brdf/rho_bound.hpp). The published materials reach 7e6 (chm_mint), the writer's
// tables of GGX α = 0.001 8e7.
inline double rgl_rho_cos_bound(double largest_abs_rgb, double largest_ndf, double smallest_sigma) {
  return largest_abs_rgb * largest_ndf / (4 * smallest_sigma);
}

struct RglOptions {
  // The RGB data holds small negative values where the spectral measurement falls outside the
  // sRGB gamut (e.g. down to -2% of the maximum in chm_mint); by default ρ is clamped at 0.
  bool clamp_negative = true;
};

// A point of the unit square of a 2D warp (see RglBrdf::vndf_inverse).
struct RglWarpPoint {
  double x, y;
};

class RglBrdf final : public Brdf {
 public:
  // Validates the material fields of a parsed tensor file (names, dtypes, shapes, values: finite,
  // densities >= 0 up to noise (kRglNoiseFraction), sigma > 0, incidence grids increasing and in
  // range, rgl_rho_cos_bound within the bound on ρ). Throws FormatError.
  RglBrdf(const TensorFile& file, std::string label, RglOptions options = {});
  ~RglBrdf() override;

  std::string name() const override;
  std::string description() const override;
  bool isotropic() const override;
  bool reciprocal() const override { return false; }  // measured: not exactly reciprocal
  // fr(ωi, ωo) in sr⁻¹ without the cosine: the reference loader's value divided by cos θo.
  // ωi is the light direction, the one the tables are indexed by. 0 when either direction is at or
  // below the horizon (z <= 0), NaN when the pair has a NaN.
  Rgb eval(const DirPair<double>& pair) const override;
  // eval() over blocks of pairs: the angles by the batch engine's SIMD conversion, the VNDF table
  // reads of a block prefetched together. Equal to eval() up to the SIMD atan2's rounding (a few
  // ulps of the angles; the values are continuous in them, and rows near a discontinuity go
  // through eval()). Throws std::invalid_argument when out.size() != pairs.size().
  void eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const override;
  std::vector<Fact> facts() const override;

  // fr·cos θo: what the reference loader's eval(wi, wo) returns.
  Rgb eval_cosine(const DirPair<double>& pair) const;

  const std::string& material_description() const;
  std::span<const float> theta_i() const;
  std::span<const float> phi_i() const;

  // The VNDF warp at an incidence (θi, φi) — the map from the stored sample coordinates to the
  // unit square of microfacet normals (u = √(2θm/π), v = (φm - φi + π)/2π for isotropic data) —
  // and its inverse, the one the evaluation uses (docs/formats.md, "Inverse warp"). Exposed for
  // tests.
  RglWarpPoint vndf_inverse(RglWarpPoint normal_coords, double theta_i, double phi_i) const;
  RglWarpPoint vndf_forward(RglWarpPoint sample, double theta_i, double phi_i) const;
  // The same by binary searches of the blended CDFs (vndf_forward starts them from the slices'
  // guide tables and returns the same point bit for bit): the tests' reference.
  RglWarpPoint vndf_forward_by_search(RglWarpPoint sample, double theta_i, double phi_i) const;
  // Density of the VNDF warp's output on the unit square at a point.
  double vndf_density(RglWarpPoint normal_coords, double theta_i, double phi_i) const;

  // Importance sampling as in Dupuy & Jakob 2018, through Brdf's interface: a uniform (u1, u2)
  // through the VNDF warp of the incidence ωo gives a microfacet normal m, and ωi is ωo reflected
  // about m. Between incidence slices, the blended density is sampled as the mixture it is: a
  // slice drawn with probability its weight, then its own warp (docs/formats.md, "Sampling"). The
  // tables' incidence is the light direction, so this draws from the lobe of ρ(ωo, ·), which
  // reciprocity makes a density resembling ρ(·, ωo) (an importance density only: pdf() is exact for
  // it, so estimates stay unbiased). pdf is per unit solid angle (0 when ωo is at or below the
  // horizon or ωi falls below it).
  BrdfSample sample(const Vec3<double>& wo, double u1, double u2) const override;
  double pdf(const Vec3<double>& wo, const Vec3<double>& wi) const override;
  // sample() and pdf() of batches, the angles by the batch engine's SIMD conversions (as
  // eval_batch): equal to them up to the rounding of the SIMD atan2 and sincos (directions and
  // pdfs within about 1e-12 relative; rows at a seam or on the axis go through sample() and
  // pdf()).
  void sample_batch(std::span<const Vec3<double>> wo, std::span<const double> u1,
                    std::span<const double> u2, std::span<BrdfSample> out) const override;
  void pdf_batch(std::span<const DirPair<double>> pairs, std::span<double> out) const override;
  bool has_importance_sampling() const override { return true; }

  struct Impl;

 private:
  void eval_block(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const;
  void sample_block(std::span<const Vec3<double>> wo, std::span<const double> u1,
                    std::span<const double> u2, std::span<BrdfSample> out) const;
  void pdf_block(std::span<const DirPair<double>> pairs, std::span<double> out) const;

  std::unique_ptr<Impl> impl_;
  std::string label_;
  RglOptions options_;
};

// Reads an RGL .bsdf file (the RGB variant, or the spectral one with its spectra integrated to RGB:
// core/spectrum.hpp); the BRDF's name is "rgl:STEM".
std::shared_ptr<const RglBrdf> load_rgl(const std::filesystem::path& path, RglOptions options = {});

}  // namespace halfback
