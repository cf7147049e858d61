// What the gonio metric (gonio_metric.cpp) leaves for the image metric (image_metric.cpp): each
// parameterization's reconstructions at the image budget, own spacing, one per layout, under
// BrdfStudy::per_param[k][kImageReconstructions] (absent: none).
#pragma once

#include <memory>
#include <vector>

#include "halfback/acquire/gonio.hpp"

namespace halfback::study {

using GonioReconstructions = std::vector<std::unique_ptr<acquire::GonioReconstruction>>;
inline constexpr const char* kImageReconstructions = "image_reconstructions";

}  // namespace halfback::study
