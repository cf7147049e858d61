#include "halfback/figure/hemisphere.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "halfback/core/parallel.hpp"
#include "halfback/figure/coordinates.hpp"
#include "halfback/figure/plot.hpp"
#include "halfback/figure/render.hpp"

namespace halfback::figure {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

double radius_of(Projection p, double psi) {
  switch (p) {
    case Projection::orthographic:
      return std::sin(psi);
    case Projection::equidistant:
      return psi / (0.5 * kPi);
    case Projection::equal_area:
      break;
  }
  return std::sqrt(2.0) * std::sin(0.5 * psi);
}

double angle_of(Projection p, double r) {  // inverse of radius_of on [0, 1]
  switch (p) {
    case Projection::orthographic:
      return std::asin(std::min(r, 1.0));
    case Projection::equidistant:
      return r * 0.5 * kPi;
    case Projection::equal_area:
      break;
  }
  return 2.0 * std::asin(std::min(r / std::sqrt(2.0), 1.0));
}

Vec3<double> cross(const Vec3<double>& a, const Vec3<double>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double dot(const Vec3<double>& a, const Vec3<double>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

std::string projection_title(Projection p) {
  switch (p) {
    case Projection::orthographic:
      return "orthographic projection (r = sin ψ)";
    case Projection::equidistant:
      return "equidistant projection (r = ψ / 90°)";
    case Projection::equal_area:
      break;
  }
  return "equal-area (Lambert azimuthal) projection, r = √2 sin(ψ/2)";
}

std::string capitalized(std::string s) {
  if (!s.empty() && s[0] >= 'a' && s[0] <= 'z') s[0] = char(s[0] - 'a' + 'A');
  return s;
}

std::string centre_title(ViewCentre c) {
  switch (c) {
    case ViewCentre::mirror:
      return "disks centred on the mirror direction of ωo";
    case ViewCentre::back:
      return "disks centred on the back (retro-reflection) direction ωi = ωo";
    case ViewCentre::normal:
      break;
  }
  return "disks centred on the normal n (top view, x right, y up)";
}

}  // namespace

std::optional<Projection> projection_from_name(std::string_view name) {
  if (name == "equal-area") return Projection::equal_area;
  if (name == "orthographic") return Projection::orthographic;
  if (name == "equidistant") return Projection::equidistant;
  return std::nullopt;
}
std::string_view name_of(Projection p) {
  switch (p) {
    case Projection::orthographic:
      return "orthographic";
    case Projection::equidistant:
      return "equidistant";
    case Projection::equal_area:
      break;
  }
  return "equal-area";
}
std::optional<ViewCentre> view_centre_from_name(std::string_view name) {
  if (name == "normal") return ViewCentre::normal;
  if (name == "mirror") return ViewCentre::mirror;
  if (name == "back") return ViewCentre::back;
  return std::nullopt;
}
std::string_view name_of(ViewCentre c) {
  switch (c) {
    case ViewCentre::mirror:
      return "mirror";
    case ViewCentre::back:
      return "back";
    case ViewCentre::normal:
      break;
  }
  return "normal";
}

Vec3<double> outgoing_direction(double theta_o) {
  return {-std::sin(theta_o), 0.0, std::cos(theta_o)};
}
Vec3<double> mirror_direction(const Vec3<double>& wo) {
  return {-wo.x, -wo.y, wo.z};
}

HemisphereView HemisphereView::around(const Vec3<double>& c, Projection projection) {
  HemisphereView v;
  v.projection = projection;
  v.centre = c;
  v.up = {0, 1, 0};
  v.right = cross(v.up, c);
  const double n = std::sqrt(dot(v.right, v.right));
  v.right = {v.right.x / n, v.right.y / n, v.right.z / n};
  v.up = cross(c, v.right);
  return v;
}

HemisphereView HemisphereView::make(ViewCentre which, const Vec3<double>& wo,
                                    Projection projection) {
  switch (which) {
    case ViewCentre::mirror:
      return around(mirror_direction(wo), projection);
    case ViewCentre::back:
      return around(wo, projection);
    case ViewCentre::normal:
      break;
  }
  return around({0, 0, 1}, projection);
}

std::optional<Vec3<double>> HemisphereView::direction(double u, double v) const {
  const double r = std::hypot(u, v);
  if (!(r <= 1.0)) return std::nullopt;
  const double psi = angle_of(projection, r);
  const double s = r > 0 ? std::sin(psi) / r : 0.0, c = std::cos(psi);
  const double a = s * u, b = s * v;  // components along right and up
  return Vec3<double>{a * right.x + b * up.x + c * centre.x, a * right.y + b * up.y + c * centre.y,
                      a * right.z + b * up.z + c * centre.z};
}

std::optional<Point> HemisphereView::project(const Vec3<double>& w) const {
  const double a = dot(w, right), b = dot(w, up), c = dot(w, centre);
  if (c < -1e-12) return std::nullopt;
  const double s = std::hypot(a, b);
  const double psi = std::atan2(s, c);
  if (s == 0) return Point{0, 0};
  const double r = radius_of(projection, psi);
  return Point{r * a / s, r * b / s};
}

HemisphereSample sample_hemisphere(Space space, const HemisphereView& view, const Vec3<double>& wo,
                                   std::size_t pixels, int threads) {
  if (space == Space::dirs)
    throw std::invalid_argument("hemisphere view: dirs is not a parameterization");
  HemisphereSample s;
  s.grid = Grid::pixel_centres(pixels, pixels, -1, 1, -1, 1);
  s.region.assign(s.grid.size(), 0);
  s.first = ScalarField(s.grid);
  s.second = ScalarField(s.grid);
  s.first.valid.assign(s.grid.size(), 0);
  s.second.valid.assign(s.grid.size(), 0);
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  const ParamDescriptor& param = space.param();
  parallel_for(
      s.grid.ny, 1,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j) {
          for (std::size_t i = 0; i < s.grid.nx; ++i) {
            const std::size_t k = s.grid.index(i, j);
            s.first.values[k] = s.second.values[k] = nan;
            const auto w = view.direction(s.grid.x(i), s.grid.y(j));
            if (!w) continue;
            if (w->z < 0) {
              s.region[k] = 1;
              continue;
            }
            const Tuple3<double> q = param.forward_iso(DirPair<double>{*w, wo});
            s.region[k] = 2;
            s.first.values[k] = q[0];
            s.second.values[k] = q[1];
            s.first.valid[k] = s.second.valid[k] = 1;
          }
        }
      },
      threads);
  return s;
}

