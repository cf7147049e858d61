#include "halfback/formats/adaptive_param.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "halfback/core/params/charts.hpp"
#include "halfback/formats/rgl.hpp"
#include "rgl_impl.hpp"

namespace halfback {

namespace adaptive_detail {  // named: the layer is a unity build

using rgl_detail::azimuth_u;
using rgl_detail::kPi;
using rgl_detail::reflection_jacobian;
using rgl_detail::theta_to_u;
using rgl_detail::u_to_theta;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Vec3<double> direction(double theta, double phi) {
  const double s = std::sin(theta);
  return {s * std::cos(phi), s * std::sin(phi), std::cos(theta)};
}

// The half vector of a point u of the unit square (the warp's tables are isotropic: its azimuth is
// relative to φi), as RglBrdf::sample takes it.
struct HalfVector {
  double theta, phi;  // phi relative to φi
};
HalfVector half_vector_of(RglWarpPoint u) {
  return {u_to_theta(u.x), 2 * kPi * u.y - kPi};
}

class AdaptiveParam final : public ParamDescriptor {
 public:
  AdaptiveParam(const Names& names, std::shared_ptr<const RglBrdf> warp)
      : ParamDescriptor(names), warp_(std::move(warp)) {}

  Tuple4<double> forward(const DirPair<double>& p) const override {
    const double theta_i = detail::elevation(p.wi.x, p.wi.y, p.wi.z);
    const double phi_i =
        (p.wi.x == 0 && p.wi.y == 0) ? 0 : detail::wrap_two_pi(std::atan2(p.wi.y, p.wi.x));
    Vec3<double> h{p.wi.x + p.wo.x, p.wi.y + p.wo.y, p.wi.z + p.wo.z};
    const double l = std::sqrt(h.x * h.x + h.y * h.y + h.z * h.z);
    h = l > 0 ? Vec3<double>{h.x / l, h.y / l, h.z / l} : Vec3<double>{0, 0, 1};
    const double theta_m = detail::elevation(h.x, h.y, h.z);
    const double phi_m = (h.x == 0 && h.y == 0) ? phi_i : std::atan2(h.y, h.x);
    const RglWarpPoint u{theta_to_u(theta_m), azimuth_u(phi_m, phi_i, true)};
    const RglWarpPoint s = warp_->vndf_inverse(u, theta_i, phi_i);
    return {theta_i, phi_i, s.x, s.y};
  }

  Solved<double> inverse(const Tuple4<double>& q) const override {
    const double theta_i = q[0], phi_i = detail::wrap_azimuth(q[1]);
    Solved<double> r{{{kNaN, kNaN, kNaN}, {kNaN, kNaN, kNaN}}, false};
    if (!(theta_i >= 0 && theta_i <= kPi / 2 && phi_i >= 0 && phi_i < 2 * kPi && q[2] >= 0 &&
          q[2] <= 1 && q[3] >= 0 && q[3] <= 1))
      return r;
    const HalfVector m = half_vector_of(warp_->vndf_forward({q[2], q[3]}, theta_i, phi_i));
    const Vec3<double> wi = direction(theta_i, phi_i), h = direction(m.theta, phi_i + m.phi);
    const double c = wi.x * h.x + wi.y * h.y + wi.z * h.z;
    const Vec3<double> wo{2 * c * h.x - wi.x, 2 * c * h.y - wi.y, 2 * c * h.z - wi.z};
    if (!(c > 0 && wo.z >= 0)) return r;
    return {{wi, wo}, true};
  }

  // dωi dωo / dq = sin θi dθi dφi · 4 (ωi·ĥ) dωm, dωm = 2π² u1 sin θm du, du = ds / p_u(u)
  // (docs/math-more-parameterizations.md §6).
  double jacobian(const Tuple4<double>& q) const override {
    const double theta_i = q[0], phi_i = detail::wrap_azimuth(q[1]);
    const RglWarpPoint u = warp_->vndf_forward({q[2], q[3]}, theta_i, phi_i);
    const double density = warp_->vndf_density(u, theta_i, phi_i);
    if (!(density > 0)) return 0;
    const HalfVector m = half_vector_of(u);
    const double c = std::sin(theta_i) * std::sin(m.theta) * std::cos(m.phi) +
                     std::cos(theta_i) * std::cos(m.theta);  // ωi·ĥ, ĥ's azimuth relative
    return std::abs(std::sin(theta_i) * reflection_jacobian(u, m.theta, c) / density);
  }

