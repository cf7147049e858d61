// The specular lobes of the published fits of Löw et al. 2012 ("BRDF models for accurate and
// efficient rendering of glossy surfaces", ACM TOG 31(1)) and Bagher et al. 2012 ("Accurate
// fitting of measured reflectances using a Shifted Gamma micro-facet distribution", CGF 31(4)),
// with exactly the conventions of BBM's restatements (bsdfbenchmark/bbm, include/bsdfmodel/low.h,
// lowsmooth.h, lowmicrofacet.h, cooktorrance.h, ashikhminshirley.h, bagher.h, ndf/low.h,
// ndf/sgd.h), so that BBM's fit files plug in unchanged. Each is the specular lobe only; a
// published fit adds a Lambertian term. Formulas and the mapping of BBM's parameters:
// docs/models.md, "The lobes of Löw et al. 2012 and Bagher et al. 2012".
// ρ in sr⁻¹ without the cosine factor. The lobes are built through the registry only
// (register_published_lobe_models), which refuses a value outside its parameter's range,
// naming the parameter.
#pragma once

#include "halfback/brdf/brdf.hpp"
#include "halfback/brdf/registry.hpp"

namespace halfback::models {

// Cook & Torrance's Fresnel reflectance of a real index η at cos θ = c (BBM's fresnel::cook):
// g = √max(η² + c² − 1, 0), F = ½ ((g − c)/(g + c))² (1 + ((c(g + c) − 1)/(c(g − c) + 1))²),
// clamped at 0.
double cook_fresnel(double eta, double c);

// "low-cook-torrance", BBM's LowCookTorrance: ρ = albedo · D G F / (π cos θi cos θo) with the
// unnormalised Beckmann D = exp(−tan²θh/m²) / (m² cos⁴θh), the V-groove G and Cook's F(η, ωi·ĥ).
struct LowCookTorranceParams {
  Rgb albedo{0.1, 0.1, 0.1};
  double roughness = 0.1;  // Beckmann's m
  double eta = 1.5;        // real index of refraction
};

// "low-ashikhmin-shirley", BBM's LowAshikhminShirley: ρ = albedo · (n + 1)/(8π) cos^n θh ·
// F(η, ωi·ĥ) / ((ωi·ĥ) max(cos θi, cos θo)), Cook's F with a real index (BBM's
// fresnelReflectance of these fits is that index).
struct LowAshikhminShirleyParams {
  Rgb albedo{0.5, 0.5, 0.5};
  double sharpness = 100;  // n
  double eta = 1.5;
};

// "low-smooth", BBM's LowSmooth (Löw's ABC smooth-surface model): ρ = A · (1 + B |p|²)^(−C) ·
// F(η, d), with p = (ωi + ωo) projected on the surface (xy), d = √max(1 − ¼|ωi,xy − ωo,xy|², 0),
// Cook's F; non-zero on the horizon too (BBM tests z ≥ 0).
struct LowSmoothParams {
  Rgb a{10, 10, 10};
  double b = 1000;
  double c = 1;
  double eta = 1.5;
};

// "low-microfacet", BBM's LowMicrofacetFit: ρ = A · S G F / (π cos θi cos θo), S = (1 + B(1 −
// cos θh))^(−C), the V-groove G, Cook's F(η, ωi·ĥ). The π is the fits' (BBM: "an additional
// (incorrect) normalization factor of π" in Löw's supplemental fits).
struct LowMicrofacetParams {
  Rgb a{10, 10, 10};
  double b = 1000;
  double c = 1;
  double eta = 1.5;
};

// "bagher-sgd", BBM's Bagher: per channel, ρ = albedo · D G F / (π cos θi cos θo) with the
// Shifted Gamma Distribution D = K · e^(−u)/u^p / (π cos⁴θh), u = α + tan²θh/α (0 when u^p ≤
// machine epsilon), G = G1(ωi) G1(ωo), G1(v) = 1 + Λ(1 − exp(c (θv − θ0)^k)) for θv > θ0, else 1,
// and F = F0 + (1 − F0)(1 − ωi·ĥ)⁵ − F1 ωi·ĥ. K, Λ, c, k, θ0 are Bagher et al.'s fitted
// normalisation and shadowing (BBM marks them dependent: not fitted by default, docs/fit.md).
struct BagherSgdParams {
  Rgb albedo{1, 1, 1};
  Rgb alpha{0.1, 0.1, 0.1};
  Rgb p{0.64, 0.64, 0.64};
  Rgb f0{0.04, 0.04, 0.04};
  Rgb f1{0, 0, 0};
  Rgb kscale{7.5, 7.5, 7.5};  // BBM's K
  Rgb lambda{0, 0, 0};        // Λ
  Rgb c{0, 0, 0};
  Rgb k{1, 1, 1};
  Rgb theta0{1.5707963267948966, 1.5707963267948966, 1.5707963267948966};
};

// Registers low-cook-torrance, low-ashikhmin-shirley, low-smooth, low-microfacet, bagher-sgd.
void register_published_lobe_models(ModelRegistry& registry);

}  // namespace halfback::models
