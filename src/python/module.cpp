// The Python module `halfback._core`: NumPy front end of the batch conversion engine and of the
// BRDF layer (load, eval, resample).
//
// Arrays are passed to the engine as strided columns pointing into NumPy's own buffer (any
// strides, no copy); the GIL is released while the engine runs on all threads. C++ exceptions
// become Python ones: std::invalid_argument -> ValueError, file and format errors -> RuntimeError.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "acquisition.hpp"
#include "halfback/brdf/albedo.hpp"
#include "halfback/brdf/registry.hpp"
#include "halfback/brdf/resample.hpp"
#include "halfback/core/batch.hpp"
#include "halfback/core/simd.hpp"
#include "halfback/figure/hemisphere.hpp"
#include "halfback/formats/table_file.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/render/envmap.hpp"
#include "halfback/render/renderer.hpp"
#include "halfback/util/format_error.hpp"
#include "halfback/util/text_encoding.hpp"
#include "py_brdf.hpp"
#include "user_param.hpp"

namespace py = pybind11;
using namespace halfback;

namespace halfback::python {

PyBrdf load_py_brdf(const std::string& spec) {
  if (BrdfPtr python = registered_python_brdf(spec)) return PyBrdf{python, spec};
  std::error_code ec;
  const std::filesystem::path path(spec);
  std::string kept = spec;  // a file, absolute: a worker in another directory finds it
  if (std::filesystem::exists(path, ec)) kept = std::filesystem::absolute(path, ec).string();
  return PyBrdf{load_brdf(spec), kept};
}

BrdfPtr brdf_of(const py::object& brdf) {
  return py::isinstance<py::str>(brdf) ? load_py_brdf(brdf.cast<std::string>()).brdf
                                       : brdf.cast<const PyBrdf&>().brdf;
}

}  // namespace halfback::python

using halfback::python::load_py_brdf;
using halfback::python::PyBrdf;

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

py::dict axis_dict(const Axis& a) {
  static constexpr const char* kKinds[] = {"angle", "azimuth", "length"};
  py::dict d;
  d["column"] = std::string(a.column);
  d["label"] = std::string(a.label);
  d["kind"] = kKinds[static_cast<int>(a.kind)];
  d["unit"] = std::string(a.unit());
  d["lo"] = a.lo;
  d["hi"] = a.hi;
  return d;
}

