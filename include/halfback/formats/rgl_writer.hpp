// Writing any isotropic BRDF as an RGL "tensor_file" material (the format of Dupuy & Jakob 2018,
// in its RGB variant, read by RGL's reference loader powitacq_rgb.h and Mitsuba 3's `measured`
// plugin in its RGB variants, or its spectral variant, read by powitacq.h, pbrt-v4's `measured`
// material and Mitsuba 3's spectral variants, or both in one file). The microfacet distribution is
// recovered from the BRDF's backscattering by power iteration (Dupuy, Heitz, Iehl, Poulin &
// Ostromoukhov 2015); the visible-normal distributions and their warps follow from it, and the RGB
// and luminance tables are ρ averaged (or sampled) through the warps. docs/formats.md ("RGL
// writer") derives every field.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/formats/rgl.hpp"

namespace halfback {

// Which colour fields a file holds: `rgb` (3 channels), `spectral` (`wavelengths` and `spectra`,
// upsampled from the RGB tables: core/spectrum.hpp), or `both` (every field of the two; read by
// pbrt-v4, both reference loaders and halfback, but refused by Mitsuba 3's RGB variants, which
// take a file with `wavelengths` for a spectral one).
enum class RglVariant { rgb, spectral, both };

// Where the incident elevations are: `sigma`, evenly spaced in σ from 0 to 90° (the published
// files' layout, and Dupuy & Jakob's acquisition); `albedo`, half of them (rounded up) so and the
// others, one at a time, where linear interpolation in θi predicts the BRDF's directional albedo
// worst (docs/formats.md, "Energy").
enum class RglIncidences { albedo, sigma };
// What a node of the colour and luminance tables holds: `hat_average`, the average of the stored
// quantity over the node's bilinear hat function in the warped square, which keeps each slice's
// directional albedo exactly (up to the midpoint rule on 12 × 12 points a cell); `point`, its value
// at the node, as an instrument measures it (the study's acquisition, its samplers).
enum class RglTabulation { hat_average, point };

struct RglExportOptions {
  int theta_i = 16;           // incident elevations, 0 to 90°, placed by `incidences`
  int resolution = 32;        // luminance and RGB tables: resolution × resolution samples
  int vndf_resolution = 128;  // the VNDF tables (N × N) and the NDF and σ tables (2 × N)
  std::string description;    // the `description` field; empty: says what the source was
  RglVariant variant = RglVariant::rgb;
  RglIncidences incidences = RglIncidences::albedo;
  RglTabulation tabulation = RglTabulation::hat_average;
  int threads = 0;  // parallel_for's convention: 0 all cores, 1 the calling thread
  // Called after each incidence slice is tabulated (from the calling thread), e.g. for a
  // progress display.
  std::function<void(int done, int total)> progress;
};

// The isotropic microfacet distribution D(θm) recovered from a BRDF, on the nodes of the NDF
// table: u_k = k/(N-1), θ_k = u_k² π/2 (the format's u = √(2θ/π)); linear in u between nodes.
struct RecoveredNdf {
  std::vector<double> ndf;  // D(θ_k), normalized so that ∫ D(m) cos θm dωm = 1
  std::vector<double> sigma;  // σ(θ_k) = ∫ D(m) max(0, ω_k·m) dωm, the projected area; σ(0) = 1
  int iterations = 0;         // power iterations until convergence
  double change = 0;          // the last iteration's largest change, relative to max D
};

// Power iteration on D = ρ(ω, ω) cos θ σ_D(ω) (the backscattering of a microfacet BRDF with
// G(ω, ω) = G1(ω)). Uses the luminance of ρ. Throws std::invalid_argument when ρ(ω, ω) is NaN or
// infinite somewhere, or zero at every node, or when nodes < 2.
RecoveredNdf recover_ndf(const Brdf& brdf, int nodes, int threads = 0);

// σ(θ) of an NDF table (nodes as above, linear in u), by the quadrature the power iteration uses.
double projected_area(const std::vector<double>& ndf, double theta);

// The warps of an RGL file of `brdf` alone: its NDF recovered as above (as Dupuy & Jakob measure
// it, from the retro-reflection), raised to at least a constant NDF holding `ndf_floor_share` of
// ∫ D cos θm dωm = 1 (the value share/π), the VNDF tables and their warps of the writer, and
// luminance and RGB tables of ones (the material's value is then the table map's Jacobian factor
// only). The floor keeps the VNDF positive wherever ωi·m > 0, so that the warp is a bijection
// there (a measured NDF may be 0 at grazing θm), while taking at most that share of the samples
// from the lobe (a floor relative to the peak took most of a near-mirror's: docs/study.md).
// Isotropic: one φi slice; an anisotropic BRDF is refused unless allow_anisotropic (then its NDF
// is the one recovered along φ = 0). Throws as recover_ndf, or std::invalid_argument for options
// out of range.
struct RglWarpOptions {
  int theta_i = 8;
  int vndf_resolution = 128;
  double ndf_floor_share = 1e-3;
  int threads = 0;
  bool allow_anisotropic = false;
};
std::shared_ptr<const RglBrdf> rgl_warp_material(const Brdf& brdf, const RglWarpOptions& options);

// The fields of the RGL file of `brdf`, in the order of the published files: version,
// description, phi_i, theta_i, sigma, ndf, vndf, luminance, rgb (variants rgb and both),
// wavelengths and spectra (variants spectral and both: float32, nm, spectral::default_wavelengths,
// and [1, θi, wavelengths, resolution, resolution]), jacobian. Isotropic BRDFs only.
// Throws std::invalid_argument for an anisotropic BRDF, options out of range (naming the option
// and the accepted range), or a BRDF that is NaN, infinite or zero where the tables sample it.
std::vector<TensorFieldData> rgl_fields(const Brdf& brdf, const RglExportOptions& options = {});

// The fields above written as a tensor file, atomically (util/atomic_file.hpp): on any error
// nothing is written and an existing file is left as it was.
void write_rgl(const std::filesystem::path& path, const Brdf& brdf,
               const RglExportOptions& options = {});

}  // namespace halfback
