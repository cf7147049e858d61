// Figure 2 of Barla et al. 2015 and its generalization to any BRDF: 2D slices of the isotropic
// forms at a fixed relative azimuth (φd for halfdiff, φk − φh for ortho and hybrid, φo − φi for
// spherical). The x axis is the first isotropic coordinate (θh, ‖h̄‖, θi), the y axis the second
// (θd, ‖k̄‖, ‖k‖, θo). Each sample is the canonical pose of inverse_iso<P>; valid_iso<P> gives the
// mask, and the region outside the valid domain is hatched grey, with the domain boundary drawn
// exactly (bisection on valid_iso).
//
// Two modes:
//  * test functions (no `brdf`): the paper's S (red), G (blue) and F (white) as isolines at
//    0.1 … 0.9 over a dark background;
//  * any Brdf: false colour of log10 luminance (viridis) or tone-mapped RGB, with luminance
//    isolines at log-spaced levels, on one colour scale shared by all panels (Figures 3–5 style).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/brdf/test_functions.hpp"
#include "halfback/core/space.hpp"
#include "halfback/figure/field.hpp"
#include "halfback/figure/plot.hpp"
#include "halfback/figure/scene.hpp"

namespace halfback::figure {

// The pairs of one slice on `grid` (x: first coordinate, y: second): valid[k] from valid_iso,
// pairs[k] from inverse_iso (NaN where invalid).
struct SliceSample {
  Grid grid;
  std::vector<std::uint8_t> valid;
  std::vector<DirPair<double>> pairs;
};
SliceSample sample_slice(Space space, double azimuth, const Grid& grid, int threads = 0);

// A test function on a slice (NaN and invalid outside the domain).
ScalarField test_function_field(const SliceSample& slice, TestFunction f);

enum class SliceColouring { luminance, rgb };

struct SliceOptions {
  std::vector<Space> params{space_of<HalfDiff>, space_of<Ortho>, space_of<Hybrid>};
  std::vector<double> azimuths_deg{0, 45, 90};
  // Test-function mode: which functions, at which levels.
  std::vector<TestFunction> test_functions{TestFunction::specular, TestFunction::grazing,
                                           TestFunction::fresnel};
  std::vector<double> levels{0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9};
  // Generic mode when set.
  BrdfPtr brdf;
  SliceColouring colouring = SliceColouring::luminance;
  std::size_t luminance_levels = 10;  // at most this many log-spaced isolines
  double panel_size = 170;            // points
  double pixels_per_point = 2;
  int threads = 0;
};

struct SliceFigure {
  struct Panel {
    Space param;
    double azimuth_deg;
    PanelMap map;  // data coordinates: the two slice coordinates (radians or magnitudes)
    SliceSample sample;
  };
  Scene scene;
  std::vector<Panel> panels;  // row-major: params × azimuths
  // Generic mode: the shared colour scale, log10 luminance from lo to hi, and the isoline levels
  // (log10 luminance).
  double log_lo = 0, log_hi = 0;
  std::vector<double> log_levels;
};

// Throws std::invalid_argument for an empty parameterization, azimuth or test-function list, or
// Space::dirs.
SliceFigure slice_figure(const SliceOptions& options);

// Log-spaced isoline levels (log10 values) in (lo, hi): decades, or 1-2-5 steps, or 1-…-9 steps,
// whichever gives the most levels not above max_count.
std::vector<double> log_levels(double lo, double hi, std::size_t max_count);

// A tick label of a log10 value: "10^{−2}", or "2·10^{−2}" off the decades (scene markup).
std::string power_of_ten_label(double log10_value);

}  // namespace halfback::figure