namespace {

// Isolines of a coordinate at its spacing, skipping levels the field does not cross.
void draw_coordinate_isolines(Scene& scene, const PanelMap& map, const ScalarField& f,
                              const CoordinateInfo& c, const Stroke& stroke) {
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t k = 0; k < f.values.size(); ++k)
    if (f.valid[k] && std::isfinite(f.values[k])) {
      lo = std::min(lo, f.values[k]);
      hi = std::max(hi, f.values[k]);
    }
  if (!(hi - lo > 1e-9)) return;  // constant (e.g. θo in the spherical view): no isolines
  for (int n = 1; n * c.spacing < c.max - 1e-9; ++n) {
    const double level = n * c.spacing;
    if (level <= lo || level >= hi) continue;
    draw_polylines(scene, map, contour(f, level), stroke);
  }
}

const Stroke kFirstStroke{{1, 1, 1, 0.95}, 0.65};
const Stroke kSecondStroke{{0, 0, 0, 0.85}, 0.65, {2.2, 1.6}};

void draw_marker_mirror(Scene& scene, Point p) {
  scene.add(CircleItem{p, 3.2, std::nullopt, Stroke{kBlack, 1.6}});
  scene.add(CircleItem{p, 3.2, std::nullopt, Stroke{kWhite, 0.8}});
}
void draw_marker_cross(Scene& scene, Point p) {
  const double d = 3.2;
  for (const auto& [w, c] : {std::pair{1.8, kBlack}, std::pair{0.9, kWhite}}) {
    scene.line({p.x - d, p.y - d}, {p.x + d, p.y + d}, Stroke{c, w});
    scene.line({p.x - d, p.y + d}, {p.x + d, p.y - d}, Stroke{c, w});
  }
}

