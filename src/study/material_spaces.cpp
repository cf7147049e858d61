#include "material_spaces.hpp"

#include <map>
#include <mutex>
#include <utility>

#include "halfback/formats/adaptive_param.hpp"
#include "halfback/models/analytic.hpp"

namespace halfback::study {

namespace {

// The warp of `brdf`'s NDF, or, when it has none to recover (a retro-reflection that is zero or
// not finite somewhere, as an ALTA file's few incidences give), of a Lambertian surface's: every
// BRDF gets a row.
std::shared_ptr<const ParamDescriptor> own_warp(const Brdf& brdf, const std::string& name) {
  RglWarpOptions o;
  o.vndf_resolution = 64;
  o.allow_anisotropic = true;  // the NDF along φ = 0
  try {
    return adaptive_parameterization(brdf, name, o);
  } catch (const std::invalid_argument&) {
    return adaptive_parameterization(models::Lambert(Rgb{1, 1, 1}), name + " [Lambertian warp]", o);
  }
}

}  // namespace

std::vector<Space> material_spaces(const Brdf& brdf, const std::string& label,
                                   std::span<const Space> params) {
  static std::mutex mutex;
  static std::map<std::pair<std::string, std::string>, Space> built;
  std::vector<Space> spaces(params.begin(), params.end());
  for (Space& s : spaces) {
    if (!is_per_material_placeholder(s.param())) continue;
    std::lock_guard lock(mutex);
    const auto key = std::pair{label, brdf.name()};
    auto it = built.find(key);
    if (it == built.end())
      it = built
               .emplace(key, register_parameterization(
                                 own_warp(brdf, "dupuy-jakob:" + brdf.name() + " (" + label + ")")))
               .first;
    s = it->second;
  }
  return spaces;
}

}  // namespace halfback::study