  // The isotropic form: (θi, s1, s2) in the canonical pose; the warp is the same at every φi.
  Tuple3<double> forward_iso(const DirPair<double>& p) const override {
    const Tuple4<double> q = forward(p);
    return {q[0], q[2], q[3]};
  }
  Solved<double> inverse_iso(const Tuple3<double>& q) const override {
    Solved<double> r = inverse({q[0], 0, q[1], q[2]});
    if (r.in_domain) detail::rotate_to_canonical_pose(r);
    return r;
  }
  double jacobian_iso(const Tuple3<double>& q) const override {
    return 2 * kPi * jacobian({q[0], 0, q[1], q[2]});
  }

  // Not closed-form (the warp at the other direction): through the pair.
  Tuple4<double> reciprocal(const Tuple4<double>& q) const override {
    const Solved<double> s = inverse(q);
    return forward({s.pair.wo, s.pair.wi});
  }
  Tuple4<double> mirror(const Tuple4<double>& q) const override {
    return forward(mirror_pair(inverse(q).pair));
  }
  Tuple3<double> reciprocal_iso(const Tuple3<double>& q) const override {
    const Solved<double> s = inverse_iso(q);
    return forward_iso({s.pair.wo, s.pair.wi});
  }
  Tuple3<double> mirror_iso(const Tuple3<double>& q) const override {
    return forward_iso(mirror_pair(inverse_iso(q).pair));
  }

 private:
  std::shared_ptr<const RglBrdf> warp_;
};

constexpr Axis kS1{"s1", "s_1", AxisKind::length, 0, 1, 0.1};
constexpr Axis kS2{"s2", "s_2", AxisKind::length, 0, 1, 0.1};

ParamDescriptor::Names names_of(std::string_view name, std::string_view summary) {
  return {name,
          summary,
          {elevation_axis("theta_i", "θ_i"), azimuth_axis("phi_i", "φ_i"), kS1, kS2},
          {elevation_axis("theta_i", "θ_i"), kS1, kS2},
          chart_of<SphericalChart>(),
          false};
}

class PerMaterialPlaceholder final : public ParamDescriptor {
 public:
  PerMaterialPlaceholder()
      : ParamDescriptor(
            names_of(kPerMaterialWarp,
                     "(θi, φi, s1, s2): each BRDF's own Dupuy & Jakob warp, in the study")) {}
  [[noreturn]] static void refuse() {
    throw std::logic_error(std::string(kPerMaterialWarp) +
                           " is each BRDF's own warp, for the study only: elsewhere, name the BRDF "
                           "(dupuy-jakob:BRDF)");
  }
  Tuple4<double> forward(const DirPair<double>&) const override { refuse(); }
  Tuple3<double> forward_iso(const DirPair<double>&) const override { refuse(); }
  Solved<double> inverse(const Tuple4<double>&) const override { refuse(); }
  Solved<double> inverse_iso(const Tuple3<double>&) const override { refuse(); }
  double jacobian(const Tuple4<double>&) const override { refuse(); }
  double jacobian_iso(const Tuple3<double>&) const override { refuse(); }
  Tuple4<double> reciprocal(const Tuple4<double>&) const override { refuse(); }
  Tuple4<double> mirror(const Tuple4<double>&) const override { refuse(); }
  Tuple3<double> reciprocal_iso(const Tuple3<double>&) const override { refuse(); }
  Tuple3<double> mirror_iso(const Tuple3<double>&) const override { refuse(); }
};

}  // namespace adaptive_detail

std::shared_ptr<const ParamDescriptor> per_material_placeholder() {
  return std::make_shared<const adaptive_detail::PerMaterialPlaceholder>();
}

bool is_per_material_placeholder(const ParamDescriptor& param) {
  return dynamic_cast<const adaptive_detail::PerMaterialPlaceholder*>(&param) != nullptr;
}

std::shared_ptr<const ParamDescriptor> adaptive_parameterization(const Brdf& brdf, std::string name,
                                                                 const RglWarpOptions& options) {
  using namespace adaptive_detail;
  const std::string summary =
      "(θi, φi, s1, s2): Dupuy & Jakob 2018's half vector warped by the visible normals of " +
      brdf.name();
  return std::make_shared<const AdaptiveParam>(names_of(name, summary),
                                               rgl_warp_material(brdf, options));
}

}  // namespace halfback
