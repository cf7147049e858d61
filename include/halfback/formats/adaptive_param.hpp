// Dupuy & Jakob 2018's per-material parameterization ("An Adaptive Parameterization for Efficient
// Material Acquisition and Representation"), as a parameterization with a parameter: the BRDF
// whose visible normals warp the half vector. Coordinates (θi, φi, s1, s2): ωi's angles, and
// s = W⁻¹(u | θi), where u = (√(2θm/π), (φm − φi + π)/2π) are the half vector's angles on the unit
// square and W is the VNDF warp at ωi of the BRDF's recovered NDF (rgl_warp_material). The map is
// what an RGL file's tables are laid out in; docs/math-more-parameterizations.md §6 derives it,
// its inverse and its Jacobian, J = sin θi · 8π² u1 sin θm (ωi·ĥ) / p_u(u).
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "halfback/brdf/brdf.hpp"
#include "halfback/core/param_descriptor.hpp"
#include "halfback/formats/rgl_writer.hpp"

namespace halfback {

// The parameterization warped by `brdf`'s NDF, named `name` (the loader's family names it
// "dupuy-jakob:SPEC"). Its maps run in double precision on any thread. Throws as
// rgl_warp_material.
std::shared_ptr<const ParamDescriptor> adaptive_parameterization(
    const Brdf& brdf, std::string name, const RglWarpOptions& options = {});

// "dupuy-jakob:per-material": the study's name for each BRDF's own warp. Its descriptor has the
// names and axes of every member, and maps that throw std::logic_error: the study replaces it by
// the member of the BRDF at hand (study/material_spaces.hpp); anywhere else it is refused.
inline constexpr std::string_view kPerMaterialWarp = "dupuy-jakob:per-material";
std::shared_ptr<const ParamDescriptor> per_material_placeholder();
bool is_per_material_placeholder(const ParamDescriptor& param);

}  // namespace halfback
