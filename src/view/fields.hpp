// The numbers behind the view's pictures, computed for one BRDF (docs/view.md, "API"). Each field
// is float32 RGB (or the luminance of ρ alone, where asked), row-major, row 0 at the bottom of the
// picture (y grows with the row), NaN where the picture has no value (outside the valid domain,
// outside the disk).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string_view>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/core/param_descriptor.hpp"
#include "halfback/core/space.hpp"

namespace halfback::view {

// A parameterization of a field: one of the registry (space; the batch engine's kernels), or
// one built for a request and never registered (own: Dupuy & Jakob's warp of a request's BRDF,
// whose maps the fields call directly). The default is dirs: no parameterization.
struct ViewForm {
  Space space = Space::dirs;
  std::shared_ptr<const ParamDescriptor> own;

  ViewForm(Space s = Space::dirs) : space(s) {}  // NOLINT: a registered space is a form
  explicit ViewForm(std::shared_ptr<const ParamDescriptor> p) : own(std::move(p)) {}
  bool is_dirs() const { return !own && space.is_dirs(); }
  const ParamDescriptor& param() const { return own ? *own : space.param(); }
  std::string_view name() const { return own ? own->name() : name_of(space); }
};

// The pairs of rows of coordinates of `form` (3 per row when `isotropic`, else 4; azimuths are
// wrapped in place) and whether each is in the valid domain: convert()'s pairs for a registered
// form, the descriptor's checked inverse for one of a request (NaN pairs outside the domain).
void form_to_pairs(const ViewForm& form, bool isotropic, std::vector<double>& coords,
                   std::vector<DirPair<double>>& pairs, std::vector<std::uint8_t>& valid,
                   int threads);

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
// `expired` (if given) is asked between blocks of evaluations of ρ: true, and the field is
// returned empty (the caller's deadline, its client gone; see hemisphere_field too).
std::vector<float> slice_field(const Brdf& brdf, const ViewForm& form, double azimuth,
                               std::size_t n, int threads, RhoValues values = RhoValues::rgb,
                               double pose = 0, const std::function<bool()>& expired = {});

// The hemisphere of ωi for a given ωo, seen from above (x right, y up) in the equal-area
// projection r = √2 sin(θi/2), on the n × n pixel centres of [−1, 1]²: ρ(ωi, ωo) when `space`
// is dirs (as `values` says), else the three isotropic coordinates of (ωi, ωo) in that
// parameterization. `expired` as in slice_field (asked only where ρ is evaluated).
std::vector<float> hemisphere_field(const Brdf* brdf, const ViewForm& space, const Vec3<double>& wo,
                                    std::size_t n, int threads, RhoValues values = RhoValues::rgb,
                                    const std::function<bool()>& expired = {});

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
