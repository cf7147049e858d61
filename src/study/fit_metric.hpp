// Metric 6 of the study (issue 37; docs/study.md, "Fitting from measurements"): a model fitted to
// the measurements of each design of the isotropic gonio-reflectometer, against the same model
// fitted to the whole BRDF.
#pragma once

#include <functional>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "halfback/fit/fit.hpp"
#include "halfback/study/study.hpp"

namespace halfback::study {

// config.fit_model fitted under config.fit_loss to the whole BRDF on fit()'s layout of
// config.fit_samples pairs: the reference of metric 6 and the fitted-mixture sampler of metric 5.
// Nullopt for an anisotropic BRDF, an empty config.fit_model, or a BRDF the fit cannot use (not
// finite or negative where sampled: `say` tells why).
std::optional<fit::FitResult> whole_fit(const Brdf& brdf, const StudyConfig& config,
                                        const std::function<void(std::string)>& say);

// The rows of config.params (whose work is done in `work`: material_spaces), for each design
// (regular, stratified; own spacing) and each of config.fit_budgets, against `whole` (whole_fit()).
// Nothing without a whole fit or budgets.
std::vector<std::pair<Space, FitPoint>> fit_metric(const Brdf& brdf, const StudyConfig& config,
                                                   std::span<const Space> work,
                                                   const std::optional<fit::FitResult>& whole);

}  // namespace halfback::study
