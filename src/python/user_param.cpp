// A parameterization written by a Python user: vectorized NumPy callables behind a ParamDescriptor,
// checked (core/param_check.hpp) before it is registered, then taken by name by every function of
// the module (convert, resample, hemisphere, study_brdf, ...). After registration its results are
// checked at every call (a map may go wrong later, or where the checks did not sample): forward's
// coordinates finite for a valid pair, inverse's pair valid (unit directions, above the horizon)
// inside the axes' ranges; otherwise a ValueError naming the parameterization and the values.
//
// The user gives forward (wi, wo) -> q and inverse q -> (wi, wo) on (N, 3) and (N, 4) float64
// arrays, the four axes, and optionally the Jacobian and the reciprocity map. The rest is derived:
// validity (finite directions, coordinates in their declared ranges), the Jacobian by finite
// differences of the inverse when not given, the mirror map, and the isotropic form: the
// coordinate `isotropic_drop` (an absolute azimuth, such as φh or φi) is dropped after rotating
// the pair about n so that it is 0; the other azimuth becomes relative and comes last.
#include "user_param.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "halfback/core/param_check.hpp"
#include "halfback/core/space.hpp"

namespace py = pybind11;

namespace halfback::python {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

AxisKind axis_kind(const std::string& kind) {
  if (kind == "angle") return AxisKind::angle;
  if (kind == "azimuth") return AxisKind::azimuth;
  if (kind == "length") return AxisKind::length;
  throw py::value_error("axes: kind '" + kind + "' is not angle, azimuth or length");
}

const SamplerChart& chart_named(const std::string& name) {
  for (const SamplerChart& c : kSamplerCharts)
    if (c.name == name) return c;
  std::string names;
  for (const SamplerChart& c : kSamplerCharts)
    names += (names.empty() ? "" : ", ") + std::string(c.name);
  throw py::value_error("sampler_chart: '" + name + "' is not one of " + names);
}

// The user's description, as given to the constructor.
struct UserSpec {
  std::string name, summary;
  py::object forward, inverse, jacobian, reciprocal;
  std::array<Axis, 4> axes;
  std::array<std::string, 8> strings;  // the axes' columns and labels, owned until copied
  std::size_t drop = 1;
  std::array<std::size_t, 3> kept{};  // the 4D coordinates of the isotropic form, in its order
  std::string chart = "half-vector";
};

class PyParam final : public ParamDescriptor {
 public:
  // `names` points into `spec`: the base copies it before the spec moves (a by-value spec would
  // move first).
  PyParam(const Names& names, UserSpec&& spec) : ParamDescriptor(names), s_(std::move(spec)) {
    const auto owned = axes(false);  // the descriptor's copies: the spec's views moved with it
    std::copy(owned.begin(), owned.end(), s_.axes.begin());
  }
  ~PyParam() override {
    // The registry outlives the interpreter: leak the callables then, rather than touch Python.
    if (!Py_IsInitialized()) {
      s_.forward.release();
      s_.inverse.release();
      s_.jacobian.release();
      s_.reciprocal.release();
      return;
    }
    py::gil_scoped_acquire gil;
    s_ = UserSpec{};
  }

  bool concurrent() const override { return false; }

  // While one lives, the results of the user's maps are not checked at each call: for the
  // registration's checks (core/param_check.hpp), which find and name the same faults (a
  // round trip off by 1e-3, ...) in their own words. Not reentrant (one thread: concurrent() is
  // false).
  class ResultChecksOff {
   public:
    explicit ResultChecksOff(const PyParam& p) : p_(p) { p_.check_results_ = false; }
    ~ResultChecksOff() { p_.check_results_ = true; }
    ResultChecksOff(const ResultChecksOff&) = delete;
    ResultChecksOff& operator=(const ResultChecksOff&) = delete;

   private:
    const PyParam& p_;
  };

