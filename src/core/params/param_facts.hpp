// What the generic property tests of the parameterizations (core/param_test.cpp) need to know of
// each one: stated beside it, in params/NAME_test.cpp, and registered there by name. A built-in
// parameterization without its facts fails those tests.
#pragma once

#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <string_view>

#include "halfback/core/param.hpp"

namespace halfback::test {

struct ParamFacts {
  // The conditioning of the inverse map at a pair (docs/math.md, "Accuracy"): the round-trip error
  // is bounded by C·ε / max(cond, √ε).
  double (*condition)(const DirPair<double>&) = nullptr;
  // Its domain by an independent reference: textbook inverse formulas in long double, "the
  // inverse gives z >= 0 for both directions" (plus the coordinate ranges).
  bool (*reference_valid)(const Tuple4<long double>&) = nullptr;
  // Pairs on which the map is not a bijection (its degenerate faces): left out of the round trips.
  bool (*degenerate)(const DirPair<double>&) = [](const DirPair<double>&) { return false; };
  // The round trip's error keeps growing like ε / cond below cond = √ε (the map neither clamps nor
  // changes form there), instead of stopping at ε / √ε.
  bool error_grows_below_sqrt_eps = false;
  // The canonical pose's conditioning multiplies the map's (the pose turns a pair known to
  // ε / cond), instead of the smaller of the two bounding the error.
  bool pose_conditioning_multiplies = false;
  // In float, the round trip is within 1e-5 wherever both z >= 0.01; else only where cond >= 0.05
  // (ortho and hybrid store ‖h̄‖, ‖k̄‖ / ‖k‖ with 6e-8 relative rounding, which alone moves z by
  // ~ε/z).
  bool float_accurate_wherever_z_above_001 = false;
  // The first isotropic coordinate's change under a rotation about n, on well-conditioned pairs.
  double iso_rotation_tolerance = 1e-12;
};

// The facts registered, by parameterization name.
inline std::map<std::string, ParamFacts, std::less<>>& param_facts_registry() {
  static std::map<std::string, ParamFacts, std::less<>> registry;
  return registry;
}

// A static object of a parameterization's test file registers its facts.
struct RegisterParamFacts {
  RegisterParamFacts(std::string_view name, const ParamFacts& facts) {
    param_facts_registry().emplace(std::string(name), facts);
  }
};

// The facts of the parameterization `name`; nullptr where none were registered.
inline const ParamFacts* find_param_facts(std::string_view name) {
  const auto& registry = param_facts_registry();
  const auto it = registry.find(name);
  return it == registry.end() ? nullptr : &it->second;
}

// Azimuths are periodic: any finite value is one (the maps reduce it to [0, 2π)).
inline bool reference_azimuths_ok(const Tuple4<long double>& q) {
  return std::isfinite(q[1]) && std::isfinite(q[3]);
}

}  // namespace halfback::test
