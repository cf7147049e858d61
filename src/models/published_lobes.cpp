// The lobes of Löw et al. 2012 and Bagher et al. 2012 as BBM restates them (formulas in
// include/halfback/models/published_lobes.hpp and docs/models.md).
#include "halfback/models/published_lobes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "colour_params.hpp"

namespace halfback::models {

namespace {
namespace pub_lobes {  // (named: the layer's unity build shares one anonymous namespace)

constexpr double kPi = std::numbers::pi;

double dot(const Vec3<double>& a, const Vec3<double>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

// BBM's halfway(in, out) = normalize(in + out); null when the sum is zero.
Vec3<double> halfway(const DirPair<double>& p) {
  const Vec3<double> s{p.wi.x + p.wo.x, p.wi.y + p.wo.y, p.wi.z + p.wo.z};
  const double len = std::sqrt(dot(s, s));
  if (!(len > 0)) return {0, 0, 0};
  return {s.x / len, s.y / len, s.z / len};
}

// BBM's V-groove masking-shadowing: 0 unless both directions face ĥ.
double vgroove(const DirPair<double>& p, const Vec3<double>& h) {
  const double in = dot(p.wi, h), out = dot(p.wo, h);
  if (!(in > 0 && out > 0)) return 0;
  return std::min({1.0, 2 * h.z * p.wi.z / in, 2 * h.z * p.wo.z / out});
}

// The microfacet frame every lobe but the smooth one shares: both directions strictly above the
// horizon (BBM's microfacet and Ashikhmin–Shirley test z > 0).
struct Frame {
  bool valid = false;
  Vec3<double> h;
  double in_h = 0, out_h = 0;
};

Frame frame_of(const DirPair<double>& p) {
  Frame f;
  if (!(p.wi.z > 0 && p.wo.z > 0)) return f;
  f.h = halfway(p);
  f.in_h = dot(p.wi, f.h);
  f.out_h = dot(p.wo, f.h);
  f.valid = true;
  return f;
}

// The form Löw's Cook–Torrance and microfacet lobes share (BBM's): D G F / (π cos θi cos θo),
// G the V-groove, F Cook's of η at the mean of ωi·ĥ and ωo·ĥ; `d` the lobe's distribution.
double cook_torrance_form(const DirPair<double>& pair, const Frame& f, double d, double eta) {
  const double fr = cook_fresnel(eta, 0.5 * (f.in_h + f.out_h));
  return d * vgroove(pair, f.h) * fr / kPi / (pair.wi.z * pair.wo.z);
}

// BBM's spherical::theta of a direction above the horizon: 2 asin(|v − n| / 2).
double theta_of(const Vec3<double>& v) {
  const double dz = v.z - 1;
  return 2 * std::asin(0.5 * std::sqrt(v.x * v.x + v.y * v.y + dz * dz));
}

std::string rgb_text(const Rgb& v) {
  return std::to_string(v.r) + "/" + std::to_string(v.g) + "/" + std::to_string(v.b);
}

}  // namespace pub_lobes
}  // namespace

double cook_fresnel(double eta, double c) {
  const double g = std::sqrt(std::max(eta * eta + c * c - 1, 0.0));
  const double a = (g - c) / (g + c);
  const double b = (c * (g + c) - 1) / (c * (g - c) + 1);
  return std::max(0.5 * a * a * (1 + b * b), 0.0);
}

namespace {
namespace pub_lobes {

class LowCookTorrance final : public Brdf {
 public:
  explicit LowCookTorrance(const LowCookTorranceParams& p) : p_(p) {}
  std::string name() const override { return "low-cook-torrance"; }
  std::string description() const override {
    return "Cook-Torrance as BBM's LowCookTorrance (Low et al. 2012), albedo " +
           rgb_text(p_.albedo) + ", roughness " + std::to_string(p_.roughness) + ", eta " +
           std::to_string(p_.eta);
  }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override {
    const Frame f = frame_of(pair);
    if (!f.valid || !(f.h.z > 0)) return {};
    const double m2 = p_.roughness * p_.roughness, cos2 = f.h.z * f.h.z;
    const double tan2 = (f.h.x * f.h.x + f.h.y * f.h.y) / cos2;
    const double d = std::exp(-tan2 / m2) / (m2 * cos2 * cos2);  // unnormalised Beckmann
    return p_.albedo * cook_torrance_form(pair, f, d, p_.eta);
  }