py::list parameterization_table() {
  py::list all;
  for (Space s : parameterizations()) {
    const ParamDescriptor& p = s.param();
    py::dict d;
    d["name"] = std::string(p.name());
    d["summary"] = std::string(p.summary());
    for (const bool iso : {false, true}) {
      py::list axes;
      for (const Axis& a : p.axes(iso)) axes.append(axis_dict(a));
      d[iso ? "iso_axes" : "axes"] = axes;
    }
    all.append(d);
  }
  return all;
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

// What a call returns: the converted tuples, the validity mask, the measure.
struct Wanted {
  bool result = false, valid = false, jacobian = false;
};

// The bytes an array's elements span, [first, last).
std::pair<const char*, const char*> byte_span(const py::array& a) {
  const char* first = static_cast<const char*>(a.data());
  const char* last = first + a.itemsize();
  for (py::ssize_t k = 0; k < a.ndim(); ++k) {
    if (a.shape(k) == 0) return {first, first};
    const py::ssize_t reach = (a.shape(k) - 1) * a.strides(k);
    (reach < 0 ? first : last) += reach;
  }
  return {first, last};
}

// Whether `out` shares memory with x other than as x itself (same start, shape and strides: the
// engine then reads each row before writing it). A row of out written before a later row of x
// is read gave wrong answers (docs/reliability/python.md, "A row with a NaN or an infinity is
// answered NaN"): x is then copied first.
bool overlaps_unsafely(const py::array& x, const py::array& out) {
  const auto [a0, a1] = byte_span(x);
  const auto [b0, b1] = byte_span(out);
  if (!(a0 < b1 && b0 < a1)) return false;
  const bool same = x.data() == out.data() && x.ndim() == out.ndim() &&
                    std::equal(x.shape(), x.shape() + x.ndim(), out.shape()) &&
                    std::equal(x.strides(), x.strides() + x.ndim(), out.strides());
  return !same;
}

template <class T>
Outputs run(const py::array& x_any, Form from, Form to, Wanted want,
            const py::object& out_obj = py::none()) {
  const bool want_result = want.result, want_jacobian = want.jacobian;
  // A view when x is already an aligned array of T with element-multiple strides; else one copy.
  auto x = py::array_t<T>::ensure(x_any);
  if (!x) throw py::type_error("x must be convertible to a floating-point array");
  if (x.strides(0) % py::ssize_t(sizeof(T)) != 0 || x.strides(1) % py::ssize_t(sizeof(T)) != 0)
    throw py::value_error("x has strides that are not a multiple of its item size");
  const auto n = static_cast<std::size_t>(x.shape(0));
  const auto dim_out = static_cast<py::ssize_t>(dimension(to));
  // The result: a new array, or `out` (any strides), whose pages are already there: for large N,
  // the first touch of a fresh array costs as much as the conversion itself.
  py::array_t<T> result;
  if (!out_obj.is_none()) {
    if (!py::isinstance<py::array_t<T>>(out_obj) ||
        !py::array(out_obj).dtype().is(py::dtype::of<T>()))
      throw py::type_error(std::string("out must be a numpy array of dtype ") +
                           (sizeof(T) == 4 ? "float32" : "float64") + ", the dtype of the result");
    result = py::reinterpret_borrow<py::array_t<T>>(out_obj);
    if (result.ndim() != 2 || result.shape(0) != py::ssize_t(n) || result.shape(1) != dim_out)
      throw py::value_error("out must have shape (" + std::to_string(n) + ", " +
                            std::to_string(dim_out) + "), got " + shape_text(result));
    if (!result.writeable()) throw py::value_error("out is read-only");
    if (result.strides(0) % py::ssize_t(sizeof(T)) != 0 ||
        result.strides(1) % py::ssize_t(sizeof(T)) != 0)
      throw py::value_error("out has strides that are not a multiple of its item size");
    if (overlaps_unsafely(x, result))
      x = py::array_t<T>::ensure(py::array(x).attr("copy")());  // read from a copy
  } else {
    result = py::array_t<T>({static_cast<py::ssize_t>(n), want_result ? dim_out : py::ssize_t(0)});
  }
  // Only when asked for: convert() returns rows that are NaN where invalid, and the mask would be
  // one more array to allocate and write.
  py::array_t<bool> valid(want.valid ? static_cast<py::ssize_t>(n) : py::ssize_t(0));
  py::array_t<T> jacobian(want_jacobian ? static_cast<py::ssize_t>(n) : py::ssize_t(0));
  // When only the mask or J is wanted, the engine still needs somewhere to put the tuples.
  std::vector<T> scratch(want_result ? 0 : n * std::size_t(dim_out));

  const auto in = columns_of(x);
  std::vector<Column<T>> out;
  for (py::ssize_t c = 0; c < dim_out; ++c) {
    if (want_result)
      out.push_back({result.mutable_data() + c * (result.strides(1) / py::ssize_t(sizeof(T))),
                     result.strides(0) / py::ssize_t(sizeof(T))});
    else
      out.push_back({scratch.data() + c, dim_out});
  }
  ConvertOutput<T> o{out};
  static_assert(sizeof(bool) == sizeof(std::uint8_t));
  if (want.valid) o.valid = reinterpret_cast<std::uint8_t*>(valid.mutable_data());
  if (want_jacobian) o.jacobian = {jacobian.mutable_data(), 1};
  {
    py::gil_scoped_release release;
    convert<T>(from, to, in, n, o);
  }
  return {want_result ? py::object(result) : py::none(),
          want.valid ? py::object(valid) : py::none(),
          want_jacobian ? py::object(jacobian) : py::none()};
}

Outputs dispatch(const py::object& obj, Form from, Form to, Wanted want,
                 const py::object& out = py::none()) {
  // Anything np.asarray accepts (lists, array-likes); arrays pass through untouched.
  const py::array x = py::module_::import("numpy").attr("asarray")(obj);
  check_input(x, from);
  if (x.dtype().is(py::dtype::of<float>())) return run<float>(x, from, to, want, out);
  if (x.dtype().kind() == 'f' || x.dtype().kind() == 'i' || x.dtype().kind() == 'u')
    return run<double>(x, from, to, want, out);
  throw py::type_error("x must be a float32 or float64 array (got dtype " +
                       std::string(py::str(x.dtype())) + ")");
}

// (N, 3) float64 copies of wi and wo (or of the halves of an (N, 6) array).
std::vector<DirPair<double>> pairs_of(const py::object& wi_obj, const py::object& wo_obj) {
  auto np = py::module_::import("numpy");
  auto as_f64 = [&](const py::object& o, const char* name) {
    py::array a = np.attr("asarray")(o);
    if (a.dtype().kind() != 'f' && a.dtype().kind() != 'i' && a.dtype().kind() != 'u')
      throw py::type_error(std::string(name) + " must be a float array (got dtype " +
                           std::string(py::str(a.dtype())) + ")");
    return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  };
  std::vector<DirPair<double>> pairs;
  if (wo_obj.is_none()) {
    const auto x = as_f64(wi_obj, "pairs");
    if (x.ndim() != 2 || x.shape(1) != 6)
      throw py::value_error(
          "pairs must have shape (N, 6) (wi_x, wi_y, wi_z, wo_x, wo_y, wo_z), "
          "got " +
          shape_text(x));
    const double* d = x.data();
    pairs.resize(std::size_t(x.shape(0)));
    for (std::size_t i = 0; i < pairs.size(); ++i, d += 6)
      pairs[i] = {{d[0], d[1], d[2]}, {d[3], d[4], d[5]}};
  } else {
    const auto a = as_f64(wi_obj, "wi"), b = as_f64(wo_obj, "wo");
    for (const auto& [arr, name] : {std::pair{&a, "wi"}, std::pair{&b, "wo"}})
      if (arr->ndim() != 2 || arr->shape(1) != 3)
        throw py::value_error(std::string(name) + " must have shape (N, 3), got " +
                              shape_text(*arr));
    if (a.shape(0) != b.shape(0))
      throw py::value_error("wi and wo must have the same number of rows, got " +
                            std::to_string(a.shape(0)) + " and " + std::to_string(b.shape(0)));
    pairs.resize(std::size_t(a.shape(0)));
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const double *p = a.data() + 3 * i, *q = b.data() + 3 * i;
      pairs[i] = {{p[0], p[1], p[2]}, {q[0], q[1], q[2]}};
    }
  }
  // The CLI's rule (accept_pair): unit vectors are required (a typo in a direction is a bug, not
  // a query) and near-unit ones normalized; directions below the horizon are answered (0). A
  // row with a NaN or an infinity is answered NaN (NumPy's convention: eval_brdf), where the
  // CLI, reading a file, names its line.
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const PairStatus st = accept_pair(pairs[i]);
    if (st == PairStatus::wi_not_unit || st == PairStatus::wo_not_unit)
      throw py::value_error("row " + std::to_string(i) + ": " + std::string(describe(st)));
  }
  return pairs;
}

