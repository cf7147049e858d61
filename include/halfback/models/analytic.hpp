// Analytic BRDF models, for testing, comparison and figures. Formulas and their sources:
// docs/models.md. All return ρ in sr⁻¹ without the cosine factor, and 0 below the horizon.
// Constructors validate their parameters and throw std::invalid_argument naming the bad one.
//
// Every model also samples itself (Brdf::sample and Brdf::pdf; docs/render.md): Lambert and
// sheen by the cosine, GGX by its visible normals (Heitz 2018), Beckmann by D(m) cos θm, ABC by its
// lobe in the projected disk plus the cosine for kd, and Sum by a mixture of its terms' samplers
// weighted by their directional albedos at θo. The sampling code is in src/models/sampling.cpp.
#pragma once

#include <memory>
#include <mutex>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/models/fresnel.hpp"

namespace halfback::models {

namespace detail {
class MixtureWeights;  // lobe weights as a function of cos θo (src/models/sampling_detail.hpp)
struct MixtureWeightsDeleter {
  void operator()(MixtureWeights* p) const;
};
using MixtureWeightsPtr = std::unique_ptr<MixtureWeights, MixtureWeightsDeleter>;
}  // namespace detail

// ρ = albedo / π.
class Lambert final : public Brdf {
 public:
  explicit Lambert(Rgb albedo);
  std::string name() const override { return "lambert"; }
  std::string description() const override;
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override;
  BrdfSample sample(const Vec3<double>& wo, double u1, double u2) const override;
  double pdf(const Vec3<double>& wo, const Vec3<double>& wi) const override;
  bool has_importance_sampling() const override { return true; }

 private:
  Rgb albedo_;
};

// Microfacet reflection (Cook–Torrance form with Walter et al. 2007 / Heitz 2014 conventions):
// ρ = F(ωi·m) D(m) G2(ωi, ωo) / (4 cos θi cos θo), m = ĥ, with the anisotropic GGX or Beckmann
// distribution and the height-correlated Smith masking-shadowing G2 = 1 / (1 + Λ(ωi) + Λ(ωo)).
struct MicrofacetParams {
  enum class Distribution { ggx, beckmann };
  Distribution distribution = Distribution::ggx;
  double alpha_x = 0.2, alpha_y = 0.2;  // roughness along t and b
  Fresnel fresnel;
};

class Microfacet final : public Brdf {
 public:
  explicit Microfacet(const MicrofacetParams& params);
  std::string name() const override;
  std::string description() const override;
  bool isotropic() const override { return params_.alpha_x == params_.alpha_y; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override;
  // One thread, no call through std::function for the renderer's batches (≤ 4096 pairs).
  void eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const override;
  BrdfSample sample(const Vec3<double>& wo, double u1, double u2) const override;
  // GGX: the visible normals of a batch in SIMD lanes, equal to sample() bit for bit.
  void sample_batch(std::span<const Vec3<double>> wo, std::span<const double> u1,
                    std::span<const double> u2, std::span<BrdfSample> out) const override;
  double pdf(const Vec3<double>& wo, const Vec3<double>& wi) const override;
  // pdf() of each pair without a virtual call per pair, equal to it bit for bit.
  void pdf_batch(std::span<const DirPair<double>> pairs, std::span<double> out) const override;
  bool has_importance_sampling() const override { return true; }

  // The distribution of normals D(m) (∫ D(m) (m·n) dm = 1) and Smith's Λ(ω).
  double distribution(const Vec3<double>& m) const;
  double lambda(const Vec3<double>& w) const;
  const MicrofacetParams& params() const { return params_; }

 private:
  MicrofacetParams params_;
  double inv_ax2_, inv_ay2_, inv_pi_axay_;          // 1/αx², 1/αy², 1/(π αx αy)
  Rgb eval_ggx(const DirPair<double>& pair) const;  // both directions above the horizon
  BrdfSample sample_ggx(const Vec3<double>& wo, double u1, double u2) const;
};

// The ABC model in the orthographic form of Löw et al. 2012: ρ = kd/π + F(θd) S(f) with the
// K-correlation spectrum S(f) = A / (1 + B f²)^((C+1)/2) of the distance f = ‖β − β0‖ = 2‖h̄‖
// between the projected view direction and the projected mirror direction.
struct AbcParams {
  double a = 1.0, b = 400.0, c = 1.5;
  double eta = 1.5;  // dielectric Fresnel at θd
  Rgb kd{0, 0, 0};
};

class Abc final : public Brdf {
 public:
  explicit Abc(const AbcParams& params);
  std::string name() const override { return "abc"; }
  std::string description() const override;
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override;
  BrdfSample sample(const Vec3<double>& wo, double u1, double u2) const override;
  double pdf(const Vec3<double>& wo, const Vec3<double>& wi) const override;
  bool has_importance_sampling() const override { return true; }

 private:
  AbcParams params_;
  // Sampling: the weights of the specular lobe and of kd, computed on first use.
  const detail::MixtureWeights& mixture() const;
  mutable std::once_flag mixture_once_;
  mutable detail::MixtureWeightsPtr mixture_;
};

// A sheen lobe for cloth-like grazing retro-reflection: the "Charlie" distribution of Estevez
// and Kulla 2017, D(m) = (2 + 1/α) sin(θm)^(1/α) / (2π), with the Ashikhmin–Premoze visibility
// V = 1 / (4 (cos θi + cos θo − cos θi cos θo)); ρ = color · D(ĥ) · V.
struct SheenParams {
  Rgb color{1, 1, 1};
  double alpha = 0.3;
};

class Sheen final : public Brdf {
 public:
  explicit Sheen(const SheenParams& params);
  std::string name() const override { return "sheen"; }
  std::string description() const override;
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override;
  BrdfSample sample(const Vec3<double>& wo, double u1, double u2) const override;
  double pdf(const Vec3<double>& wo, const Vec3<double>& wi) const override;
  bool has_importance_sampling() const override { return true; }

 private:
  SheenParams params_;
};

// The sum of several BRDFs (e.g. a diffuse base with a sheen or a glossy layer on top).
class Sum final : public Brdf {
 public:
  explicit Sum(std::vector<BrdfPtr> terms);
  std::string name() const override;
  std::string description() const override;
  bool isotropic() const override;
  bool reciprocal() const override;
  Rgb eval(const DirPair<double>& pair) const override;
  BrdfSample sample(const Vec3<double>& wo, double u1, double u2) const override;
  double pdf(const Vec3<double>& wo, const Vec3<double>& wi) const override;
  bool has_importance_sampling() const override { return true; }

 private:
  std::vector<BrdfPtr> terms_;
  // Sampling: the terms' weights (their albedos at θo), computed on first use.
  const detail::MixtureWeights& mixture() const;
  mutable std::once_flag mixture_once_;
  mutable detail::MixtureWeightsPtr mixture_;
};

}  // namespace halfback::models
