#include "halfback/models/analytic.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace halfback::models {

namespace {

constexpr double kPi = std::numbers::pi;

std::string rgb_text(const Rgb& v) {
  if (v.r == v.g && v.g == v.b) return std::to_string(v.r);
  return std::to_string(v.r) + "/" + std::to_string(v.g) + "/" + std::to_string(v.b);
}

void require(bool ok, const std::string& model, const std::string& what) {
  if (!ok) throw std::invalid_argument(model + ": " + what);
}

void require_range(const std::string& model, const char* name, double v, double lo, double hi,
                   bool lo_open = false) {
  const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && v <= hi;
  require(ok, model,
          std::string(name) + " must be in " + (lo_open ? "(" : "[") + std::to_string(lo) + ", " +
              std::to_string(hi) + "], got " + std::to_string(v));
}

void require_rgb(const std::string& model, const char* name, const Rgb& v, double lo, double hi) {
  require_range(model, name, v.r, lo, hi);
  require_range(model, name, v.g, lo, hi);
  require_range(model, name, v.b, lo, hi);
}

bool below_horizon(const DirPair<double>& p) {
  return !(p.wi.z > 0 && p.wo.z > 0);
}

Vec3<double> half_vector(const DirPair<double>& p) {
  Vec3<double> h{p.wi.x + p.wo.x, p.wi.y + p.wo.y, p.wi.z + p.wo.z};
  const double len = std::sqrt(h.x * h.x + h.y * h.y + h.z * h.z);
  return {h.x / len, h.y / len, h.z / len};  // len > 0 when both z > 0
}

void validate_fresnel(const std::string& model, const Fresnel& f) {
  switch (f.kind) {
    case Fresnel::Kind::none:
      break;
    case Fresnel::Kind::schlick:
      require_rgb(model, "f0", f.f0, 0, 1);
      break;
    case Fresnel::Kind::dielectric:
      require_rgb(model, "eta", f.eta, 1e-3, 100);
      break;
    case Fresnel::Kind::conductor:
      require_rgb(model, "eta", f.eta, 1e-3, 100);
      require_rgb(model, "k", f.k, 0, 100);
      break;
  }
}

}  // namespace

// --- Lambert ------------------------------------------------------------------------------

Lambert::Lambert(Rgb albedo) : albedo_(albedo) {
  require_rgb("lambert", "albedo", albedo, 0, 1);
}

std::string Lambert::description() const {
  return "Lambertian diffuse, albedo " + rgb_text(albedo_);
}

Rgb Lambert::eval(const DirPair<double>& pair) const {
  if (below_horizon(pair)) return {};
  return albedo_ * (1 / kPi);
}

// --- Microfacet -----------------------------------------------------------------------------

Microfacet::Microfacet(const MicrofacetParams& params) : params_(params) {
  const std::string model = name();
  require_range(model, "alpha_x", params.alpha_x, 0, 10, true);
  require_range(model, "alpha_y", params.alpha_y, 0, 10, true);
  validate_fresnel(model, params.fresnel);
  inv_ax2_ = 1 / (params.alpha_x * params.alpha_x);
  inv_ay2_ = 1 / (params.alpha_y * params.alpha_y);
  inv_pi_axay_ = 1 / (kPi * params.alpha_x * params.alpha_y);
}

std::string Microfacet::name() const {
  return params_.distribution == MicrofacetParams::Distribution::ggx ? "ggx" : "beckmann";
}

std::string Microfacet::description() const {
  return (params_.distribution == MicrofacetParams::Distribution::ggx ? "GGX" : "Beckmann") +
         std::string(" microfacet reflection, alpha ") + std::to_string(params_.alpha_x) +
         (isotropic() ? "" : " x " + std::to_string(params_.alpha_y)) +
         ", height-correlated Smith G2, " + params_.fresnel.describe();
}

