#include "halfback/figure/color.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace halfback::figure {

std::uint8_t to_byte(double v) {
  if (!(v > 0.0)) return 0;  // also NaN
  if (v >= 1.0) return 255;
  return static_cast<std::uint8_t>(std::lround(v * 255.0));
}

Color viridis(double t) {
  // Least-squares degree-6 polynomial fit of the viridis map, one per channel; coefficients of
  // t^0 … t^6 (published with the fit by M. Zucker, 2020; the map itself is defined by a spline in
  // CAM02-UCS, Smith and van der Walt 2015).
  static constexpr std::array<std::array<double, 7>, 3> c{{
      {0.2777273272234177, 0.1050930431085774, -0.3308618287255563, -4.634230498983486,
       6.228269936347081, 4.776384997670288, -5.435455855934631},
      {0.005407344544966578, 1.404613529898575, 0.214847559468213, -5.799100973351585,
       14.17993336680509, -13.74514537774601, 4.645852612178535},
      {0.3340998053353061, 1.384590162594685, 0.09509516302823659, -19.33244095627987,
       56.69055260068105, -65.35303263337234, 26.3124352495832},
  }};
  if (std::isnan(t)) return {t, t, t, 1};
  t = std::clamp(t, 0.0, 1.0);
  std::array<double, 3> out{};
  for (std::size_t k = 0; k < 3; ++k) {
    double v = 0;
    for (std::size_t i = 7; i-- > 0;) v = v * t + c[k][i];
    out[k] = std::clamp(v, 0.0, 1.0);
  }
  return {out[0], out[1], out[2], 1};
}

Color diverging(double t) {
  if (std::isnan(t)) return {t, t, t, 1};
  static constexpr Color kCool{0.230, 0.299, 0.754}, kWarm{0.706, 0.016, 0.150};
  t = std::clamp(t, 0.0, 1.0);
  const Color& end = t < 0.5 ? kCool : kWarm;
  const double s = std::abs(2 * t - 1);  // 0 at the centre, 1 at either end
  return {1 + s * (end.r - 1), 1 + s * (end.g - 1), 1 + s * (end.b - 1), 1};
}

Color coordinate_colour(double u, double v) {
  return {std::clamp(u, 0.0, 1.0), std::clamp(v, 0.0, 1.0), 0.0, 1.0};
}

double srgb_encode(double x) {
  if (!(x > 0.0)) return 0.0;
  if (x >= 1.0) return 1.0;
  return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

Color tonemap_log(const Rgb& c, double log_lo, double log_hi) {
  const Rgb p{std::max(c.r, 0.0), std::max(c.g, 0.0), std::max(c.b, 0.0)};
  const double l = p.luminance();
  if (!(l > 0.0) || !std::isfinite(l)) return {0, 0, 0, 1};
  const double t = std::clamp((std::log10(l) - log_lo) / (log_hi - log_lo), 0.0, 1.0);
  const double s = t / l;
  return {std::min(p.r * s, 1.0), std::min(p.g * s, 1.0), std::min(p.b * s, 1.0), 1};
}

}  // namespace halfback::figure
