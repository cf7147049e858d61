// Measurement plans and reconstructions (docs/acquisition.md): halfback.plan and the
// core of halfback.reconstruct (acquisition.cpp).
#pragma once

#include <pybind11/pybind11.h>

#include <string_view>

namespace halfback::python {

void bind_acquisition(pybind11::module_& m);

// An instrument's reach given to Python in radians (every angle of the Python API is), as the
// degrees of the library's setups: a ValueError that says radians unless it is in [π/180, π/2]
// (1° to 90°), so that a reach in degrees (85) is refused rather than read as radians.
double reach_degrees(double max_theta, std::string_view argument);

}  // namespace halfback::python