 private:
  LowCookTorranceParams p_;
};

class LowAshikhminShirley final : public Brdf {
 public:
  explicit LowAshikhminShirley(const LowAshikhminShirleyParams& p) : p_(p) {}
  std::string name() const override { return "low-ashikhmin-shirley"; }
  std::string description() const override {
    return "Ashikhmin-Shirley as BBM's LowAshikhminShirley (Low et al. 2012), albedo " +
           rgb_text(p_.albedo) + ", sharpness " + std::to_string(p_.sharpness) + ", eta " +
           std::to_string(p_.eta);
  }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override {
    const Frame f = frame_of(pair);
    if (!f.valid) return {};
    const double n = p_.sharpness;
    const double lobe = (n + 1) / (8 * kPi) * std::pow(f.h.z, n);
    const double fr = cook_fresnel(p_.eta, f.in_h);
    return p_.albedo * (lobe * fr / (f.in_h * std::max(pair.wi.z, pair.wo.z)));
  }

 private:
  LowAshikhminShirleyParams p_;
};

class LowSmooth final : public Brdf {
 public:
  explicit LowSmooth(const LowSmoothParams& p) : p_(p) {}
  std::string name() const override { return "low-smooth"; }
  std::string description() const override {
    return "Low et al. 2012's smooth (ABC) model as BBM's LowSmooth, A " + rgb_text(p_.a) + ", B " +
           std::to_string(p_.b) + ", C " + std::to_string(p_.c) + ", eta " + std::to_string(p_.eta);
  }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override {
    const Vec3<double>&wi = pair.wi, &wo = pair.wo;
    if (!(wi.z >= 0 && wo.z >= 0)) return {};
    const double sx = wi.x + wo.x, sy = wi.y + wo.y, dx = wi.x - wo.x, dy = wi.y - wo.y;
    const double s = std::pow(1 + p_.b * (sx * sx + sy * sy), -p_.c);
    const double cos_d = std::sqrt(std::max(1 - 0.25 * (dx * dx + dy * dy), 0.0));
    return p_.a * (s * cook_fresnel(p_.eta, cos_d));
  }

 private:
  LowSmoothParams p_;
};

class LowMicrofacet final : public Brdf {
 public:
  explicit LowMicrofacet(const LowMicrofacetParams& p) : p_(p) {}
  std::string name() const override { return "low-microfacet"; }
  std::string description() const override {
    return "Low et al. 2012's microfacet model as BBM's LowMicrofacetFit, A " + rgb_text(p_.a) +
           ", B " + std::to_string(p_.b) + ", C " + std::to_string(p_.c) + ", eta " +
           std::to_string(p_.eta);
  }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override {
    const Frame f = frame_of(pair);
    if (!f.valid || !(f.h.z > 0)) return {};
    const double s = std::pow(1 + p_.b * (1 - f.h.z), -p_.c);
    return p_.a * cook_torrance_form(pair, f, s, p_.eta);
  }

