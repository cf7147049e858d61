// The JSON of a fit (docs/fit.md, "Output"): what `halfback fit` writes to its file and what the
// view's /api/fit answers, one writer for both.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "halfback/fit/fit.hpp"

namespace halfback::fit {

// The unit of a fitted parameter, where it has one; "1" (dimensionless) otherwise.
std::string_view fit_parameter_unit(std::string_view model, std::string_view param);

// The fit as one JSON object (keys in this order): the target spec and model asked for, the
// fitted spec, the loss, the sample layout, the parameters by term (value, unit, fitted or held,
// range), each term's albedo share and whether it is a dead lobe, starts, iterations, seconds.
// Its strings are well-formed UTF-8 (the specs asked for through valid_utf8), so that dump()
// cannot throw.
nlohmann::ordered_json fit_json(const FitResult& r, std::string_view brdf, std::string_view model,
                                const FitEnergy& energy);

}  // namespace halfback::fit
