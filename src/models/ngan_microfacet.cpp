// The lobes of Ngan et al. 2005 as BBM defines them (include/bsdfmodel/ngan.h of
// bsdfbenchmark/bbm): formulas in the header and docs/models.md.
#include "halfback/models/ngan_microfacet.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "colour_params.hpp"

namespace halfback::models {

namespace {
namespace ngan_mf {  // (named: the layer's unity build shares one anonymous namespace)

constexpr double kPi = std::numbers::pi;

void check_range(const char* model, const std::string& param, double v, double lo, double hi) {
  if (std::isfinite(v) && v >= lo && v <= hi) return;
  throw std::invalid_argument(std::string(model) + ": " + param + " must be in [" +
                              std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                              std::to_string(v));
}

void check_albedo(const char* model, const Rgb& albedo) {
  check_range(model, "albedo_r", albedo.r, 0, 1);
  check_range(model, "albedo_g", albedo.g, 0, 1);
  check_range(model, "albedo_b", albedo.b, 0, 1);
}

std::string rgb_text(const Rgb& v) {
  if (v.r == v.g && v.g == v.b) return std::to_string(v.r);
  return std::to_string(v.r) + "/" + std::to_string(v.g) + "/" + std::to_string(v.b);
}

// The unit half vector of a pair with both directions above the horizon, and cos θd = ωi·ĥ as the
// mean of ωi·ĥ and ωo·ĥ (as BBM, so that swapping ωi and ωo gives the same bits).
struct Half {
  Vec3<double> h;
  double cos_d;
};

Half half_of(const DirPair<double>& p) {
  const Vec3<double>&wi = p.wi, &wo = p.wo;
  Vec3<double> h{wi.x + wo.x, wi.y + wo.y, wi.z + wo.z};
  const double len = std::sqrt(h.x * h.x + h.y * h.y + h.z * h.z);  // > 0: both z > 0
  h = {h.x / len, h.y / len, h.z / len};
  const double in = wi.x * h.x + wi.y * h.y + wi.z * h.z;
  const double out = wo.x * h.x + wo.y * h.y + wo.z * h.z;
  return {h, 0.5 * (in + out)};
}

double schlick(double f0, double cos_d) {
  const double x = 1 - cos_d;
  const double x2 = x * x;
  return f0 + (1 - f0) * x2 * x2 * x;
}

}  // namespace ngan_mf
}  // namespace

// --- NganCookTorrance ----------------------------------------------------------------------

NganCookTorrance::NganCookTorrance(const NganCookTorranceParams& p) : params_(p) {
  ngan_mf::check_albedo("cook-torrance", p.albedo);
  ngan_mf::check_range("cook-torrance", "eta", p.eta, 0, 1);
  ngan_mf::check_range("cook-torrance", "roughness", p.roughness, 1e-3, 2);
}

std::string NganCookTorrance::description() const {
  return "Cook-Torrance as BBM's NganCookTorrance (Ngan et al. 2005), albedo " +
         ngan_mf::rgb_text(params_.albedo) + ", eta (F0) " + std::to_string(params_.eta) +
         ", roughness " + std::to_string(params_.roughness);
}

Rgb NganCookTorrance::eval(const DirPair<double>& pair) const {
  const double zi = pair.wi.z, zo = pair.wo.z;
  if (!(zi > 0 && zo > 0)) return {};
  const auto [h, cos_d] = ngan_mf::half_of(pair);
  const double m2 = params_.roughness * params_.roughness;
  const double cos2 = h.z * h.z;
  const double tan2 = (h.x * h.x + h.y * h.y) / cos2;
  const double d = std::exp(-tan2 / m2) / (ngan_mf::kPi * m2 * cos2 * cos2);     // Beckmann
  const double g = std::min({1.0, 2 * h.z * zi / cos_d, 2 * h.z * zo / cos_d});  // V-groove
  const double f = ngan_mf::schlick(params_.eta, cos_d);
  return params_.albedo * (d * g * f / (ngan_mf::kPi * (zi * zo)));  // (zi zo): reciprocal bits
}

// --- NganAshikhminShirley ------------------------------------------------------------------

NganAshikhminShirley::NganAshikhminShirley(const NganAshikhminShirleyParams& p) : params_(p) {
  ngan_mf::check_albedo("ashikhmin-shirley", p.albedo);
  ngan_mf::check_range("ashikhmin-shirley", "f0", p.f0, 0, 1);
  ngan_mf::check_range("ashikhmin-shirley", "sharpness", p.sharpness, 0, 1e6);
}

std::string NganAshikhminShirley::description() const {
  return "Ashikhmin-Shirley as BBM's NganAshikhminShirley (Ngan et al. 2005), albedo " +
         ngan_mf::rgb_text(params_.albedo) + ", f0 " + std::to_string(params_.f0) + ", sharpness " +
         std::to_string(params_.sharpness);
}

Rgb NganAshikhminShirley::eval(const DirPair<double>& pair) const {
  const double zi = pair.wi.z, zo = pair.wo.z;
  if (!(zi > 0 && zo > 0)) return {};
  const auto [h, cos_d] = ngan_mf::half_of(pair);
  const double n = params_.sharpness;
  const double lobe = (n + 1) / (8 * ngan_mf::kPi) * std::pow(h.z, n);
  const double f = ngan_mf::schlick(params_.f0, cos_d);
  return params_.albedo * (lobe * f / (cos_d * std::max(zi, zo)));
}

// --- NganHe --------------------------------------------------------------------------------

namespace {
namespace ngan_he {  // He et al. 1991 as BBM's NganHe (bsdfmodel/he.h, ngan.h); docs/models.md

using ngan_mf::kPi;
using Channels = std::array<double, 3>;

// BBM's RGB wavelengths (backbone.h), µm: σ and τ are in µm.
constexpr Channels kWavelength{0.645, 0.526, 0.444};
constexpr int kTerms = 64;         // BBM's TaylorTerms for NganHe
constexpr double kRoughFrom = 18;  // BBM's RoughApproxThreshold: blended over [18, 19]
constexpr int kNewtonSteps = 4;    // BBM's NewtonRaphsonSteps
constexpr double kEps = std::numeric_limits<double>::epsilon();  // BBM's Constants::Epsilon

double tan_theta(const Vec3<double>& w) {
  return std::sqrt(w.x * w.x + w.y * w.y) / w.z;
}

// S(ω) of He's Eqs. 24-25 with the errata's exponential: (1 − erfc(a)/2) / (Λ(a) + 1), Λ Smith's
// Beckmann term at a = τ cot θ / (2σ0). 1 at the normal.
double shadowing(double tan_t, double sigma, double tau) {
  if (tan_t == 0) return 1;
  const double a = tau / (2 * sigma * tan_t);
  const double half_erfc = 0.5 * std::erfc(a);
  const double lambda = std::exp(-a * a) / (2 * std::sqrt(kPi) * a) - half_erfc;
  return (1 - half_erfc) / (lambda + 1);
}

// σ_eff = σ0 / √(1 + x²), x = z0/σ0 the root of x e^(x²/2) = (K_i + K_o)/√(8π), K = tan θ ·
// erfc(τ / (2σ0 tan θ)) (He's Eqs. 80-83). BBM's start and its 4 Newton steps, not the exact
// root: they leave x up to 1.3e-5 relative off at grazing angles (docs/models.md).
double effective_roughness(double tan_i, double tan_o, double sigma, double tau) {
  const auto k = [&](double t) { return t > kEps ? t * std::erfc(tau / (2 * sigma * t)) : 0.0; };
  const double f0 = (k(tan_i) + k(tan_o)) / std::sqrt(8 * kPi);
  double x = f0 <= 1 ? f0 : std::sqrt(2 * std::log(f0));
  for (int step = 0; step < kNewtonSteps; ++step) {
    const double e = std::exp(0.5 * x * x);
    x -= (x * e - f0) / ((1 + x * x) * e);  // the derivative is ≥ 1
  }
  return sigma / std::sqrt(1 + x * x);
}

// 1/m for the series' terms: products, not divisions, in its loop (it is the fit's hot spot).
constexpr std::array<double, kTerms + 1> kInverse = [] {
  std::array<double, kTerms + 1> inv{};
  for (int m = 1; m <= kTerms; ++m) inv[m] = 1.0 / m;
  return inv;
}();

// exp(x) underflows to exactly 0 below this (the smallest subnormal is e^−744.44): such terms are
// skipped, not computed (glibc's underflow path is slow, and off the specular peak most are).
constexpr double kExpZeroBelow = -746;

// Σ_{m ≥ 1} e^(−g − b/m) g^m/(m!·m) per channel, as BBM sums it: at most 64 terms, all channels
// stopped together after the first term at which the smallest channel's term is < ε and smaller
// than the previous smallest one.
Channels taylor_sum(const Channels& g, const Channels& b) {
  Channels sum{}, power{1, 1, 1};
  double previous_min = -1;
  for (int m = 1; m <= kTerms; ++m) {
    double term_min = std::numeric_limits<double>::infinity();
    for (int c = 0; c < 3; ++c) {
      power[c] *= g[c] * kInverse[m];
      const double x = -g[c] - b[c] * kInverse[m];
      const double term = x < kExpZeroBelow ? 0.0 : std::exp(x) * power[c] * kInverse[m];
      sum[c] += term;
      term_min = std::min(term_min, term);
    }
    if (term_min < kEps && term_min < previous_min) break;
    previous_min = term_min;
  }
  return sum;
}

// D_c / (π²τ²/(4λ_c²)): the series, Beckmann's rough limit e^(−b/g)/g, or their blend, chosen by
// the smallest channel's g (the red one) as BBM does for all three.
Channels series(const Channels& g, const Channels& b) {
  const double g_min = std::min({g[0], g[1], g[2]});
  const double w = g_min > kRoughFrom ? std::min(g_min - kRoughFrom, 1.0) : 0.0;
  const Channels taylor = g_min - 1 > kRoughFrom ? Channels{} : taylor_sum(g, b);
  Channels out = taylor;
  if (w > 0)
    for (int c = 0; c < 3; ++c) out[c] = (1 - w) * taylor[c] + w * std::exp(-b[c] / g[c]) / g[c];
  return out;
}

// D_c of He's Eq. 78 at v = ωi + ωo: π²τ²/(4λ_c²) times the series of g_c = (2π σ_eff v_z/λ_c)²
// and b_c = π²τ²|v_xy|²/λ_c² (Westin's exponent).
Channels distribution(double sigma_eff, double tau, const Vec3<double>& v) {
  const double g_unit = std::pow(2 * kPi * sigma_eff * v.z, 2);
  const double b_unit = kPi * kPi * tau * tau * (v.x * v.x + v.y * v.y);
  Channels g, b;
  for (int c = 0; c < 3; ++c) {
    g[c] = g_unit / (kWavelength[c] * kWavelength[c]);
    b[c] = b_unit / (kWavelength[c] * kWavelength[c]);
  }
  Channels d = series(g, b);
  for (int c = 0; c < 3; ++c) d[c] *= kPi * kPi * tau * tau / (4 * kWavelength[c] * kWavelength[c]);
  return d;
}

// Cook & Torrance's unpolarized Fresnel reflectance of a real index at cos θd (BBM's
// fresnel::cook); η² − 1 first, so that η = 1 gives 0 exactly.
double fresnel_cook(double eta, double c) {
  const double g = std::sqrt(std::max(eta * eta - 1 + c * c, 0.0));
  const double a = (g - c) / (g + c);
  const double b = (c * (g + c) - 1) / (c * (g - c) + 1);
  return std::max(0.5 * a * a * (1 + b * b), 0.0);
}

}  // namespace ngan_he
}  // namespace

NganHe::NganHe(const NganHeParams& p) : params_(p) {
  ngan_mf::check_range("he", "albedo_r", p.albedo.r, 0, 1e10);
  ngan_mf::check_range("he", "albedo_g", p.albedo.g, 0, 1e10);
  ngan_mf::check_range("he", "albedo_b", p.albedo.b, 0, 1e10);
  ngan_mf::check_range("he", "autocorrelation", p.autocorrelation, 0.1, 1000);
  ngan_mf::check_range("he", "roughness", p.roughness, 1e-3, 100);
  ngan_mf::check_range("he", "eta", p.eta, 1, 100);
}

std::string NganHe::description() const {
  return "He et al. 1991 as BBM's NganHe (Ngan et al. 2005), albedo " +
         ngan_mf::rgb_text(params_.albedo) + ", autocorrelation " +
         std::to_string(params_.autocorrelation) + " um, roughness " +
         std::to_string(params_.roughness) + " um, eta " + std::to_string(params_.eta);
}

Rgb NganHe::eval(const DirPair<double>& pair) const {
  const Vec3<double>&wi = pair.wi, &wo = pair.wo;
  if (!(wi.z > 0 && wo.z > 0)) return {};
  using namespace ngan_he;
  const double sigma = params_.roughness, tau = params_.autocorrelation;
  const double tan_i = tan_theta(wi), tan_o = tan_theta(wo);
  const double s = shadowing(tan_i, sigma, tau) * shadowing(tan_o, sigma, tau);
  const Vec3<double> v{wi.x + wo.x, wi.y + wo.y, wi.z + wo.z};
  const double vv = v.x * v.x + v.y * v.y + v.z * v.z;
  const double geometry = (vv / v.z) * (vv / v.z);  // He's Eq. 76, simplified (docs/models.md)
  const double cos_d =
      std::sqrt(std::max((1 + (wi.x * wo.x + wi.y * wo.y + wi.z * wo.z)) / 2, 0.0));
  const double f = fresnel_cook(params_.eta, cos_d);
  const Channels d = distribution(effective_roughness(tan_i, tan_o, sigma, tau), tau, v);
  const double common = f * s * geometry / (kPi * (wi.z * wo.z));
  return {params_.albedo.r * d[0] * common, params_.albedo.g * d[1] * common,
          params_.albedo.b * d[2] * common};
}

// --- Registry ------------------------------------------------------------------------------

void register_ngan_microfacet_models(ModelRegistry& registry) {
  using detail::colour;
  using detail::colour_params;
  std::vector<ModelParam> ct = colour_params("albedo", "specular scale (BBM's albedo)", 0.5, 1);
  ct.push_back(
      {"eta", "Schlick's reflectance at normal incidence F0 (BBM's eta; not an index)", 0.1, 0, 1});
  ct.push_back({"roughness", "Beckmann roughness m (RMS slope)", 0.1, 1e-3, 2});
  registry.add({"cook-torrance",
                "Cook-Torrance lobe as BBM's NganCookTorrance (Ngan et al. 2005): albedo D G F / "
                "(pi cos_i cos_o), Beckmann D, V-groove G, Schlick F with F0 = eta",
                std::move(ct), [](const ModelArgs& a) {
                  return std::make_shared<NganCookTorrance>(
                      NganCookTorranceParams{colour(a, "albedo"), a["eta"], a["roughness"]});
                }});

  std::vector<ModelParam> as = colour_params("albedo", "specular scale (BBM's albedo)", 0.5, 1);
  as.push_back(
      {"f0", "Schlick's reflectance at normal incidence (BBM's fresnelReflectance)", 0.1, 0, 1});
  as.push_back({"sharpness", "exponent n of cos(theta_h)", 32, 0, 1e6});
  registry.add({"ashikhmin-shirley",
                "Ashikhmin-Shirley specular lobe as BBM's NganAshikhminShirley (Ngan et al. "
                "2005): albedo (n+1)/(8 pi) cos^n(theta_h) F / ((wi.h) max(cos_i, cos_o)), "
                "Schlick F",
                std::move(as), [](const ModelArgs& a) {
                  return std::make_shared<NganAshikhminShirley>(
                      NganAshikhminShirleyParams{colour(a, "albedo"), a["f0"], a["sharpness"]});
                }});

  std::vector<ModelParam> he = colour_params("albedo", "specular scale (BBM's albedo)", 1, 1e10);
  he.push_back({"autocorrelation", "autocorrelation length tau of the surface, micrometres", 3.0,
                0.1, 1000});
  he.push_back({"roughness", "RMS height sigma0 of the surface, micrometres", 0.18, 1e-3, 100});
  he.push_back({"eta", "real index of refraction (Cook's Fresnel)", 1.5, 1, 100});
  registry.add({"he",
                "He et al. 1991's directional-diffuse lobe as BBM's NganHe (Ngan et al. 2005): "
                "albedo F S G D / (pi cos_i cos_o), Westin's exponent, Cook's Fresnel, per-channel "
                "wavelengths 0.645/0.526/0.444 um, no mirror spike",
                std::move(he), [](const ModelArgs& a) {
                  return std::make_shared<NganHe>(NganHeParams{
                      colour(a, "albedo"), a["autocorrelation"], a["roughness"], a["eta"]});
                }});
}

}  // namespace halfback::models
