// Figure 1 of Barla et al. 2015: for a fixed outgoing direction ωo, every incoming direction ωi
// of the hemisphere drawn on a disk and coloured by the two non-azimuthal coordinates of the pair
// (ωi, ωo) in a parameterization: the first in red, the second in green, each divided by its range
// (θ/90° or the magnitude itself), with isolines of both at 10° or 0.1.
//
// Geometry (docs/figures.md): ωo = (−sin θo, 0, cos θo), so the mirror direction
// (sin θo, 0, cos θo) is on the right of a disk centred on n and ωo itself, the back
// (retro-reflection) direction, on its left. A view is centred on a direction c: the disk is the
// hemisphere of directions within 90° of c, seen from outside along −c, with the bitangent b = +y
// pointing up and e1 = b × c pointing right (so the view centred on n is the usual top view,
// x right and y up). Disk radius 1 is 90° from c. Directions below the surface's horizon (z < 0),
// which only the views centred on the mirror or back direction contain, are hatched.
#pragma once

#include <optional>
#include <string_view>
#include <vector>

#include "halfback/core/space.hpp"
#include "halfback/figure/field.hpp"
#include "halfback/figure/plot.hpp"
#include "halfback/figure/scene.hpp"

namespace halfback::figure {

// Azimuthal projections of a hemisphere onto the unit disk, as a function of the angle ψ from
// the centre: equal-area (Lambert) r = √2 sin(ψ/2); orthographic r = sin ψ; equidistant
// r = ψ/(π/2). All three send ψ = 90° to r = 1.
enum class Projection { equal_area, orthographic, equidistant };
enum class ViewCentre { normal, mirror, back };

std::optional<Projection> projection_from_name(std::string_view name);  // "equal-area", ...
std::string_view name_of(Projection p);
std::optional<ViewCentre> view_centre_from_name(std::string_view name);  // "normal", ...
std::string_view name_of(ViewCentre c);

// ωo at polar angle theta_o (radians) in the xz-plane, azimuth π.
Vec3<double> outgoing_direction(double theta_o);
Vec3<double> mirror_direction(const Vec3<double>& wo);  // (−x, −y, z)

struct HemisphereView {
  Projection projection = Projection::equal_area;
  Vec3<double> centre{0, 0, 1}, right{1, 0, 0}, up{0, 1, 0};

  // The view of the hemisphere around `centre` (a unit vector not along ±y is assumed; the
  // figures' centres lie in the xz-plane).
  static HemisphereView around(const Vec3<double>& centre, Projection projection);
  // The view `which` for outgoing direction wo.
  static HemisphereView make(ViewCentre which, const Vec3<double>& wo, Projection projection);

  // The direction at disk point (u, v) (u right, v up); nullopt outside the unit disk.
  std::optional<Vec3<double>> direction(double u, double v) const;
  // The disk point of a direction; nullopt when it is more than 90° from the centre.
  std::optional<Point> project(const Vec3<double>& w) const;
};

// The sampled content of one disk: on the pixel-centre grid of [−1, 1]², `region` is 0 outside
// the disk, 1 where ωi is below the horizon, 2 where the pair is valid; `first` and `second` are
// the two coordinates of the pair in radians or as magnitudes (NaN unless region == 2).
struct HemisphereSample {
  Grid grid;
  std::vector<std::uint8_t> region;
  ScalarField first, second;
};

HemisphereSample sample_hemisphere(Space space, const HemisphereView& view, const Vec3<double>& wo,
                                   std::size_t pixels, int threads = 0);

struct HemisphereOptions {
  std::vector<Space> params{space_of<HalfDiff>, space_of<Ortho>, space_of<Hybrid>};
  std::vector<double> elevations_deg{0, 40, 80};  // θo, the polar angle of ωo from n
  Projection projection = Projection::equal_area;
  ViewCentre centre = ViewCentre::normal;
  double disk_size = 150;  // points
  double pixels_per_point = 2;
  int threads = 0;
  bool isolines = true;
  bool markers = true;  // mark ωo (×) and the mirror direction (○)
};

struct HemisphereFigure {
  struct Panel {
    Space param;
    double elevation_deg;
    Vec3<double> wo;
    HemisphereView view;
    PanelMap map;  // data coordinates: the disk point (u, v)
    HemisphereSample sample;
  };
  Scene scene;
  std::vector<Panel> panels;  // row-major: params × elevations
};

// Throws std::invalid_argument for an empty list, Space::dirs, or an elevation outside [0°, 90°].
HemisphereFigure hemisphere_figure(const HemisphereOptions& options);

}  // namespace halfback::figure
