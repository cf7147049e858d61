// A fixture of the layer check (docs/architecture.md): brdf reaching up into figure.
#pragma once

#include "halfback/figure/scene.hpp"
