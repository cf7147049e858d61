// The Python module `halfback._core`: NumPy front end of the batch conversion engine.
//
// Arrays are passed to the engine as strided columns pointing into NumPy's own buffer (any
// strides, no copy); the GIL is released while the engine runs on all threads.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <string>
#include <vector>

#include "halfback/core/batch.hpp"

namespace py = pybind11;
using namespace halfback;

namespace {

Space parse_space(const std::string& name, const char* argument) {
  const auto s = space_from_name(name);
  if (!s)
    throw py::value_error(std::string(argument) + ": unknown parameterization '" + name +
                          "' (expected one of: " + space_names() + ")");
  return *s;
}

Form parse_form(const std::string& name, bool isotropic, const char* argument) {
  const Space s = parse_space(name, argument);
  return {s, isotropic && s != Space::dirs};
}

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// Checks that `x` is a 2-D float32/float64 array with `dim` columns.
void check_input(const py::array& x, Form form) {
  const std::size_t dim = dimension(form);
  const std::string what =
      std::string(name_of(form.space)) + (form.isotropic ? " (isotropic)" : "");
  if (x.ndim() != 2 || static_cast<std::size_t>(x.shape(1)) != dim)
    throw py::value_error("x must have shape (N, " + std::to_string(dim) + ") for " + what +
                          ", got " + shape_text(x));
}

template <class T>
std::vector<ConstColumn<T>> columns_of(const py::array_t<T>& x) {
  std::vector<ConstColumn<T>> cols;
  const auto row = x.strides(0) / py::ssize_t(sizeof(T));
  const auto col = x.strides(1) / py::ssize_t(sizeof(T));
  for (py::ssize_t c = 0; c < x.shape(1); ++c) cols.push_back({x.data() + c * col, row});
  return cols;
}

struct Outputs {
  py::object result, valid, jacobian;
};

template <class T>
Outputs run(const py::array& x_any, Form from, Form to, bool want_result, bool want_jacobian) {
  // A view when x is already an aligned array of T with element-multiple strides; else one copy.
  const auto x = py::array_t<T>::ensure(x_any);
  if (!x) throw py::type_error("x must be convertible to a floating-point array");
  if (x.strides(0) % py::ssize_t(sizeof(T)) != 0 || x.strides(1) % py::ssize_t(sizeof(T)) != 0)
    throw py::value_error("x has strides that are not a multiple of its item size");
  const auto n = static_cast<std::size_t>(x.shape(0));
  const auto dim_out = static_cast<py::ssize_t>(dimension(to));
  py::array_t<T> result({static_cast<py::ssize_t>(n), want_result ? dim_out : py::ssize_t(0)});
  py::array_t<bool> valid(static_cast<py::ssize_t>(n));
  py::array_t<T> jacobian(want_jacobian ? static_cast<py::ssize_t>(n) : py::ssize_t(0));
  // When only the mask or J is wanted, the engine still needs somewhere to put the tuples.
  std::vector<T> scratch(want_result ? 0 : n * std::size_t(dim_out));

  const auto in = columns_of(x);
  std::vector<Column<T>> out;
  for (py::ssize_t c = 0; c < dim_out; ++c) {
    if (want_result)
      out.push_back({result.mutable_data() + c, dim_out});
    else
      out.push_back({scratch.data() + c, dim_out});
  }
  ConvertOutput<T> o{out};
  static_assert(sizeof(bool) == sizeof(std::uint8_t));
  o.valid = reinterpret_cast<std::uint8_t*>(valid.mutable_data());
  if (want_jacobian) o.jacobian = {jacobian.mutable_data(), 1};
  {
    py::gil_scoped_release release;
    convert<T>(from, to, in, n, o);
  }
  return {want_result ? py::object(result) : py::none(), valid,
          want_jacobian ? py::object(jacobian) : py::none()};
}

Outputs dispatch(const py::object& obj, Form from, Form to, bool want_result, bool want_jacobian) {
  // Anything np.asarray accepts (lists, array-likes); arrays pass through untouched.
  const py::array x = py::module_::import("numpy").attr("asarray")(obj);
  check_input(x, from);
  if (x.dtype().is(py::dtype::of<float>()))
    return run<float>(x, from, to, want_result, want_jacobian);
  if (x.dtype().kind() == 'f' || x.dtype().kind() == 'i' || x.dtype().kind() == 'u')
    return run<double>(x, from, to, want_result, want_jacobian);
  throw py::type_error("x must be a float32 or float64 array (got dtype " +
                       std::string(py::str(x.dtype())) + ")");
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "halfback: exact, fast changes of variables between BRDF parameterizations";

  m.def(
      "convert",
      [](const py::object& x, const std::string& src, const std::string& dst, bool isotropic) {
        const Form from = parse_form(src, isotropic, "src"), to = parse_form(dst, isotropic, "dst");
        return dispatch(x, from, to, true, false).result;
      },
      py::arg("x"), py::arg("src"), py::arg("dst"), py::arg("isotropic") = false,
      R"doc(Converts N tuples from one parameterization to another.

x: array of shape (N, 6) for "dirs" (wi_x, wi_y, wi_z, wo_x, wo_y, wo_z) or (N, 4) / (N, 3) for a
parameterization ("spherical", "halfdiff", "ortho", "hybrid"), columns in the CLI's order.
isotropic: use the 3-coordinate isotropic form of every parameterization side.
Returns an array of the same dtype (float32 stays float32, anything else becomes float64); rows
whose input is invalid (not unit, below the horizon, outside the domain, NaN) are NaN.)doc");

  m.def(
      "valid",
      [](const py::object& x, const std::string& param, bool isotropic) {
        const Form form = parse_form(param, isotropic, "param");
        const Form other = form.space == Space::dirs ? Form{Space::hybrid} : Form{Space::dirs};
        return dispatch(x, form, other, false, false).valid;
      },
      py::arg("x"), py::arg("param"), py::arg("isotropic") = false,
      R"doc(Boolean mask of the rows of x that are valid in `param`: inside the parameterization's
domain, or unit directions above the horizon for "dirs".)doc");

  m.def(
      "jacobian",
      [](const py::object& x, const std::string& param, bool isotropic) {
        const Form form = parse_form(param, isotropic, "param");
        if (form.space == Space::dirs)
          throw py::value_error("param: the Jacobian is defined for a parameterization, not dirs");
        return dispatch(x, form, Form{Space::dirs}, false, true).jacobian;
      },
      py::arg("x"), py::arg("param"), py::arg("isotropic") = false,
      R"doc(J with d(wi) d(wo) = J d(params) at each row of x (NaN where invalid). For isotropic
forms, the measure of the 3 coordinates: 2*pi times the 4D J of the canonical pose.)doc");

  m.def(
      "columns",
      [](const std::string& name, bool isotropic) {
        const Form form = parse_form(name, isotropic, "name");
        std::vector<std::string> cols;
        for (auto c : column_names(form)) cols.emplace_back(c);
        return cols;
      },
      py::arg("name"), py::arg("isotropic") = false, "Column names of a form, in order.");
}
