// Colour parameters of registry entries: a grey value plus per-channel overrides that default to
// it, because registry parameters are scalars. Every channel has the grey value's range.
#pragma once

#include <string>
#include <vector>

#include "halfback/brdf/registry.hpp"

namespace halfback::models::detail {

inline std::vector<ModelParam> colour_params(const std::string& name, const std::string& what,
                                             double default_value, double max) {
  return {{name, what + " (grey)", default_value, 0, max},
          defaults_to(name + "_r", what + ", red channel", name, 0, max),
          defaults_to(name + "_g", what + ", green channel", name, 0, max),
          defaults_to(name + "_b", what + ", blue channel", name, 0, max)};
}

inline Rgb colour(const ModelArgs& a, const std::string& name) {
  return {a[name + "_r"], a[name + "_g"], a[name + "_b"]};
}

}  // namespace halfback::models::detail
