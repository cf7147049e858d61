// Sampler charts: the 2D chart of ωi, for a fixed ωo, in which a tabulated importance sampler of a
// parameterization lays out its cells (render/brdf_sampler.hpp). A chart is polar: a radial
// coordinate r ∈ [0, r_max] and an azimuth φ ∈ [0, 2π) (docs/render.md, "Sampling tabulated
// BRDFs"). Each parameterization names the chart of its first two coordinates (SamplerChart).
//
// A chart C has
//   name, r_max
//   to_direction(wo, r, dr, phi, wi, jac)  ωi at (r, φ), and jac = |dωi / (ds dt)| for cells laid
//                                          out in (s, t) with r = r(s), dr = r'(s), φ = 2π t;
//                                          false where (r, φ) has no direction above the horizon
//   from_direction(wo, wi, r, phi, jac)    (r, φ) of ωi, φ not yet wrapped, and the density
//                                          factor jac = |dωi / (dr dφ)|; false where undefined
#pragma once

#include <cmath>
#include <numbers>
#include <string_view>

#include "halfback/core/params/common.hpp"

namespace halfback {

namespace detail {
inline double chart_azimuth(double y, double x) {
  const double p = std::atan2(y, x);
  return p < 0 ? p + 2 * std::numbers::pi : p;
}
}  // namespace detail

// (θi, φi − φo): dωi = sin θi dθi dφ.
struct SphericalChart {
  static constexpr std::string_view name = "spherical";
  static constexpr double r_max = std::numbers::pi / 2;

  static bool to_direction(const Vec3<double>& wo, double r, double dr, double phi,
                           Vec3<double>& wi, double& jac) {
    constexpr double kPi = std::numbers::pi;
    const double po = (wo.x == 0 && wo.y == 0) ? 0 : std::atan2(wo.y, wo.x);
    const double st = std::sin(r);
    wi = {st * std::cos(phi + po), st * std::sin(phi + po), std::cos(r)};
    jac = st * dr * 2 * kPi;
    return true;
  }

  static bool from_direction(const Vec3<double>& wo, const Vec3<double>& wi, double& r, double& phi,
                             double& jac) {
    r = std::atan2(std::sqrt(wi.x * wi.x + wi.y * wi.y), wi.z);
    const double po = (wo.x == 0 && wo.y == 0) ? 0 : std::atan2(wo.y, wo.x);
    phi = detail::chart_azimuth(wi.y, wi.x) - po;
    jac = std::sin(r);
    return true;
  }
};

// (θh, φh) of the half vector ĥ: ωi = 2(ωo·ĥ)ĥ − ωo, dωi = 4 (ωo·ĥ) sin θh dθh dφh.
struct HalfVectorChart {
  static constexpr std::string_view name = "half-vector";
  static constexpr double r_max = std::numbers::pi / 2;

  static bool to_direction(const Vec3<double>& wo, double r, double dr, double phi,
                           Vec3<double>& wi, double& jac) {
    constexpr double kPi = std::numbers::pi;
    const double cp = std::cos(phi), sp = std::sin(phi);
    const double st = std::sin(r);
    const Vec3<double> h{st * cp, st * sp, std::cos(r)};
    const double c = wo.x * h.x + wo.y * h.y + wo.z * h.z;
    if (!(c > 0)) return false;
    wi = {2 * c * h.x - wo.x, 2 * c * h.y - wo.y, 2 * c * h.z - wo.z};
    jac = 4 * c * st * dr * 2 * kPi;
    return true;
  }

  static bool from_direction(const Vec3<double>& wo, const Vec3<double>& wi, double& r, double& phi,
                             double& jac) {
    Vec3<double> h{wi.x + wo.x, wi.y + wo.y, wi.z + wo.z};
    const double l = std::sqrt(h.x * h.x + h.y * h.y + h.z * h.z);
    if (!(l > 0)) return false;
    h = {h.x / l, h.y / l, h.z / l};
    const double sin_r = std::sqrt(h.x * h.x + h.y * h.y);
    r = std::atan2(sin_r, h.z);
    phi = detail::chart_azimuth(h.y, h.x);
    jac = 4 * (wo.x * h.x + wo.y * h.y + wo.z * h.z) * sin_r;
    return true;
  }
};

// (‖h̄‖, φh) of the projected half vector: ωi_xy = 2h̄ − ωo_xy, dωi = 4‖h̄‖ d‖h̄‖ dφh / cos θi, so
// ρ cos θi dωi = 4 ρ ‖h̄‖ d‖h̄‖ dφh: the cosine cancels.
struct ProjectedHalfChart {
  static constexpr std::string_view name = "projected-half-vector";
  static constexpr double r_max = 1.0;

  static bool to_direction(const Vec3<double>& wo, double r, double dr, double phi,
                           Vec3<double>& wi, double& jac) {
    constexpr double kPi = std::numbers::pi;
    const double cp = std::cos(phi), sp = std::sin(phi);
    const double x = 2 * r * cp - wo.x, y = 2 * r * sp - wo.y;
    const double z2 = 1 - x * x - y * y;
    if (!(z2 > 0)) return false;
    wi = {x, y, std::sqrt(z2)};
    jac = 4 * r * dr * 2 * kPi / wi.z;
    return true;
  }

  static bool from_direction(const Vec3<double>& wo, const Vec3<double>& wi, double& r, double& phi,
                             double& jac) {
    const double hx = 0.5 * (wi.x + wo.x), hy = 0.5 * (wi.y + wo.y);
    r = std::sqrt(hx * hx + hy * hy);
    phi = detail::chart_azimuth(hy, hx);
    jac = 4 * r / wi.z;
    return true;
  }
};

// A chart at run time (ParamDescriptor::sampler_chart()).
struct SamplerChart {
  std::string_view name;
  double r_max = 1;
  bool (*to_direction)(const Vec3<double>& wo, double r, double dr, double phi, Vec3<double>& wi,
                       double& jac) = nullptr;
  bool (*from_direction)(const Vec3<double>& wo, const Vec3<double>& wi, double& r, double& phi,
                         double& jac) = nullptr;
};

template <class C>
constexpr SamplerChart chart_of() {
  return {C::name, C::r_max, &C::to_direction, &C::from_direction};
}

// The charts a run-time parameterization (Python) may name.
inline constexpr SamplerChart kSamplerCharts[] = {
    chart_of<SphericalChart>(), chart_of<HalfVectorChart>(), chart_of<ProjectedHalfChart>()};

}  // namespace halfback
