#include "halfback/figure/coordinates.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace halfback::figure {

namespace {
CoordinateInfo info_of(const Axis& a) {
  return {std::string(a.label), a.hi, a.is_angle(), a.spacing};
}
}  // namespace

std::array<CoordinateInfo, 2> iso_coordinates(Space space) {
  if (space.is_dirs()) throw std::invalid_argument("the dirs space has no isotropic coordinates");
  const auto axes = space.param().axes(true);
  return {info_of(axes[0]), info_of(axes[1])};
}

std::string relative_azimuth_label(Space space) {
  if (space.is_dirs()) throw std::invalid_argument("the dirs space has no isotropic coordinates");
  return std::string(space.param().axes(true)[2].label);
}

double third_coordinate_at(Space space, double radians) {
  const Axis& a = space.param().axes(true)[2];
  if (a.kind == AxisKind::azimuth) return radians;
  return a.lo + radians / (2 * std::numbers::pi) * (a.hi - a.lo);
}

std::string third_coordinate_title(Space space, double degrees) {
  const Axis& a = space.param().axes(true)[2];
  if (a.kind == AxisKind::azimuth)
    return fmt::format("{} = {:g}°", relative_azimuth_label(space), degrees);
  const double turn = std::fmod(std::fmod(degrees, 360.0) + 360.0, 360.0) / 360.0;
  return fmt::format("{} = {:g}", a.label, a.lo + turn * (a.hi - a.lo));
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
