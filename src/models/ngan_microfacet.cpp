// The lobes of Ngan et al. 2005 as BBM defines them (include/bsdfmodel/ngan.h of
// bsdfbenchmark/bbm): formulas in the header and docs/models.md.
#include "halfback/models/ngan_microfacet.hpp"

#include <algorithm>
#include <cmath>
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
}

}  // namespace halfback::models