// The colour key of a parameterization: the square of (first, second) coordinate values,
// hatched where no pair has them (outside the isotropic domain at relative azimuth 90°, the
// largest slice: docs/figures.md; for a third coordinate that is no azimuth, at any of 32 values
// across its range).
void draw_key(Scene& scene, Space space, const Rect& rect, double ppp) {
  const auto coords = iso_coordinates(space);
  PanelMap map{rect, 0, coords[0].max, 0, coords[1].max};
  const Grid g = map.raster_grid(ppp);
  ScalarField a(g), b(g);
  a.valid.assign(g.size(), 0);
  b.valid.assign(g.size(), 0);
  const ParamDescriptor& param = space.param();
  const Axis& third = param.axes(true)[2];
  auto inside = [&](double x, double y) {
    if (third.kind == AxisKind::azimuth)
      return bool(param.inverse_iso(Tuple3<double>{x, y, 0.5 * kPi}).in_domain);
    for (int k = 0; k < 32; ++k)
      if (param.inverse_iso({x, y, third.lo + (k + 0.5) / 32 * (third.hi - third.lo)}).in_domain)
        return true;
    return false;
  };
  for (std::size_t j = 0; j < g.ny; ++j)
    for (std::size_t i = 0; i < g.nx; ++i) {
      const std::size_t k = g.index(i, j);
      a.values[k] = g.x(i);
      b.values[k] = g.y(j);
      a.valid[k] = b.valid[k] = inside(g.x(i), g.y(j)) ? 1 : 0;
    }
  scene.add(raster(map, g, [&](std::size_t i, std::size_t j) {
    const std::size_t k = g.index(i, j);
    if (!a.valid[k]) return hatch(i, j, kInvalidLight, kInvalidDark);
    return coordinate_colour(a.values[k] / coords[0].max, b.values[k] / coords[1].max);
  }));
  draw_coordinate_isolines(scene, map, a, coords[0], kFirstStroke);
  draw_coordinate_isolines(scene, map, b, coords[1], kSecondStroke);
  if (std::find(a.valid.begin(), a.valid.end(), 0) != a.valid.end()) {
    // The domain boundary (at 90°; ‖h̄‖² + ‖k‖² = 1 for hybrid), drawn exactly.
    std::vector<std::uint8_t> flags(a.valid);
    draw_polylines(scene, map, region_boundary(g, flags, inside), Stroke{kBlack, 0.8});
  }
  AxisSpec ax{coords[0].label + " (red)", {0, 0.5 * coords[0].max, coords[0].max}, {}};
  AxisSpec ay{coords[1].label + " (green)", {0, 0.5 * coords[1].max, coords[1].max}, {}};
  for (double t : ax.ticks) ax.labels.push_back(format_coordinate(coords[0], t));
  for (double t : ay.ticks) ay.labels.push_back(format_coordinate(coords[1], t));
  draw_axes(scene, map, ax, ay, true, true, 7.5);
}

}  // namespace

namespace {
std::size_t utf8_length(std::string_view s) {
  std::size_t n = 0;
  for (unsigned char c : s) n += (c & 0xC0) != 0x80;
  return n;
}
}  // namespace

