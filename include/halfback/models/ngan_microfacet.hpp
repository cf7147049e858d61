// The microfacet-style specular lobes of Ngan, Durand & Matusik 2005 ("Experimental Analysis of
// BRDF Models", EGSR), with exactly the conventions of BBM (bsdfbenchmark/bbm,
// include/bsdfmodel/ngan.h), so that the published fits BBM distributes plug in unchanged:
// NganCookTorrance ("cook-torrance"), NganAshikhminShirley ("ashikhmin-shirley") and NganHe
// ("he"). Each is the specular lobe only; a published fit adds a Lambertian term
// ("lambert:...+cook-torrance:...").
// Formulas, parameter meanings and energy: docs/models.md, "The lobes of Ngan et al. 2005".
// ρ in sr⁻¹ without the cosine factor, 0 below the horizon; constructors throw
// std::invalid_argument naming a parameter outside its range.
#pragma once

#include "halfback/brdf/brdf.hpp"
#include "halfback/brdf/registry.hpp"

namespace halfback::models {

// ρ = albedo · D(ĥ) G(ωi, ωo) F(ωi·ĥ) / (π cos θi cos θo), with the normalized Beckmann
// D = exp(−tan²θh/m²) / (π m² cos⁴θh), the V-groove G = min(1, 2 cos θh cos θi/(ωi·ĥ),
// 2 cos θh cos θo/(ωo·ĥ)) and Schlick's F = F0 + (1 − F0)(1 − ωi·ĥ)⁵, where F0 is BBM's `eta`.
struct NganCookTorranceParams {
  Rgb albedo{0.5, 0.5, 0.5};  // BBM's SpecularScale, per channel, in [0, 1]
  double eta = 0.1;           // Schlick's reflectance at normal incidence F0 (not an index), [0, 1]
  double roughness = 0.1;     // Beckmann's m (RMS slope), [1e-3, 2]
};

class NganCookTorrance final : public Brdf {
 public:
  explicit NganCookTorrance(const NganCookTorranceParams& params);
  std::string name() const override { return "cook-torrance"; }
  std::string description() const override;
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override;

 private:
  NganCookTorranceParams params_;
};

// ρ = albedo · (n + 1)/(8π) · cos^n θh · F(ωi·ĥ) / ((ωi·ĥ) max(cos θi, cos θo)), Schlick's F with
// F0 = BBM's `fresnelReflectance`: the isotropic specular lobe of Ashikhmin & Shirley 2000.
struct NganAshikhminShirleyParams {
  Rgb albedo{0.5, 0.5, 0.5};  // BBM's SpecularScale, per channel, in [0, 1]
  double f0 = 0.1;            // BBM's fresnelReflectance, [0, 1]
  double sharpness = 32;      // the exponent n, [0, 1e6]
};

class NganAshikhminShirley final : public Brdf {
 public:
  explicit NganAshikhminShirley(const NganAshikhminShirleyParams& params);
  std::string name() const override { return "ashikhmin-shirley"; }
  std::string description() const override;
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override;

 private:
  NganAshikhminShirleyParams params_;
};

// The directional-diffuse lobe of He, Torrance, Sillion & Greenberg 1991 as BBM's NganHe: Westin
// et al.'s scaling of the exponent, Cook's Fresnel with a real index, the errata's shadowing, no
// mirror spike. Per channel c, with BBM's wavelengths λ = (0.645, 0.526, 0.444) µm:
//   ρ_c = albedo_c · F(cos θd) S(ωi) S(ωo) G D_c / (π cos θi cos θo),
//   G = (v·v / v_z)², v = ωi + ωo,
//   D_c = π²τ²/(4λ_c²) Σ_{m=1..64} e^(−g_c) g_c^m/(m!·m) · exp(−π²τ² v_xy²/(m λ_c²)),
//   g_c = (2π σ_eff (cos θi + cos θo)/λ_c)²,
// with BBM's numerics: σ_eff from 4 Newton steps on He's Eq. 80, the series stopped on the
// smallest channel's term, the rough limit e^(−b/g)/g blended in as the red g goes from 18 to 19.
// docs/models.md, "he", derives it and lists where BBM's numerics leave the formula.
struct NganHeParams {
  Rgb albedo{1, 1, 1};           // BBM's SpecularScale, per channel, in [0, 1e10]
  double autocorrelation = 3.0;  // τ, the surface's autocorrelation length, µm, [0.1, 1000]
  double roughness = 0.18;       // σ0, the RMS height, µm, [0.001, 100]
  double eta = 1.5;              // real index of refraction of Cook's Fresnel, [1, 100]
};

class NganHe final : public Brdf {
 public:
  explicit NganHe(const NganHeParams& params);
  std::string name() const override { return "he"; }
  std::string description() const override;
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override;

 private:
  NganHeParams params_;
};

// Adds "cook-torrance", "ashikhmin-shirley" and "he" (parameters named as BBM's, in lower case).
void register_ngan_microfacet_models(ModelRegistry& registry);

}  // namespace halfback::models