bool finite_pair(const DirPair<double>& p) {
  return std::isfinite(p.wi.x) && std::isfinite(p.wi.y) && std::isfinite(p.wi.z) &&
         std::isfinite(p.wo.x) && std::isfinite(p.wo.y) && std::isfinite(p.wo.z);
}

py::array_t<double> eval_brdf(const PyBrdf& b, const py::object& wi, const py::object& wo) {
  const std::vector<DirPair<double>> pairs = pairs_of(wi, wo);
  std::vector<Rgb> rho(pairs.size());
  {
    py::gil_scoped_release release;
    b.brdf->eval_batch(pairs, rho);
  }
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 0; i < pairs.size(); ++i)  // not a BRDF's answer: NaN in, NaN out
    if (!finite_pair(pairs[i])) rho[i] = {nan, nan, nan};
  py::array_t<double> out({py::ssize_t(pairs.size()), py::ssize_t(3)});
  double* o = out.mutable_data();
  for (std::size_t i = 0; i < rho.size(); ++i) {
    o[3 * i] = rho[i].r;
    o[3 * i + 1] = rho[i].g;
    o[3 * i + 2] = rho[i].b;
  }
  return out;
}

GridKind parse_kind(const std::string& kind) {
  if (kind == "full") return GridKind::full;
  if (kind == "isotropic") return GridKind::isotropic;
  if (kind == "slice") return GridKind::slice;
  throw py::value_error("kind: expected 'full', 'isotropic' or 'slice', got '" + kind + "'");
}

std::string python_repr(const py::handle& v) {
  return std::string(py::str(py::type::of(v).attr("__name__"))) + " " + std::string(py::repr(v));
}

