// Measurement plans for a real gonio-reflectometer (docs/acquisition.md): the points of
// a design of the virtual gonio-reflectometer (gonio.hpp) as the positions of an instrument, each
// configuration measured once, in an order that keeps the motors' travel short.
//
// The instrument: a four-axis light/detector gonio-reflectometer with the sample fixed — the
// light at zenith θl and azimuth φl about the sample's normal, the detector at (θv, φv). A pair
// (ωi, ωo) is the light along ωi and the detector along ωo.
#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/acquire/dupuy_jakob_design.hpp"
#include "halfback/acquire/gonio.hpp"
#include "halfback/acquire/nielsen.hpp"
#include "halfback/acquire/samples.hpp"

namespace halfback::acquire {

// A plan's settings as a user gives them (`halfback plan`, halfback.plan, a sidecar's "setup").
struct PlanSettings {
  std::string param = "hybrid", design = "regular", spacing = "own";
  std::size_t budget = 10000;
  bool full = false;  // the full (4D) form, for anisotropic materials
  double max_theta = 90;
  std::uint64_t seed = 1;
  // The learned spacing's warps (a sequential plan's main stage, from its pilot's values).
  std::optional<LearnedWarps> learned;
};
// The setup they describe. Throws std::invalid_argument naming the setting: a param that is no
// parameterization, a design other than regular, stratified or sequential (isotropic), a spacing
// other than own, angle or merl, or learned without warps of that parameterization, a budget
// outside [1, kMaxSampleBudget], a reach outside [1, 90] degrees.
GonioSetup plan_setup(const PlanSettings& settings);

// The instruments a plan is written for: how a pair (ωi, ωo) becomes its four motors' angles.
//   light_detector  the sample fixed; the light at zenith θl and azimuth φl about the sample's
//                   normal, the detector at (θv, φv): (θi, φi, θo, φo).
//   sample_turning  the light fixed in the laboratory; the sample on a two-axis stage, spun about
//                   its normal (spin) then tilted about a laboratory axis perpendicular to the
//                   light (tilt), so that ωi points at the light: spin = −φi, tilt = θi; the
//                   detector on a two-axis arm about the sample, at a zenith from the light (the
//                   angle between ωi and ωo, up to 180°) and an azimuth about it, 0 in the plane of
//                   the tilt away from the normal's lean (the mirror direction is at zenith 2θi,
//                   azimuth 180°).
enum class Instrument { light_detector, sample_turning };
std::string_view name_of(Instrument instrument);  // "light-detector", "sample-turning"
std::optional<Instrument> parse_instrument(std::string_view name);
// The motors in the order of GonioPosition::angle (the plan's CSV columns, in degrees).
std::array<std::string_view, 4> motor_names(Instrument instrument);

// An instrument's position: its motors' angles in radians, in the order of motor_names. Angles 1
// and 3 (φl and φv; the spin and the detector's azimuth) turn all the way round, in [0, 2π).
struct GonioPosition {
  std::array<double, 4> angle{};
};
GonioPosition position_of(const DirPair<double>& pair,
                          Instrument instrument = Instrument::light_detector);
// The pair at a position (position_of's inverse, to rounding).
DirPair<double> pair_at(const GonioPosition& position,
                        Instrument instrument = Instrument::light_detector);

// The motors' travel from one position to the next: the sum of the four axes' moves (radians),
// angles 1 and 3 the short way round.
double travel(const GonioPosition& from, const GonioPosition& to);

struct AcquisitionPlan {
  GonioPlan plan;
  Instrument instrument = Instrument::light_detector;
  // The positions to measure, in the order to measure them.
  std::vector<DirPair<double>> measured;
  std::vector<GonioPosition> positions;  // the same, as the motors' angles
  // plan.points[k] takes the value measured at measured[row_of_point[k]].
  std::vector<std::size_t> row_of_point;
  // The motors' travel through `measured` in this order, and through the plan's points in the
  // order of its cells (before reciprocity and the isotropic turn).
  double travel = 0, cell_order_travel = 0;
  // A stage of the sequential design (sequential_design.hpp): the design's whole budget, and
  // whether this is its main stage (else its pilot). The plan itself is a grid (`plan.setup`).
  struct SequentialStage {
    std::size_t budget = 0;
    bool main = false;
  };
  std::optional<SequentialStage> sequential;
  // A stage of Dupuy & Jakob's layout (plan.setup.design dupuy_jakob; its points are the pairs of
  // dupuy_jakob_retro_pairs, or of dupuy_jakob_slice_pairs for the main stage, not a grid's):
  // the design's budget, whether this is the slices' stage (else the retro-reflection's), and for
  // the slices the values measured at the retro-reflection's pairs, which they follow from.
  struct DupuyJakobStage {
    std::size_t budget = 0;
    bool main = false;
    std::vector<Rgb> retro;
  };
  std::optional<DupuyJakobStage> dupuy_jakob;
  // Nielsen's design (plan.setup.design nielsen; its points are the candidate configurations
  // chosen): the basis they were chosen in (the whole database: the material measured is not in
  // it, its options those of the design: reach, seed, Tikhonov weight), the configurations and
  // the database's fingerprint.
  struct NielsenDesign {
    std::shared_ptr<const NielsenBasis> basis;
    std::vector<std::size_t> configurations;
    std::string database;
  };
  std::optional<NielsenDesign> nielsen;
};

// The plan of a setup for the instrument:
//   * an isotropic setup's pairs are turned about the normal so that the light's azimuth is 0
//     (the BRDF is the same at every turn: a three-axis instrument suffices);
//   * by reciprocity, a pair whose swap (ωo, ωi) is also in the plan (to 1e-9 rad) is measured
//     once: the one whose light is nearer the normal;
//   * the order is a serpentine: the light's zenith in bands, the detector's azimuth in strips
//     within a band, its zenith along a strip, each band and strip run back and forth.
//     (When the points' own order, their first rows, travels less, that order is kept.)
// The order and the travel are the instrument's; which pairs are measured is not. Throws what
// gonio_plan() throws (the sequential design is two plans: below).
AcquisitionPlan acquisition_plan(const GonioSetup& setup,
                                 Instrument instrument = Instrument::light_detector);

// The sequential design's stages for the instrument (docs/acquisition.md, "The sequential
// design"): the pilot's plan, then the main stage's from the values measured at the pilot's rows
// (row_values[r] at pilot.measured[r]; NaN: not measured), in the warps their second differences
// ask for (error space log, the study's default). Throws std::invalid_argument for a setup that
// is not sequential, a pilot that is not a sequential pilot, counts that differ.
AcquisitionPlan sequential_pilot_plan(const GonioSetup& setup,
                                      Instrument instrument = Instrument::light_detector);
AcquisitionPlan sequential_main_plan(const AcquisitionPlan& pilot, std::span<const Rgb> row_values);

// Dupuy & Jakob's layout for the instrument (dupuy_jakob_design.hpp): the retro-reflection's
// plan for a budget, then the slices' from the values measured at its rows (every row measured:
// the power iteration reads them all). The layout reaches 90°: it has no reach of its own (the
// study measures it whole). Throws std::invalid_argument for a budget below the smallest layout,
// a plan that is not the retro-reflection's, counts that differ, a value that is not finite.
AcquisitionPlan dupuy_jakob_pilot_plan(std::size_t budget,
                                       Instrument instrument = Instrument::light_detector);
AcquisitionPlan dupuy_jakob_main_plan(const AcquisitionPlan& pilot,
                                      std::span<const Rgb> row_values);
// The main stage of either two-stage design from its pilot: sequential_main_plan or
// dupuy_jakob_main_plan. Throws std::invalid_argument for a plan that is neither's pilot.
AcquisitionPlan main_stage_plan(const AcquisitionPlan& pilot, std::span<const Rgb> row_values);

// Nielsen et al.'s design for the instrument (nielsen.hpp): the first `count` directions of the
// greedy selection in the basis of the whole database (its options: the reach, the seed).
// Throws std::invalid_argument for a count of 0 or above the database's candidate configurations.
AcquisitionPlan nielsen_plan(std::shared_ptr<const NielsenDatabase> database, std::size_t count,
                             Instrument instrument = Instrument::light_detector);

// The plan's sidecar, PLAN.json beside PLAN.csv (docs/acquisition.md, "Files"): the setup, the
// cells and warps, the counts, the travel, and row_of_point. `measurements` names the CSV file.
// What the points follow from is written too (a learned spacing's warps, the retro-reflection's
// values of Dupuy & Jakob's slices, Nielsen's configurations and database), so that the plan is
// planned again from the sidecar alone (Nielsen's: and its database).
std::string plan_sidecar(const AcquisitionPlan& plan, std::string_view measurements);
// The plan a sidecar describes: its setup planned again (the points depend on the setup alone),
// checked against the sidecar's counts and rows. Throws FormatError naming the file and the
// field (unreadable, not JSON, a field missing or of the wrong kind, a plan that does not
// match: made by another version of halfback, or edited).
// A plan of Nielsen's design is planned again in `database`, which must be the one it was planned
// in (its fingerprint): without it, or with another, FormatError says so.
AcquisitionPlan read_plan_sidecar(const std::filesystem::path& path,
                                  std::shared_ptr<const NielsenDatabase> database = nullptr);
// The options of the database a plan of Nielsen's design was planned in (nullopt for a plan of
// another design): what the database is built with again, from its members, to read the plan.
// Throws FormatError as read_plan_sidecar.
std::optional<NielsenOptions> sidecar_nielsen_options(const std::filesystem::path& path);
// The same from the sidecar's text (`source` names it in errors); a budget above `max_budget`
// (planning it again is the planner's cost, not the reader's) is refused like a bad field.
AcquisitionPlan parse_plan_sidecar(std::string_view text, const std::string& source,
                                   std::size_t max_budget = kMaxSampleBudget,
                                   std::shared_ptr<const NielsenDatabase> database = nullptr);

// The values measured at a plan's rows (row_values[r] at measured[r]; NaN where a row was not
// measured), spread back to its points, reconstructed as the study does. Throws
// std::invalid_argument when the counts differ or a value is negative (naming the row),
// std::runtime_error when no value is finite.
GonioReconstruction reconstruct(const AcquisitionPlan& plan, std::span<const Rgb> row_values,
                                std::string name);
// The same for a plan of any design, reconstructed as the study does: a grid's as above, Dupuy &
// Jakob's slices' stage as their RGL file (dupuy_jakob_fields: every row must be measured),
// Nielsen's as the combination of its basis (nielsen.hpp). Throws std::invalid_argument as
// reconstruct, and for the retro-reflection's stage of Dupuy & Jakob's layout (not a material).
std::shared_ptr<const Brdf> reconstruct_any(const AcquisitionPlan& plan,
                                            std::span<const Rgb> row_values, std::string name);
// Dupuy & Jakob's slices' stage: the RGL file's fields (what reconstruct_any reads back).
std::vector<TensorFieldData> dupuy_jakob_plan_fields(const AcquisitionPlan& plan,
                                                     std::span<const Rgb> row_values,
                                                     int threads = 0);

}  // namespace halfback::acquire
