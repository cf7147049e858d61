// Parameterizations written in Python: the class halfback.Parameterization and
// halfback.register_parameterization (user_param.cpp).
#pragma once

#include <pybind11/pybind11.h>

namespace halfback::python {

void bind_user_parameterizations(pybind11::module_& m);

}  // namespace halfback::python