// resample()'s size: an int, or a sequence of ints (one per axis); a clear TypeError otherwise
// (a str is a sequence too, but of characters).
std::vector<std::size_t> grid_counts(const py::object& size) {
  const auto count = [&](const py::handle& v) {
    if (!py::isinstance<py::int_>(v) || py::isinstance<py::bool_>(v))
      throw py::type_error(
          "resample(): size must be an int or a sequence of ints (one per "
          "axis), got " +
          python_repr(size));
    const long c = v.cast<long>();
    if (c <= 0) throw py::value_error("resample(): size must be positive, got " + python_repr(v));
    return std::size_t(c);
  };
  if (py::isinstance<py::int_>(size)) return {count(size)};
  if (py::isinstance<py::str>(size) || py::isinstance<py::bytes>(size) ||
      !py::isinstance<py::sequence>(size))
    throw py::type_error(
        "resample(): size must be an int or a sequence of ints (one per axis), "
        "got " +
        python_repr(size));
  std::vector<std::size_t> counts;
  for (const auto& v : size) counts.push_back(count(v));
  return counts;
}

// resample()'s ranges[axis]: a (lo, hi) pair of numbers.
std::pair<double, double> range_bounds(const py::handle& value, const std::string& axis) {
  try {
    if (!py::isinstance<py::str>(value)) return value.cast<std::pair<double, double>>();
  } catch (const py::cast_error&) {
  }
  throw py::type_error("resample(): ranges['" + axis +
                       "'] must be a (lo, hi) pair of numbers, got " + python_repr(value));
}

py::dict resample_brdf(const PyBrdf& b, const std::string& param, const std::string& kind,
                       const py::object& size, double azimuth, bool nodes, const py::dict& ranges) {
  const Space space = parse_space(param, "param");
  const std::vector<std::size_t> counts = grid_counts(size);
  // Radians, as every angle of the Python API (the CLI's --azimuth is in degrees), from -2π to
  // 2π, wrapped into [0, 2π): a value beyond is refused rather than wrapped, since it is most
  // likely in degrees (azimuth=90 would silently be 90 - 28π radians).
  if (!(std::abs(azimuth) <= 2 * std::numbers::pi))
    throw py::value_error("azimuth = " + python_repr(py::float_(azimuth)) +
                          ": expected radians from -2 pi to 2 pi (every angle of the Python API "
                          "is in radians; for degrees: math.radians(" +
                          python_repr(py::float_(azimuth)) + "))");
  GridSpec g = default_grid(space, parse_kind(kind), counts, wrap_azimuth_radians(azimuth));
  g.sampling = nodes ? GridSampling::nodes : GridSampling::centres;
  for (const auto& [key, value] : ranges) {
    GridAxis* axis = nullptr;
    try {
      axis = &g.axis(key.cast<std::string>());
    } catch (const std::invalid_argument& e) {
      throw py::value_error(std::string("ranges: ") + e.what());
    }
    const auto lohi = range_bounds(value, key.cast<std::string>());
    axis->lo = lohi.first;
    axis->hi = lohi.second;
  }
  validate(g);
  ResampledTable t;
  {
    py::gil_scoped_release release;
    t = resample(*b.brdf, g);
  }
  if (t.valid_count() == 0 &&
      PyErr_WarnEx(PyExc_RuntimeWarning,
                   "resample: no grid point is inside the domain: every value is NaN", 1) != 0)
    throw py::error_already_set();  // warnings turned into errors
  std::vector<py::ssize_t> shape;
  for (const GridAxis& a : g.axes) shape.push_back(py::ssize_t(a.count));
  std::vector<py::ssize_t> rgb_shape = shape;
  rgb_shape.push_back(3);
  py::array_t<double> rho(rgb_shape);
  std::copy(t.rgb.begin(), t.rgb.end(), rho.mutable_data());
  py::array_t<bool> valid(shape);
  std::copy(t.valid.begin(), t.valid.end(), valid.mutable_data());
  py::list axes, names;
  for (const GridAxis& a : g.axes) {
    py::array_t<double> p(py::ssize_t(a.count));
    for (std::size_t i = 0; i < a.count; ++i) p.mutable_data()[i] = a.position(i, g.sampling);
    axes.append(p);
    names.append(a.name);
  }
  py::dict d;
  d["rho"] = rho;
  d["valid"] = valid;
  d["axes"] = axes;
  d["axis_names"] = names;
  d["metadata"] = py::module_::import("json").attr("loads")(table_metadata_json(t));
  return d;
}