  // --- rows: one call of the user's code per block --------------------------------------------
  void forward_rows(bool iso, const DirPair<double>* pairs, std::size_t m,
                    double* coords) const override {
    if (!iso) return forward4(pairs, m, coords);
    std::vector<double> q(4 * m);
    forward4(pairs, m, q.data());
    std::vector<DirPair<double>> turned(m);
    for (std::size_t i = 0; i < m; ++i) {  // the dropped azimuth to 0
      const double a = -q[4 * i + s_.drop], c = std::cos(a), s = std::sin(a);
      turned[i] = {detail::rotate_z(pairs[i].wi, c, s), detail::rotate_z(pairs[i].wo, c, s)};
    }
    forward4(turned.data(), m, q.data());
    for (std::size_t i = 0; i < m; ++i)
      for (std::size_t k = 0; k < 3; ++k) coords[3 * i + k] = q[4 * i + s_.kept[k]];
  }

  void inverse_rows(bool iso, const double* coords, std::size_t m, DirPair<double>* pairs,
                    std::uint8_t* in_domain) const override {
    if (!iso) return inverse4(coords, m, pairs, in_domain);
    const std::vector<double> q = lift(coords, m);
    inverse4(q.data(), m, pairs, in_domain);
    for (std::size_t i = 0; i < m; ++i) {
      if (!in_domain[i]) continue;
      Solved<double> s{pairs[i], true};
      detail::rotate_to_canonical_pose(s);
      pairs[i] = s.pair;
    }
  }

  void jacobian_rows(bool iso, const double* coords, std::size_t m,
                     double* jacobian) const override {
    std::vector<double> q = iso ? lift(coords, m) : std::vector<double>(coords, coords + 4 * m);
    if (s_.jacobian.is_none())
      finite_difference_jacobian(q, jacobian);
    else
      user_jacobian(q, jacobian);
    if (iso)
      for (std::size_t i = 0; i < m; ++i) jacobian[i] *= kTwoPi;
  }

  // --- single rows, through the block maps ----------------------------------------------------
  Tuple4<double> forward(const DirPair<double>& p) const override {
    Tuple4<double> q;
    forward_rows(false, &p, 1, q.data());
    return q;
  }
  Tuple3<double> forward_iso(const DirPair<double>& p) const override {
    Tuple3<double> q;
    forward_rows(true, &p, 1, q.data());
    return q;
  }
  Solved<double> inverse(const Tuple4<double>& q) const override { return solve(false, q.data()); }
  Solved<double> inverse_iso(const Tuple3<double>& q) const override {
    return solve(true, q.data());
  }
  double jacobian(const Tuple4<double>& q) const override {
    double j;
    jacobian_rows(false, q.data(), 1, &j);
    return j;
  }
  double jacobian_iso(const Tuple3<double>& q) const override {
    double j;
    jacobian_rows(true, q.data(), 1, &j);
    return j;
  }
  Tuple4<double> reciprocal(const Tuple4<double>& q) const override {
    if (!s_.reciprocal.is_none()) return user_reciprocal(q);
    const Solved<double> s = inverse(q);
    return forward(DirPair<double>{s.pair.wo, s.pair.wi});
  }
  Tuple4<double> mirror(const Tuple4<double>& q) const override {
    return forward(mirror_pair(inverse(q).pair));
  }
  Tuple3<double> reciprocal_iso(const Tuple3<double>& q) const override {
    const Solved<double> s = inverse_iso(q);
    return forward_iso(DirPair<double>{s.pair.wo, s.pair.wi});
  }
  Tuple3<double> mirror_iso(const Tuple3<double>& q) const override {
    return forward_iso(mirror_pair(inverse_iso(q).pair));
  }

 private:
  using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

  static Array rows_of(const double* data, std::size_t m, std::size_t d) {
    Array a({py::ssize_t(m), py::ssize_t(d)});
    std::copy(data, data + m * d, a.mutable_data());
    return a;
  }
  // A user's result as an (m, d) array (or (m,) when d is 0), or a ValueError naming the map.
  static Array checked(const py::object& r, std::size_t m, std::size_t d, const char* what) {
    Array a = Array::ensure(r);
    const bool ok = a && (d == 0 ? a.ndim() == 1 && std::size_t(a.shape(0)) == m
                                 : a.ndim() == 2 && std::size_t(a.shape(0)) == m &&
                                       std::size_t(a.shape(1)) == d);
    if (!ok)
      throw py::value_error(std::string(what) + " must return an array of shape (" +
                            std::to_string(m) + (d ? ", " + std::to_string(d) : std::string(",")) +
                            ") for " + std::to_string(m) +
                            " rows: is it vectorized (NumPy operations on whole arrays)?");
    return a;
  }

