// The spaces a study computes in for one BRDF: config.params, with the placeholder
// "dupuy-jakob:per-material" (formats/adaptive_param.hpp) replaced by that BRDF's own warp.
// Results stay under the placeholder's name, so every BRDF's rows line up.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/core/space.hpp"

namespace halfback::study {

// `params` with each per-material placeholder replaced by the warp of `brdf`'s recovered NDF,
// registered once per BRDF (by `label` and the BRDF's name) for the process's lifetime (about
// 0.3 MB each: tables of 64 × 64 on 8 incidences); an anisotropic BRDF gets the warp of its NDF
// along φ = 0, and a BRDF with no NDF to recover (its retro-reflection zero or not finite
// somewhere) the warp of a Lambertian surface's ("[Lambertian warp]" in the member's name).
std::vector<Space> material_spaces(const Brdf& brdf, const std::string& label,
                                   std::span<const Space> params);

}  // namespace halfback::study
