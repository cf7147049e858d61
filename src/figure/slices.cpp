#include "halfback/figure/slices.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "halfback/core/parallel.hpp"
#include "halfback/figure/coordinates.hpp"
#include "halfback/figure/render.hpp"

namespace halfback::figure {

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

const Color kSliceBackground{0.10, 0.10, 0.13};

Color test_function_colour(TestFunction f) {
  switch (f) {
    case TestFunction::specular:
      return {1.0, 0.22, 0.18};
    case TestFunction::grazing:
      return {0.30, 0.62, 1.0};
    case TestFunction::fresnel:
      break;
  }
  return kWhite;
}

std::string colour_name(TestFunction f) {
  switch (f) {
    case TestFunction::specular:
      return "red";
    case TestFunction::grazing:
      return "blue";
    case TestFunction::fresnel:
      break;
  }
  return "white";
}

std::string formula(TestFunction f) {
  switch (f) {
    case TestFunction::specular:
      return "S = 1 − ‖h\u0304‖";
    case TestFunction::grazing:
      return "G = 1 − (ωi·n)(ωo·n)";
    case TestFunction::fresnel:
      break;
  }
  return "F = 1 − cos θ_d";
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return kNan;
  const std::size_t k = std::min(v.size() - 1, std::size_t(p * double(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return v[k];
}

}  // namespace

std::string power_of_ten_label(double log10_value) {
  const long e = std::lround(std::floor(log10_value + 1e-9));
  const double m = std::pow(10.0, log10_value - double(e));
  const long mi = std::lround(m);
  const std::string exp = e < 0 ? fmt::format("−{}", -e) : fmt::format("{}", e);
  if (mi == 1) return fmt::format("10^{{{}}}", exp);
  return fmt::format("{}·10^{{{}}}", mi, exp);
}

SliceSample sample_slice(Space space, double azimuth, const Grid& grid, int threads) {
  if (space == Space::dirs) throw std::invalid_argument("slice: dirs is not a parameterization");
  SliceSample s;
  s.grid = grid;
  s.valid.assign(grid.size(), 0);
  s.pairs.resize(grid.size());
  const ParamDescriptor& param = space.param();
  parallel_for(
      grid.ny, 1,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j) {
          for (std::size_t i = 0; i < grid.nx; ++i) {
            const Solved<double> r = param.inverse_iso({grid.x(i), grid.y(j), azimuth});
            const std::size_t k = grid.index(i, j);
            s.valid[k] = r.in_domain ? 1 : 0;
            s.pairs[k] = r.pair;
          }
        }
      },
      threads);
  return s;
}

ScalarField test_function_field(const SliceSample& slice, TestFunction f) {
  ScalarField out(slice.grid);
  out.valid = slice.valid;
  for (std::size_t k = 0; k < out.values.size(); ++k)
    out.values[k] = slice.valid[k] ? test_function_value(f, slice.pairs[k]) : kNan;
  return out;
}

std::vector<double> log_levels(double lo, double hi, std::size_t max_count) {
  std::vector<double> best;
  static const std::vector<std::vector<double>> steps{{1}, {1, 2, 5}, {1, 2, 3, 4, 5, 6, 7, 8, 9}};
  for (const auto& mantissas : steps) {
    std::vector<double> levels;
    for (long e = long(std::floor(lo)) - 1; e <= long(std::ceil(hi)); ++e)
      for (double m : mantissas) {
        const double l = double(e) + std::log10(m);
        if (l > lo + 1e-9 && l < hi - 1e-9) levels.push_back(l);
      }
    if (levels.size() <= max_count && levels.size() >= best.size()) best = levels;
    if (levels.size() > max_count) break;
  }
  if (best.empty() && max_count > 0 && hi > lo) {
    // Less than one level per decade fits: every n-th decade.
    const long n = long(std::ceil((hi - lo) / double(max_count)));
    for (long e = long(std::ceil(lo)); e < hi; ++e)
      if (e % n == 0) best.push_back(double(e));
  }
  return best;
}

namespace {

void check_slice_options(const SliceOptions& o) {
  if (o.params.empty()) throw std::invalid_argument("slice figure: no parameterization given");
  if (o.azimuths_deg.empty()) throw std::invalid_argument("slice figure: no azimuth given");
  if (!o.brdf && o.test_functions.empty())
    throw std::invalid_argument("slice figure: no test function and no BRDF given");
  for (Space s : o.params)
    if (s == Space::dirs)
      throw std::invalid_argument("slice figure: 'dirs' is not a parameterization (use " +
                                  parameterization_names() + ")");
  for (double a : o.azimuths_deg)
    if (!std::isfinite(a))
      throw std::invalid_argument("slice figure: the azimuths must be finite numbers");
  if (!(o.panel_size > 10) || !(o.pixels_per_point > 0))
    throw std::invalid_argument("slice figure: bad panel size or pixel density");
}

// Where things go, in points: a row of panels per parameterization, a column per azimuth.
struct SliceLayout {
  double panel = 0, gap = 26, vgap = 56, left = 84, right = 24, bottom = 64, top = 0;
  std::size_t rows = 0, cols = 0;