  void forward4(const DirPair<double>* pairs, std::size_t m, double* coords) const {
    py::gil_scoped_acquire gil;
    std::vector<double> wi(3 * m), wo(3 * m);
    for (std::size_t i = 0; i < m; ++i) {
      const auto& p = pairs[i];
      const double a[3] = {p.wi.x, p.wi.y, p.wi.z}, b[3] = {p.wo.x, p.wo.y, p.wo.z};
      std::copy(a, a + 3, wi.begin() + std::ptrdiff_t(3 * i));
      std::copy(b, b + 3, wo.begin() + std::ptrdiff_t(3 * i));
    }
    const Array q =
        checked(s_.forward(rows_of(wi.data(), m, 3), rows_of(wo.data(), m, 3)), m, 4, "forward");
    std::copy(q.data(), q.data() + 4 * m, coords);
    for (std::size_t i = 0; i < m && check_results_; ++i)
      if (check_pair(pairs[i]) == PairStatus::ok &&
          !std::all_of(coords + 4 * i, coords + 4 * i + 4,
                       [](double x) { return std::isfinite(x); }))
        throw py::value_error(s_.name + ": forward returned coordinates that are not finite, (" +
                              numbers(coords + 4 * i, 4) + "), for the valid pair wi = (" +
                              vec_text(pairs[i].wi) + "), wo = (" + vec_text(pairs[i].wo) + ")");
  }

  // "a, b, c" of n numbers, %.17g.
  static std::string numbers(const double* x, std::size_t n) {
    std::string s;
    for (std::size_t k = 0; k < n; ++k) {
      char b[32];
      std::snprintf(b, sizeof b, "%.17g", x[k]);
      (s += k ? ", " : "") += b;
    }
    return s;
  }

  static std::string vec_text(const Vec3<double>& w) {
    const double x[3] = {w.x, w.y, w.z};
    return numbers(x, 3);
  }

  // A ValueError unless the pair the user's inverse gave for `q` (inside the axes' ranges, both
  // directions finite) is valid: unit directions (to kUnitTolerance) above the horizon (to its
  // tolerance), as every built-in inverse returns and everything downstream assumes.
  void require_valid_inverse(const double* q, const DirPair<double>& p) const {
    const PairStatus status = check_pair(p);
    if (status == PairStatus::ok) return;
    const auto length = [](const Vec3<double>& w) { return std::sqrt(detail::dot(w, w)); };
    char lengths[96];
    std::snprintf(lengths, sizeof lengths, "|wi| = %.9g, |wo| = %.9g", length(p.wi), length(p.wo));
    throw py::value_error(s_.name + ": inverse returned a pair that is not valid (" +
                          std::string(describe(status)) + "; " + lengths + ": wi = (" +
                          vec_text(p.wi) + "), wo = (" + vec_text(p.wo) + ")) for q = (" +
                          numbers(q, 4) +
                          ") inside the axes' ranges: it must return unit directions above the "
                          "horizon, or NaN outside the domain");
  }

  // The user's inverse, then the declared ranges; valid pairs onto the hemisphere (as the built-in
  // inverses, within their tolerance), the others NaN.
  void inverse4(const double* coords, std::size_t m, DirPair<double>* pairs,
                std::uint8_t* in_domain) const {
    inverse_rows_raw(coords, m, pairs, in_domain);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t i = 0; i < m; ++i) {
      in_domain[i] = in_domain[i] && in_ranges(coords + 4 * i);
      if (in_domain[i] && check_results_) require_valid_inverse(coords + 4 * i, pairs[i]);
      if (in_domain[i]) {
        pairs[i].wi.z = std::max(pairs[i].wi.z, 0.0);
        pairs[i].wo.z = std::max(pairs[i].wo.z, 0.0);
      } else {
        pairs[i] = {{nan, nan, nan}, {nan, nan, nan}};
      }
    }
  }

