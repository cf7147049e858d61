// How the figures name, scale and contour the isotropic coordinates of each parameterization.
#pragma once

#include <array>
#include <string>

#include "halfback/core/space.hpp"

namespace halfback::figure {

// One of the two non-azimuthal isotropic coordinates (θi/θo, θh/θd, ‖h̄‖/‖k̄‖, ‖h̄‖/‖k‖).
struct CoordinateInfo {
  std::string label;   // with the markup of scene.hpp, e.g. "θ_h", "‖h̄‖"
  double max = 1;      // range is [0, max]: π/2 for angles, 1 for magnitudes
  bool angle = false;  // shown in degrees
  double spacing = 0;  // isoline spacing in the coordinate's units: 10° or 0.1
};

// The two non-azimuthal isotropic coordinates of a parameterization, in the order of its
// isotropic form (docs/math.md §1). Throws std::invalid_argument for Space::dirs.
std::array<CoordinateInfo, 2> iso_coordinates(Space space);

// The relative azimuth of the isotropic form: "Δφ" (spherical, φo − φi), "φ_d" (halfdiff),
// "φ_k − φ_h" (ortho, hybrid).
std::string relative_azimuth_label(Space space);

// The third isotropic coordinate of the slice at relative azimuth `radians` ∈ [0, 2π): that
// azimuth when the coordinate is one (every built-in parameterization), else the same fraction of
// its range (Dupuy & Jakob's s2, the half vector's relative azimuth through the warp's CDF).
double third_coordinate_at(Space space, double radians);
// The slice's title: "φ_d = 45°", or "s_2 = 0.125" for a third coordinate that is no azimuth.
std::string third_coordinate_title(Space space, double degrees);

// Formats a coordinate value for a tick label: "40°" for angles (value in radians), "0.5" else.
std::string format_coordinate(const CoordinateInfo& c, double value);

}  // namespace halfback::figure
