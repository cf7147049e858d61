#include "acquisition.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "halfback/acquire/acquisition.hpp"
#include "halfback/formats/merl.hpp"
#include "halfback/formats/rgl_writer.hpp"
#include "halfback/util/atomic_file.hpp"
#include "py_brdf.hpp"

namespace py = pybind11;

namespace halfback::python {

namespace {

constexpr double kDeg = 180 / std::numbers::pi;

void write_tensor_file(const std::string& out, const std::vector<TensorFieldData>& fields) {
  AtomicFile file(out);
  const std::vector<std::byte> bytes = serialize_tensor_file(fields);
  file.write({reinterpret_cast<const char*>(bytes.data()), bytes.size()});
  file.commit();
}

// A plan as Python sees it: the rows' positions (degrees and radians), directions, the row of
// each point, the travel and the sidecar.
py::dict plan_dict(const acquire::AcquisitionPlan& a) {
  const auto rows = py::ssize_t(a.measured.size());
  py::array_t<double> positions({rows, py::ssize_t(4)}), radians({rows, py::ssize_t(4)}),
      wi({rows, py::ssize_t(3)}), wo({rows, py::ssize_t(3)});
  auto p = positions.mutable_unchecked<2>();
  auto q = radians.mutable_unchecked<2>();
  auto i = wi.mutable_unchecked<2>();
  auto o = wo.mutable_unchecked<2>();
  for (py::ssize_t r = 0; r < rows; ++r) {
    const acquire::GonioPosition& g = a.positions[std::size_t(r)];
    const DirPair<double>& d = a.measured[std::size_t(r)];
    for (py::ssize_t m = 0; m < 4; ++m) {
      q(r, m) = g.angle[std::size_t(m)];
      p(r, m) = g.angle[std::size_t(m)] * kDeg;
    }
    i(r, 0) = d.wi.x, i(r, 1) = d.wi.y, i(r, 2) = d.wi.z;
    o(r, 0) = d.wo.x, o(r, 1) = d.wo.y, o(r, 2) = d.wo.z;
  }
  py::dict out;
  out["positions_deg"] = positions;
  out["positions"] = radians;
  py::list motors;
  for (std::string_view name : acquire::motor_names(a.instrument)) motors.append(std::string(name));
  out["motors"] = motors;
  out["wi"] = wi;
  out["wo"] = wo;
  out["row_of_point"] =
      py::array_t<std::size_t>(py::ssize_t(a.row_of_point.size()), a.row_of_point.data());
  out["travel_deg"] = a.travel * kDeg;
  out["cell_order_travel_deg"] = a.cell_order_travel * kDeg;
  out["sidecar"] = acquire::plan_sidecar(a, "measurements.csv");
  return out;
}

py::dict plan(const std::string& param, const std::string& design, std::size_t budget,
              const std::string& spacing, bool full, double max_theta, std::uint64_t seed,
              const std::string& instrument_name) {
  const auto instrument = acquire::parse_instrument(instrument_name);
  if (!instrument)
    throw py::value_error("instrument '" + instrument_name +
                          "': expected light-detector or sample-turning");
  max_theta = reach_degrees(max_theta, "max_theta");  // radians in, degrees for plan_setup
  acquire::AcquisitionPlan a;
  if (design == "dupuy-jakob") {  // its own layout: the budget alone (a ValueError below it)
    {
      py::gil_scoped_release release;
      a = acquire::dupuy_jakob_pilot_plan(budget, *instrument);
    }
    return plan_dict(a);
  }
  // plan_setup's std::invalid_argument reaches Python as a ValueError naming the setting.
  const acquire::GonioSetup s =
      acquire::plan_setup({param, design, spacing, budget, full, max_theta, seed, std::nullopt});
  {
    py::gil_scoped_release release;
    // A sequential design's plan is its pilot (the main stage needs the pilot's values).
    a = s.design == acquire::Design::sequential ? acquire::sequential_pilot_plan(s, *instrument)
                                                : acquire::acquisition_plan(s, *instrument);
  }
  return plan_dict(a);
}

// A sidecar given as its text or as a path.
acquire::AcquisitionPlan sidecar_plan(const std::string& sidecar) {
  const bool text = !sidecar.empty() && sidecar.front() == '{';
  return text ? acquire::parse_plan_sidecar(sidecar, "<sidecar>")
              : acquire::read_plan_sidecar(sidecar);
}

// The values of the plan's rows: (rows, 3) or (rows,) one channel; NaN: not measured.
std::vector<Rgb> row_values(const py::object& values, std::size_t rows) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
  if (!a) throw py::value_error("values: expected an array of numbers");
  const bool grey = a.ndim() == 1;
  if (!(grey || (a.ndim() == 2 && a.shape(1) == 3)) || std::size_t(a.shape(0)) != rows)
    throw py::value_error("values: expected (" + std::to_string(rows) + ", 3) or (" +
                          std::to_string(rows) + ",) for the plan's rows");
  std::vector<Rgb> v(rows);
  const double* d = a.data();
  for (std::size_t r = 0; r < rows; ++r)
    v[r] = grey ? Rgb{d[r], d[r], d[r]} : Rgb{d[3 * r], d[3 * r + 1], d[3 * r + 2]};
  return v;
}

py::dict plan_main(const std::string& pilot_sidecar, const py::object& values) {
  const acquire::AcquisitionPlan pilot = sidecar_plan(pilot_sidecar);
  const std::vector<Rgb> v = row_values(values, pilot.measured.size());
  acquire::AcquisitionPlan a;
  {
    py::gil_scoped_release release;
    a = acquire::main_stage_plan(pilot, v);  // std::invalid_argument: a ValueError
  }
  return plan_dict(a);
}

double plan_error(const std::string& sidecar, const py::object& values, const py::object& truth,
                  std::size_t test_pairs, std::uint64_t seed, double max_theta,
                  const std::string& space) {
  const auto es = acquire::parse_error_space(space);
  if (!es)
    throw py::value_error("space '" + space + "': expected linear, log, cbrt, nielsen or low");
  if (test_pairs < 100 || test_pairs > 10000000)
    throw py::value_error("test_pairs: expected 100 to 10000000");
  const double reach = reach_degrees(max_theta, "max_theta");
  const acquire::AcquisitionPlan a = sidecar_plan(sidecar);
  const std::vector<Rgb> v = row_values(values, a.measured.size());
  const BrdfPtr t = brdf_of(truth);
  py::gil_scoped_release release;
  const auto reconstruction = acquire::reconstruct_any(a, v, "measured");
  return acquire::reconstruction_error(*reconstruction,
                                       acquire::draw_test_pairs(*t, test_pairs, seed, *es, reach));
}

py::dict reconstruct(const std::string& sidecar, const py::object& values, const std::string& out,
                     const std::string& name) {
  const std::string ext = std::filesystem::path(out).extension().string();
  if (ext != ".binary" && ext != ".bsdf")
    throw py::value_error("out '" + out + "': write a MERL .binary or an RGL .bsdf file");
  const acquire::AcquisitionPlan a = sidecar_plan(sidecar);
  if (!a.plan.setup.isotropic)
    throw py::value_error("a full (4D) plan's reconstruction is anisotropic: not written yet");
  const std::vector<Rgb> v = row_values(values, a.measured.size());
  {
    py::gil_scoped_release release;
    const auto brdf = acquire::reconstruct_any(a, v, name);
    if (ext == ".bsdf" && a.dupuy_jakob)  // Dupuy & Jakob's own tables
      write_tensor_file(out, acquire::dupuy_jakob_plan_fields(a, v));
    else if (ext == ".binary")
      write_merl(out, *brdf);
    else
      write_rgl(out, *brdf);
  }
  py::dict d;
  d["rows"] = a.measured.size();
  d["cells"] = a.plan.cells.points();
  return d;
}

}  // namespace

