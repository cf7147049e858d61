#include "halfback/brdf/test_functions.hpp"

#include <cmath>

namespace halfback {

double test_function_value(TestFunction f, const DirPair<double>& p) {
  const double hx = 0.5 * (p.wi.x + p.wo.x), hy = 0.5 * (p.wi.y + p.wo.y),
               hz = 0.5 * (p.wi.z + p.wo.z);
  switch (f) {
    case TestFunction::fresnel:  // cos θd = ‖h‖ (docs/math.md §1)
      return 1.0 - std::sqrt(hx * hx + hy * hy + hz * hz);
    case TestFunction::specular:
      return 1.0 - std::hypot(hx, hy);
    case TestFunction::grazing:
      break;
  }
  return 1.0 - p.wi.z * p.wo.z;
}

std::optional<TestFunction> test_function_from_name(std::string_view name) {
  if (name == "F" || name == "fresnel") return TestFunction::fresnel;
  if (name == "S" || name == "specular") return TestFunction::specular;
  if (name == "G" || name == "grazing") return TestFunction::grazing;
  return std::nullopt;
}

std::string_view letter_of(TestFunction f) {
  switch (f) {
    case TestFunction::fresnel:
      return "F";
    case TestFunction::specular:
      return "S";
    case TestFunction::grazing:
      break;
  }
  return "G";
}

std::string_view name_of(TestFunction f) {
  switch (f) {
    case TestFunction::fresnel:
      return "fresnel";
    case TestFunction::specular:
      return "specular";
    case TestFunction::grazing:
      break;
  }
  return "grazing";
}

std::string TestFunctionBrdf::name() const {
  return "test:" + std::string(letter_of(f_));
}

std::string TestFunctionBrdf::description() const {
  switch (f_) {
    case TestFunction::fresnel:
      return "Fresnel-like test function F = 1 - cos(theta_d) (Barla et al. 2015)";
    case TestFunction::specular:
      return "specular test function S = 1 - |h_bar| (Barla et al. 2015)";
    case TestFunction::grazing:
      break;
  }
  return "grazing test function G = 1 - (wi.n)(wo.n) (Barla et al. 2015)";
}

Rgb TestFunctionBrdf::eval(const DirPair<double>& pair) const {
  if (!(pair.wi.z >= 0.0) || !(pair.wo.z >= 0.0)) return {0, 0, 0};
  const double v = test_function_value(f_, pair);
  return {v, v, v};
}

}  // namespace halfback
