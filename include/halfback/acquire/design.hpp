// Designs of the virtual gonio-reflectometer that separate a parameterization's coordinates from
// the spacing of the samples along them (docs/study.md, "Designs"). The cells of
// gonio.hpp are uniform in warped coordinates u = F(x), one monotone bijection F of each axis'
// range [lo, hi] onto itself; the measurements are at x = F⁻¹(u) and the reconstruction
// interpolates in u. The iso-surfaces (which configurations share a coordinate value) are the
// parameterization's; only the spacing changes.
//
//   own      F = identity: uniform in the parameterization's own coordinates (the default);
//   angle    each sine-like magnitude (‖h̄‖, ‖k‖, ‖k̄‖, range [0, 1]) through its arcsine,
//            F(x) = asin(x) / (π/2); angles (θ) and azimuths unchanged. Identical to own for
//            halfdiff and spherical;
//   merl     angle, then MERL's √ warp of the half-vector axis (θh, or asin ‖h̄‖):
//            F(x) = (α(x) / α(hi))^½ · hi with α the angle map: denser near the specular peak.
//            Identical to angle for spherical (which has no half-vector axis);
//   learned  per-axis warps fitted on other BRDFs (learn_warps(): leave-one-out).
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/acquire/samples.hpp"
#include "halfback/brdf/brdf.hpp"
#include "halfback/brdf/resample.hpp"
#include "halfback/core/space.hpp"

namespace halfback::acquire {

enum class Spacing { own, angle, merl, learned };
inline constexpr std::array<Spacing, 4> kSpacings{Spacing::own, Spacing::angle, Spacing::merl,
                                                  Spacing::learned};
std::string_view name_of(Spacing s);
// "own", "angle", "merl" or "learned"; nullopt for anything else.
std::optional<Spacing> parse_spacing(std::string_view name);

// A monotone bijection of [lo, hi] onto itself.
class AxisWarp {
 public:
  enum class Kind { identity, arcsine, merl_angle, merl_arcsine, table };
  AxisWarp() = default;
  AxisWarp(Kind kind, double lo, double hi);
  // A learned warp: F piecewise linear through (lo + i (hi − lo)/n, lo + cdf[i] (hi − lo)),
  // i = 0..n, cdf strictly increasing from 0 to 1 (std::invalid_argument otherwise).
  static AxisWarp from_cdf(double lo, double hi, std::vector<double> cdf);

  double forward(double x) const;  // x ↦ u, clamped to [lo, hi]
  double inverse(double u) const;  // u ↦ x, clamped to [lo, hi]
  Kind kind() const { return kind_; }
  double lo() const { return lo_; }
  double hi() const { return hi_; }
  const std::vector<double>& cdf() const { return cdf_; }
  bool operator==(const AxisWarp&) const = default;

 private:
  Kind kind_ = Kind::identity;
  double lo_ = 0, hi_ = 1;
  std::vector<double> cdf_;  // Kind::table only
};

// Warps learned for one parameterization: one per axis of its isotropic form (a, b, φ).
struct LearnedWarps {
  Space space = space_of<Hybrid>;
  std::array<AxisWarp, 3> axes;
  bool operator==(const LearnedWarps&) const = default;
};

// The warps of a design for the grid `cells` (its form's axes, in order). For `learned`,
// `learned` must hold the warps of the same space; a full (4D) form takes the learned warps of
// its magnitudes a, b and leaves its azimuths unwarped. Throws std::invalid_argument when
// `learned` is missing or of another space.
std::vector<AxisWarp> design_warps(const GridSpec& cells, Spacing spacing,
                                   const LearnedWarps* learned);

// Whether a design's warps for a space are all the identity (then it is the own design).
bool same_as_own(Space space, bool isotropic, Spacing spacing);

// What one BRDF contributes to learning: per parameterization and axis of the isotropic form,
// D(x) = ∫ w (∂²T/∂x²)² over the other axes (T the BRDF's luminance in the error space, w the
// measure of samples.hpp), by second differences on the grid of sample_isotropic, normalized by
// ∫ w T² so that every BRDF weighs the same in relative error.
struct AxisDemand {
  Space space = space_of<Hybrid>;
  std::array<std::vector<double>, 3> demand;  // per axis, one value per grid cell
};
struct DesignProfile {
  std::vector<AxisDemand> spaces;
};
AxisDemand axis_demand(const IsoSamples& s);
// A BRDF's profile in each of `spaces`, on their isotropic grids of `grid` cells.
DesignProfile design_profile(const Brdf& brdf, std::span<const Space> spaces, const IsoGrid& grid,
                             ErrorSpace es);

// The warps learned for profile `held_out` from all the others: per axis, the density of samples
// that minimizes the error of interpolation, ρ ∝ D^(1/5) summed over the other BRDFs, mixed with
// 1/5 of the uniform density (a floor, so that no region goes unmeasured) and integrated to F.
// With no other profile the warps are the identity. The held-out profile is never read.
std::vector<LearnedWarps> learn_warps(std::span<const DesignProfile> profiles,
                                      std::size_t held_out);
// The warps of one demand by the same rule with a floor of `uniform_share` of the uniform density
// (the sequential design's, from its pilot; learn_warps's floor is 1/5).
LearnedWarps warps_for_demand(const AxisDemand& demand, double uniform_share);

}  // namespace halfback::acquire