  bool in_ranges(const double* q) const {
    for (std::size_t k = 0; k < 4; ++k) {
      const Axis& a = s_.axes[k];
      const bool in =
          a.kind == AxisKind::azimuth ? q[k] >= a.lo && q[k] < a.hi : q[k] >= a.lo && q[k] <= a.hi;
      if (!in) return false;
    }
    return true;
  }

  void user_jacobian(const std::vector<double>& q, double* jacobian) const {
    py::gil_scoped_acquire gil;
    const std::size_t m = q.size() / 4;
    const Array j = checked(s_.jacobian(rows_of(q.data(), m, 4)), m, 0, "jacobian");
    std::copy(j.data(), j.data() + m, jacobian);
  }

  // √det(AᵀA) of the central differences of the inverse: the volume element, by one call of the
  // inverse on the 8 m perturbed tuples.
  void finite_difference_jacobian(const std::vector<double>& q, double* jacobian) const {
    const std::size_t m = q.size() / 4;
    std::vector<double> moved;
    moved.reserve(36 * m);
    std::array<double, 4> step{};
    for (std::size_t k = 0; k < 4; ++k) step[k] = 1e-6 * (s_.axes[k].hi - s_.axes[k].lo);
    for (std::size_t i = 0; i < m; ++i)
      for (std::size_t k = 0; k < 4; ++k)
        for (const double sign : {1.0, -1.0}) {
          moved.insert(moved.end(), q.begin() + std::ptrdiff_t(4 * i),
                       q.begin() + std::ptrdiff_t(4 * i + 4));
          moved[moved.size() - 4 + k] += sign * step[k];
        }
    moved.insert(moved.end(), q.begin(), q.end());  // the centres, last
    std::vector<DirPair<double>> p(9 * m);
    std::vector<std::uint8_t> ok(9 * m);
    inverse_rows_raw(moved.data(), 9 * m, p.data(), ok.data());
    for (std::size_t i = 0; i < m; ++i)
      jacobian[i] = gram_volume(&p[8 * i], &ok[8 * i], p[8 * m + i], ok[8 * m + i], step);
  }
  // The user's inverse alone (no range test, so that differences at a range's end are taken):
  // `ok` where both directions are finite.
  void inverse_rows_raw(const double* coords, std::size_t m, DirPair<double>* pairs,
                        std::uint8_t* ok) const {
    py::gil_scoped_acquire gil;
    const py::object r = s_.inverse(rows_of(coords, m, 4));
    py::tuple t;
    if (!py::isinstance<py::tuple>(r) || (t = r.cast<py::tuple>()).size() != 2)
      throw py::value_error("inverse must return a tuple (wi, wo) of two (N, 3) arrays");
    const Array wi = checked(t[0], m, 3, "inverse's wi"), wo = checked(t[1], m, 3, "inverse's wo");
    for (std::size_t i = 0; i < m; ++i) {
      const double *a = wi.data() + 3 * i, *b = wo.data() + 3 * i;
      pairs[i] = {{a[0], a[1], a[2]}, {b[0], b[1], b[2]}};
      ok[i] = std::isfinite(a[0] + a[1] + a[2] + b[0] + b[1] + b[2]);
    }
  }
  // `p` holds the pairs at q ± step along each coordinate, and `centre` the pair at q: a one-sided
  // difference where one side leaves the domain (at its boundary).
  static double gram_volume(const DirPair<double>* p, const std::uint8_t* ok,
                            const DirPair<double>& centre, bool centre_ok,
                            const std::array<double, 4>& step) {
    auto flat = [](const DirPair<double>& w) {
      return std::array<double, 6>{w.wi.x, w.wi.y, w.wi.z, w.wo.x, w.wo.y, w.wo.z};
    };
    double a[4][6];
    for (int k = 0; k < 4; ++k) {
      const bool plus = ok[2 * k], minus = ok[2 * k + 1];
      std::array<double, 6> hi, lo;
      double width = 2 * step[std::size_t(k)];
      if (plus && minus) {
        hi = flat(p[2 * k]), lo = flat(p[2 * k + 1]);
      } else if (centre_ok && (plus || minus)) {
        hi = plus ? flat(p[2 * k]) : flat(centre);
        lo = plus ? flat(centre) : flat(p[2 * k + 1]);
        width = step[std::size_t(k)];
      } else {
        return std::numeric_limits<double>::quiet_NaN();
      }
      for (int r = 0; r < 6; ++r) a[k][r] = (hi[std::size_t(r)] - lo[std::size_t(r)]) / width;
    }
    return halfback::gram_volume(a);
  }

