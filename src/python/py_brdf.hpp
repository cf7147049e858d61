// The Python module's Brdf: a loaded BRDF and the spec it was loaded from (module.cpp), shared by
// the binding files (fit_bindings.cpp, ...).
#pragma once

#include <pybind11/pybind11.h>

#include <string>

#include "halfback/brdf/brdf.hpp"

namespace halfback::python {

// A BRDF and the spec it was loaded from (a file as an absolute path): what pickling sends and
// what two Brdf objects compare by (load(x) == load(x)). The C++ object is immutable and shared.
struct PyBrdf {
  BrdfPtr brdf;
  std::string spec;
};

// load_brdf(spec), keeping a file's spec as its absolute path.
PyBrdf load_py_brdf(const std::string& spec);

// A BRDF argument: a spec, as for load(), or a Brdf.
BrdfPtr brdf_of(const pybind11::object& brdf);

// The BRDF register_brdf registered as spec "python:NAME"; nullptr for a spec of another kind,
// ValueError for a name not registered (view_bindings.cpp).
BrdfPtr registered_python_brdf(const std::string& spec);

void bind_fit(pybind11::module_& m);    // fit_bindings.cpp
void bind_view(pybind11::module_& m);   // view_bindings.cpp
void bind_study(pybind11::module_& m);  // study_bindings.cpp (and the SSIM)
void bind_nbrdf(pybind11::module_& m);  // nbrdf_bindings.cpp

}  // namespace halfback::python
