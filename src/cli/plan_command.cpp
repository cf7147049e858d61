// `halfback plan`: the measurement plan of a design for a real gonio-reflectometer
// (study/acquisition.hpp, docs/acquisition.md): the positions to measure as a CSV file, and
// beside it a JSON file with what a reconstruction needs (the setup, the cells, the warps and
// which measured row each point of the design takes).
#include <fmt/format.h>

#include <filesystem>
#include <numbers>
#include <string>

#include "command.hpp"
#include "halfback/study/acquisition.hpp"

namespace halfback::cli {

namespace {

struct PlanOptions {
  std::string param = "hybrid", design = "regular", spacing = "own", output;
  std::size_t budget = 10000;
  bool full = false;
  double max_theta = 90;
  std::uint64_t seed = 1;
};

constexpr double kDeg = 180 / std::numbers::pi;

study::GonioSetup setup_of(const PlanOptions& o) {
  study::GonioSetup s;
  const auto space = space_from_name(o.param);
  if (!space || space->is_dirs())
    throw UsageError(fmt::format("--param '{}': expected a parameterization: {}", o.param,
                                 parameterization_names()));
  s.space = *space;
  const auto design = study::parse_design(o.design);
  if (!design)
    throw UsageError(fmt::format("--design '{}': expected regular or stratified", o.design));
  s.design = *design;
  const auto spacing = study::parse_spacing(o.spacing);
  if (!spacing || *spacing == study::Spacing::learned)
    throw UsageError(
        fmt::format("--spacing '{}': expected own, angle or merl (a learned spacing "
                    "needs the profiles of a study)",
                    o.spacing));
  s.spacing = *spacing;
  s.isotropic = !o.full;
  s.budget = o.budget;
  s.max_theta_deg = o.max_theta;
  s.seed = o.seed;
  return s;
}

std::string plan_csv(const study::AcquisitionPlan& a) {
  std::string out =
      "row,light_theta_deg,light_phi_deg,detector_theta_deg,detector_phi_deg,"
      "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n";
  for (std::size_t r = 0; r < a.measured.size(); ++r) {
    const study::GonioPosition& g = a.positions[r];
    const DirPair<double>& p = a.measured[r];
    out += fmt::format(
        "{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n", r,
        g.light_theta * kDeg, g.light_phi * kDeg, g.detector_theta * kDeg, g.detector_phi * kDeg,
        p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z);
  }
  return out;
}

int run_plan(const PlanOptions& o) {
  const study::GonioSetup setup = setup_of(o);
  const std::filesystem::path csv(o.output);
  if (csv.extension() != ".csv")
    throw UsageError(
        fmt::format("-o '{}': the plan is a .csv file (its .json sidecar is written "
                    "beside it)",
                    o.output));
  const std::filesystem::path json = std::filesystem::path(csv).replace_extension(".json");
  Output csv_out(csv.string()), json_out(json.string());  // both writable before any work
  const study::AcquisitionPlan a = study::acquisition_plan(setup);
  csv_out.write(plan_csv(a));
  json_out.write(study::plan_sidecar(a, csv.filename().string()));
  csv_out.commit();
  json_out.commit();
  fmt::print(stderr,
             "halfback plan: {} positions to measure for the {} points of the {} design of {} "
             "spaced {} ({} fewer by reciprocity{}); motor travel {:.0f}° in this order, {:.0f}° "
             "in the cells' order; {} and {}\n",
             a.measured.size(), a.plan.points.size(), study::name_of(setup.design),
             name_of(setup.space), study::name_of(setup.spacing),
             a.plan.points.size() - a.measured.size(),
             setup.isotropic ? ", the light at azimuth 0 by isotropy" : "", a.travel * kDeg,
             a.cell_order_travel * kDeg, csv.string(), json.string());
  return kExitOk;
}

}  // namespace

Command register_plan(CLI::App& parent) {
  auto o = std::make_shared<PlanOptions>();
  CLI::App* app = parent.add_subcommand(
      "plan", "Measurement plan of a design for a real gonio-reflectometer (CSV + JSON sidecar)");
  app->add_option("--param", o->param, "Parameterization whose cells are measured")
      ->capture_default_str();
  app->add_option("--design", o->design,
                  "regular (cell centres) or stratified (a random point "
                  "in each cell)")
      ->capture_default_str();
  app->add_option("--spacing", o->spacing,
                  "Spacing of the cells: own, angle or merl "
                  "(docs/study.md, Designs)")
      ->capture_default_str();
  app->add_option("--budget", o->budget, "Cells wanted inside the domain")
      ->check(CLI::Range(std::size_t{1}, std::size_t{10000000}))
      ->capture_default_str();
  app->add_flag("--full", o->full, "Plan the full (4D) form, for anisotropic materials");
  app->add_option("--max-theta", o->max_theta, "The instrument's reach: degrees from the normal")
      ->check(CLI::Range(1.0, 90.0))
      ->capture_default_str();
  app->add_option("--seed", o->seed, "Seed of the stratified design's points")
      ->capture_default_str();
  app->add_option("-o,--output", o->output, "Output: PLAN.csv (and PLAN.json beside it)")
      ->required()
      ->type_name("FILE");
  app->footer(
      "Rows: the positions to measure, in order (light and detector zenith and azimuth in\n"
      "degrees, and the directions). An isotropic plan turns every pair so that the light is at\n"
      "azimuth 0 and measures a pair and its swap (wo, wi) once. See docs/acquisition.md.\n"
      "\n"
      "Example:\n"
      "  halfback plan --param hybrid --budget 2000 --max-theta 85 -o plan.csv");
  return {app, [o] { return run_plan(*o); }};
}

}  // namespace halfback::cli
