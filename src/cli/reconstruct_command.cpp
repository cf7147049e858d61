// `halfback reconstruct`: the values a laboratory measured at the rows of a plan (`halfback
// plan`) back to a BRDF, reconstructed in the plan's parameterization as the study does
// (study/acquisition.hpp, docs/acquisition.md), written as a MERL or RGL file that every command
// reads.
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "command.hpp"
#include "halfback/formats/merl.hpp"
#include "halfback/formats/rgl_writer.hpp"
#include "halfback/study/acquisition.hpp"
#include "halfback/util/format_error.hpp"
#include "measurements.hpp"

namespace halfback::cli {

namespace {

struct ReconstructOptions {
  std::string plan, measurements, name, output;
};

int run_reconstruct(const ReconstructOptions& o) {
  const std::filesystem::path out(o.output);
  const std::string ext = out.extension().string();
  if (ext != ".binary" && ext != ".bsdf")
    throw UsageError(fmt::format("-o '{}': write a MERL .binary or an RGL .bsdf file", o.output));
  check_writable(o.output);
  const study::AcquisitionPlan plan = study::read_plan_sidecar(o.plan);
  if (!plan.plan.setup.isotropic)
    throw UsageError(
        fmt::format("--plan '{}': a full (4D) plan's reconstruction is anisotropic; "
                    "MERL and RGL files are isotropic (not written yet)",
                    o.plan));
  std::size_t measured = 0;
  const std::vector<Rgb> values = read_measurements(o.measurements, plan.measured.size(), measured);
  const std::string name =
      o.name.empty() ? std::filesystem::path(o.measurements).stem().string() : o.name;
  const study::GonioReconstruction brdf = study::reconstruct(plan, values, name);
  if (ext == ".binary")
    write_merl(out, brdf);
  else
    write_rgl(out, brdf);
  fmt::print(stderr,
             "halfback reconstruct: {} of the plan's {} rows measured; {} of its {} cells filled "
             "from their neighbours; {} written ({})\n",
             measured, plan.measured.size(), plan.plan.cells.points() - brdf.samples(),
             plan.plan.cells.points(), o.output, brdf.description());
  return kExitOk;
}

}  // namespace

Command register_reconstruct(CLI::App& parent) {
  auto o = std::make_shared<ReconstructOptions>();
  CLI::App* app = parent.add_subcommand(
      "reconstruct", "A BRDF from the values measured at a plan's positions (MERL or RGL file)");
  app->add_option("--plan", o->plan, "PLAN.json, written by `halfback plan`")->required();
  app->add_option("--measurements", o->measurements,
                  "CSV: row and r, g, b (or row and value), a line per measured row")
      ->required();
  app->add_option("--name", o->name, "The material's name (default: the measurements' file name)");
  app->add_option("-o,--output", o->output, "Output: .binary (MERL) or .bsdf (RGL)")
      ->required()
      ->type_name("FILE");
  app->footer(
      "Rows missing or not finite are not measured: their points are filled from the\n"
      "neighbouring cells, as cells out of the instrument's reach (docs/acquisition.md).\n"
      "\n"
      "Example:\n"
      "  halfback plan --budget 2000 -o plan.csv\n"
      "  halfback reconstruct --plan plan.json --measurements lab.csv -o material.binary");
  return {app, [o] { return run_reconstruct(*o); }};
}

}  // namespace halfback::cli
