// RglBrdf (include/halfback/formats/rgl.hpp): its description and facts, and the one-pair paths:
// eval, sample, pdf and the warp's probes. The material's tables are read by rgl_read.cpp; the
// batch paths are in rgl_batch.cpp, the block kernel in rgl_kernel.cpp, the 2D warp in
// rgl_warp.cpp. This file is compiled with the flags of all of them (src/formats/CMakeLists.txt),
// so that the block paths round as these one-pair paths do.
#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "halfback/formats/rgl.hpp"
#include "rgl_impl.hpp"

namespace halfback {

using rgl_detail::azimuth_u;
using rgl_detail::Flips;
using rgl_detail::flips_for;
using rgl_detail::kPi;
using rgl_detail::phi_to_u;
using rgl_detail::reflection_jacobian;
using rgl_detail::Slices;
using rgl_detail::theta_to_u;
using rgl_detail::u_to_theta;

std::string RglBrdf::name() const {
  return "rgl:" + label_;
}

std::string RglBrdf::description() const {
  return "RGL measured BRDF: " + impl_->description + " (" + std::to_string(impl_->n_slices) +
         " incidence slices, " + (impl_->isotropic ? "isotropic" : "anisotropic") + ")";
}

std::vector<Brdf::Fact> RglBrdf::facts() const {
  const Impl& m = *impl_;
  std::vector<Fact> f;
  f.push_back({"format", m.wavelengths == 0
                             ? std::string("RGL tensor_file (Dupuy & Jakob 2018), RGB variant")
                             : fmt::format("RGL tensor_file (Dupuy & Jakob 2018), spectral variant "
                                           "({} wavelengths, integrated to RGB)",
                                           m.wavelengths)});
  f.push_back({"material", m.description});
  f.push_back({"incidence grid",
               fmt::format("{} θi × {} φi{}", m.theta_i_raw.size(), m.phi_i_raw.size(),
                           m.reduction > 1 ? fmt::format(" (1/{} of the azimuths, the rest "
                                                         "by symmetry)",
                                                         m.reduction)
                                           : std::string())});
  f.push_back({"spectral slices",
               fmt::format("{} × {} samples per incidence, 3 channels", m.rgb.h, m.rgb.w)});
  f.push_back({"VNDF / NDF tables",
               fmt::format("{} × {} / {} × {}", m.vndf.h, m.vndf.w, m.ndf.h, m.ndf.w)});
  f.push_back({"symmetry", m.isotropic ? "isotropic" : "anisotropic"});
  f.push_back({"negative values",
               fmt::format("{} tiny negative density values (noise) set to 0; {} negative RGB "
                           "values (out of gamut) {}",
                           m.noise_clamped, m.rgb_negative,
                           options_.clamp_negative ? "clamped to 0 in ρ" : "kept in ρ")});
  return f;
}

bool RglBrdf::isotropic() const {
  return impl_->isotropic;
}
const std::string& RglBrdf::material_description() const {
  return impl_->description;
}
std::span<const float> RglBrdf::theta_i() const {
  return impl_->theta_i_raw;
}
std::span<const float> RglBrdf::phi_i() const {
  return impl_->phi_i_raw;
}

RglWarpPoint RglBrdf::vndf_inverse(RglWarpPoint p, double theta_i, double phi_i) const {
  return impl_->vndf.inverse(impl_->slices(phi_i, theta_i), p);
}

RglWarpPoint RglBrdf::vndf_forward(RglWarpPoint u, double theta_i, double phi_i) const {
  return impl_->vndf.forward(impl_->slices(phi_i, theta_i), u);
}

RglWarpPoint RglBrdf::vndf_forward_by_search(RglWarpPoint u, double theta_i, double phi_i) const {
  return impl_->vndf.forward(impl_->slices(phi_i, theta_i), u, false);
}

double RglBrdf::vndf_density(RglWarpPoint p, double theta_i, double phi_i) const {
  return impl_->vndf.density(impl_->slices(phi_i, theta_i), p);
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

BrdfSample RglBrdf::sample(const Vec3<double>& wo, double u1, double u2) const {
  const Impl& m = *impl_;
  if (!(wo.z > 0)) return {};
  const Flips flips = flips_for(m.reduction, wo);
  const Vec3<double> g = flips.apply(wo);
  const double theta_g = std::atan2(std::hypot(g.x, g.y), g.z);
  const double phi_g = std::atan2(g.y, g.x);
  const Slices s = m.slices(phi_g, theta_g);
  const auto [um, pdf_u] = m.vndf.draw(s, {u1, u2});
  const double theta_m = u_to_theta(um.x);
  const double phi_m = (2 * um.y - 1) * kPi + (m.isotropic ? phi_g : 0.0);
  const Vec3<double> n{std::sin(theta_m) * std::cos(phi_m), std::sin(theta_m) * std::sin(phi_m),
                       std::cos(theta_m)};
  const double dot = g.x * n.x + g.y * n.y + g.z * n.z;
  const Vec3<double> wi =
      flips.apply({2 * dot * n.x - g.x, 2 * dot * n.y - g.y, 2 * dot * n.z - g.z});
  const double jacobian = reflection_jacobian(um, theta_m, dot);
  return {wi, jacobian > 0 && wi.z > 0 ? pdf_u / jacobian : 0.0};
}

double RglBrdf::pdf(const Vec3<double>& wo, const Vec3<double>& wi) const {
  const Impl& m = *impl_;
  if (!(wo.z > 0) || !(wi.z > 0)) return 0;
  const Flips flips = flips_for(m.reduction, wo);
  const Vec3<double> g = flips.apply(wo), d = flips.apply(wi);
  // The microfacet normal that reflects g into d: their half vector.
  const Vec3<double> h{g.x + d.x, g.y + d.y, g.z + d.z};
  const double len = std::sqrt(h.x * h.x + h.y * h.y + h.z * h.z);
  if (!(len > 0)) return 0;
  const Vec3<double> n{h.x / len, h.y / len, h.z / len};
  const double theta_g = std::atan2(std::hypot(g.x, g.y), g.z);
  const double phi_g = std::atan2(g.y, g.x);
  const double theta_m = std::atan2(std::hypot(n.x, n.y), n.z);
  double v = (std::atan2(n.y, n.x) - (m.isotropic ? phi_g : 0.0) + kPi) / (2 * kPi);
  v -= std::floor(v);
  const RglWarpPoint um{std::sqrt(theta_m / (kPi / 2)), v};
  const double pdf_u = m.vndf.density(m.slices(phi_g, theta_g), um);
  const double jacobian = reflection_jacobian(um, theta_m, g.x * n.x + g.y * n.y + g.z * n.z);
  return jacobian > 0 && std::isfinite(pdf_u) ? pdf_u / jacobian : 0;
}

Rgb RglBrdf::eval_cosine(const DirPair<double>& pair) const {
  const Impl& m = *impl_;
  Vec3<double> wi = pair.wi, wo = pair.wo;
  const double v[6] = {wi.x, wi.y, wi.z, wo.x, wo.y, wo.z};
  for (double x : v)
    if (std::isnan(x)) return {kNaN, kNaN, kNaN};
  if (!(wi.z > 0) || !(wo.z > 0)) return {};
  const Flips flips = flips_for(m.reduction, wi);  // ωi into the range of φi the data covers
  wi = flips.apply(wi);
  wo = flips.apply(wo);
  const double hx = wi.x + wo.x, hy = wi.y + wo.y, hz = wi.z + wo.z;
  const double theta_i = std::atan2(std::hypot(wi.x, wi.y), wi.z);
  const double phi_i = std::atan2(wi.y, wi.x);
  const double theta_m = std::atan2(std::hypot(hx, hy), hz);
  const double phi_m = std::atan2(hy, hx);
  const RglWarpPoint um{theta_to_u(theta_m), azimuth_u(phi_m, phi_i, m.isotropic)};
  const RglWarpPoint uwi{theta_to_u(theta_i), phi_to_u(phi_i)};
  return m.value(m.slices(phi_i, theta_i), um, uwi, options_.clamp_negative);
}

namespace {

// fr from fr·cos θo, for a pair with both directions above the horizon.
Rgb over_cosine(Rgb r, const Vec3<double>& wo) {
  const double inverse_cos_o = std::sqrt(wo.x * wo.x + wo.y * wo.y + wo.z * wo.z) / wo.z;
  r.r *= inverse_cos_o;
  r.g *= inverse_cos_o;
  r.b *= inverse_cos_o;
  return r;
}
}  // namespace

Rgb RglBrdf::eval(const DirPair<double>& pair) const {
  const Rgb r = eval_cosine(pair);
  if (!(pair.wi.z > 0) || !(pair.wo.z > 0)) return r;  // 0, or NaN for NaN input
  // The reference loader returns fr·cos θo (a sampling-friendly quantity); fr is that over cos θo.
  return over_cosine(r, pair.wo);
}

}  // namespace halfback