HemisphereFigure hemisphere_figure(const HemisphereOptions& o) {
  if (o.params.empty()) throw std::invalid_argument("hemisphere figure: no parameterization given");
  if (o.elevations_deg.empty())
    throw std::invalid_argument("hemisphere figure: no elevation given");
  for (Space s : o.params)
    if (s == Space::dirs)
      throw std::invalid_argument("hemisphere figure: 'dirs' is not a parameterization (use " +
                                  parameterization_names() + ")");
  for (double e : o.elevations_deg)
    if (!(e >= 0 && e <= 90))
      throw std::invalid_argument(
          fmt::format("hemisphere figure: elevation {}° is outside [0°, 90°] (it is θo, the "
                      "angle of ωo from the normal)",
                      e));
  if (!(o.disk_size > 10) || !(o.pixels_per_point > 0))
    throw std::invalid_argument("hemisphere figure: bad disk size or pixel density");

  HemisphereFigure fig;
  const double D = snap(o.disk_size), gap = 18, vgap = 22;
  // The row labels (names in bold 11 pt, about 0.62 em a character) fit in the left margin.
  std::size_t longest = 0;
  for (Space s : o.params) longest = std::max(longest, utf8_length(name_of(s)));
  const double left = snap(std::max(92.0, 16 + 0.62 * 11 * double(longest)));
  const double key_gap = 62, key = snap(0.62 * D), right = 24;
  const std::size_t rows = o.params.size(), cols = o.elevations_deg.size();
  Scene& sc = fig.scene;
  sc.width = snap(left + double(cols) * D + double(cols - 1) * gap + key_gap + key + right);
  // The heading, subtitle and notes are wrapped to the width (a figure of one or two columns is
  // narrower than their lines): the margins above and below grow with their lines.
  const auto heading =
      wrap_text("Incoming directions ωi for a fixed ωo, coloured by the coordinates of (ωi, ωo)",
                sc.width - left - 8, 12);
  const auto subtitle = wrap_text(
      "red: first coordinate / range, green: second / range; isolines every 10° or 0.1 "
      "(white: first, black dashed: second)",
      sc.width - left - 8, 9);
  std::string legend = "ωo = (−sin θ_o, 0, cos θ_o).";
  if (o.markers) legend += "  ○: mirror direction of ωo;  ×: ωo itself (the back direction).";
  legend += "  Hatched: ωi below the horizon.";
  std::vector<std::string> notes;
  for (const std::string& note :
       {capitalized(projection_title(o.projection)) + ", ψ the angle from the disk centre; " +
            centre_title(o.centre) + ".",
        legend,
        std::string("Colour key: (first, second) coordinate → (red, green); hatched where no "
                    "pair has these coordinates.")})
    for (std::string& line : wrap_text(note, sc.width - 16, 9)) notes.push_back(std::move(line));
  const double top = 64 + 15 * double(heading.size() - 1) + 12 * double(subtitle.size() - 1);
  const double bottom = 64 + 13 * double(notes.size() - 3);
  sc.height = snap(top + double(rows) * D + double(rows - 1) * vgap + bottom);
  check_raster_size(sc.width, sc.height, o.pixels_per_point,
                    fmt::format("fewer elevations ({} given) or parameterizations ({} given), or "
                                "a lower pixel density",
                                cols, rows));
  sc.title = "Figure 1: the hemisphere of incoming directions for a fixed outgoing direction";

  double line_y = 20;
  for (const std::string& line : heading) {
    sc.text({left, line_y}, line, 12, HAlign::left, VAlign::baseline, kBlack, 0, true);
    line_y += 15;
  }
  line_y += 1;
  for (const std::string& line : subtitle) {
    sc.text({left, line_y}, line, 9);
    line_y += 12;
  }
  const std::size_t pixels = std::size_t(std::lround(D * o.pixels_per_point));

  for (std::size_t c = 0; c < cols; ++c) {
    const double x = left + double(c) * (D + gap);
    sc.text({x + 0.5 * D, top - 6}, fmt::format("θ_o = {:g}°", o.elevations_deg[c]), 10,
            HAlign::centre, VAlign::bottom);
  }
  const double key_x = left + double(cols) * D + double(cols - 1) * gap + key_gap;
  sc.text({key_x + 0.5 * key, top - 6}, "colour key", 10, HAlign::centre, VAlign::bottom);

  for (std::size_t r = 0; r < rows; ++r) {
    const Space space = o.params[r];
    const auto coords = iso_coordinates(space);
    const double y = top + double(r) * (D + vgap);
    sc.text({8, y + 0.5 * D - 10}, std::string(name_of(space)), 11, HAlign::left, VAlign::middle,
            kBlack, 0, true);
    sc.text({8, y + 0.5 * D + 6}, "red: " + coords[0].label, 9, HAlign::left, VAlign::middle);
    sc.text({8, y + 0.5 * D + 19}, "green: " + coords[1].label, 9, HAlign::left, VAlign::middle);
    for (std::size_t c = 0; c < cols; ++c) {
      HemisphereFigure::Panel p;
      p.param = space;
      p.elevation_deg = o.elevations_deg[c];
      p.wo = outgoing_direction(p.elevation_deg * kDeg);
      p.view = HemisphereView::make(o.centre, p.wo, o.projection);
      p.map = PanelMap{{left + double(c) * (D + gap), y, D, D}, -1, 1, -1, 1};
      p.sample = sample_hemisphere(space, p.view, p.wo, pixels, o.threads);
      const HemisphereSample& s = p.sample;
      sc.add(raster(p.map, s.grid, [&](std::size_t i, std::size_t j) -> Color {
        const std::size_t k = s.grid.index(i, j);
        if (s.region[k] == 0) return {1, 1, 1, 0};
        if (s.region[k] == 1) return hatch(i, j, kBelowHorizonLight, kBelowHorizonDark);
        return coordinate_colour(s.first.values[k] / coords[0].max,
                                 s.second.values[k] / coords[1].max);
      }));
      if (o.isolines) {
        draw_coordinate_isolines(sc, p.map, s.first, coords[0], kFirstStroke);
        draw_coordinate_isolines(sc, p.map, s.second, coords[1], kSecondStroke);
      }
      const Point centre = p.map.to_page(0, 0);
      // The horizon inside the disk (views not centred on n), traced exactly.
      if (p.view.centre.z < 1 - 1e-12) {
        Polyline h;
        for (int t = 0; t <= 1440; ++t) {
          const double a = 2 * kPi * t / 1440;
          const auto q = p.view.project({std::cos(a), std::sin(a), 0});
          if (q && dot({std::cos(a), std::sin(a), 0}, p.view.centre) >= 0) {
            h.points.push_back(*q);
          } else if (!h.points.empty()) {
            draw_polylines(sc, p.map, {h}, Stroke{kBlack, 0.9});
            h.points.clear();
          }
        }
        draw_polylines(sc, p.map, {h}, Stroke{kBlack, 0.9});
      }
      sc.add(CircleItem{centre, 0.5 * D, std::nullopt, Stroke{kBlack, 0.9}});
      if (o.markers) {
        if (const auto m = p.view.project(mirror_direction(p.wo)))
          draw_marker_mirror(sc, p.map.to_page(m->x, m->y));
        if (const auto b = p.view.project(p.wo)) draw_marker_cross(sc, p.map.to_page(b->x, b->y));
      }
      fig.panels.push_back(std::move(p));
    }
    draw_key(sc, space, {key_x, y + 0.5 * (D - key), key, key}, o.pixels_per_point);
  }

  double fy = top + double(rows) * D + double(rows - 1) * vgap + 20;
  for (const std::string& line : notes) {
    sc.text({8, fy}, line, 9);
    fy += 13;
  }
  return fig;
}

}  // namespace halfback::figure