  Tuple4<double> user_reciprocal(const Tuple4<double>& q) const {
    py::gil_scoped_acquire gil;
    const Array r = checked(s_.reciprocal(rows_of(q.data(), 1, 4)), 1, 4, "reciprocal");
    return {r.data()[0], r.data()[1], r.data()[2], r.data()[3]};
  }

  // The 4D tuples of isotropic rows: the dropped azimuth 0, the others in their places.
  std::vector<double> lift(const double* coords, std::size_t m) const {
    std::vector<double> q(4 * m, 0.0);
    for (std::size_t i = 0; i < m; ++i)
      for (std::size_t k = 0; k < 3; ++k) q[4 * i + s_.kept[k]] = coords[3 * i + k];
    return q;
  }

  Solved<double> solve(bool iso, const double* q) const {
    Solved<double> s;
    std::uint8_t ok = 0;
    inverse_rows(iso, q, 1, &s.pair, &ok);
    s.in_domain = ok != 0;
    return s;
  }

  UserSpec s_;
  mutable bool check_results_ = true;  // see ResultChecksOff
};

// The isotropic form's coordinates: the 4D ones but `drop`, the remaining azimuth last.
std::array<std::size_t, 3> kept_coordinates(const std::array<Axis, 4>& axes, std::size_t drop) {
  if (drop > 3 || axes[drop].kind != AxisKind::azimuth)
    throw py::value_error("isotropic_drop: coordinate " + std::to_string(drop) +
                          " must be an azimuth (the one a rotation about n shifts, like φh)");
  std::vector<std::size_t> rest, azimuths;
  for (std::size_t k = 0; k < 4; ++k)
    if (k != drop) (axes[k].kind == AxisKind::azimuth ? azimuths : rest).push_back(k);
  if (azimuths.size() != 1)
    throw py::value_error(
        "axes: the isotropic form needs exactly two azimuths (one dropped, one made relative)");
  return {rest[0], rest[1], azimuths[0]};
}

std::shared_ptr<PyParam> make_param(const std::string& name, py::object forward, py::object inverse,
                                    const std::vector<py::tuple>& axes, py::object jacobian,
                                    py::object reciprocal, std::size_t isotropic_drop,
                                    const std::string& summary, const std::string& sampler_chart) {
  if (name.empty() || name == "dirs") throw py::value_error("name: '" + name + "' is not allowed");
  if (!PyCallable_Check(forward.ptr()) || !PyCallable_Check(inverse.ptr()))
    throw py::value_error("forward and inverse must be callables");
  if (axes.size() != 4)
    throw py::value_error("axes: four (column, kind, lo, hi[, label]) tuples, got " +
                          std::to_string(axes.size()));
  UserSpec s;
  s.name = name;
  s.summary = summary.empty() ? "a parameterization written in Python" : summary;
  s.forward = std::move(forward);
  s.inverse = std::move(inverse);
  s.jacobian = std::move(jacobian);
  s.reciprocal = std::move(reciprocal);
  for (std::size_t k = 0; k < 4; ++k) {
    const py::tuple& t = axes[k];
    if (t.size() != 4 && t.size() != 5)
      throw py::value_error("axes: each is (column, kind, lo, hi[, label])");
    s.strings[2 * k] = t[0].cast<std::string>();
    s.strings[2 * k + 1] = t.size() == 5 ? t[4].cast<std::string>() : s.strings[2 * k];
    const double lo = t[2].cast<double>(), hi = t[3].cast<double>();
    if (!(std::isfinite(lo) && std::isfinite(hi) && lo < hi))
      throw py::value_error("axes: the range of '" + s.strings[2 * k] +
                            "' must be finite, lo < hi");
    const AxisKind kind = axis_kind(t[1].cast<std::string>());
    s.axes[k] = Axis{s.strings[2 * k],
                     s.strings[2 * k + 1],
                     kind,
                     lo,
                     hi,
                     kind == AxisKind::length ? (hi - lo) / 10 : std::numbers::pi / 18};
  }
  s.drop = isotropic_drop;
  s.kept = kept_coordinates(s.axes, s.drop);
  s.chart = sampler_chart;
  ParamDescriptor::Names names{s.name, s.summary, s.axes, {}, chart_named(sampler_chart)};
  for (std::size_t k = 0; k < 3; ++k) names.iso_axes[k] = s.axes[s.kept[k]];
  std::string relative = "d" + std::string(names.iso_axes[2].column);
  std::string relative_label = "Δ" + std::string(names.iso_axes[2].label);
  names.iso_axes[2].column = relative;
  names.iso_axes[2].label = relative_label;
  return std::make_shared<PyParam>(names, std::move(s));  // the descriptor copies the strings
}

