// The JSON of a fit (docs/fit.md, "Output"): what `halfback fit` writes to its file and what the
// view's /api/fit answers, one writer for both.
#pragma once

#include <string>
#include <string_view>

#include "halfback/fit/fit.hpp"
#include "json.hpp"

namespace halfback::view {

// The unit of a fitted parameter, where it has one; "1" (dimensionless) otherwise.
std::string_view fit_parameter_unit(std::string_view model, std::string_view param);

// The fit as one JSON object: the target spec and model asked for, the fitted spec, the loss, the
// sample layout, the parameters by term (value, unit, fitted or held, range), starts, iterations,
// seconds.
void write_fit(JsonWriter& j, const fit::FitResult& r, std::string_view brdf,
               std::string_view model);

}  // namespace halfback::view
