// `halfback resample`: a BRDF tabulated on a regular grid of a parameterization (4D, isotropic
// 3D, or a 2D slice at a fixed relative azimuth), written as OpenEXR, .npz or .npy
// (brdf/resample.hpp).
#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "command.hpp"
#include "halfback/brdf/resample.hpp"
#include "halfback/formats/table_file.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::cli {

namespace {

struct ResampleOptions {
  std::string brdf, param = "hybrid", kind = "isotropic", size = "64", output;
  std::vector<std::string> ranges;
  double azimuth_deg = 0;
  bool azimuth_given = false;
  bool nodes = false;
  int threads = 0;
};

int run_resample(const ResampleOptions& o) {
  std::string problem;
  const auto space = space_or_message(o.param, problem);
  if (!problem.empty()) throw UsageError("--param " + problem);
  if (!space || *space == Space::dirs)
    throw UsageError(fmt::format("--param '{}': expected a parameterization: {}", o.param,
                                 parameterization_names()));
  const GridKind kind = o.kind == "full"        ? GridKind::full
                        : o.kind == "isotropic" ? GridKind::isotropic
                                                : GridKind::slice;
  if (o.azimuth_given && kind != GridKind::slice)
    throw UsageError("--azimuth fixes the relative azimuth of a slice: it needs --kind slice");
  double azimuth_deg = 0;
  try {
    azimuth_deg = wrap_azimuth_degrees(o.azimuth_deg, "--azimuth");  // -90 is 270, 400 is 40
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  GridSpec grid;
  try {
    grid = default_grid(*space, kind, count_list(o.size, "--size", "sample count"),
                        azimuth_deg * std::numbers::pi / 180);
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("--size: {}", e.what()));
  }
  grid.sampling = o.nodes ? GridSampling::nodes : GridSampling::centres;
  for (const std::string& r : o.ranges) {
    const std::size_t eq = r.find('='), colon = r.find(':', eq == std::string::npos ? 0 : eq);
    if (eq == std::string::npos || colon == std::string::npos)
      throw UsageError(fmt::format("--range '{}': expected NAME=LO:HI, e.g. theta_h=0:0.5", r));
    GridAxis* axis = nullptr;
    try {
      axis = &grid.axis(r.substr(0, eq));
    } catch (const std::invalid_argument& e) {
      throw UsageError(fmt::format("--range '{}': {}", r, e.what()));
    }
    axis->lo = parse_number(std::string_view(r).substr(eq + 1, colon - eq - 1), "--range " + r);
    axis->hi = parse_number(std::string_view(r).substr(colon + 1), "--range " + r);
  }
  try {
    validate(grid);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  if (!table_format_from_path(o.output))
    throw UsageError(fmt::format("-o '{}': the table is written as .exr, .npz or .npy", o.output));
  check_writable(o.output);  // an unwritable destination fails before any work
  const BrdfPtr brdf = brdf_argument(o.brdf, "--brdf");
  halfback::ResampleOptions ro;
  ro.threads = o.threads;
  const ResampledTable t = resample(*brdf, grid, ro);
  write_table(o.output, t);
  if (t.valid_count() == 0)
    warn("resample", "no grid point is inside the domain of " + o.param +
                         ": every value is NaN (check the --range options)");
  fmt::print(stderr, "halfback resample: {} written: {} grid points ({} inside the domain)\n",
             o.output, grid.points(), t.valid_count());
  return kExitOk;
}

}  // namespace

Command register_resample(CLI::App& parent) {
  auto o = std::make_shared<ResampleOptions>();
  CLI::App* app = parent.add_subcommand(
      "resample", "Tabulate a BRDF on a regular grid of a parameterization (.exr, .npz, .npy)");
  app->add_option("--brdf", o->brdf, "BRDF SPEC: a MERL, RGL or ALTA file, or a model")->required();
  app->add_option("--param", o->param, "Parameterization: " + parameterization_names())
      ->type_name("PARAM")
      ->capture_default_str();
  app->add_option("--kind", o->kind,
                  "full (4D), isotropic (3D, phi_h = 0) or slice (2D, at --azimuth)")
      ->check(CLI::IsMember({"full", "isotropic", "slice"}))
      ->capture_default_str();
  app->add_option("--azimuth", o->azimuth_deg,
                  "Slice: the relative azimuth in degrees (phi_d, or phi_k - phi_h, or phi_o - "
                  "phi_i); any finite value, wrapped into [0, 360)")
      ->each([o](const std::string&) { o->azimuth_given = true; });
  app->add_option("--size", o->size, "Samples per axis: N (every axis) or N1,N2,...")
      ->capture_default_str();
  app->add_option("--range", o->ranges,
                  "NAME=LO:HI, the range of an axis in its own units (radians, or unitless "
                  "lengths); repeatable")
      ->take_all();
  app->add_flag("--nodes", o->nodes,
                "Sample at N nodes including both ends (default: at the centres of N cells)");
  app->add_option("--threads", o->threads,
                  "Threads: 0 all cores, 1 the calling thread, n at most n")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app->add_option("-o,--output", o->output, "Output: .exr, .npz or .npy, replaced only on success")
      ->required()
      ->type_name("FILE");
  app->footer(
      "Axes (the last one is the fastest in the table):\n"
      "  full:      the 4 columns of the parameterization (see 'halfback convert --help')\n"
      "  isotropic: its 3 isotropic columns, the pair rotated to phi_h = 0\n"
      "  slice:     the first 2 isotropic columns, at a fixed relative azimuth\n"
      "Default ranges bound the domain: theta in [0, pi/2], phi in [0, 2 pi), hbar, kbar, k in\n"
      "[0, 1]. Points outside the domain have NaN values and valid = 0.\n"
      "Files: .exr (float R, G, B, valid; halfback:* attributes give the grid), .npz (rho,\n"
      "valid, axis0..., axis_names, metadata), .npy (rho only).\n"
      "\n"
      "Examples:\n"
      "  halfback resample --brdf ggx:alpha=0.2 --param hybrid --size 90,90,180 -o ggx.npz\n"
      "  halfback resample --brdf paper.bsdf --param ortho --kind slice --azimuth 90 --size 256 "
      "-o s.exr");
  return {app, [o] { return run_resample(*o); }};
}

}  // namespace halfback::cli
