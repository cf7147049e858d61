// `halfback plan`: the measurement plan of a design for a real gonio-reflectometer
// (study/acquisition.hpp, docs/acquisition.md): the positions to measure as a CSV file, and
// beside it a JSON file with what a reconstruction needs (the setup, the cells, the warps and
// which measured row each point of the design takes).
#include <fmt/format.h>

#include <filesystem>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "command.hpp"
#include "halfback/study/acquisition.hpp"
#include "halfback/util/format_error.hpp"
#include "measurements.hpp"

namespace halfback::cli {

namespace {

struct PlanOptions {
  study::PlanSettings settings;
  std::string output;
  // The sequential design's main stage: the pilot's sidecar and the values measured at its rows.
  std::string pilot, pilot_measurements;
  std::string instrument = "light-detector";
};

constexpr double kDeg = 180 / std::numbers::pi;

// The rows to measure: their index, the motors' angles in degrees and the directions.
std::string plan_csv(const study::AcquisitionPlan& a) {
  std::vector<std::string> header{"row"};
  for (std::string_view motor : study::motor_names(a.instrument))
    header.push_back(std::string(motor) + "_deg");
  for (const char* c : {"wi_x", "wi_y", "wi_z", "wo_x", "wo_y", "wo_z"}) header.emplace_back(c);
  std::vector<std::vector<double>> c(header.size(), std::vector<double>(a.measured.size()));
  for (std::size_t r = 0; r < a.measured.size(); ++r) {
    const study::GonioPosition& g = a.positions[r];
    const DirPair<double>& p = a.measured[r];
    const double row[] = {double(r),
                          g.angle[0] * kDeg,
                          g.angle[1] * kDeg,
                          g.angle[2] * kDeg,
                          g.angle[3] * kDeg,
                          p.wi.x,
                          p.wi.y,
                          p.wi.z,
                          p.wo.x,
                          p.wo.y,
                          p.wo.z};
    for (std::size_t k = 0; k < header.size(); ++k) c[k][r] = row[k];
  }
  const std::vector<std::span<const double>> columns(c.begin(), c.end());
  return to_csv(header, columns);
}

// The plan asked for: of a grid design; a sequential design's pilot; or, with --pilot, its main
// stage from the pilot's measurements.
study::AcquisitionPlan plan_asked(const PlanOptions& o) {
  if (o.pilot.empty() != o.pilot_measurements.empty())
    throw UsageError(
        "--pilot and --pilot-measurements go together (the sequential design's "
        "main stage)");
  if (!o.pilot.empty()) {
    const study::AcquisitionPlan pilot = study::read_plan_sidecar(o.pilot);
    if (!pilot.sequential || pilot.sequential->main)
      throw UsageError(fmt::format(
          "--pilot '{}': not the pilot of a sequential design (plan it with --design sequential)",
          o.pilot));
    std::size_t measured = 0;
    const std::vector<Rgb> values =
        read_measurements(o.pilot_measurements, pilot.measured.size(), measured);
    if (measured == 0)
      throw FormatError(o.pilot_measurements, "rows", "no row of the pilot was measured");
    return study::sequential_main_plan(pilot, values);
  }
  const study::GonioSetup setup = [&] {
    try {
      return study::plan_setup(o.settings);
    } catch (const std::invalid_argument& e) {
      throw UsageError(fmt::format("--{}", e.what()));  // "--design 'x': expected ..."
    }
  }();
  const auto instrument = study::parse_instrument(o.instrument);
  if (!instrument)
    throw UsageError(
        fmt::format("--instrument '{}': expected light-detector or sample-turning", o.instrument));
  return setup.design == study::Design::sequential
             ? study::sequential_pilot_plan(setup, *instrument)
             : study::acquisition_plan(setup, *instrument);
}

int run_plan(const PlanOptions& o) {
  const std::filesystem::path csv(o.output);
  if (csv.extension() != ".csv")
    throw UsageError(
        fmt::format("-o '{}': the plan is a .csv file (its .json sidecar is written "
                    "beside it)",
                    o.output));
  const std::filesystem::path json = std::filesystem::path(csv).replace_extension(".json");
  Output csv_out(csv.string()), json_out(json.string());  // both writable before any work
  const study::AcquisitionPlan a = plan_asked(o);
  const study::GonioSetup& setup = a.plan.setup;
  csv_out.write(plan_csv(a));
  json_out.write(study::plan_sidecar(a, csv.filename().string()));
  csv_out.commit();
  json_out.commit();
  const std::string stage =
      !a.sequential ? std::string()
      : a.sequential->main
          ? fmt::format(" (the main stage of a sequential design of {})", a.sequential->budget)
          : fmt::format(
                " (the pilot of a sequential design of {}: measure it, then plan the "
                "main stage with --pilot {} --pilot-measurements VALUES.csv)",
                a.sequential->budget, json.string());
  fmt::print(stderr,
             "halfback plan: {} positions to measure for the {} points of the {} design of {} "
             "spaced {}{} ({} fewer by reciprocity{}); motor travel {:.0f}° in this order, {:.0f}° "
             "in the cells' order; {} and {}\n",
             a.measured.size(), a.plan.points.size(), study::name_of(setup.design),
             name_of(setup.space), study::name_of(setup.spacing), stage,
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
  app->add_option("--param", o->settings.param, "Parameterization whose cells are measured")
      ->capture_default_str();
  app->add_option("--design", o->settings.design,
                  "regular (cell centres), stratified (a random point in each cell) or "
                  "sequential (a pilot grid, then a grid where the pilot's values ask: this "
                  "plans the pilot, --pilot the rest)")
      ->capture_default_str();
  app->add_option("--instrument", o->instrument,
                  "light-detector (the sample fixed, the light and the detector on arms) or "
                  "sample-turning (the light fixed, the sample tilted and spun, the detector on "
                  "an arm): the motors' angles in the CSV, the order and the travel "
                  "(docs/acquisition.md)")
      ->capture_default_str();
  app->add_option("--pilot", o->pilot,
                  "The sequential design's main stage: the pilot's PLAN.json (its setup is "
                  "taken from there)")
      ->type_name("FILE");
  app->add_option("--pilot-measurements", o->pilot_measurements,
                  "The values measured at the pilot's rows (as `halfback reconstruct "
                  "--measurements` reads them)")
      ->type_name("FILE");
  app->add_option("--spacing", o->settings.spacing,
                  "Spacing of the cells: own, angle or merl "
                  "(docs/study.md, Designs)")
      ->capture_default_str();
  app->add_option("--budget", o->settings.budget, "Cells wanted inside the domain")
      ->check(CLI::Range(std::size_t{1}, study::kMaxSampleBudget))
      ->capture_default_str();
  app->add_flag("--full", o->settings.full, "Plan the full (4D) form, for anisotropic materials");
  app->add_option("--max-theta", o->settings.max_theta,
                  "The instrument's reach: degrees from the normal")
      ->check(CLI::Range(1.0, 90.0))
      ->capture_default_str();
  app->add_option("--seed", o->settings.seed, "Seed of the stratified design's points")
      ->capture_default_str();
  app->add_option("-o,--output", o->output, "Output: PLAN.csv (and PLAN.json beside it)")
      ->required()
      ->type_name("FILE");
  app->footer(
      "Rows: the positions to measure, in order (light and detector zenith and azimuth in\n"
      "degrees, and the directions). An isotropic plan turns every pair so that the light is at\n"
      "azimuth 0 and measures a pair and its swap (wo, wi) once. See docs/acquisition.md.\n"
      "\n"
      "Examples:\n"
      "  halfback plan --param hybrid --budget 2000 --max-theta 85 -o plan.csv\n"
      "  halfback plan --param halfdiff --design sequential --budget 10000 -o pilot.csv\n"
      "  halfback plan --pilot pilot.json --pilot-measurements pilot-values.csv -o main.csv");
  return {app, [o] { return run_plan(*o); }};
}

}  // namespace halfback::cli