 private:
  LowMicrofacetParams p_;
};

class BagherSgd final : public Brdf {
 public:
  explicit BagherSgd(const BagherSgdParams& p) : p_(p) {}
  std::string name() const override { return "bagher-sgd"; }
  std::string description() const override {
    return "Bagher et al. 2012's Shifted Gamma microfacet model as BBM's Bagher, albedo " +
           rgb_text(p_.albedo) + ", alpha " + rgb_text(p_.alpha) + ", p " + rgb_text(p_.p);
  }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override {
    const Frame f = frame_of(pair);
    if (!f.valid || !(f.h.z > 0)) return {};
    const double cos2 = f.h.z * f.h.z, tan2 = std::max(1 - cos2, 0.0) / cos2;
    const double cos_d = 0.5 * (f.in_h + f.out_h);
    const bool faces = f.in_h > 0 && f.out_h > 0;  // BBM's uncorrelated G: 0 otherwise
    const double ti = theta_of(pair.wi), to = theta_of(pair.wo);
    Rgb out;
    for (int ch = 0; ch < 3; ++ch) {
      const auto at = [ch](const Rgb& v) { return ch == 0 ? v.r : ch == 1 ? v.g : v.b; };
      const double alpha = at(p_.alpha), u = alpha + tan2 / alpha;
      const double denom = std::pow(u, at(p_.p));
      const double p22 = denom > std::numeric_limits<double>::epsilon() ? std::exp(-u) / denom : 0;
      const double d = at(p_.kscale) * p22 / (kPi * cos2 * cos2);
      const auto g1 = [&](double theta) {
        const double t0 = at(p_.theta0);
        if (!(theta > t0)) return 1.0;
        return 1 + at(p_.lambda) * (1 - std::exp(at(p_.c) * std::pow(theta - t0, at(p_.k))));
      };
      const double g = faces ? g1(ti) * g1(to) : 0.0;
      const double f0 = at(p_.f0), x = 1 - cos_d;
      const double fr = f0 + (1 - f0) * std::pow(x, 5.0) - at(p_.f1) * cos_d;
      const double v = at(p_.albedo) * d * g * fr / kPi / (pair.wi.z * pair.wo.z);
      (ch == 0 ? out.r : ch == 1 ? out.g : out.b) = v;
    }
    return out;
  }

