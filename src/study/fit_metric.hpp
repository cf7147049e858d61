// Metric 6 of the study (issue 37; docs/study.md, "Fitting from measurements"): a model fitted to
// the measurements of each design of the isotropic gonio-reflectometer, against the same model
// fitted to the whole BRDF.
#pragma once

#include <functional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "halfback/study/study.hpp"

namespace halfback::study {

// The rows of config.params (whose work is done in `work`: material_spaces), for each design
// (regular, stratified; own spacing) and each of config.fit_budgets. Nothing for an anisotropic
// BRDF, an empty config.fit_model, or a BRDF the fit cannot use (not finite or negative where
// sampled: `say` tells why).
std::vector<std::pair<Space, FitPoint>> fit_metric(const Brdf& brdf, const StudyConfig& config,
                                                   std::span<const Space> work,
                                                   const std::function<void(std::string)>& say);

}  // namespace halfback::study
