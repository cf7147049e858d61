// `halfback plan`: the measurement plan of a design for a real gonio-reflectometer
// (acquire/acquisition.hpp, docs/acquisition.md): the positions to measure as a CSV file, and
// beside it a JSON file with what a reconstruction needs (the setup, the cells, the warps and
// which measured row each point of the design takes).
#include <fmt/format.h>

#include <filesystem>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "command.hpp"
#include "halfback/acquire/acquisition.hpp"
#include "halfback/util/format_error.hpp"
#include "measurements.hpp"
#include "plan_inputs.hpp"

namespace halfback::cli {

namespace {

struct PlanOptions {
  acquire::PlanSettings settings;
  std::string output;
  // The sequential design's main stage: the pilot's sidecar and the values measured at its rows.
  std::string pilot, pilot_measurements;
  std::string instrument = "light-detector";
  // What the designs learn from: Nielsen's database (or BRDFs whose profiles the learned spacing
  // takes), a study's profiles, the label of one left out; Nielsen's Tikhonov weight (its count
  // of measurements is the budget).
  std::vector<std::string> database, profiles;
  std::string leave_out;
  double eta = acquire::NielsenOptions{}.eta;
  // The options of the setup given on the command line (refused with --pilot, whose sidecar
  // holds the setup).
  std::vector<std::string> setup_given;
};

// The options that set up a plan, which --pilot takes from the pilot's sidecar instead.
constexpr const char* kSetupOptions[] = {"--param",    "--design",    "--instrument", "--spacing",
                                         "--budget",   "--max-theta", "--seed",       "--full",
                                         "--database", "--profiles",  "--leave-out",  "--eta"};

constexpr double kDeg = 180 / std::numbers::pi;

// The rows to measure: their index, the motors' angles in degrees and the directions.
std::string plan_csv(const acquire::AcquisitionPlan& a) {
  std::vector<std::string> header{"row"};
  for (std::string_view motor : acquire::motor_names(a.instrument))
    header.push_back(std::string(motor) + "_deg");
  for (const char* c : {"wi_x", "wi_y", "wi_z", "wo_x", "wo_y", "wo_z"}) header.emplace_back(c);
  std::vector<std::vector<double>> c(header.size(), std::vector<double>(a.measured.size()));
  for (std::size_t r = 0; r < a.measured.size(); ++r) {
    const acquire::GonioPosition& g = a.positions[r];
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

// The first of `options` given, refused with the design: it does not take it (`why`).
void refuse_options(const PlanOptions& o, std::initializer_list<std::string_view> options,
                    std::string_view why) {
  for (const std::string& given : o.setup_given)
    if (std::find(options.begin(), options.end(), given) != options.end())
      throw UsageError(fmt::format("{} with --design {}: {}", given, o.settings.design, why));
}

// The main stage of a two-stage design from its pilot's sidecar and measurements.
acquire::AcquisitionPlan main_stage_asked(const PlanOptions& o) {
  if (!o.setup_given.empty())
    throw UsageError(fmt::format(
        "{} with --pilot: the main stage's setup is the pilot's (its sidecar's design, "
        "parameterization, budget, reach and instrument); leave {} out, or plan another pilot",
        o.setup_given.front(), o.setup_given.size() == 1 ? "it" : "them"));
  const acquire::AcquisitionPlan pilot = acquire::read_plan_sidecar(o.pilot);
  const bool sequential = pilot.sequential && !pilot.sequential->main;
  const bool retro = pilot.dupuy_jakob && !pilot.dupuy_jakob->main;
  if (!sequential && !retro)
    throw UsageError(fmt::format(
        "--pilot '{}': not the pilot of a sequential design or Dupuy & Jakob's layout (plan it "
        "with --design sequential or dupuy-jakob)",
        o.pilot));
  std::size_t measured = 0;
  const std::vector<Rgb> values =
      read_measurements(o.pilot_measurements, pilot.measured.size(), measured);
  if (measured == 0)
    throw FormatError(o.pilot_measurements, "rows", "no row of the pilot was measured");
  try {
    return acquire::main_stage_plan(pilot, values);
  } catch (const std::invalid_argument& e) {  // a row the layout needs, not measured: the data's
    throw FormatError(o.pilot_measurements, "rows", e.what());
  }
}

acquire::AcquisitionPlan dupuy_jakob_asked(const PlanOptions& o, acquire::Instrument instrument) {
  refuse_options(o,
                 {"--param", "--spacing", "--full", "--max-theta", "--seed", "--database",
                  "--profiles", "--leave-out", "--eta"},
                 "the layout is Dupuy & Jakob's own (their parameterization, to 90°), sized by "
                 "--budget alone");
  try {
    return acquire::dupuy_jakob_pilot_plan(o.settings.budget, instrument);
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("--budget: {}", e.what()));
  }
}

acquire::AcquisitionPlan nielsen_asked(const PlanOptions& o, acquire::Instrument instrument) {
  refuse_options(o, {"--param", "--spacing", "--full", "--profiles", "--leave-out"},
                 "Nielsen's design measures --budget configurations of its --database's basis "
                 "(MERL's bins)");
  if (o.database.empty())
    throw UsageError("--design nielsen needs its --database (two or more isotropic BRDFs)");
  if (std::find(o.setup_given.begin(), o.setup_given.end(), "--budget") == o.setup_given.end())
    throw UsageError(
        "--design nielsen needs --budget (its measurements, >= 1; --count is its older "
        "name)");
  acquire::NielsenOptions options;  // the study's: its reach, seed and Tikhonov weight
  options.max_theta_deg = o.settings.max_theta;
  options.seed = o.settings.seed;
  options.eta = o.eta;
  const auto database = nielsen_database(o.database, options, "--database");
  try {
    return acquire::nielsen_plan(database, o.settings.budget, instrument);
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("--{}", e.what()));  // "--budget 0: expected 1 to ..."
  }
}

// The plan asked for: of a grid design (the learned spacing's warps from profiles); a two-stage
// design's pilot, or with --pilot its main stage; one of the literature's designs.
acquire::AcquisitionPlan plan_asked(const PlanOptions& o) {
  if (o.pilot.empty() != o.pilot_measurements.empty())
    throw UsageError(
        "--pilot and --pilot-measurements go together (the main stage of the sequential design "
        "or of Dupuy & Jakob's layout)");
  if (!o.pilot.empty()) return main_stage_asked(o);
  const auto instrument = acquire::parse_instrument(o.instrument);
  if (!instrument)
    throw UsageError(
        fmt::format("--instrument '{}': expected light-detector or sample-turning", o.instrument));
  if (o.settings.design == "dupuy-jakob") return dupuy_jakob_asked(o, *instrument);
  if (o.settings.design == "nielsen") return nielsen_asked(o, *instrument);
  acquire::PlanSettings settings = o.settings;
  if (settings.design == "learned") {  // the study's learned design: the regular grid, learned
    if (std::find(o.setup_given.begin(), o.setup_given.end(), "--spacing") != o.setup_given.end() &&
        settings.spacing != "learned")
      throw UsageError(
          fmt::format("--spacing {} with --design learned: the learned design's spacing is learned",
                      settings.spacing));
    settings.design = "regular";
    settings.spacing = "learned";
  }
  refuse_options(o, {"--eta"}, "that is Nielsen's design's");
  if (settings.spacing == "learned") {
    if (o.profiles.empty() && o.database.empty())
      throw UsageError(
          "the learned spacing needs what to learn from: --profiles (a study's profile files or "
          "their folder, OUT/profiles/SPACE-GRID) or --database (BRDFs)");
    const auto space = space_from_name(settings.param);
    if (space && !space->is_dirs())
      settings.learned = learned_warps(o.profiles, o.database, o.leave_out, *space);
  } else {
    refuse_options(o, {"--database", "--profiles", "--leave-out"},
                   "only the learned spacing and Nielsen's design learn from other BRDFs");
  }
  const acquire::GonioSetup setup = [&] {
    try {
      return acquire::plan_setup(settings);
    } catch (const std::invalid_argument& e) {
      throw UsageError(fmt::format("--{}", e.what()));  // "--design 'x': expected ..."
    }
  }();
  return setup.design == acquire::Design::sequential
             ? acquire::sequential_pilot_plan(setup, *instrument)
             : acquire::acquisition_plan(setup, *instrument);
}

// What the plan is, for the summary line.
std::string plan_described(const acquire::AcquisitionPlan& a, const std::filesystem::path& json) {
  const acquire::GonioSetup& setup = a.plan.setup;
  if (a.dupuy_jakob)
    return a.dupuy_jakob->main
               ? fmt::format("the incidence slices of Dupuy & Jakob's layout of {}",
                             a.dupuy_jakob->budget)
               : fmt::format(
                     "the retro-reflection of Dupuy & Jakob's layout of {}: measure it, then plan "
                     "the slices with --pilot {} --pilot-measurements VALUES.csv",
                     a.dupuy_jakob->budget, json.string());
  if (a.nielsen)
    return fmt::format("Nielsen's design of {} in the basis of {}", setup.budget,
                       a.nielsen->database);
  const std::string stage =
      !a.sequential ? std::string()
      : a.sequential->main
          ? fmt::format(" (the main stage of a sequential design of {})", a.sequential->budget)
          : fmt::format(
                " (the pilot of a sequential design of {}: measure it, then plan the "
                "main stage with --pilot {} --pilot-measurements VALUES.csv)",
                a.sequential->budget, json.string());
  return fmt::format("the {} design of {} spaced {}{}", acquire::name_of(setup.design),
                     name_of(setup.space), acquire::name_of(setup.spacing), stage);
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
  const acquire::AcquisitionPlan a = plan_asked(o);
  const acquire::GonioSetup& setup = a.plan.setup;
  if (a.measured.empty())
    throw UsageError(fmt::format(
        "nothing to measure: no cell of the design of {} reaches a point within {}° of the "
        "normal (--max-theta); raise --max-theta or --budget",
        setup.budget, setup.max_theta_deg));
  csv_out.write(plan_csv(a));
  json_out.write(acquire::plan_sidecar(a, csv.filename().string()));
  csv_out.commit();
  json_out.commit();
  fmt::print(stderr,
             "halfback plan: {} positions to measure for the {} points of {} ({} fewer by "
             "reciprocity{}); motor travel {:.0f}° in this order, {:.0f}° in the points' order; "
             "{} and {}\n",
             a.measured.size(), a.plan.points.size(), plan_described(a, json),
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
  app->add_option("--param", o->settings.param,
                  "Parameterization whose cells are measured: " + parameterization_names())
      ->type_name("PARAM")
      ->capture_default_str();
  app->add_option("--design", o->settings.design,
                  "regular (cell centres), stratified (a random point in each cell), "
                  "sequential (a pilot grid, then a grid where the pilot's values ask: this "
                  "plans the pilot, --pilot the rest), learned (the regular grid in warps "
                  "learned from --profiles or --database), dupuy-jakob (Dupuy & Jakob's layout: "
                  "the retro-reflection, then with --pilot the slices) or nielsen (--budget "
                  "directions of the basis of --database)")
      ->capture_default_str();
  app->add_option("--instrument", o->instrument,
                  "light-detector (the sample fixed, the light and the detector on arms) or "
                  "sample-turning (the light fixed, the sample tilted and spun, the detector on "
                  "an arm): the motors' angles in the CSV, the order and the travel "
                  "(docs/acquisition.md)")
      ->capture_default_str();
  app->add_option("--pilot", o->pilot,
                  "The main stage of the sequential design or Dupuy & Jakob's layout: the pilot's "
                  "PLAN.json (its setup is "
                  "taken from there)")
      ->type_name("FILE");
  app->add_option("--pilot-measurements", o->pilot_measurements,
                  "The values measured at the pilot's rows (as `halfback reconstruct "
                  "--measurements` reads them)")
      ->type_name("FILE");
  app->add_option("--spacing", o->settings.spacing,
                  "Spacing of the cells: own, angle, merl or learned "
                  "(docs/study.md, Designs)")
      ->capture_default_str();
  app->add_option("--database", o->database,
                  "BRDFs to learn from (files, folders, specs; repeat the option): Nielsen's "
                  "basis, or the learned spacing's profiles taken as a study takes them")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app->add_option("--profiles", o->profiles,
                  "The learned spacing: a study's .profile files or their folder "
                  "(OUT/profiles/SPACE-GRID; repeat the option)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app->add_option("--leave-out", o->leave_out,
                  "The learned spacing: the label of a profile not to learn from (as the study "
                  "leaves out the BRDF it studies)");
  app->add_option("--eta", o->eta,
                  "Nielsen's design: the Tikhonov weight of its reconstruction (the study's "
                  "--nielsen-eta)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app->add_option("--budget,--count", o->settings.budget,
                  "Measurements: the cells wanted inside the domain (dupuy-jakob: the layout's "
                  "measurements; nielsen: its directions, no default; --count is an alias)")
      ->check(CLI::Range(std::size_t{1}, acquire::kMaxSampleBudget))
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
      "  halfback plan --pilot pilot.json --pilot-measurements pilot-values.csv -o main.csv\n"
      "  halfback plan --design dupuy-jakob --budget 10000 -o retro.csv\n"
      "  halfback plan --design learned --param hybrid --profiles study/profiles/log-32x32x32 "
      "-o learned.csv\n"
      "  halfback plan --design nielsen --database merl-networks/ --budget 20 -o nielsen.csv");
  const auto sidecar = [o] {
    const std::filesystem::path csv(o->output);
    if (csv.extension() != ".csv") return std::vector<std::string>{};
    return std::vector<std::string>{std::filesystem::path(csv).replace_extension(".json").string()};
  };
  const auto run = [o, app] {
    for (const char* name : kSetupOptions)
      if (app->count(name) > 0) o->setup_given.emplace_back(name);
    return run_plan(*o);
  };
  return {app, run, sidecar};
}

}  // namespace halfback::cli