py::dict hemisphere_view(const std::string& param, double theta_o, std::size_t pixels,
                         const std::string& projection, const std::string& centre) {
  const Space space = parse_space(param, "param");
  if (space == Space::dirs) throw py::value_error("param: a parameterization, not dirs");
  if (!(theta_o >= 0 && theta_o <= std::numbers::pi / 2))
    throw py::value_error("theta_o must be in [0, pi/2] (radians), got " + std::to_string(theta_o));
  if (pixels < 2 || pixels > 8192) throw py::value_error("pixels must be in [2, 8192]");
  const auto proj = figure::projection_from_name(projection);
  if (!proj)
    throw py::value_error("projection: expected 'equal-area', 'orthographic' or 'equidistant'");
  const auto c = figure::view_centre_from_name(centre);
  if (!c) throw py::value_error("centre: expected 'normal', 'mirror' or 'back'");
  const Vec3<double> wo = figure::outgoing_direction(theta_o);
  const figure::HemisphereView view = figure::HemisphereView::make(*c, wo, *proj);
  figure::HemisphereSample hs;
  {
    py::gil_scoped_release release;
    hs = figure::sample_hemisphere(space, view, wo, pixels);
  }
  const auto ny = py::ssize_t(hs.grid.ny), nx = py::ssize_t(hs.grid.nx);
  py::array_t<double> first({ny, nx}), second({ny, nx}), u(nx), v(ny);
  py::array_t<std::uint8_t> region({ny, nx});
  std::copy(hs.first.values.begin(), hs.first.values.end(), first.mutable_data());
  std::copy(hs.second.values.begin(), hs.second.values.end(), second.mutable_data());
  std::copy(hs.region.begin(), hs.region.end(), region.mutable_data());
  for (py::ssize_t i = 0; i < nx; ++i) u.mutable_data()[i] = hs.grid.x(std::size_t(i));
  for (py::ssize_t j = 0; j < ny; ++j) v.mutable_data()[j] = hs.grid.y(std::size_t(j));
  py::dict d;
  d["first"] = first;
  d["second"] = second;
  d["region"] = region;
  d["u"] = u;
  d["v"] = v;
  d["wo"] = py::make_tuple(wo.x, wo.y, wo.z);
  return d;
}

py::object render_brdf(const PyBrdf& b, const std::string& env, int width, int height, int spp,
                       std::uint64_t seed, const std::string& strategy, int threads,
                       const std::string& brdf_sampling) {
  render::RenderSettings s;
  s.width = width;
  s.height = height;
  s.spp = spp;
  s.seed = seed;
  s.threads = threads;
  const auto parsed = render::strategy_from_name(strategy);
  if (!parsed)
    throw py::value_error("strategy: expected 'mis', 'brdf' or 'env', got '" + strategy + "'");
  s.strategy = *parsed;
  const auto sampling = render::brdf_sampling_from_name(brdf_sampling);
  if (!sampling)
    throw py::value_error("brdf_sampling: expected 'auto', 'table' or 'cosine', got '" +
                          brdf_sampling + "'");
  s.brdf_sampling = *sampling;
  const render::EnvMap map = render::EnvMap::from_spec(env);
  render::RenderResult r;
  {
    py::gil_scoped_release release;
    r = render::render(*b.brdf, map, s);
  }
  py::array_t<float> img({py::ssize_t(r.image.height), py::ssize_t(r.image.width), py::ssize_t(3)});
  std::copy(r.image.rgb.begin(), r.image.rgb.end(), img.mutable_data());
  // The array, with the BRDF sampler used (the line `halfback render` prints on stderr).
  return py::module_::import("halfback").attr("RenderedImage")(img, r.sampler);
}