double Microfacet::distribution(const Vec3<double>& m) const {
  if (m.z <= 0) return 0;
  const double ax = params_.alpha_x, ay = params_.alpha_y;
  const double x = m.x / ax, y = m.y / ay, z2 = m.z * m.z;
  if (params_.distribution == MicrofacetParams::Distribution::ggx) {
    const double d = x * x + y * y + z2;  // GGX: 1 / (π αx αy (x²/αx² + y²/αy² + z²)²)
    return 1 / (kPi * ax * ay * d * d);
  }
  const double tan2 = (x * x + y * y) / z2;  // Beckmann: exp(−tan²θ (…)) / (π αx αy cos⁴θ)
  return std::exp(-tan2) / (kPi * ax * ay * z2 * z2);
}

double Microfacet::lambda(const Vec3<double>& w) const {
  const double ax = params_.alpha_x, ay = params_.alpha_y;
  const double a2_tan2 = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / (w.z * w.z);
  if (params_.distribution == MicrofacetParams::Distribution::ggx)
    return 0.5 * (std::sqrt(1 + a2_tan2) - 1);
  if (a2_tan2 == 0) return 0;
  const double a = 1 / std::sqrt(a2_tan2);
  return 0.5 * (std::erf(a) - 1) + std::exp(-a * a) / (2 * a * std::sqrt(kPi));
}

Rgb Microfacet::eval(const DirPair<double>& pair) const {
  if (below_horizon(pair)) return {};
  if (params_.distribution == MicrofacetParams::Distribution::ggx) return eval_ggx(pair);
  const Vec3<double> m = half_vector(pair);
  const double cos_d = pair.wi.x * m.x + pair.wi.y * m.y + pair.wi.z * m.z;
  const double g2 = 1 / (1 + lambda(pair.wi) + lambda(pair.wo));
  const double scalar = distribution(m) * g2 / (4 * pair.wi.z * pair.wo.z);
  return params_.fresnel.eval(cos_d) * scalar;
}

// GGX in closed form (docs/models.md, "GGX without normalizing"): with h = ωi + ωo (not
// normalized), Q = h_x²/αx² + h_y²/αy² + h_z² and L(ω) = ‖(αx ω_x, αy ω_y, ω_z)‖,
// D(ĥ) = ‖h‖⁴ / (π αx αy Q²) and 1 + Λ(ω) = (1 + L(ω)/ω_z)/2, so
// ρ = F(ωi·ĥ) ‖h‖⁴ / (2 π αx αy Q² (L(ωi) cos θo + L(ωo) cos θi)): three square roots and one
// division where distribution() and lambda() take three and seven. Both z > 0 here.
Rgb Microfacet::eval_ggx(const DirPair<double>& pair) const {
  const Vec3<double>&wi = pair.wi, &wo = pair.wo;
  const double ax = params_.alpha_x, ay = params_.alpha_y;
  const double hx = wi.x + wo.x, hy = wi.y + wo.y, hz = wi.z + wo.z;
  const double h2 = hx * hx + hy * hy + hz * hz;
  const double q = hx * hx * inv_ax2_ + hy * hy * inv_ay2_ + hz * hz;
  const double li = std::sqrt(ax * ax * wi.x * wi.x + ay * ay * wi.y * wi.y + wi.z * wi.z);
  const double lo = std::sqrt(ax * ax * wo.x * wo.x + ay * ay * wo.y * wo.y + wo.z * wo.z);
  const double len = std::sqrt(h2);
  const double cos_d = (wi.x * hx + wi.y * hy + wi.z * hz) / len;
  const double scalar = h2 * h2 * inv_pi_axay_ / (2 * q * q * (li * wo.z + lo * wi.z));
  return params_.fresnel.eval(cos_d) * scalar;
}

void Microfacet::eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const {
  if (out.size() != pairs.size() || pairs.size() > 4096) {
    Brdf::eval_batch(pairs, out);  // the size check, and threads for a large batch
    return;
  }
  for (std::size_t i = 0; i < pairs.size(); ++i) out[i] = eval(pairs[i]);
}

