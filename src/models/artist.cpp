// Burley's principled BRDF and Oren–Nayar's qualitative model (include/halfback/models/artist.hpp;
// derivations and sources in docs/models.md, "Artists' models").
#include "halfback/models/artist.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "halfback/models/fresnel.hpp"

namespace halfback::models {

namespace {

constexpr double kPi = std::numbers::pi;

void check_unit(const char* model, const char* param, double v) {
  if (!(v >= 0 && v <= 1))
    throw std::invalid_argument(fmt::format("{}: {} = {} is outside [0, 1]", model, param, v));
}

double dot(const Vec3<double>& a, const Vec3<double>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

double mix(double a, double b, double t) {
  return a + (b - a) * t;
}

Rgb mix(const Rgb& a, const Rgb& b, double t) {
  return a + (b - a) * t;
}

// Schlick's weight (1 − c)⁵: Schlick's Fresnel from 0.
double schlick_weight(double c) {
  return fresnel_schlick(0, c);
}

// Burley's GTR1 (γ = 1) distribution, normalised: (α² − 1) / (π ln α² (1 + (α² − 1) cos²θh)).
double gtr1(double cos_h, double a) {
  const double a2 = a * a;
  return (a2 - 1) / (kPi * std::log(a2) * (1 + (a2 - 1) * cos_h * cos_h));
}

// Smith's separable GGX masking of one direction divided by 2 cos θ (the product of two of them
// is G / (4 cos θi cos θo)): 1 / (cos θ + sqrt((αx ωx)² + (αy ωy)² + cos²θ)).
double masking_over_cos(const Vec3<double>& w, double ax, double ay) {
  const double x = ax * w.x, y = ay * w.y;
  return 1 / (w.z + std::sqrt(x * x + y * y + w.z * w.z));
}

}  // namespace

// --- Disney --------------------------------------------------------------------------------

Disney::Disney(const DisneyParams& p) : params_(p) {
  for (const double c : {p.base_color.r, p.base_color.g, p.base_color.b})
    check_unit("disney", "base_color", c);
  check_unit("disney", "subsurface", p.subsurface);
  check_unit("disney", "metallic", p.metallic);
  check_unit("disney", "specular", p.specular);
  check_unit("disney", "specular_tint", p.specular_tint);
  check_unit("disney", "roughness", p.roughness);
  check_unit("disney", "anisotropic", p.anisotropic);
  check_unit("disney", "sheen", p.sheen);
  check_unit("disney", "sheen_tint", p.sheen_tint);
  check_unit("disney", "clearcoat", p.clearcoat);
  check_unit("disney", "clearcoat_gloss", p.clearcoat_gloss);
  const double aspect = std::sqrt(1 - 0.9 * p.anisotropic), r2 = p.roughness * p.roughness;
  ax_ = std::max(0.001, r2 / aspect);
  ay_ = std::max(0.001, r2 * aspect);
}

double Disney::clearcoat_alpha() const {
  return mix(0.1, 0.001, params_.clearcoat_gloss);
}

std::string Disney::description() const {
  const DisneyParams& p = params_;
  return fmt::format(
      "Burley 2012 principled BRDF: base_color ({:g}, {:g}, {:g}), subsurface {:g}, metallic {:g}, "
      "specular {:g}, specular_tint {:g}, roughness {:g}, anisotropic {:g}, sheen {:g}, "
      "sheen_tint {:g}, clearcoat {:g}, clearcoat_gloss {:g}",
      p.base_color.r, p.base_color.g, p.base_color.b, p.subsurface, p.metallic, p.specular,
      p.specular_tint, p.roughness, p.anisotropic, p.sheen, p.sheen_tint, p.clearcoat,
      p.clearcoat_gloss);
}

Rgb Disney::eval(const DirPair<double>& pair) const {
  const Vec3<double>&l = pair.wi, &v = pair.wo;
  if (!(l.z > 0 && v.z > 0)) return {};
  const DisneyParams& p = params_;
  const double hx0 = l.x + v.x, hy0 = l.y + v.y, hz0 = l.z + v.z;
  const double len = std::sqrt(hx0 * hx0 + hy0 * hy0 + hz0 * hz0);
  const Vec3<double> h{hx0 / len, hy0 / len, hz0 / len};
  const double cos_l = l.z, cos_v = v.z, cos_h = h.z, cos_d = dot(l, h);

  // Colours: the tint is the base colour's hue (its luminance divided out).
  const Rgb& base = p.base_color;
  const double lum = 0.3 * base.r + 0.6 * base.g + 0.1 * base.b;
  const Rgb tint = lum > 0 ? base * (1 / lum) : Rgb{1, 1, 1};
  const Rgb spec0 =
      mix(mix(Rgb{1, 1, 1}, tint, p.specular_tint) * (0.08 * p.specular), base, p.metallic);
  const Rgb sheen_colour = mix(Rgb{1, 1, 1}, tint, p.sheen_tint);

  // Diffuse: Schlick-like retro-reflection at grazing, blended with the subsurface lobe.
  const double fl = schlick_weight(cos_l), fv = schlick_weight(cos_v);
  const double fd90 = 0.5 + 2 * cos_d * cos_d * p.roughness;
  const double fd = mix(1, fd90, fl) * mix(1, fd90, fv);
  const double fss90 = cos_d * cos_d * p.roughness;
  const double fss = mix(1, fss90, fl) * mix(1, fss90, fv);
  const double ss = 1.25 * (fss * (1 / (cos_l + cos_v) - 0.5) + 0.5);
  const double diffuse = mix(fd, ss, p.subsurface) / kPi;

  // Specular: anisotropic GGX (GTR2), Schlick's Fresnel, separable Smith GGX masking.
  const double hx = h.x / ax_, hy = h.y / ay_;
  const double q = hx * hx + hy * hy + cos_h * cos_h;
  const double ds = 1 / (kPi * ax_ * ay_ * q * q);
  const double fh = schlick_weight(cos_d);
  const Rgb fs{fresnel_schlick(spec0.r, cos_d), fresnel_schlick(spec0.g, cos_d),
               fresnel_schlick(spec0.b, cos_d)};
  const double gs = masking_over_cos(l, ax_, ay_) * masking_over_cos(v, ax_, ay_);

  // Clearcoat: GTR1, a fixed index (F0 = 0.04), Smith GGX masking at α = 0.25.
  double coat = 0;
  if (p.clearcoat > 0) {
    const double dr = gtr1(cos_h, clearcoat_alpha());
    const double fr = fresnel_schlick(0.04, cos_d);
    const double gr = masking_over_cos(l, 0.25, 0.25) * masking_over_cos(v, 0.25, 0.25);
    coat = 0.25 * p.clearcoat * gr * fr * dr;
  }

  return (base * diffuse + sheen_colour * (fh * p.sheen)) * (1 - p.metallic) + fs * (gs * ds) +
         Rgb{coat, coat, coat};
}

// --- Oren–Nayar ----------------------------------------------------------------------------

OrenNayar::OrenNayar(const OrenNayarParams& p) : params_(p) {
  for (const double c : {p.albedo.r, p.albedo.g, p.albedo.b}) check_unit("oren-nayar", "albedo", c);
  if (!(p.sigma >= 0 && p.sigma <= kPi / 2))
    throw std::invalid_argument(
        fmt::format("oren-nayar: sigma = {} is outside [0, pi/2] (radians)", p.sigma));
  const double s2 = p.sigma * p.sigma;
  a_ = 1 - 0.5 * s2 / (s2 + 0.33);
  b_ = 0.45 * s2 / (s2 + 0.09);
}

std::string OrenNayar::description() const {
  return fmt::format("Oren-Nayar qualitative model, albedo ({:g}, {:g}, {:g}), sigma {:g} rad",
                     params_.albedo.r, params_.albedo.g, params_.albedo.b, params_.sigma);
}

// cos(φi − φo) sin α tan β = sin θi sin θo cos(φi − φo) / max(cos θi, cos θo)
//                          = (ωi·ωo − cos θi cos θo) / max(cos θi, cos θo).
Rgb OrenNayar::eval(const DirPair<double>& pair) const {
  const Vec3<double>&l = pair.wi, &v = pair.wo;
  if (!(l.z > 0 && v.z > 0)) return {};
  const double s = dot(l, v) - l.z * v.z;
  const double t = s > 0 ? s / std::max(l.z, v.z) : 0.0;
  return params_.albedo * ((a_ + b_ * t) / kPi);
}

// --- Registry --------------------------------------------------------------------------------

namespace {

ModelParam unit(std::string name, std::string what, double default_value) {
  return {std::move(name), std::move(what), default_value, 0, 1};
}

}  // namespace

void register_artist_models(ModelRegistry& registry) {
  // Defaults are Burley's except sheen and clearcoat, 0.1 instead of 0: at 0, sheen_tint and
  // clearcoat_gloss have no effect, and a fit from the defaults would hold them (fit.hpp).
  // The base colour's channels are named _red/_green/_blue, not _r/_g/_b: through the tints
  // (the colour divided by its luminance) each drives every channel, which the fit's colour
  // parameters must not (fit.hpp, channel_of).
  registry.add(
      {"disney",
       "Burley 2012 principled BRDF (Disney): diffuse with retro-reflection, subsurface, GGX "
       "specular, sheen, clearcoat",
       {unit("base_color", "base colour, linear (grey)", 0.5),
        defaults_to("base_color_red", "base colour, red channel", "base_color", 0, 1),
        defaults_to("base_color_green", "base colour, green channel", "base_color", 0, 1),
        defaults_to("base_color_blue", "base colour, blue channel", "base_color", 0, 1),
        unit("subsurface", "blend of the diffuse towards Burley's subsurface lobe", 0),
        unit("metallic", "0 dielectric, 1 metal (the specular takes the base colour)", 0),
        unit("specular", "dielectric specular amount: F0 = 0.08 specular", 0.5),
        unit("specular_tint", "tints the dielectric specular towards the base colour", 0),
        unit("roughness", "roughness; the GGX alpha is its square", 0.5),
        unit("anisotropic", "aspect of the specular lobe along t (alpha_x) and b (alpha_y)", 0),
        unit("sheen", "grazing sheen amount", 0.1),
        unit("sheen_tint", "tints the sheen towards the base colour", 0.5),
        unit("clearcoat", "clearcoat amount (a second, fixed-index GTR1 lobe)", 0.1),
        unit("clearcoat_gloss", "clearcoat gloss: GTR1 alpha = 0.1 - 0.099 gloss", 1)},
       [](const ModelArgs& a) {
         DisneyParams p;
         p.base_color = {a["base_color_red"], a["base_color_green"], a["base_color_blue"]};
         p.subsurface = a["subsurface"];
         p.metallic = a["metallic"];
         p.specular = a["specular"];
         p.specular_tint = a["specular_tint"];
         p.roughness = a["roughness"];
         p.anisotropic = a["anisotropic"];
         p.sheen = a["sheen"];
         p.sheen_tint = a["sheen_tint"];
         p.clearcoat = a["clearcoat"];
         p.clearcoat_gloss = a["clearcoat_gloss"];
         return std::make_shared<Disney>(p);
       }});
  registry.add(
      {"oren-nayar",
       "Oren-Nayar 1994 qualitative model of rough diffuse reflection (V-cavities of slope "
       "deviation sigma)",
       {{"albedo", "albedo (grey)", 0.5, 0, 1},
        defaults_to("albedo_r", "albedo, red channel", "albedo", 0, 1),
        defaults_to("albedo_g", "albedo, green channel", "albedo", 0, 1),
        defaults_to("albedo_b", "albedo, blue channel", "albedo", 0, 1),
        {"sigma", "standard deviation of the facets' slope angle, radians", 0.3, 0, kPi / 2}},
       [](const ModelArgs& a) {
         OrenNayarParams p;
         p.albedo = {a["albedo_r"], a["albedo_g"], a["albedo_b"]};
         p.sigma = a["sigma"];
         return std::make_shared<OrenNayar>(p);
       }});
}

}  // namespace halfback::models