// convert()'s docstring, with the columns of every form from the registry (the built-in
// parameterizations, and those registered before the module was imported), aligned.
const std::string& convert_doc() {
  static const std::string doc = [] {
    std::vector<Space> spaces{Space::dirs};
    for (Space p : parameterizations()) spaces.push_back(p);
    const auto joined = [](Form f) {
      std::string s;
      for (std::string_view c : column_names(f)) s += (s.empty() ? "" : ", ") + std::string(c);
      return s;
    };
    std::size_t name_width = 0, columns_width = 0;
    for (Space space : spaces) {
      name_width = std::max(name_width, name_of(space).size() + 2);
      columns_width = std::max(columns_width, joined({space, false}).size());
    }
    std::string s = R"doc(Converts N tuples from one parameterization to another.

x: array of shape (N, 6) for "dirs" or (N, 4) / (N, 3) for a parameterization (every one:
parameterizations()), columns in the CLI's order:
)doc";
    const auto row = [&](std::string name, std::string columns, const std::string& iso) {
      name.resize(name_width, ' ');
      columns.resize(columns_width, ' ');
      return "  " + name + "  " + columns + "  " + iso + "\n";
    };
    s += row("form", "columns", "isotropic=True");
    for (Space space : spaces)
      s += row('"' + std::string(name_of(space)) + '"', joined({space, false}),
               space == Space::dirs ? "(none)" : joined({space, true}));
    s += "isotropic: use the 3-coordinate isotropic form of every parameterization side.\n";
    return s +
           R"doc(Returns an array of the same dtype (float32 stays float32, anything else becomes float64); rows
whose input is invalid (not unit, below the horizon, outside the domain, NaN) are NaN.
out: an existing (N, dim) array of the result's dtype to write into (and return), e.g. to convert
many batches without allocating; when it overlaps x (other than being x itself), x is copied
first, so the result is always that of a separate out.)doc";
  }();
  return doc;
}