// --- ABC -----------------------------------------------------------------------------------

Abc::Abc(const AbcParams& p) : params_(p) {
  require_range("abc", "a", p.a, 0, 1e6);
  require_range("abc", "b", p.b, 0, 1e9);
  require_range("abc", "c", p.c, 0, 100);
  require_range("abc", "eta", p.eta, 1, 100);  // from air into the dielectric
  require_rgb("abc", "kd", p.kd, 0, 1);
}

std::string Abc::description() const {
  return "ABC smooth-surface model (Löw et al. 2012), A = " + std::to_string(params_.a) +
         ", B = " + std::to_string(params_.b) + ", C = " + std::to_string(params_.c) +
         ", eta = " + std::to_string(params_.eta) + ", kd = " + rgb_text(params_.kd);
}

Rgb Abc::eval(const DirPair<double>& pair) const {
  if (below_horizon(pair)) return {};
  const double hx = pair.wi.x + pair.wo.x, hy = pair.wi.y + pair.wo.y;  // 2 h̄
  const double f2 = hx * hx + hy * hy;
  const double s = params_.a / std::pow(1 + params_.b * f2, 0.5 * (params_.c + 1));
  const Vec3<double> m = half_vector(pair);
  const double cos_d = pair.wi.x * m.x + pair.wi.y * m.y + pair.wi.z * m.z;
  const double spec = fresnel_dielectric(params_.eta, cos_d) * s;
  return params_.kd * (1 / kPi) + Rgb{spec, spec, spec};
}

// --- Sheen ---------------------------------------------------------------------------------

Sheen::Sheen(const SheenParams& p) : params_(p) {
  require_rgb("sheen", "color", p.color, 0, 1);
  require_range("sheen", "alpha", p.alpha, 1e-3, 1);
}

std::string Sheen::description() const {
  return "Charlie sheen (Estevez & Kulla 2017), color " + rgb_text(params_.color) + ", alpha " +
         std::to_string(params_.alpha);
}

Rgb Sheen::eval(const DirPair<double>& pair) const {
  if (below_horizon(pair)) return {};
  const Vec3<double> m = half_vector(pair);
  const double sin2 = std::max(0.0, 1 - m.z * m.z);
  const double inv_alpha = 1 / params_.alpha;
  const double d = (2 + inv_alpha) * std::pow(sin2, 0.5 * inv_alpha) / (2 * kPi);
  const double zi = pair.wi.z, zo = pair.wo.z;
  const double v = 1 / (4 * (zi + zo - zi * zo));
  return params_.color * (d * v);
}

// --- Sum -----------------------------------------------------------------------------------

Sum::Sum(std::vector<BrdfPtr> terms) : terms_(std::move(terms)) {
  if (terms_.empty()) throw std::invalid_argument("sum: needs at least one BRDF");
  for (const auto& t : terms_)
    if (!t) throw std::invalid_argument("sum: null BRDF");
}

std::string Sum::name() const {
  std::string s;
  for (const auto& t : terms_) {
    if (!s.empty()) s += '+';  // (not "+" + name(): GCC 12 warns -Wrestrict falsely there)
    s += t->name();
  }
  return s;
}

std::string Sum::description() const {
  std::string s;
  for (const auto& t : terms_) {
    if (!s.empty()) s += " + ";
    s += t->description();
  }
  return s;
}

bool Sum::isotropic() const {
  for (const auto& t : terms_)
    if (!t->isotropic()) return false;
  return true;
}

bool Sum::reciprocal() const {
  for (const auto& t : terms_)
    if (!t->reciprocal()) return false;
  return true;
}

Rgb Sum::eval(const DirPair<double>& pair) const {
  Rgb total;
  for (const auto& t : terms_) total = total + t->eval(pair);
  return total;
}

}  // namespace halfback::models