 private:
  BagherSgdParams p_;
};

// Colour parameters of any range (colour_params starts at 0): grey value plus channels.
std::vector<ModelParam> channels(const std::string& name, const std::string& what, double def,
                                 double lo, double hi) {
  return {{name, what + " (grey)", def, lo, hi},
          defaults_to(name + "_r", what + ", red channel", name, lo, hi),
          defaults_to(name + "_g", what + ", green channel", name, lo, hi),
          defaults_to(name + "_b", what + ", blue channel", name, lo, hi)};
}

void append(std::vector<ModelParam>& a, const std::vector<ModelParam>& b) {
  a.insert(a.end(), b.begin(), b.end());
}

// Bounds wide enough for every published fit (docs/models.md lists which values are unphysical).
constexpr double kMaxAlbedo = 10;  // Löw's Ashikhmin–Shirley albedos reach 1.82
constexpr double kMaxEta = 100;    // Löw's microfacet fits reach η = 100

}  // namespace pub_lobes
}  // namespace

void register_published_lobe_models(ModelRegistry& registry) {
  using detail::colour;
  using pub_lobes::append;
  using pub_lobes::channels;
  using pub_lobes::kMaxAlbedo;
  using pub_lobes::kMaxEta;

  std::vector<ModelParam> ct = channels("albedo", "specular scale", 0.1, 0, kMaxAlbedo);
  ct.push_back({"roughness", "Beckmann roughness m", 0.1, 1e-3, 5});
  ct.push_back({"eta", "real index of refraction (Cook's Fresnel)", 1.5, 1, kMaxEta});
  registry.add({"low-cook-torrance",
                "Cook-Torrance as in Low et al. 2012's fits (BBM's LowCookTorrance): albedo D G F "
                "/ (pi cos_i cos_o), unnormalised Beckmann D, V-groove G, Cook's Fresnel of eta",
                std::move(ct), [](const ModelArgs& a) {
                  LowCookTorranceParams p;
                  p.albedo = colour(a, "albedo");
                  p.roughness = a["roughness"];
                  p.eta = a["eta"];
                  return std::make_shared<pub_lobes::LowCookTorrance>(p);
                }});

  std::vector<ModelParam> as = channels("albedo", "specular scale", 0.5, 0, kMaxAlbedo);
  as.push_back({"sharpness", "exponent n of cos(theta_h)", 100, 0, 1e7});
  as.push_back({"eta", "real index of refraction (Cook's Fresnel)", 1.5, 1, kMaxEta});
  registry.add({"low-ashikhmin-shirley",
                "Ashikhmin-Shirley as in Low et al. 2012's fits (BBM's LowAshikhminShirley): "
                "albedo (n+1)/(8 pi) cos^n(theta_h) F / ((wi.h) max(cos_i, cos_o)), Cook's Fresnel",
                std::move(as), [](const ModelArgs& a) {
                  LowAshikhminShirleyParams p;
                  p.albedo = colour(a, "albedo");
                  p.sharpness = a["sharpness"];
                  p.eta = a["eta"];
                  return std::make_shared<pub_lobes::LowAshikhminShirley>(p);
                }});

  const auto abc = [](double a_default) {
    std::vector<ModelParam> v = channels("a", "scale A", a_default, 0, 1e6);
    append(v, {{"b", "width B", 1000, 1e-3, 1e9},
               {"c", "fall-off exponent C", 1, 1e-3, 100},
               {"eta", "real index of refraction (Cook's Fresnel)", 1.5, 1, kMaxEta}});
    return v;
  };
  registry.add({"low-smooth",
                "Low et al. 2012's smooth model (BBM's LowSmooth): A (1 + B |p|^2)^-C F, p the "
                "surface projection of wi + wo, Cook's Fresnel; A per channel",
                abc(10), [](const ModelArgs& a) {
                  LowSmoothParams p;
                  p.a = colour(a, "a");
                  p.b = a["b"];
                  p.c = a["c"];
                  p.eta = a["eta"];
                  return std::make_shared<pub_lobes::LowSmooth>(p);
                }});
  registry.add(
      {"low-microfacet",
       "Low et al. 2012's microfacet model as in its fits (BBM's LowMicrofacetFit): A S G "
       "F / (pi cos_i cos_o), S = (1 + B (1 - cos theta_h))^-C, V-groove G, Cook's Fresnel",
       abc(10), [](const ModelArgs& a) {
         LowMicrofacetParams p;
         p.a = colour(a, "a");
         p.b = a["b"];
         p.c = a["c"];
         p.eta = a["eta"];
         return std::make_shared<pub_lobes::LowMicrofacet>(p);
       }});

  std::vector<ModelParam> sgd = channels("albedo", "specular scale", 1, 0, 100);
  append(sgd, channels("alpha", "SGD alpha", 0.1, 1e-6, 10));
  append(sgd, channels("p", "SGD p", 0.64, 0, 10));
  append(sgd, channels("f0", "Fresnel F0 (BBM's eta, first row)", 0.04, -10, 10));
  append(sgd, channels("f1", "Fresnel F1 (BBM's eta, second row)", 0, -10, 10));
  append(sgd, channels("kscale", "normalisation K (BBM's K; dependent)", 7.5, 0, 1e7));
  append(sgd, channels("lambda", "shadowing Lambda (dependent)", 0, 0, 1e10));
  append(sgd, channels("c", "shadowing c (dependent)", 0, 0, 1e300));
  append(sgd, channels("k", "shadowing exponent k (dependent)", 1, 0, 1e4));
  append(sgd, channels("theta0", "shadowing onset theta0, radians (dependent)",
                       std::numbers::pi / 2, -std::numbers::pi, std::numbers::pi));
  registry.add({"bagher-sgd",
                "Bagher et al. 2012's Shifted Gamma microfacet model (BBM's Bagher): albedo D G F "
                "/ (pi cos_i cos_o), per channel",
                std::move(sgd), [](const ModelArgs& a) {
                  BagherSgdParams p;
                  p.albedo = colour(a, "albedo");
                  p.alpha = colour(a, "alpha");
                  p.p = colour(a, "p");
                  p.f0 = colour(a, "f0");
                  p.f1 = colour(a, "f1");
                  p.kscale = colour(a, "kscale");
                  p.lambda = colour(a, "lambda");
                  p.c = colour(a, "c");
                  p.k = colour(a, "k");
                  p.theta0 = colour(a, "theta0");
                  return std::make_shared<pub_lobes::BagherSgd>(p);
                }});
}

}  // namespace halfback::models
