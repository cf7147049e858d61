// Measurement plans and reconstructions (docs/acquisition.md): halfback.plan and the
// core of halfback.reconstruct (acquisition.cpp).
#pragma once

#include <pybind11/pybind11.h>

namespace halfback::python {

void bind_acquisition(pybind11::module_& m);

}  // namespace halfback::python
