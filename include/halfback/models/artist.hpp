// The models artists and renderers carry materials in: Burley's "principled" BRDF (Disney, 2012)
// and the qualitative Oren–Nayar model (1994). Formulas and sources: docs/models.md, "Artists'
// models"; their renderer forms (`halfback fit --emit blender|materialx`): docs/fit.md. Both are
// reciprocal, 0 below the horizon, sampled by the cosine (the renderer tabulates them).
// Constructors throw std::invalid_argument naming a bad parameter.
#pragma once

#include <string>

#include "halfback/brdf/brdf.hpp"
#include "halfback/brdf/registry.hpp"

namespace halfback::models {

// Burley 2012, "Physically-Based Shading at Disney", the BRDF part (no transmission): a
// retro-reflective diffuse (or Hanrahan–Krueger-like subsurface) lobe, an anisotropic GGX specular
// lobe with Schlick's Fresnel between a tinted Cspec0 and 1, a sheen and a GTR1 clearcoat. Every
// parameter is in [0, 1]. base_color is linear RGB (Disney's explorer squares its sRGB-like input
// first; halfback takes the linear value a renderer's node takes).
struct DisneyParams {
  Rgb base_color{0.5, 0.5, 0.5};
  double subsurface = 0, metallic = 0, specular = 0.5, specular_tint = 0, roughness = 0.5,
         anisotropic = 0, sheen = 0, sheen_tint = 0.5, clearcoat = 0, clearcoat_gloss = 1;
};

class Disney final : public Brdf {
 public:
  explicit Disney(const DisneyParams& params);
  std::string name() const override { return "disney"; }
  std::string description() const override;
  bool isotropic() const override { return params_.anisotropic == 0; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override;
  const DisneyParams& params() const { return params_; }

  // The specular lobe's roughnesses: αx = max(0.001, r²/aspect), αy = max(0.001, r² aspect),
  // aspect = sqrt(1 − 0.9 anisotropic); and the clearcoat's GTR1 α = 0.1 + (0.001 − 0.1) gloss.
  double alpha_x() const { return ax_; }
  double alpha_y() const { return ay_; }
  double clearcoat_alpha() const;

 private:
  DisneyParams params_;
  double ax_, ay_;
};

// Oren & Nayar 1994, the qualitative model (their eq. 30): ρ = albedo/π · (A + B max(0, cos(φi −
// φo)) sin α tan β), α = max(θi, θo), β = min(θi, θo), A = 1 − σ²/(2(σ² + 0.33)),
// B = 0.45 σ²/(σ² + 0.09); σ the standard deviation of the facets' slope angle, in radians.
// σ = 0 is Lambert.
struct OrenNayarParams {
  Rgb albedo{0.5, 0.5, 0.5};
  double sigma = 0.3;
};

class OrenNayar final : public Brdf {
 public:
  explicit OrenNayar(const OrenNayarParams& params);
  std::string name() const override { return "oren-nayar"; }
  std::string description() const override;
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override;
  double a() const { return a_; }
  double b() const { return b_; }

 private:
  OrenNayarParams params_;
  double a_, b_;
};

// The registry entries "disney" and "oren-nayar".
void register_artist_models(ModelRegistry& registry);

}  // namespace halfback::models
