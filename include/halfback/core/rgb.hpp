// The one RGB type of halfback: linear RGB with the Rec. 709 (sRGB) primaries, in doubles. A BRDF
// value ρ in sr⁻¹, a radiance, an albedo or a pixel are all Rgb.
#pragma once

#include <cmath>

namespace halfback {

struct Rgb {
  double r = 0, g = 0, b = 0;

  friend bool operator==(const Rgb&, const Rgb&) = default;

  Rgb& operator+=(const Rgb& o) {
    r += o.r, g += o.g, b += o.b;
    return *this;
  }
  Rgb& operator-=(const Rgb& o) {
    r -= o.r, g -= o.g, b -= o.b;
    return *this;
  }
  Rgb& operator*=(const Rgb& o) {
    r *= o.r, g *= o.g, b *= o.b;
    return *this;
  }
  Rgb& operator*=(double s) {
    r *= s, g *= s, b *= s;
    return *this;
  }
  Rgb& operator/=(double s) {
    r /= s, g /= s, b /= s;
    return *this;
  }
  friend Rgb operator+(Rgb a, const Rgb& b) { return a += b; }
  friend Rgb operator-(Rgb a, const Rgb& b) { return a -= b; }
  friend Rgb operator*(Rgb a, const Rgb& b) { return a *= b; }  // per channel
  friend Rgb operator*(Rgb a, double s) { return a *= s; }
  friend Rgb operator*(double s, Rgb a) { return a *= s; }
  friend Rgb operator/(Rgb a, double s) { return a /= s; }

  // Relative luminance Y of the Rec. 709 primaries (the weights of ITU-R BT.709).
  double luminance() const { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }
  double max_channel() const { return std::fmax(r, std::fmax(g, b)); }
  bool finite() const { return std::isfinite(r) && std::isfinite(g) && std::isfinite(b); }
};

}  // namespace halfback
