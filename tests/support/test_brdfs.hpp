// BRDFs for the tests of the BRDF layer and the study (not part of the library).
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <utility>

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

// An isotropic "BRDF" from a scalar function of the pair, ρ = f · tint (a tint with unequal
// channels shows a mixed-up channel; the default's luminance is f itself).
class FunctionBrdf : public Brdf {
 public:
  explicit FunctionBrdf(std::function<double(const DirPair<double>&)> f, Rgb tint = {1, 1, 1})
      : f_(std::move(f)), tint_(tint) {}
  std::string name() const override { return "function"; }
  std::string description() const override { return "test function"; }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return false; }
  Rgb eval(const DirPair<double>& p) const override {
    const double v = f_(p);
    return {v * tint_.r, v * tint_.g, v * tint_.b};
  }
  using Brdf::eval;

 private:
  std::function<double(const DirPair<double>&)> f_;
  Rgb tint_;
};

// A BRDF with another's ρ and no sampler of its own (the cosine default), as measured data: the
// renderer tabulates it.
class Opaque final : public Brdf {
 public:
  explicit Opaque(BrdfPtr b) : b_(std::move(b)) {}
  std::string name() const override { return "opaque:" + b_->name(); }
  std::string description() const override { return b_->description(); }
  bool isotropic() const override { return b_->isotropic(); }
  bool reciprocal() const override { return b_->reciprocal(); }
  Rgb eval(const DirPair<double>& p) const override { return b_->eval(p); }
  using Brdf::eval;

 private:
  BrdfPtr b_;
};

}  // namespace halfback::test
