// The BRDF interface: ρ(ωi, ωo) in sr⁻¹, RGB, without the cosine factor.
//
// Directions follow the core conventions (halfback/core/param.hpp): ωi is the incoming (light)
// direction, ωo the outgoing (view) direction, unit vectors in the frame n = +z, t = +x, b = +y.
// Analytic models, the paper's test functions and measured data (MERL, RGL, ALTA) all implement it.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "halfback/brdf/sampling.hpp"
#include "halfback/core/param.hpp"
#include "halfback/core/rgb.hpp"
#include "halfback/core/space.hpp"

namespace halfback {

class Brdf {
 public:
  virtual ~Brdf() = default;

  // Short identifier, e.g. "ggx" or "merl:gold-metallic-paint"; and one line for humans.
  virtual std::string name() const = 0;
  virtual std::string description() const = 0;

  // Whether ρ is invariant under rotations about n, and under ωi <-> ωo.
  virtual bool isotropic() const = 0;
  virtual bool reciprocal() const = 0;

  // ρ(ωi, ωo). A pair with a direction below the horizon (z < 0) gives 0.
  virtual Rgb eval(const DirPair<double>& pair) const = 0;

  // What a user inspecting the data wants to know beyond name() and description() (`halfback
  // info`): format, dimensions, unmeasured bins, identity... as (label, value) lines. Empty for
  // analytic models, which their spec describes.
  struct Fact {
    std::string label, value;
  };
  virtual std::vector<Fact> facts() const { return {}; }

  // Batch evaluation (out.size() == pairs.size()). The default runs eval() over all threads;
  // formats with a faster batched path override it.
  virtual void eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const;

  // Importance sampling, the one sampling interface of halfback (sampling.hpp): ωi drawn given ωo
  // (unit, ωo.z > 0) from two numbers u1, u2 in [0, 1), with a density p(ωi | ωo) per unit solid
  // angle meant to resemble ρ(ωi, ωo) cos θi. The density may put mass below the horizon (a
  // microfacet reflection can leave the hemisphere): such a sample comes back with pdf 0, so pdf()
  // integrates to at most 1 over the upper hemisphere. pdf() is the density of sample() at ωi (0
  // for ωi or ωo below the horizon). The defaults sample the cosine-weighted hemisphere; a BRDF
  // that follows its own lobes overrides all three.
  virtual BrdfSample sample(const Vec3<double>& wo, double u1, double u2) const;
  virtual double pdf(const Vec3<double>& wo, const Vec3<double>& wi) const;
  // sample() of a batch: out[i] = sample(wo[i], u1[i], u2[i]), the same numbers (all four spans
  // the same size, else std::invalid_argument). A model whose sampling vectorizes overrides it.
  virtual void sample_batch(std::span<const Vec3<double>> wo, std::span<const double> u1,
                            std::span<const double> u2, std::span<BrdfSample> out) const;
  // pdf() of a batch: out[i] = pdf(pairs[i].wo, pairs[i].wi), the same numbers up to rounding
  // (out.size() == pairs.size(), else std::invalid_argument). The default calls pdf() one at a
  // time; a model whose pdf vectorizes overrides it (the renderer's MIS weights use it).
  virtual void pdf_batch(std::span<const DirPair<double>> pairs, std::span<double> out) const;
  // Whether sample() follows ρ (true) or is the cosine default (false; the renderer then
  // tabulates ρ to sample it, render/brdf_sampler.hpp).
  virtual bool has_importance_sampling() const { return false; }
  // Which sampler sample() is, for reports: "cosine-weighted hemisphere", "own sampler of NAME"...
  virtual std::string describe_sampling() const;
};

using BrdfPtr = std::shared_ptr<const Brdf>;

// ρ at the coordinates `coords` of any form (dimension(form) values): the pair is reconstructed
// with the core's checked inverse (convert_one), so coordinates outside the parameterization's
// domain, or a dirs row that check_pair() rejects, give NaN in all three channels. Throws
// std::invalid_argument when coords.size() != dimension(form). Isotropic coordinates stand for
// their canonical pose (param.hpp), which is what an anisotropic ρ is evaluated at.
Rgb eval_at(const Brdf& brdf, Form form, std::span<const double> coords);

}  // namespace halfback
