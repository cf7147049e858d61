// Registers the analytic models (lambert, ggx, beckmann, abc, sheen) in a model registry.
#pragma once

#include "halfback/brdf/registry.hpp"

namespace halfback::models {

void register_analytic_models(ModelRegistry& registry);

}  // namespace halfback::models
