// Colours and colour maps of the figures.
//
// Colours are display values in [0, 1] (sRGB-encoded, as written to a PNG), except where a
// function says it takes linear values.
#pragma once

#include <cstdint>

#include "halfback/brdf/brdf.hpp"

namespace halfback::figure {

struct Color {
  double r = 0, g = 0, b = 0, a = 1;
  friend bool operator==(const Color&, const Color&) = default;
};

// 8-bit value of a display value in [0, 1] (clamped, rounded to nearest).
std::uint8_t to_byte(double v);

// Viridis (Smith and van der Walt 2015), the perceptually uniform map of matplotlib, for
// t in [0, 1] (clamped); NaN gives NaN components. Evaluated with a degree-6 polynomial fit per
// channel; it agrees with the published 256-entry map within 0.013 (3.3/255) in every channel
// (checked once against matplotlib's table; render_test.cpp checks five anchors).
Color viridis(double t);

// A diverging map for signed values, t in [0, 1] (clamped; NaN gives NaN components): blue at 0,
// white at 0.5, red at 1, the display values interpolated linearly on each half. The end colours
// are those of Moreland's cool-warm map (2009), without its interpolation in Msh space: a map of
// ours, for residuals (figure/compare.hpp), where 0.5 is "no difference".
Color diverging(double t);

// The paper's colouring of a pair of coordinates: u (the first, normalized to [0, 1]) in red,
// v (the second) in green, no blue. Values outside [0, 1] are clamped.
Color coordinate_colour(double u, double v);

// sRGB transfer function: linear [0, 1] -> display value (clamped).
double srgb_encode(double linear);

// Tone mapping of linear RGB for display on a logarithmic scale: the colour is scaled so that its
// luminance L becomes t = (log10 L − log_lo) / (log_hi − log_lo), clamped to [0, 1], keeping its
// chromaticity (channels clamped to 1). So the grey levels follow the same scale as the false
// colour of log luminance, and a colour bar of t in [0, 1] labels both. L <= 0 gives black.
Color tonemap_log(const Rgb& c, double log_lo, double log_hi);

// Colours used by the figures for things that are not data.
inline constexpr Color kInvalidLight{0.80, 0.80, 0.80};  // hatching of invalid regions
inline constexpr Color kInvalidDark{0.62, 0.62, 0.62};
inline constexpr Color kBelowHorizonLight{0.86, 0.84, 0.78};  // ωi below the horizon
inline constexpr Color kBelowHorizonDark{0.70, 0.67, 0.60};
inline constexpr Color kBlack{0, 0, 0};
inline constexpr Color kWhite{1, 1, 1};

}  // namespace halfback::figure