py::dict report_dict(const ParamCheckReport& r) {
  py::dict d;
  d["parameterization"] = r.parameterization;
  d["passed"] = r.passed();
  py::list checks;
  for (const ParamCheck& c : r.checks) {
    py::dict x;
    x["name"] = c.name;
    x["passed"] = c.passed;
    x["detail"] = c.detail;
    checks.append(x);
  }
  d["checks"] = checks;
  d["text"] = r.text();
  return d;
}

// The checks; a map that raises (a Python error, or a result of the wrong shape) fails them as
// not vectorized, with its error.
ParamCheckReport run_checks(const PyParam& p, std::size_t pairs, std::size_t box_samples) {
  ParamCheckOptions o;
  o.pairs = pairs;
  o.box_samples = box_samples;
  const PyParam::ResultChecksOff off(p);  // the checks name what is wrong themselves
  try {
    py::gil_scoped_release release;  // the maps take it back for each call
    return check_parameterization(p, o);
  } catch (const std::exception& e) {
    ParamCheckReport r;
    r.parameterization = std::string(p.name());
    r.checks.push_back({"vectorized", false,
                        std::string(e.what()) + " (the maps take (N, 3) and (N, 4) float64 arrays "
                                                "and must use NumPy operations on whole arrays)"});
    return r;
  }
}

}  // namespace

void bind_user_parameterizations(py::module_& m) {
  py::class_<PyParam, std::shared_ptr<PyParam>>(
      m, "Parameterization",
      "A parameterization written in Python (vectorized NumPy callables); see register().")
      .def(py::init(&make_param), py::arg("name"), py::arg("forward"), py::arg("inverse"),
           py::arg("axes"), py::arg("jacobian") = py::none(), py::arg("reciprocal") = py::none(),
           py::arg("isotropic_drop") = 1, py::arg("summary") = "",
           py::arg("sampler_chart") = "half-vector")
      .def_property_readonly("name", [](const PyParam& p) { return std::string(p.name()); })
      .def(
          "check",
          [](const PyParam& p, std::size_t pairs, std::size_t box_samples) {
            return report_dict(run_checks(p, pairs, box_samples));
          },
          py::arg("pairs") = 20000, py::arg("box_samples") = 200000,
          "Runs the checks (round trip, range, domain, Jacobian, isotropic form, reciprocity) "
          "and returns their report.");

  m.def(
      "register_parameterization",
      [](std::shared_ptr<PyParam> p, std::size_t pairs, std::size_t box_samples) {
        const ParamCheckReport r = run_checks(*p, pairs, box_samples);
        if (!r.passed()) throw py::value_error(r.first_failure());
        register_parameterization(std::shared_ptr<const ParamDescriptor>(p));
        return std::string(p->name());
      },
      py::arg("param"), py::arg("pairs") = 20000, py::arg("box_samples") = 200000,
      R"doc(Checks a Parameterization and, if it passes, makes its name a parameterization of every
function (convert, columns, resample, hemisphere, study_brdf's "params", ...). Raises ValueError
naming the first failed check. Returns the name.)doc");
}

}  // namespace halfback::python
