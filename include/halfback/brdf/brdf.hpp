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

#include "halfback/core/param.hpp"
#include "halfback/core/space.hpp"

namespace halfback {

struct Rgb {
  double r = 0, g = 0, b = 0;
  friend bool operator==(const Rgb&, const Rgb&) = default;
};

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
  virtual void eval(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const;
};

using BrdfPtr = std::shared_ptr<const Brdf>;

// ρ at the coordinates `coords` of any form (dimension(form) values): the pair is reconstructed
// with the core's checked inverse (convert_one), so coordinates outside the parameterization's
// domain, or a dirs row that check_pair() rejects, give NaN in all three channels. Throws
// std::invalid_argument when coords.size() != dimension(form). Isotropic coordinates stand for
// their canonical pose (param.hpp), which is what an anisotropic ρ is evaluated at.
Rgb eval_at(const Brdf& brdf, Form form, std::span<const double> coords);

}  // namespace halfback
