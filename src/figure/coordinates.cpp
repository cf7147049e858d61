#include "halfback/figure/coordinates.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace halfback::figure {

namespace {
constexpr double kHalfPi = std::numbers::pi / 2;
constexpr double kTenDegrees = std::numbers::pi / 18;
const std::string kHbar = "‖h\u0304‖";
const std::string kKbar = "‖k\u0304‖";
}  // namespace

std::array<CoordinateInfo, 2> iso_coordinates(Space space) {
  switch (space) {
    case Space::spherical:
      return {{{"θ_i", kHalfPi, true, kTenDegrees}, {"θ_o", kHalfPi, true, kTenDegrees}}};
    case Space::halfdiff:
      return {{{"θ_h", kHalfPi, true, kTenDegrees}, {"θ_d", kHalfPi, true, kTenDegrees}}};
    case Space::ortho:
      return {{{kHbar, 1.0, false, 0.1}, {kKbar, 1.0, false, 0.1}}};
    case Space::hybrid:
      return {{{kHbar, 1.0, false, 0.1}, {"‖k‖", 1.0, false, 0.1}}};
    case Space::dirs:
      break;
  }
  throw std::invalid_argument("the dirs space has no isotropic coordinates");
}

std::string relative_azimuth_label(Space space) {
  switch (space) {
    case Space::spherical:
      return "φ_o − φ_i";
    case Space::halfdiff:
      return "φ_d";
    case Space::ortho:
    case Space::hybrid:
      return "φ_k − φ_h";
    case Space::dirs:
      break;
  }
  throw std::invalid_argument("the dirs space has no isotropic coordinates");
}

std::string format_coordinate(const CoordinateInfo& c, double value) {
  if (c.angle) return fmt::format("{}°", std::lround(value * 180.0 / std::numbers::pi));
  const std::string s = fmt::format("{:.2f}", value);
  // 0.50 -> 0.5, 1.00 -> 1
  std::string t = s;
  while (t.back() == '0') t.pop_back();
  if (t.back() == '.') t.pop_back();
  return t;
}

}  // namespace halfback::figure
