// The analytic models' entries in the model registry: names, parameters (defaults, ranges) and
// factories, so that "ggx:alpha=0.2,f0=0.9" works everywhere a BRDF SPEC is accepted.
#include "halfback/models/register.hpp"

#include "colour_params.hpp"
#include "halfback/models/analytic.hpp"
#include "halfback/models/artist.hpp"
#include "halfback/models/ngan_lobes.hpp"
#include "halfback/models/ngan_microfacet.hpp"
#include "halfback/models/published_lobes.hpp"

namespace halfback::models {

namespace {

using detail::colour;
using detail::colour_params;

std::vector<ModelParam> concat(std::vector<ModelParam> a, const std::vector<ModelParam>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

ModelInfo microfacet_info(MicrofacetParams::Distribution d, std::string name, std::string title) {
  std::vector<ModelParam> params{
      {"alpha", "roughness (both directions)", 0.2, 1e-3, 10},
      defaults_to("alpha_x", "roughness along t", "alpha", 1e-3, 10),
      defaults_to("alpha_y", "roughness along b", "alpha", 1e-3, 10),
      {"eta", "index of refraction; > 0 selects exact Fresnel instead of Schlick", 0, 0, 100},
      {"k", "extinction coefficient (conductor when > 0; needs eta)", 0, 0, 100},
  };
  params = concat(params, colour_params("f0", "Schlick reflectance at normal incidence", 0.04, 1));
  return {std::move(name), std::move(title), std::move(params), [d](const ModelArgs& a) {
            MicrofacetParams p;
            p.distribution = d;
            p.alpha_x = a["alpha_x"];
            p.alpha_y = a["alpha_y"];
            if (a["eta"] > 0) {
              p.fresnel.kind = a["k"] > 0 ? Fresnel::Kind::conductor : Fresnel::Kind::dielectric;
              p.fresnel.eta = {a["eta"], a["eta"], a["eta"]};
              p.fresnel.k = {a["k"], a["k"], a["k"]};
            } else {
              if (a["k"] > 0) throw std::invalid_argument(std::string("k needs eta > 0"));
              p.fresnel.kind = Fresnel::Kind::schlick;
              p.fresnel.f0 = colour(a, "f0");
            }
            return std::make_shared<Microfacet>(p);
          }};
}

}  // namespace

void register_analytic_models(ModelRegistry& registry) {
  registry.add({"lambert", "Lambertian diffuse reflection, rho = albedo / pi",
                colour_params("albedo", "albedo", 0.5, 1),
                [](const ModelArgs& a) { return std::make_shared<Lambert>(colour(a, "albedo")); }});
  registry.add(microfacet_info(MicrofacetParams::Distribution::ggx, "ggx",
                               "GGX microfacet reflection, anisotropic, Smith G2, Fresnel"));
  registry.add(microfacet_info(MicrofacetParams::Distribution::beckmann, "beckmann",
                               "Beckmann microfacet reflection, anisotropic, Smith G2, Fresnel"));
  registry.add({"abc",
                "ABC smooth-surface model of Low et al. 2012: F(theta_d) A/(1+B f^2)^((C+1)/2), "
                "f = 2|h_bar|, plus kd/pi",
                {{"a", "A: specular scale", 1, 0, 1e6},
                 {"b", "B: inverse squared width in f = 2|h_bar|", 400, 0, 1e9},
                 {"c", "C: fall-off exponent", 1.5, 0, 100},
                 {"eta", "index of refraction of the dielectric Fresnel factor (from air: >= 1)",
                  1.5, 1, 100},
                 {"kd", "diffuse albedo", 0, 0, 1}},
                [](const ModelArgs& a) {
                  AbcParams p;
                  p.a = a["a"];
                  p.b = a["b"];
                  p.c = a["c"];
                  p.eta = a["eta"];
                  p.kd = {a["kd"], a["kd"], a["kd"]};
                  return std::make_shared<Abc>(p);
                }});
  registry.add({"sheen",
                "Charlie sheen lobe (Estevez & Kulla 2017) for cloth-like grazing reflection",
                concat({{"alpha", "roughness of the sheen distribution", 0.3, 1e-3, 1}},
                       colour_params("color", "sheen colour", 1, 1)),
                [](const ModelArgs& a) {
                  return std::make_shared<Sheen>(SheenParams{colour(a, "color"), a["alpha"]});
                }});
  register_ngan_lobe_models(registry);
  register_ngan_microfacet_models(registry);
  register_artist_models(registry);

  // The lobes of Löw et al. 2012's and Bagher et al. 2012's published fits
  // (models/published_lobes).
  register_published_lobe_models(registry);
}

}  // namespace halfback::models
