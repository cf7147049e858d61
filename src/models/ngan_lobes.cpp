#include "halfback/models/ngan_lobes.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "colour_params.hpp"

namespace halfback::models {

namespace {

constexpr double kPi = std::numbers::pi;

void check(bool ok, const char* model, const char* param, double value) {
  if (!ok)
    throw std::invalid_argument(fmt::format("{}: {} = {} is out of range", model, param, value));
}

void check_albedo(const char* model, const Rgb& a) {
  for (const double c : {a.r, a.g, a.b}) check(std::isfinite(c) && c >= 0, model, "albedo", c);
}

bool above(const DirPair<double>& p) {
  return p.wi.z > 0 && p.wo.z > 0;
}

}  // namespace

Ward::Ward(Rgb albedo, double roughness, bool duer)
    : albedo_(albedo), alpha_(roughness), duer_(duer) {
  check_albedo(duer ? "ward-duer" : "ward", albedo);
  check(std::isfinite(roughness) && roughness > 0, duer ? "ward-duer" : "ward", "roughness",
        roughness);
}

std::string Ward::description() const {
  return fmt::format("{} lobe (Ngan et al. 2005, as BBM), roughness {:g}",
                     duer_ ? "Ward-Dur" : "Ward", alpha_);
}

Rgb Ward::eval(const DirPair<double>& p) const {
  if (!above(p)) return {0, 0, 0};
  // H = ωi + ωo unnormalized: tan²θh = (Hx² + Hy²) / Hz².
  const double hx = p.wi.x + p.wo.x, hy = p.wi.y + p.wo.y, hz = p.wi.z + p.wo.z;
  const double tan2 = (hx * hx + hy * hy) / (hz * hz);
  const double cosines = duer_ ? p.wi.z * p.wo.z : std::sqrt(p.wi.z * p.wo.z);
  const double lobe = std::exp(-tan2 / (alpha_ * alpha_)) / (4 * kPi * alpha_ * alpha_ * cosines);
  return albedo_ * lobe;
}

BlinnPhong::BlinnPhong(Rgb albedo, double sharpness) : albedo_(albedo), n_(sharpness) {
  check_albedo("blinn-phong", albedo);
  check(std::isfinite(sharpness) && sharpness >= 0, "blinn-phong", "sharpness", sharpness);
}

std::string BlinnPhong::description() const {
  return fmt::format(
      "Phong lobe about the mirror direction (Ngan et al.'s Blinn-Phong, as BBM), "
      "sharpness {:g}",
      n_);
}

Rgb BlinnPhong::eval(const DirPair<double>& p) const {
  if (!above(p)) return {0, 0, 0};
  const double c = std::max(0.0, -p.wi.x * p.wo.x - p.wi.y * p.wo.y + p.wi.z * p.wo.z);
  return albedo_ * ((n_ + 2) / (2 * kPi) * std::pow(c, n_));
}

Lafortune::Lafortune(Rgb albedo, double cxy, double cz, double sharpness)
    : albedo_(albedo), cxy_(cxy), cz_(cz), n_(sharpness) {
  check_albedo("lafortune", albedo);
  check(std::isfinite(cxy), "lafortune", "cxy", cxy);
  check(std::isfinite(cz), "lafortune", "cz", cz);
  check(std::isfinite(sharpness) && sharpness >= 0, "lafortune", "sharpness", sharpness);
  const double c = std::max(std::abs(cxy), std::abs(cz));
  check(c > 0, "lafortune", "cxy and cz", 0);
  // The normalisation 1 / max(Cxy², Cz²)^(n/2) taken inside the power, (d / c)ⁿ: separately, a
  // published n of 16600 with c² = 0.5 makes inf × 0.
  cxy_ /= c;
  cz_ /= c;
  scale_ = (n_ + 2) / (2 * kPi);
}

std::string Lafortune::description() const {
  return fmt::format(
      "Lafortune lobe with Ngan et al.'s normalisation (as BBM), Cxy : Cz = {:g} : "
      "{:g}, sharpness {:g}",
      cxy_, cz_, n_);
}

Rgb Lafortune::eval(const DirPair<double>& p) const {
  if (!above(p)) return {0, 0, 0};
  const double d = cxy_ * (p.wi.x * p.wo.x + p.wi.y * p.wo.y) + cz_ * p.wi.z * p.wo.z;
  return albedo_ * (scale_ * std::pow(std::max(0.0, d), n_));
}

namespace {

// The specular scale of every lobe: the published ones reach 1.7, so up to 10.
std::vector<ModelParam> albedo_params() {
  return detail::colour_params("albedo", "specular scale", 0.05, 10);
}

Rgb albedo_of(const ModelArgs& a) {
  return detail::colour(a, "albedo");
}

ModelInfo ward_info(bool duer) {
  auto params = albedo_params();
  params.push_back({"roughness", "alpha: the lobe's width (RMS slope)", 0.1, 1e-3, 1});
  return {duer ? "ward-duer" : "ward",
          duer ? "Ward-Dur lobe as BBM's NganWardDuer (Ngan et al. 2005): albedo exp(-tan^2 "
                 "theta_h / a^2) / (4 pi a^2 cos theta_i cos theta_o)"
               : "Ward lobe as BBM's NganWard (Ngan et al. 2005): albedo exp(-tan^2 theta_h / "
                 "a^2) / (4 pi a^2 sqrt(cos theta_i cos theta_o))",
          params, [duer](const ModelArgs& a) {
            return std::make_shared<Ward>(albedo_of(a), a["roughness"], duer);
          }};
}

}  // namespace

void register_ngan_lobe_models(ModelRegistry& registry) {
  registry.add(ward_info(false));
  registry.add(ward_info(true));
  auto phong = albedo_params();
  phong.push_back({"sharpness", "exponent n of the lobe", 100, 0.1, 1e6});
  registry.add({"blinn-phong",
                "Phong lobe about the mirror direction as BBM's NganBlinnPhong (Ngan et al. 2005): "
                "albedo (n+2)/(2 pi) max(0, mirror(wi).wo)^n",
                phong, [](const ModelArgs& a) {
                  return std::make_shared<BlinnPhong>(albedo_of(a), a["sharpness"]);
                }});
  auto lafortune = albedo_params();
  lafortune.push_back(
      {"cxy", "Cxy: the lobe's weight of x and y (negative: forward)", -0.577, -1, 1});
  lafortune.push_back({"cz", "Cz: the lobe's weight of z", 0.577, 0, 1});
  lafortune.push_back({"sharpness", "exponent n of the lobe", 100, 0.1, 1e6});
  registry.add(
      {"lafortune",
       "Lafortune lobe as BBM's NganLafortune (Ngan et al. 2005): albedo max(0, C.(wi*wo))^n "
       "(n+2) / (2 pi max(Cxy^2, Cz^2)^(n/2))",
       lafortune, [](const ModelArgs& a) {
         return std::make_shared<Lafortune>(albedo_of(a), a["cxy"], a["cz"], a["sharpness"]);
       }});
}

}  // namespace halfback::models
