// The numbers behind the view's pictures, computed for one BRDF (docs/view.md, "API"). Each field
// is float32 RGB (or the luminance of ρ alone, where asked), row-major, row 0 at the bottom of the
// picture (y grows with the row), NaN where the picture has no value (outside the valid domain,
// outside the disk).
#pragma once

#include <cstddef>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/core/space.hpp"

namespace halfback::view {

// What a field of ρ holds per pixel: its RGB, or its luminance (Rgb::luminance) alone, which is
// all the page draws (a third of the bytes to send).
enum class RhoValues { rgb, luminance };
inline std::size_t channels_of(RhoValues v) {
  return v == RhoValues::rgb ? 3 : 1;
}

// ρ on an n × n slice of an isotropic form at relative azimuth `azimuth` (radians, in [0, 2π)):
// x the first isotropic coordinate over [0, max], y the second (figure/slices.hpp; the pixel
// centres of figure::Grid::pixel_centres). `pose` (radians) turns every pair about the normal
// from the form's canonical pose (its first azimuth, φh or φi, = 0) to that azimuth: the slice
// of an anisotropic BRDF at another orientation (an isotropic BRDF's does not change).
std::vector<float> slice_field(const Brdf& brdf, Space space, double azimuth, std::size_t n,
                               int threads, RhoValues values = RhoValues::rgb, double pose = 0);

// The hemisphere of ωi for a given ωo, seen from above (x right, y up) in the equal-area
// projection r = √2 sin(θi/2), on the n × n pixel centres of [−1, 1]²: ρ(ωi, ωo) when `space`
// is dirs (as `values` says), else the three isotropic coordinates of (ωi, ωo) in that
// parameterization.
std::vector<float> hemisphere_field(const Brdf* brdf, Space space, const Vec3<double>& wo,
                                    std::size_t n, int threads, RhoValues values = RhoValues::rgb);

// ρ along two great half-circles of ωi through the zenith side, for angles t from −90° to 90°
// (n samples): in the plane of incidence (t > 0 towards the mirror direction of ωo) and across
// it (through the mirror direction, perpendicular to the plane of incidence).
struct PolarCurves {
  std::vector<double> angles_deg;
  std::vector<Rgb> in_plane, across;
};
PolarCurves polar_curves(const Brdf& brdf, const Vec3<double>& wo, std::size_t n);

// ωi of the two polar curves at angle t (radians).
Vec3<double> polar_in_plane(const Vec3<double>& wo, double t);
Vec3<double> polar_across(const Vec3<double>& wo, double t);

}  // namespace halfback::view