  double panels_height() const { return double(rows) * panel + double(rows - 1) * vgap; }
  double panels_right() const { return left + double(cols) * panel + double(cols - 1) * gap; }
  double panels_bottom() const { return top + double(rows) * panel + double(rows - 1) * vgap; }
};

// The scene's title, and the heading and subtitle drawn above the panels.
struct SliceText {
  std::string title, heading, subtitle;
};

SliceText brdf_slice_text(const SliceOptions& o) {
  SliceText t;
  t.title = fmt::format("Slices of the isotropic forms: {}", o.brdf->name());
  t.heading = fmt::format("Slices of the isotropic forms at fixed relative azimuth: {}",
                          escape_markup(o.brdf->name()));
  t.subtitle = fmt::format(
      "{}. Colour: {}; isolines of luminance at log-spaced levels; one scale "
      "for all panels, clipped at the 0.5 % and 99.5 % percentiles; hatched: outside "
      "the valid domain.",
      escape_markup(o.brdf->description()),
      o.colouring == SliceColouring::rgb ? "RGB tone-mapped on the log-luminance scale"
                                         : "false colour (viridis) of log₁₀ luminance");
  return t;
}

SliceText test_function_slice_text(const SliceOptions& o) {
  std::string names;
  for (std::size_t k = 0; k < o.test_functions.size(); ++k)
    names += (k ? ", " : "") + std::string(letter_of(o.test_functions[k]));
  SliceText t;
  t.title = fmt::format("Slices of the isotropic forms: test functions {}", names);
  t.heading = fmt::format(
      "Slices of the isotropic forms at fixed relative azimuth: test functions {}", names);
  if (!o.levels.empty())
    t.subtitle = fmt::format("Isolines at {:g} … {:g}", o.levels.front(), o.levels.back());
  if (o.levels.size() == 9 && o.levels.front() == 0.1) t.subtitle += " (step 0.1; 0.5 thicker)";
  t.subtitle += "; hatched: outside the valid domain.";
  return t;
}

// The azimuth in [0, 2π) for the core, from degrees reduced to [0°, 360°).
double core_azimuth(double degrees) {
  double a = std::fmod(degrees, 360.0);
  if (a < 0) a += 360.0;
  double rad = a * kDeg;
  if (rad >= 2 * kPi) rad = 0;
  return rad;
}

// Every panel is sampled before any is drawn: in generic mode the colour scale is shared.
std::vector<SliceFigure::Panel> sample_panels(const SliceOptions& o, const SliceLayout& l) {
  std::vector<SliceFigure::Panel> panels;
  for (std::size_t r = 0; r < l.rows; ++r) {
    const auto coords = iso_coordinates(o.params[r]);
    for (std::size_t c = 0; c < l.cols; ++c) {
      SliceFigure::Panel p;
      p.param = o.params[r];
      p.azimuth_deg = o.azimuths_deg[c];
      p.map = PanelMap{{l.left + double(c) * (l.panel + l.gap),
                        l.top + double(r) * (l.panel + l.vgap), l.panel, l.panel},
                       0,
                       coords[0].max,
                       0,
                       coords[1].max};
      p.sample = sample_slice(p.param, third_coordinate_at(p.param, core_azimuth(p.azimuth_deg)),
                              p.map.raster_grid(o.pixels_per_point), o.threads);
      panels.push_back(std::move(p));
    }
  }
  return panels;
}

// Generic mode: the BRDF on every valid pair of every panel, as RGB and as log10 luminance.
struct PanelValues {
  std::vector<std::vector<Rgb>> rgb;
  std::vector<ScalarField> log_luminance;
};

// One panel's values; the finite log luminances are also appended to `all`.
void evaluate_panel(const Brdf& brdf, const SliceSample& s, PanelValues& v,
                    std::vector<double>& all) {
  std::vector<DirPair<double>> pairs;
  std::vector<std::size_t> where;
  for (std::size_t k = 0; k < s.valid.size(); ++k)
    if (s.valid[k]) {
      pairs.push_back(s.pairs[k]);
      where.push_back(k);
    }
  std::vector<Rgb> values(pairs.size());
  brdf.eval_batch(pairs, values);
  std::vector<Rgb>& rgb = v.rgb.emplace_back(s.valid.size(), Rgb{kNan, kNan, kNan});
  ScalarField f(s.grid);
  f.valid = s.valid;
  std::fill(f.values.begin(), f.values.end(), kNan);
  for (std::size_t m = 0; m < where.size(); ++m) {
    rgb[where[m]] = values[m];
    const double l = values[m].luminance();
    if (l > 0 && std::isfinite(l)) {
      f.values[where[m]] = std::log10(l);
      all.push_back(f.values[where[m]]);
    }
  }
  v.log_luminance.push_back(std::move(f));
}

// The shared scale (fig.log_lo … fig.log_hi) from the log luminances of every panel, and its
// isoline levels.
void set_luminance_scale(SliceFigure& fig, const std::vector<double>& all, std::size_t max_levels) {
  if (all.empty()) {
    fig.log_lo = -1;
    fig.log_hi = 0;
  } else {
    // Percentiles, not extremes: grazing spikes (1/cos θ factors) would otherwise take the
    // whole scale. At most 7 decades.
    fig.log_hi = percentile(all, 0.995);
    fig.log_lo = std::max(percentile(all, 0.005), fig.log_hi - 7.0);
    if (!(fig.log_hi - fig.log_lo > 1e-6)) fig.log_lo = fig.log_hi - 1;
  }
  fig.log_levels = log_levels(fig.log_lo, fig.log_hi, max_levels);
}

PanelValues evaluate_panels(const SliceOptions& o, SliceFigure& fig) {
  PanelValues v;
  std::vector<double> all;
  for (const SliceFigure::Panel& p : fig.panels) evaluate_panel(*o.brdf, p.sample, v, all);
  set_luminance_scale(fig, all, o.luminance_levels);
  // Luminance 0 (or below the scale) sits at the bottom of the scale, and contours as such.
  for (ScalarField& f : v.log_luminance)
    for (std::size_t k = 0; k < f.values.size(); ++k)
      if (f.valid[k] && !std::isfinite(f.values[k])) f.values[k] = fig.log_lo - 1;
  return v;
}

void draw_panel_raster(Scene& sc, const SliceOptions& o, const SliceFigure& fig,
                       const SliceFigure::Panel& p, const PanelValues& values, std::size_t n) {
  const SliceSample& s = p.sample;
  const Grid& g = s.grid;
  const bool generic = o.brdf != nullptr;
  sc.add(raster(p.map, g, [&](std::size_t i, std::size_t j) -> Color {
    const std::size_t k = g.index(i, j);
    if (!s.valid[k]) return hatch(i, j, kInvalidLight, kInvalidDark);
    if (!generic) return kSliceBackground;
    if (o.colouring == SliceColouring::rgb)
      return tonemap_log(values.rgb[n][k], fig.log_lo, fig.log_hi);
    const double v = values.log_luminance[n].values[k];
    return viridis((v - fig.log_lo) / (fig.log_hi - fig.log_lo));
  }));
}

void draw_panel_isolines(Scene& sc, const SliceOptions& o, const SliceFigure& fig,
                         const SliceFigure::Panel& p, const PanelValues& values, std::size_t n) {
  if (o.brdf) {
    for (double level : fig.log_levels) {
      const bool decade = std::abs(level - std::round(level)) < 1e-9;
      // White on viridis; orange on the grey levels of tone-mapped RGB.
      const Color lc =
          o.colouring == SliceColouring::rgb ? Color{1.0, 0.55, 0.1, 0.9} : Color{1, 1, 1, 0.8};
      draw_polylines(sc, p.map, contour(values.log_luminance[n], level),
                     Stroke{lc, decade ? 0.9 : 0.5});
    }
    return;
  }
  for (TestFunction f : o.test_functions) {
    const ScalarField field = test_function_field(p.sample, f);
    for (double level : o.levels) {
      const double w = std::abs(level - 0.5) < 1e-12 ? 1.3 : 0.75;
      draw_polylines(sc, p.map, contour(field, level), Stroke{test_function_colour(f), w});
    }
  }
}

// The domain boundary, exactly (bisection on valid_iso).
void draw_domain_boundary(Scene& sc, const SliceFigure::Panel& p) {
  const double third = third_coordinate_at(p.param, core_azimuth(p.azimuth_deg));
  auto inside = [&](double x, double y) {
    return bool(p.param.param().inverse_iso({x, y, third}).in_domain);
  };
  draw_polylines(sc, p.map, region_boundary(p.sample.grid, p.sample.valid, inside),
                 Stroke{kBlack, 0.8});
}

// The axes, the azimuth above the panel and, in the first column, the parameterization's name.
void draw_panel_labels(Scene& sc, const SliceFigure::Panel& p, const SliceLayout& l,
                       bool first_column) {
  const auto coords = iso_coordinates(p.param);
  const double fs = 8.5;
  AxisSpec ax{coords[0].label, ticks(0, coords[0].max, coords[0].angle ? 15 * kDeg : 0.2), {}};
  AxisSpec ay{coords[1].label, ticks(0, coords[1].max, coords[1].angle ? 15 * kDeg : 0.2), {}};
  for (double t : ax.ticks) ax.labels.push_back(format_coordinate(coords[0], t));
  for (double t : ay.ticks) ay.labels.push_back(format_coordinate(coords[1], t));
  draw_axes(sc, p.map, ax, ay, true, first_column, fs);
  sc.text({p.map.rect.x + 0.5 * l.panel, p.map.rect.y - 5},
          third_coordinate_title(p.param, p.azimuth_deg), 9.5, HAlign::centre, VAlign::bottom);
  if (first_column)
    sc.text({14, p.map.rect.y + 0.5 * l.panel}, std::string(name_of(p.param)), 11, HAlign::centre,
            VAlign::middle, kBlack, 90, true);
}

// Test-function mode: the legend's items (label, width from its length), in rows that fit
// `width` points.
struct LegendRows {
  std::vector<std::string> labels;
  std::vector<double> widths;
  std::vector<std::vector<std::size_t>> rows;  // item indices, row by row
};
LegendRows test_function_legend(const SliceOptions& o, double width) {
  LegendRows g;
  double x = 0;
  for (TestFunction f : o.test_functions) {
    g.labels.push_back(formula(f) + " (" + colour_name(f) + ")");
    g.widths.push_back(40 + approx_text_width(g.labels.back(), 9));
    if (g.rows.empty() || x + g.widths.back() > width) g.rows.emplace_back(), x = 0;
    g.rows.back().push_back(g.labels.size() - 1);
    x += g.widths.back();
  }
  return g;
}

// The legend on a dark strip per row (the white swatch needs it).
void draw_test_function_legend(Scene& sc, const SliceOptions& o, const SliceLayout& l,
                               const LegendRows& g, double ly) {
  for (const std::vector<std::size_t>& row : g.rows) {
    double total = 0;
    for (std::size_t k : row) total += g.widths[k];
    sc.rect(l.left - 8, ly - 9, total + 4, 18, kSliceBackground, std::nullopt);
    double x = l.left;
    for (std::size_t k : row) {
      draw_legend_line(sc, {x, ly}, Stroke{test_function_colour(o.test_functions[k]), 1.6},
                       g.labels[k], 9, kWhite);
      x += g.widths[k];
    }
    ly += 20;
  }
}

// Generic mode: the note below the panels, wrapped to the figure's width.
constexpr std::string_view kLuminanceNote =
    "Luminance isolines at the levels marked on the colour bar (decades thicker).";

// Generic mode: the colour bar of the shared scale, right of the panels, and the note's lines
// below.
void draw_luminance_colour_bar(Scene& sc, const SliceOptions& o, const SliceFigure& fig,
                               const SliceLayout& l, const std::vector<std::string>& note,
                               double ly) {
  const double bar_x = l.panels_right() + 22;
  const Rect bar{bar_x, l.top + 10, 14, l.panels_height() - 20};
  std::vector<double> tick_t;
  std::vector<std::string> labels;
  const std::vector<double> label_levels = log_levels(fig.log_lo - 1e-6, fig.log_hi + 1e-6, 8);
  const double span = fig.log_hi - fig.log_lo;
  for (double v : label_levels) {
    tick_t.push_back((v - fig.log_lo) / span);
    labels.push_back(power_of_ten_label(v));
  }
  if (o.colouring == SliceColouring::luminance)
    draw_colour_bar(
        sc, bar, [](double t) { return viridis(t); }, tick_t, labels, "luminance",
        o.pixels_per_point);
  else  // tonemap_log: luminance t on the same scale, drawn as grey t
    draw_colour_bar(
        sc, bar,
        [](double t) {
          return Color{t, t, t};
        },
        tick_t, labels, "luminance", o.pixels_per_point);
  for (const std::string& line : note) {
    sc.text({l.left, ly}, line, 9);
    ly += 12;
  }
}

}  // namespace

SliceFigure slice_figure(const SliceOptions& o) {
  check_slice_options(o);
  SliceFigure fig;
  Scene& sc = fig.scene;
  const bool generic = o.brdf != nullptr;
  SliceLayout l;
  l.panel = snap(o.panel_size);
  if (generic) l.right = 96;  // room for the colour bar
  l.rows = o.params.size();
  l.cols = o.azimuths_deg.size();
  sc.width = snap(l.panels_right() + l.right);

  const SliceText text = generic ? brdf_slice_text(o) : test_function_slice_text(o);
  sc.title = text.title;
  // Heading, subtitle and legend wrapped to the figure's width (one column is narrower than
  // their lines): the margins grow with their lines.
  const std::vector<std::string> heading = wrap_text(text.heading, sc.width - l.left - 8, 12);
  const std::vector<std::string> subtitle = wrap_text(text.subtitle, sc.width - l.left - 12, 9);
  const double heading_extra = 15 * double(heading.size() - 1);
  l.top = 58 + heading_extra + 12 * double(subtitle.size());
  const LegendRows legend = generic ? LegendRows{} : test_function_legend(o, sc.width - l.left);
  const std::vector<std::string> note =
      generic ? wrap_text(kLuminanceNote, sc.width - l.left - 8, 9) : std::vector<std::string>{};
  l.bottom += generic ? 12 * double(note.size() - 1)
                      : 20 * double(std::max<std::size_t>(legend.rows.size(), 1) - 1);
  sc.height = snap(l.panels_bottom() + l.bottom);
  check_raster_size(sc.width, sc.height, o.pixels_per_point,
                    fmt::format("fewer azimuths ({} given) or parameterizations ({} given), or a "
                                "lower pixel density",
                                l.cols, l.rows));

  fig.panels = sample_panels(o, l);
  const PanelValues values = generic ? evaluate_panels(o, fig) : PanelValues{};

  for (std::size_t k = 0; k < heading.size(); ++k)
    sc.text({l.left, 20 + 15 * double(k)}, heading[k], 12, HAlign::left, VAlign::baseline, kBlack,
            0, true);
  for (std::size_t k = 0; k < subtitle.size(); ++k)
    sc.text({l.left, 36 + heading_extra + 12 * double(k)}, subtitle[k], 9);

  for (std::size_t n = 0; n < fig.panels.size(); ++n) {
    const SliceFigure::Panel& p = fig.panels[n];
    draw_panel_raster(sc, o, fig, p, values, n);
    draw_panel_isolines(sc, o, fig, p, values, n);
    draw_domain_boundary(sc, p);
    draw_panel_labels(sc, p, l, n % l.cols == 0);
  }

  // Legend or colour bar.
  const double ly = l.panels_bottom() + 46;
  if (generic)
    draw_luminance_colour_bar(sc, o, fig, l, note, ly);
  else
    draw_test_function_legend(sc, o, l, legend, ly);
  return fig;
}

}  // namespace halfback::figure
