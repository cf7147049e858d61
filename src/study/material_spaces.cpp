#include "material_spaces.hpp"

#include <map>
#include <mutex>
#include <utility>

#include "halfback/formats/adaptive_param.hpp"

namespace halfback::study {

namespace {

// A constant ρ: the BRDF whose recovered NDF is the warp of a BRDF that has none to recover.
class ConstantBrdf final : public Brdf {
 public:
  std::string name() const override { return "constant"; }
  std::string description() const override { return "a constant BRDF"; }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>&) const override { return Rgb{1.0, 1.0, 1.0}; }
};

// The warp of `brdf`'s NDF, or, when it has none to recover (a retro-reflection that is zero or
// not finite somewhere, as an ALTA file's few incidences give), of a constant BRDF's: every BRDF
// gets a row.
std::shared_ptr<const ParamDescriptor> own_warp(const Brdf& brdf, const std::string& name) {
  RglWarpOptions o;
  o.vndf_resolution = 64;
  o.allow_anisotropic = true;  // the NDF along φ = 0
  try {
    return adaptive_parameterization(brdf, name, o);
  } catch (const std::invalid_argument&) {
    return adaptive_parameterization(ConstantBrdf(), name + " [constant NDF]", o);
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
