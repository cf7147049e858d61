#include "acquisition.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "halfback/formats/merl.hpp"
#include "halfback/formats/rgl_writer.hpp"
#include "halfback/study/acquisition.hpp"

namespace py = pybind11;

namespace halfback::python {

namespace {

constexpr double kDeg = 180 / std::numbers::pi;

py::dict plan(const std::string& param, const std::string& design, std::size_t budget,
              const std::string& spacing, bool full, double max_theta, std::uint64_t seed,
              const std::string& instrument_name) {
  // plan_setup's std::invalid_argument reaches Python as a ValueError naming the setting.
  const study::GonioSetup s =
      study::plan_setup({param, design, spacing, budget, full, max_theta, seed, std::nullopt});
  const auto instrument = study::parse_instrument(instrument_name);
  if (!instrument)
    throw py::value_error("instrument '" + instrument_name +
                          "': expected light-detector or sample-turning");
  study::AcquisitionPlan a;
  {
    py::gil_scoped_release release;
    // A sequential design's plan is its pilot (the main stage needs the pilot's values).
    a = s.design == study::Design::sequential ? study::sequential_pilot_plan(s, *instrument)
                                              : study::acquisition_plan(s, *instrument);
  }
  const auto rows = py::ssize_t(a.measured.size());
  py::array_t<double> positions({rows, py::ssize_t(4)}), wi({rows, py::ssize_t(3)}),
      wo({rows, py::ssize_t(3)});
  auto p = positions.mutable_unchecked<2>();
  auto i = wi.mutable_unchecked<2>();
  auto o = wo.mutable_unchecked<2>();
  for (py::ssize_t r = 0; r < rows; ++r) {
    const study::GonioPosition& g = a.positions[std::size_t(r)];
    const DirPair<double>& d = a.measured[std::size_t(r)];
    for (py::ssize_t m = 0; m < 4; ++m) p(r, m) = g.angle[std::size_t(m)] * kDeg;
    i(r, 0) = d.wi.x, i(r, 1) = d.wi.y, i(r, 2) = d.wi.z;
    o(r, 0) = d.wo.x, o(r, 1) = d.wo.y, o(r, 2) = d.wo.z;
  }
  py::dict out;
  out["positions_deg"] = positions;
  py::list motors;
  for (std::string_view name : study::motor_names(a.instrument)) motors.append(std::string(name));
  out["motors"] = motors;
  out["wi"] = wi;
  out["wo"] = wo;
  out["row_of_point"] =
      py::array_t<std::size_t>(py::ssize_t(a.row_of_point.size()), a.row_of_point.data());
  out["travel_deg"] = a.travel * kDeg;
  out["cell_order_travel_deg"] = a.cell_order_travel * kDeg;
  out["sidecar"] = study::plan_sidecar(a, "measurements.csv");
  return out;
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

py::dict reconstruct(const std::string& sidecar, const py::object& values, const std::string& out,
                     const std::string& name) {
  const std::string ext = std::filesystem::path(out).extension().string();
  if (ext != ".binary" && ext != ".bsdf")
    throw py::value_error("out '" + out + "': write a MERL .binary or an RGL .bsdf file");
  const bool text = !sidecar.empty() && sidecar.front() == '{';
  const study::AcquisitionPlan a =
      text ? study::parse_plan_sidecar(sidecar, "<sidecar>") : study::read_plan_sidecar(sidecar);
  if (!a.plan.setup.isotropic)
    throw py::value_error("a full (4D) plan's reconstruction is anisotropic: not written yet");
  const std::vector<Rgb> v = row_values(values, a.measured.size());
  {
    py::gil_scoped_release release;
    const study::GonioReconstruction brdf = study::reconstruct(a, v, name);
    if (ext == ".binary")
      write_merl(out, brdf);
    else
      write_rgl(out, brdf);
  }
  py::dict d;
  d["rows"] = a.measured.size();
  d["cells"] = a.plan.cells.points();
  return d;
}

}  // namespace

void bind_acquisition(py::module_& m) {
  m.def("plan", &plan, py::arg("param") = "hybrid", py::arg("design") = "regular",
        py::arg("budget") = 10000, py::arg("spacing") = "own", py::arg("full") = false,
        py::arg("max_theta") = 90.0, py::arg("seed") = 1, py::arg("instrument") = "light-detector",
        R"doc(The measurement plan of a design for a gonio-reflectometer, as `halfback plan`
(docs/acquisition.md): a dict of positions_deg (rows x 4, degrees: the motors named in motors,
light zenith, light azimuth, detector zenith, detector azimuth for the light-detector instrument;
sample tilt, sample spin, detector zenith and azimuth about the light for the sample-turning
one), wi and wo (rows x 3), row_of_point (the row each point of the design takes), travel_deg and
cell_order_travel_deg, and sidecar (the JSON text that reconstruct() reads; save it beside your
measurements). The sequential design's plan is its pilot.)doc");
  m.def("_reconstruct", &reconstruct, py::arg("plan"), py::arg("values"), py::arg("out"),
        py::arg("name"));
}

}  // namespace halfback::python
