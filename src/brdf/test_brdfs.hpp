// BRDFs for the tests of the BRDF layer (not part of the library).
#pragma once

#include <atomic>
#include <string>

#include "halfback/brdf/brdf.hpp"

namespace halfback::test {

// Smooth, anisotropic and non-reciprocal: a resampling or an evaluation that mixes up
// coordinates, directions or channels shows. Counts its calls.
class Smooth final : public Brdf {
 public:
  std::string name() const override { return "smooth"; }
  std::string description() const override { return "smooth test function"; }
  bool isotropic() const override { return false; }
  bool reciprocal() const override { return false; }
  Rgb eval(const DirPair<double>& p) const override {
    ++calls;
    if (p.wi.z < 0 || p.wo.z < 0) return {};
    return {1 + p.wi.x + 0.5 * p.wo.y, 2 + p.wi.z * p.wo.z, 0.5 + 0.1 * p.wo.x - 0.2 * p.wi.y};
  }
  using Brdf::eval;
  mutable std::atomic<long> calls{0};
};

}  // namespace halfback::test