double reach_degrees(double max_theta, std::string_view argument) {
  constexpr double lo = std::numbers::pi / 180, hi = std::numbers::pi / 2;
  if (!(max_theta >= lo * (1 - 1e-12) && max_theta <= hi * (1 + 1e-12))) {
    const std::string v = py::repr(py::float_(max_theta)).cast<std::string>();
    throw py::value_error(std::string(argument) + " = " + v +
                          ": the reach is in radians, from pi/180 to pi/2 (1 to 90 degrees); "
                          "every angle of the Python API is in radians (for degrees: "
                          "math.radians(" +
                          v + "))");
  }
  // Rounded to 1e-9 degrees, so that math.radians(85) is 85 degrees exactly: the settings a study
  // records (and merge_study compares) are the CLI's --max-theta 85.
  return std::clamp(std::round(max_theta * kDeg * 1e9) / 1e9, 1.0, 90.0);
}

void bind_acquisition(py::module_& m) {
  m.def("plan", &plan, py::arg("param") = "hybrid", py::arg("design") = "regular",
        py::arg("budget") = 10000, py::arg("spacing") = "own", py::arg("full") = false,
        py::arg("max_theta") = std::numbers::pi / 2, py::arg("seed") = 1,
        py::arg("instrument") = "light-detector",
        R"doc(The measurement plan of a design for a gonio-reflectometer, as `halfback plan`
(docs/acquisition.md): a dict of positions_deg (rows x 4, degrees: the motors named in motors,
light zenith, light azimuth, detector zenith, detector azimuth for the light-detector instrument;
sample tilt, sample spin, detector zenith and azimuth about the light for the sample-turning
one), wi and wo (rows x 3), row_of_point (the row each point of the design takes), travel_deg and
cell_order_travel_deg, and sidecar (the JSON text that reconstruct() reads; save it beside your
measurements), positions (the same angles in radians). The sequential design's plan is its pilot,
Dupuy & Jakob's ("dupuy-jakob", sized by budget alone) its retro-reflection: plan_main() plans
the rest from their values. max_theta: the instrument's reach from the normal, in radians (as every
angle of the Python API; `halfback plan --max-theta` takes degrees), from pi/180 to pi/2.)doc");
  m.def(
      "plan_main", &plan_main, py::arg("pilot"), py::arg("values"),
      R"doc(The main stage of a two-stage plan from its pilot, as `halfback plan --pilot`: pilot is
the pilot's sidecar (plan()'s "sidecar" text of design "sequential" or "dupuy-jakob", or a
PLAN.json path), values the values measured at its rows ((rows, 3) or (rows,); NaN: not measured;
Dupuy & Jakob's layout needs every row). Returns a dict as plan() does; its "sidecar" is what
reconstruct() reads.)doc");
  m.def("plan_error", &plan_error, py::arg("plan"), py::arg("values"), py::arg("truth"),
        py::arg("test_pairs") = 200000, py::arg("seed") = 1,
        py::arg("max_theta") = 85 * std::numbers::pi / 180, py::arg("space") = "log",
        R"doc(The study's error (metric 3, docs/study.md) of the reconstruction of a plan's
measured values against `truth` (a spec or Brdf): the relative error over test_pairs pairs drawn
from the measure within max_theta radians of the normal (the study's defaults: 85 degrees), in the error space `space`. For a
plan of design `learned`, `sequential` (its main stage) or `dupuy-jakob` (its slices), the number
the study reports for that design and budget when the values are the truth's.)doc");
  m.def("_reconstruct", &reconstruct, py::arg("plan"), py::arg("values"), py::arg("out"),
        py::arg("name"));
}

}  // namespace halfback::python