void bind_conversions(py::module_& m) {
  m.def(
      "simd_isa", [] { return std::string(simd_isa_name(simd_isa())); },
      R"doc(The instruction set of the SIMD kernels in use: "scalar", "sse2", "avx2" or "avx512".

The best this CPU runs, or the one the environment variable HALFBACK_ISA names (read once, when
first needed) if this CPU runs it. The instruction sets agree within the conversions' accuracy,
not bit for bit.)doc");
  m.def(
      "convert",
      [](const py::object& x, const std::string& src, const std::string& dst, bool isotropic,
         const py::object& out) {
        const Form from = parse_form(src, isotropic, "src"), to = parse_form(dst, isotropic, "dst");
        if (isotropic && from.space == Space::dirs && to.space == Space::dirs)  // as the CLI
          throw py::value_error("isotropic needs a parameterization on one side (src or dst)");
        return dispatch(x, from, to, {.result = true}, out).result;
      },
      py::arg("x"), py::arg("src"), py::arg("dst"), py::arg("isotropic") = false,
      py::arg("out") = py::none(), convert_doc().c_str());

  m.def(
      "valid",
      [](const py::object& x, const std::string& param, bool isotropic) {
        const Form form = parse_form(param, isotropic, "param");
        const Form other = form.space == Space::dirs ? Form{space_of<Hybrid>} : Form{Space::dirs};
        return dispatch(x, form, other, {.valid = true}).valid;
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
        return dispatch(x, form, Form{Space::dirs}, {.jacobian = true}).jacobian;
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

  m.def("parameterizations", &parameterization_table,
        R"doc(Every parameterization (built in, then registered), each a dict: name, summary, axes
and iso_axes (per coordinate: column, label, kind ("angle", "azimuth" or "length"), unit, lo, hi).)doc");
}

void bind_brdf_class(py::module_& m) {
  py::class_<PyBrdf>(m, "Brdf",
                     "A BRDF: an analytic model, measured data (MERL, RGL, ALTA) or a neural BRDF.")
      .def_property_readonly("name", [](const PyBrdf& b) { return b.brdf->name(); })
      .def_property_readonly("description", [](const PyBrdf& b) { return b.brdf->description(); })
      .def_property_readonly("isotropic", [](const PyBrdf& b) { return b.brdf->isotropic(); })
      .def_property_readonly("reciprocal", [](const PyBrdf& b) { return b.brdf->reciprocal(); })
      .def_property_readonly(
          "info",
          [](const PyBrdf& b) {
            py::dict d;
            d["name"] = b.brdf->name();
            d["description"] = b.brdf->description();
            d["isotropic"] = b.brdf->isotropic();
            d["reciprocal"] = b.brdf->reciprocal();
            for (const auto& f : b.brdf->facts()) d[py::str(f.label)] = f.value;
            return d;
          },
          "The BRDF's name, description, symmetries and data facts (format, dimensions, ...).")
      .def("eval", &eval_brdf, py::arg("wi"), py::arg("wo") = py::none(),
           R"doc(rho(wi, wo) in 1/sr (RGB, no cosine factor) as an (N, 3) float64 array.

wi, wo: (N, 3) arrays of unit directions (wi: light, wo: view; frame n = +z), or wi alone as an
(N, 6) array of pairs. A pair with a direction below the horizon gives 0, a row with NaN gives NaN;
a direction that is not a unit vector raises ValueError naming the row.)doc")
      .def(
          "albedo",
          [](const PyBrdf& b, double theta_i, int n) {
            if (n < 1) throw py::value_error("n must be positive");
            // Radians in [0, π/2]: albedo(30.0), degrees by mistake, gave a plausible number.
            if (!(theta_i >= 0 && theta_i <= std::numbers::pi / 2))
              throw py::value_error(
                  "theta_i: " + py::repr(py::float_(theta_i)).cast<std::string>() +
                  " is not an angle of incidence in radians, in [0, pi/2] (degrees? use "
                  "math.radians)");
            AlbedoEstimate a;
            {
              py::gil_scoped_release release;
              a = directional_albedo(*b.brdf, {std::sin(theta_i), 0, std::cos(theta_i)}, n);
            }
            return py::make_tuple(
                py::make_tuple(a.mean.r, a.mean.g, a.mean.b),
                py::make_tuple(a.standard_error.r, a.standard_error.g, a.standard_error.b));
          },
          py::arg("theta_i"), py::arg("n") = 256,
          "Directional albedo at incidence theta_i (radians): ((r, g, b), (standard errors)), by "
          "n x n stratified samples, cosine-weighted and, when the BRDF samples itself, combined "
          "with "
          "its sampler (MIS).")
      .def("resample", &resample_brdf, py::arg("param") = "hybrid", py::arg("kind") = "isotropic",
           py::arg("size") = 64, py::arg("azimuth") = 0.0, py::arg("nodes") = false,
           py::arg("ranges") = py::dict(),
           R"doc(The BRDF on a regular grid of a parameterization (as `halfback resample`).

kind: "full" (4 axes), "isotropic" (3 axes, phi_h = 0) or "slice" (2 axes at relative azimuth
`azimuth`, in radians from -2 pi to 2 pi, wrapped into [0, 2 pi): every angle of the Python API is
in radians; a value beyond is a ValueError). size: samples per axis, an int or one per axis. Samples at cell centres,
or at nodes including both ends with nodes=True. ranges: {axis name: (lo, hi)}.
Returns a dict: rho (shape..., 3) float64 (NaN outside the domain), valid (shape...) bool, axes
(sample positions), axis_names, metadata.)doc")
      .def("render", &render_brdf, py::arg("env") = "sky", py::arg("width") = 256,
           py::arg("height") = 256, py::arg("spp") = 64, py::arg("seed") = 1,
           py::arg("strategy") = "mis", py::arg("threads") = 0, py::arg("brdf_sampling") = "auto",
           R"doc(A unit sphere of the BRDF under an environment (as `halfback render`): an (H, W, 3)
float32 array of linear radiance, row 0 at the top. env: "sky" (a sky with a sun; "default" is its older name), "studio", "sunset",
"constant:V", "constant:R,G,B" or a .hdr/.exr file. strategy: "mis", "brdf" or "env".
brdf_sampling (a BRDF without a sampler of its own): "table", "cosine", or "auto": both samplers
estimate the BRDF's directional albedo, and auto takes the table when the cosine's estimate misses
energy the table's finds, or when the ratio of the two estimates' variances (cosine over table)
is at least a threshold that rises as the environment leaves less of its light to the BRDF
sampler (150 under a constant environment, 445 under "sky", 1499 under "studio"); else the
cosine (as `halfback render --brdf-sampling`, docs/render.md). E.g. "embedded:pink-felt" (a
ratio of 30) gets the cosine and "embedded:gold-metallic-paint3" (7.6e3) the table under both; a
ratio of 900 gets the table under "sky" and the cosine under "studio". The array is a halfback.RenderedImage (a numpy array)
whose `sampler` says which BRDF sampler was used and, when "auto" chose it, why (the measured
albedo variance ratio and its threshold), as `halfback render` says on stderr:
  img = halfback.load("embedded:gold-metallic-paint3").render(env="studio", spp=16)
  print(img.sampler))doc")
      .def("__repr__", [](const PyBrdf& b) { return "<halfback.Brdf " + b.brdf->name() + ">"; })
      .def_property_readonly(
          "spec", [](const PyBrdf& b) { return b.spec; },
          "The spec it was loaded from (a file: its absolute path).")
      .def(
          "__eq__",
          [](const PyBrdf& a, const py::object& other) {
            if (!py::isinstance<PyBrdf>(other)) return false;
            const PyBrdf& b = other.cast<const PyBrdf&>();
            return a.brdf == b.brdf || (!a.spec.empty() && a.spec == b.spec);
          },
          "Equal when loaded from the same spec (or the same object).")
      .def("__hash__", [](const PyBrdf& b) { return py::hash(py::str(b.spec)); })
      .def(py::pickle(
          [](const PyBrdf& b) { return py::make_tuple(b.spec); },  // rebuilt from its spec
          [](const py::tuple& t) {
            if (t.size() != 1) throw std::runtime_error("Brdf: a pickled Brdf is (spec,)");
            return load_py_brdf(t[0].cast<std::string>());
          }));
}

void bind_hemisphere(py::module_& m) {
  m.def(
      "hemisphere", &hemisphere_view, py::arg("param"), py::arg("theta_o"), py::arg("pixels") = 256,
      py::arg("projection") = "equal-area", py::arg("centre") = "normal",
      R"doc(Figure 1's data: for wo = (-sin theta_o, 0, cos theta_o), every wi of a disk view of the
hemisphere. Returns a dict: first, second (pixels x pixels) the pair's two non-azimuthal
coordinates in `param` (NaN where there is no valid pair), region (0 outside the disk, 1 wi below
the horizon, 2 valid), u (columns) and v (rows) the disk coordinates of the pixel centres (v up),
and wo; row j of the arrays is at v = v[j] (row 0 is the bottom). projection: "equal-area", "orthographic" or "equidistant"; centre: "normal", "mirror" or
"back".)doc");
}

py::dict models_dict() {
  py::dict out;
  for (const std::string& name : model_registry().names()) {
    const ModelInfo* m = model_registry().find(name);
    if (!m) continue;
    py::list params;
    for (const ModelParam& p : m->params) {
      py::dict d;
      d["name"] = p.name;
      d["description"] = p.description;
      d["default"] = p.default_from.empty() ? py::object(py::float_(p.default_value)) : py::none();
      d["min"] = p.min;
      d["max"] = p.max;
      d["default_from"] = p.default_from;
      d["choices"] = p.choices;
      params.append(d);
    }
    py::dict model;
    model["description"] = m->description;
    model["params"] = params;
    out[py::str(name)] = model;
  }
  return out;
}

void bind_loading(py::module_& m) {
  m.def("load", &load_py_brdf, py::arg("spec"),
        R"doc(Loads a BRDF from a SPEC: a MERL/RGL/ALTA file, a neural BRDF (.h5, or the folder or
NAME_fc1.npy of its NumPy form), a model such as "ggx:alpha=0.2" or
"lambert:albedo=0.5", a sum "a+b", or "embedded:NAME" (as on the command line).)doc");
  m.def("models", &models_dict,
        R"doc(The analytic models: a dict name -> {"description", "params"}, each parameter a dict
of "name", "description", "default", "min", "max", "default_from" (the parameter whose value it
takes when not given, or "") and "choices" (named values, or []). Iterating it gives the
names, as before.)doc");
}

}  // namespace

// The class before the functions that return it, so that their signatures name it.
PYBIND11_MODULE(_core, m) {
  m.attr("__version__") = HALFBACK_VERSION;
  m.doc() = "halfback: exact, fast changes of variables between BRDF parameterizations";
  halfback::register_brdf_parameterization_families();
  // A reader's message may quote bytes of its file that are not UTF-8: pybind11 would then raise
  // the exception without its text. FormatError stays a RuntimeError, its text made valid UTF-8.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const halfback::FormatError& e) {
      PyErr_SetString(PyExc_RuntimeError, halfback::valid_utf8(e.what()).c_str());
    }
  });
  bind_conversions(m);
  bind_brdf_class(m);
  bind_hemisphere(m);
  bind_loading(m);
  halfback::python::bind_study(m);
  halfback::python::bind_fit(m);
  halfback::python::bind_nbrdf(m);
  halfback::python::bind_user_parameterizations(m);
  halfback::python::bind_acquisition(m);
  halfback::python::bind_view(m);
}
