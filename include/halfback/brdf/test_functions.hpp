// The scalar test functions of Barla, Belcour and Pacanowski 2015 (their Figure 2), as grey BRDFs.
//
// Each is a simple function of the pair chosen to stand for one feature of real BRDFs:
//   F, Fresnel-like:  F = 1 − cos θd = 1 − ‖h‖      (grows with the difference angle)
//   S, specular-like: S = 1 − ‖h̄‖ = 1 − sin θh cos θd (peaks at the mirror configuration, h̄ = 0)
//   G, grazing-like:  G = 1 − (ωi·n)(ωo·n)          (grows as either direction grazes)
// with h = (ωi + ωo)/2 unnormalized (docs/math.md). All three lie in [0, 1] on the closed upper
// hemisphere, are isotropic and reciprocal, and (like every Brdf) give 0 when a direction is
// below the horizon. They are not physical BRDFs: their values are unitless, and the figures draw
// them only as isolines at 0.1 … 0.9.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "halfback/brdf/brdf.hpp"

namespace halfback {

enum class TestFunction { fresnel, specular, grazing };

// The value of a test function for a pair in the upper hemisphere (no horizon check).
double test_function_value(TestFunction f, const DirPair<double>& pair);

// "F", "S", "G" (the paper's letters) and the names "fresnel", "specular", "grazing"; case
// sensitive for the letters, lower case for the names.
std::optional<TestFunction> test_function_from_name(std::string_view name);
std::string_view letter_of(TestFunction f);  // "F", "S", "G"
std::string_view name_of(TestFunction f);    // "fresnel", "specular", "grazing"

// A test function as a Brdf: eval() returns the value in all three channels.
class TestFunctionBrdf final : public Brdf {
 public:
  explicit TestFunctionBrdf(TestFunction f) : f_(f) {}
  std::string name() const override;  // "test:F", "test:S", "test:G"
  std::string description() const override;
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& pair) const override;
  TestFunction function() const { return f_; }

 private:
  TestFunction f_;
};

}  // namespace halfback
