// `halfback reconstruct`: the values a laboratory measured at the rows of a plan (`halfback
// plan`) back to a BRDF, reconstructed in the plan's parameterization as the study does
// (acquire/acquisition.hpp, docs/acquisition.md), written as a MERL or RGL file that every command
// reads.
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "command.hpp"
#include "halfback/acquire/acquisition.hpp"
#include "halfback/formats/merl.hpp"
#include "halfback/formats/rgl_writer.hpp"
#include "halfback/util/atomic_file.hpp"
#include "halfback/util/format_error.hpp"
#include "measurements.hpp"
#include "plan_inputs.hpp"

namespace halfback::cli {

namespace {

struct ReconstructOptions {
  std::string plan, measurements, name, output;
  std::vector<std::string> database;  // a plan of Nielsen's design: the BRDFs of its basis
};

// The plan, with Nielsen's database built again as it was planned (the sidecar's options).
acquire::AcquisitionPlan plan_read(const ReconstructOptions& o) {
  const auto options = acquire::sidecar_nielsen_options(o.plan);
  if (!options) {
    if (!o.database.empty())
      throw UsageError(fmt::format(
          "--database with --plan '{}': only a plan of Nielsen's design is reconstructed through "
          "a database",
          o.plan));
    return acquire::read_plan_sidecar(o.plan);
  }
  if (o.database.empty())
    throw UsageError(fmt::format(
        "--plan '{}' is of Nielsen's design: give its --database (the BRDFs it was planned with)",
        o.plan));
  return acquire::read_plan_sidecar(o.plan, nielsen_database(o.database, *options, "--database"));
}

// Dupuy & Jakob's layout written as an RGL file is its own tables (export-rgl's of the values),
// not the reconstruction tabulated again.
void write_dupuy_jakob_rgl(const std::filesystem::path& out, const acquire::AcquisitionPlan& plan,
                           const std::vector<Rgb>& values) {
  AtomicFile file(out);
  const std::vector<std::byte> bytes =
      serialize_tensor_file(acquire::dupuy_jakob_plan_fields(plan, values));
  file.write({reinterpret_cast<const char*>(bytes.data()), bytes.size()});
  file.commit();
}

int run_reconstruct(const ReconstructOptions& o) {
  const std::filesystem::path out(o.output);
  const std::string ext = out.extension().string();
  if (ext != ".binary" && ext != ".bsdf")
    throw UsageError(fmt::format("-o '{}': write a MERL .binary or an RGL .bsdf file", o.output));
  check_writable(o.output);
  const acquire::AcquisitionPlan plan = plan_read(o);
  if (!plan.plan.setup.isotropic)
    throw UsageError(
        fmt::format("--plan '{}': a full (4D) plan's reconstruction is anisotropic; "
                    "MERL and RGL files are isotropic (not written yet)",
                    o.plan));
  std::size_t measured = 0;
  const std::vector<Rgb> values = read_measurements(o.measurements, plan.measured.size(), measured);
  const std::string name =
      o.name.empty() ? std::filesystem::path(o.measurements).stem().string() : o.name;
  if (plan.plan.setup.design == acquire::Design::dupuy_jakob ||
      plan.plan.setup.design == acquire::Design::nielsen) {
    std::shared_ptr<const Brdf> brdf;
    try {
      brdf = acquire::reconstruct_any(plan, values, name);
    } catch (const std::invalid_argument& e) {  // the wrong stage; a row the layout needs
      if (plan.dupuy_jakob && !plan.dupuy_jakob->main)
        throw UsageError(fmt::format("--plan '{}': {}", o.plan, e.what()));
      throw FormatError(o.measurements, "rows", e.what());
    }
    if (ext == ".bsdf" && plan.dupuy_jakob)
      write_dupuy_jakob_rgl(out, plan, values);
    else if (ext == ".binary")
      write_merl(out, *brdf);
    else
      write_rgl(out, *brdf);
    fmt::print(stderr, "halfback reconstruct: {} of the plan's {} rows measured; {} written ({})\n",
               measured, plan.measured.size(), o.output, brdf->description());
    return kExitOk;
  }
  const acquire::GonioReconstruction brdf = acquire::reconstruct(plan, values, name);
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
  app->add_option("--database", o->database,
                  "A plan of Nielsen's design: the BRDFs of its basis, as given to `halfback "
                  "plan` (repeat the option)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
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
