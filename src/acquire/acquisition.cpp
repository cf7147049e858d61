#include "halfback/acquire/acquisition.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <type_traits>

#include "halfback/acquire/sequential_design.hpp"
#include "halfback/core/parameterization.hpp"
#include "halfback/util/bounded_read.hpp"
#include "halfback/util/format_error.hpp"

namespace halfback::acquire {

namespace {

constexpr double kFullTurn = 2 * std::numbers::pi;
constexpr double kRightAngle = std::numbers::pi / 2;
// Configurations closer than this (radians, every angle) are the same measurement.
constexpr double kSameAngle = 1e-9;

// The pair turned about the normal so that the light's azimuth is 0 (the detector's, when the
// light is at the normal).
DirPair<double> light_at_azimuth_zero(const DirPair<double>& p) {
  const double r = std::hypot(p.wi.x, p.wi.y);
  const Vec3<double>& turn = r == 0 ? p.wo : p.wi;  // the direction brought to azimuth 0
  const double len = std::hypot(turn.x, turn.y);
  if (len == 0) return p;                            // both at the normal
  const double c = turn.x / len, s = -turn.y / len;  // the rotation by minus its azimuth
  DirPair<double> q{detail::rotate_z(p.wi, c, s), detail::rotate_z(p.wo, c, s)};
  if (r > 0)
    q.wi = {r, 0, p.wi.z};  // exactly at azimuth 0, not a rounding away from it
  else
    q.wo = {len, 0, p.wo.z};
  return q;
}

// Of a pair and its swap (ωo, ωi), the one a plan measures: the light nearer the normal; at equal
// zeniths, the smaller light azimuth, else (an isotropic plan, both at azimuth 0) the detector's
// azimuth in [0, π].
DirPair<double> reciprocal_representative(const DirPair<double>& p, bool isotropic) {
  DirPair<double> swap{p.wo, p.wi};
  if (isotropic) swap = light_at_azimuth_zero(swap);
  const auto& a = position_of(p).angle;  // θi, φi, θo, φo
  const auto& b = position_of(swap).angle;
  if (std::abs(a[0] - b[0]) > kSameAngle) return a[0] < b[0] ? p : swap;
  if (std::abs(a[1] - b[1]) > kSameAngle) return a[1] < b[1] ? p : swap;
  return a[3] <= b[3] ? p : swap;
}

// The configuration's angles on a lattice of kSameAngle, to find repeats.
std::array<long long, 4> key_of(const GonioPosition& g) {
  const auto q = [](double x) { return std::llround(x / kSameAngle); };
  return {q(g.angle[0]), q(g.angle[1]), q(g.angle[2]), q(g.angle[3])};
}

// The serpentine order of positions: per level a bin (the last level's value itself), each level
// run forwards or backwards by the parity of the bins above it. Levels: angle 0 (the light's
// zenith, the tilt) in bands, angle 1 (the light's azimuth, the spin; not for an isotropic plan,
// where it is constant), angle 3 (the detector's azimuth) in strips, angle 2 along a strip.
std::vector<std::size_t> serpentine(const std::vector<GonioPosition>& positions, bool isotropic) {
  const std::size_t n = positions.size();
  const std::size_t levels = isotropic ? 3 : 4;
  const auto bins =
      std::size_t(std::max(1.0, std::round(std::pow(double(n), 1.0 / double(levels)))));
  const auto bin = [&](double x, double range) {
    return std::min(bins - 1, std::size_t(std::max(0.0, x / range * double(bins))));
  };
  struct Key {
    std::array<std::size_t, 3> bin{};
    double last = 0;
  };
  std::vector<Key> keys(n);
  for (std::size_t k = 0; k < n; ++k) {
    const auto& a = positions[k].angle;
    std::array<double, 4> v{a[0], a[1], a[3], a[2]};
    std::array<double, 4> range{kRightAngle, kFullTurn, kFullTurn, kRightAngle};
    if (isotropic) {  // angle 1 constant
      v = {a[0], a[3], a[2], 0};
      range = {kRightAngle, kFullTurn, kRightAngle, 1};
    }
    std::size_t parity = 0;
    for (std::size_t l = 0; l + 1 < levels; ++l) {
      const std::size_t b = bin(v[l], range[l]);
      keys[k].bin[l] = parity % 2 == 0 ? b : bins - 1 - b;
      parity += b;
    }
    keys[k].last = parity % 2 == 0 ? v[levels - 1] : -v[levels - 1];
  }
  std::vector<std::size_t> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (keys[a].bin != keys[b].bin) return keys[a].bin < keys[b].bin;
    return keys[a].last < keys[b].last;
  });
  return order;
}

double path_travel(const std::vector<GonioPosition>& path) {
  double sum = 0;
  for (std::size_t k = 1; k < path.size(); ++k) sum += travel(path[k - 1], path[k]);
  return sum;
}

}  // namespace

std::string_view name_of(Instrument instrument) {
  return instrument == Instrument::sample_turning ? "sample-turning" : "light-detector";
}

std::optional<Instrument> parse_instrument(std::string_view name) {
  for (Instrument i : {Instrument::light_detector, Instrument::sample_turning})
    if (name_of(i) == name) return i;
  return std::nullopt;
}

std::array<std::string_view, 4> motor_names(Instrument instrument) {
  if (instrument == Instrument::sample_turning)
    return {"sample_tilt", "sample_spin", "detector_zenith", "detector_azimuth"};
  return {"light_theta", "light_phi", "detector_theta", "detector_phi"};
}

namespace {

// The sample-turning instrument's stage (docs/acquisition.md, "The instrument"): sample → lab is
// R = R_y(−tilt) R_z(spin); R ωi is the light, +z in the laboratory.
Vec3<double> stage_to_lab(const Vec3<double>& v, double tilt, double spin) {
  const Vec3<double> s = detail::rotate_z(v, std::cos(spin), std::sin(spin));
  const double c = std::cos(tilt), n = std::sin(tilt);
  return {s.x * c - s.z * n, s.y, s.x * n + s.z * c};
}
Vec3<double> lab_to_stage(const Vec3<double>& v, double tilt, double spin) {
  const double c = std::cos(tilt), n = std::sin(tilt);
  const Vec3<double> s{v.x * c + v.z * n, v.y, -v.x * n + v.z * c};
  return detail::rotate_z(s, std::cos(spin), -std::sin(spin));
}

double wrapped(double phi) {  // into [0, 2π)
  phi = std::fmod(phi, kFullTurn);
  return phi < 0 ? phi + kFullTurn : phi;
}

}  // namespace

GonioPosition position_of(const DirPair<double>& p, Instrument instrument) {
  const Tuple4<double> q = Spherical::forward(p);  // (θi, φi, θo, φo), azimuths in [0, 2π)
  if (instrument == Instrument::light_detector) return {{q[0], q[1], q[2], q[3]}};
  const double tilt = q[0], spin = p.wi.x == 0 && p.wi.y == 0 ? 0.0 : wrapped(-q[1]);
  const Vec3<double> d = stage_to_lab(p.wo, tilt, spin);
  const double zenith = std::atan2(std::hypot(d.x, d.y), d.z);
  const double azimuth = d.x == 0 && d.y == 0 ? 0.0 : wrapped(std::atan2(d.y, d.x));
  return {{tilt, spin, zenith, azimuth}};
}

DirPair<double> pair_at(const GonioPosition& g, Instrument instrument) {
  const auto& a = g.angle;
  auto dir = [](double theta, double phi) {
    return Vec3<double>{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                        std::cos(theta)};
  };
  if (instrument == Instrument::light_detector) return {dir(a[0], a[1]), dir(a[2], a[3])};
  return {lab_to_stage({0, 0, 1}, a[0], a[1]), lab_to_stage(dir(a[2], a[3]), a[0], a[1])};
}

GonioSetup plan_setup(const PlanSettings& o) {
  GonioSetup s;
  const auto space = space_from_name(o.param);
  if (!space || space->is_dirs())
    throw std::invalid_argument(fmt::format("param '{}': expected a parameterization: {}", o.param,
                                            parameterization_names()));
  const auto design = parse_design(o.design);
  if (!design || *design == Design::dupuy_jakob || *design == Design::nielsen ||
      (*design == Design::sequential && o.full))
    throw std::invalid_argument(fmt::format(
        "design '{}': expected regular, stratified or sequential (isotropic)", o.design));
  const auto spacing = parse_spacing(o.spacing);
  if (!spacing || (*spacing == Spacing::learned && (!o.learned || o.learned->space != *space)))
    throw std::invalid_argument(fmt::format(
        "spacing '{}': expected own, angle or merl (a learned spacing needs its warps: the "
        "profiles of a study, or a sequential plan's pilot)",
        o.spacing));
  if (o.budget < 1 || o.budget > kMaxSampleBudget)
    throw std::invalid_argument(
        fmt::format("budget {}: expected 1 to {}", o.budget, kMaxSampleBudget));
  if (!(o.max_theta >= 1 && o.max_theta <= 90))
    throw std::invalid_argument(fmt::format("max_theta {}: expected 1 to 90 degrees", o.max_theta));
  s.space = *space;
  s.design = *design;
  s.spacing = *spacing;
  s.budget = o.budget;
  s.isotropic = !o.full;
  s.max_theta_deg = o.max_theta;
  s.seed = o.seed;
  if (s.spacing == Spacing::learned) s.learned = o.learned;
  return s;
}

double travel(const GonioPosition& a, const GonioPosition& b) {
  const auto around = [](double x, double y) {
    const double d = std::abs(x - y);
    return std::min(d, kFullTurn - d);
  };
  return std::abs(a.angle[0] - b.angle[0]) + around(a.angle[1], b.angle[1]) +
         std::abs(a.angle[2] - b.angle[2]) + around(a.angle[3], b.angle[3]);
}

namespace {

// The rows of a plan whose points are set (out.plan): each configuration once, turned and in the
// serpentine order (acquisition_plan's header comment).
void order_rows(AcquisitionPlan& out) {
  const bool iso = out.plan.setup.isotropic;
  // Each point's configuration, once: the first point of a configuration adds a row.
  std::map<std::array<long long, 4>, std::size_t> row_of_key;
  std::vector<DirPair<double>> rows;
  std::vector<GonioPosition> positions, cell_order;  // of the rows; of the points
  out.row_of_point.resize(out.plan.points.size());
  for (std::size_t k = 0; k < out.plan.points.size(); ++k) {
    const DirPair<double>& pair = out.plan.points[k].pair;
    cell_order.push_back(position_of(pair, out.instrument));
    const DirPair<double> p =
        reciprocal_representative(iso ? light_at_azimuth_zero(pair) : pair, iso);
    // The configuration is the same whatever the instrument: repeats are found by (θi, φi, θo, φo).
    const auto [it, fresh] = row_of_key.try_emplace(key_of(position_of(p)), rows.size());
    if (fresh) {
      rows.push_back(p);
      positions.push_back(position_of(p, out.instrument));
    }
    out.row_of_point[k] = it->second;
  }
  std::vector<std::size_t> order = serpentine(positions, iso);
  // A literature's list of pairs may come in an order that travels less (a line of
  // retro-reflections): then that order is kept.
  std::vector<GonioPosition> by_order(positions.size());
  for (std::size_t j = 0; j < order.size(); ++j) by_order[j] = positions[order[j]];
  if (path_travel(positions) < path_travel(by_order))
    for (std::size_t j = 0; j < order.size(); ++j) order[j] = j;
  std::vector<std::size_t> new_row(rows.size());
  for (std::size_t j = 0; j < order.size(); ++j) {
    new_row[order[j]] = j;
    out.measured.push_back(rows[order[j]]);
    out.positions.push_back(positions[order[j]]);
  }
  for (std::size_t& r : out.row_of_point) r = new_row[r];
  out.travel = path_travel(out.positions);
  out.cell_order_travel = path_travel(cell_order);
}

// The plan of a list of pairs (a literature's design): point k at pairs[k], isotropic, the
// instrument reaching 90° unless told.
AcquisitionPlan plan_of_pairs(Design design, std::size_t budget,
                              std::span<const DirPair<double>> pairs, Instrument instrument,
                              double max_theta_deg = 90) {
  AcquisitionPlan out;
  out.instrument = instrument;
  out.plan.setup.design = design;
  out.plan.setup.budget = budget;
  out.plan.setup.max_theta_deg = max_theta_deg;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    PlannedPoint p;
    p.cell = k;
    p.pair = pairs[k];
    out.plan.points.push_back(p);
  }
  order_rows(out);
  return out;
}

// The values of a plan's points from those of its rows.
std::vector<Rgb> point_values(const AcquisitionPlan& a, std::span<const Rgb> row_values) {
  std::vector<Rgb> values(a.plan.points.size());
  for (std::size_t k = 0; k < values.size(); ++k) values[k] = row_values[a.row_of_point[k]];
  return values;
}

// One value per row, none negative (NaN: not measured); std::invalid_argument naming the row.
void check_row_values(const AcquisitionPlan& a, std::span<const Rgb> row_values) {
  if (row_values.size() != a.measured.size())
    throw std::invalid_argument(
        fmt::format("{} values for the {} rows of the plan", row_values.size(), a.measured.size()));
  for (std::size_t r = 0; r < row_values.size(); ++r) {
    const Rgb& v = row_values[r];
    if (v.r < 0 || v.g < 0 || v.b < 0)  // NaN (not measured) passes
      throw std::invalid_argument(
          fmt::format("row {}: the measured value ({:g}, {:g}, {:g}) is negative: a reflectance "
                      "is not (clamp noise below 0 to 0, or leave the row out)",
                      r, v.r, v.g, v.b));
  }
}

// Every row measured, or std::invalid_argument naming the first that is not.
void require_every_row(std::span<const Rgb> row_values, const char* design) {
  for (std::size_t r = 0; r < row_values.size(); ++r)
    if (!row_values[r].finite())
      throw std::invalid_argument(
          fmt::format("row {} was not measured: {} needs every row", r, design));
}

}  // namespace

AcquisitionPlan acquisition_plan(const GonioSetup& setup, Instrument instrument) {
  if (setup.design == Design::sequential)
    throw std::invalid_argument(
        "the sequential design is two plans: sequential_pilot_plan, then sequential_main_plan");
  if (setup.design == Design::dupuy_jakob || setup.design == Design::nielsen)
    throw std::invalid_argument(
        fmt::format("the {} design is not a grid: dupuy_jakob_pilot_plan or nielsen_plan",
                    name_of(setup.design)));
  AcquisitionPlan out;
  out.instrument = instrument;
  out.plan = gonio_plan(setup);
  order_rows(out);
  return out;
}

AcquisitionPlan sequential_pilot_plan(const GonioSetup& setup, Instrument instrument) {
  AcquisitionPlan a = acquisition_plan(sequential_pilot(setup), instrument);
  a.sequential = AcquisitionPlan::SequentialStage{setup.budget, false};
  return a;
}

AcquisitionPlan sequential_main_plan(const AcquisitionPlan& pilot,
                                     std::span<const Rgb> row_values) {
  if (!pilot.sequential || pilot.sequential->main)
    throw std::invalid_argument("the plan is not the pilot of a sequential design");
  if (row_values.size() != pilot.measured.size())
    throw std::invalid_argument(fmt::format("{} values for the {} rows of the pilot",
                                            row_values.size(), pilot.measured.size()));
  // The rows' values spread back to the points: the pilot's measurements are counted by points
  // (a row that two reciprocal points share counts twice), so that the budget is the study's.
  const std::vector<Rgb> values = point_values(pilot, row_values);
  GonioSetup setup = pilot.plan.setup;
  setup.design = Design::sequential;
  setup.budget = pilot.sequential->budget;
  AcquisitionPlan a = acquisition_plan(sequential_main(setup, pilot.plan, values, ErrorSpace::log),
                                       pilot.instrument);
  a.sequential = AcquisitionPlan::SequentialStage{setup.budget, true};
  return a;
}

AcquisitionPlan dupuy_jakob_pilot_plan(std::size_t budget, Instrument instrument) {
  const DupuyJakobLayout layout = dupuy_jakob_layout(budget);
  AcquisitionPlan a =
      plan_of_pairs(Design::dupuy_jakob, budget, dupuy_jakob_retro_pairs(layout), instrument);
  a.dupuy_jakob = AcquisitionPlan::DupuyJakobStage{budget, false, {}};
  return a;
}

namespace {

// The slices' stage from the values at the retro-reflection's points (what a sidecar holds).
AcquisitionPlan dupuy_jakob_slices(std::size_t budget, std::vector<Rgb> retro,
                                   Instrument instrument) {
  const DupuyJakobLayout layout = dupuy_jakob_layout(budget);
  AcquisitionPlan a = plan_of_pairs(Design::dupuy_jakob, budget,
                                    dupuy_jakob_slice_pairs(layout, retro), instrument);
  a.dupuy_jakob = AcquisitionPlan::DupuyJakobStage{budget, true, std::move(retro)};
  return a;
}

}  // namespace

AcquisitionPlan dupuy_jakob_main_plan(const AcquisitionPlan& pilot,
                                      std::span<const Rgb> row_values) {
  if (!pilot.dupuy_jakob || pilot.dupuy_jakob->main)
    throw std::invalid_argument(
        "the plan is not the retro-reflection stage of Dupuy & Jakob's layout");
  if (row_values.size() != pilot.measured.size())
    throw std::invalid_argument(fmt::format("{} values for the {} rows of the retro-reflection",
                                            row_values.size(), pilot.measured.size()));
  require_every_row(row_values, "the power iteration of Dupuy & Jakob's layout");
  return dupuy_jakob_slices(pilot.dupuy_jakob->budget, point_values(pilot, row_values),
                            pilot.instrument);
}

AcquisitionPlan main_stage_plan(const AcquisitionPlan& pilot, std::span<const Rgb> row_values) {
  check_row_values(pilot, row_values);
  if (pilot.dupuy_jakob) return dupuy_jakob_main_plan(pilot, row_values);
  return sequential_main_plan(pilot, row_values);
}

AcquisitionPlan nielsen_plan(std::shared_ptr<const NielsenDatabase> database, std::size_t count,
                             Instrument instrument) {
  if (!database) throw std::invalid_argument("Nielsen's design needs a database");
  const std::size_t candidates = database->configurations().size();
  if (count < 1 || count > candidates)
    throw std::invalid_argument(fmt::format(
        "budget {}: expected 1 to {} (the database's candidate configurations within the "
        "reach)",
        count, candidates));
  AcquisitionPlan::NielsenDesign n;
  n.basis = std::make_shared<const NielsenBasis>(database, std::vector<std::size_t>{});
  n.configurations = n.basis->directions(count);
  n.database = nielsen_fingerprint(*database);
  std::vector<DirPair<double>> pairs;
  for (const std::size_t c : n.configurations) pairs.push_back(database->configurations()[c]);
  AcquisitionPlan a =
      plan_of_pairs(Design::nielsen, count, pairs, instrument, database->options().max_theta_deg);
  a.plan.setup.seed = database->options().seed;
  a.nielsen = std::move(n);
  return a;
}

namespace {

std::string_view warp_name(AxisWarp::Kind k) {
  switch (k) {
    case AxisWarp::Kind::identity:
      return "identity";
    case AxisWarp::Kind::arcsine:
      return "arcsine";
    case AxisWarp::Kind::merl_angle:
      return "merl-angle";
    case AxisWarp::Kind::merl_arcsine:
      return "merl-arcsine";
    case AxisWarp::Kind::table:
      return "table";
  }
  return "identity";
}

constexpr double kDegree = 180 / std::numbers::pi;

}  // namespace

namespace {

// A hash of the points' pairs (their doubles' bits): what a literature's design measures is not a
// grid that the setup alone gives, so a sidecar says which pairs it was planned with.
std::string pairs_digest(const AcquisitionPlan& a) {
  std::uint64_t h = 1469598103934665603ull;
  for (const PlannedPoint& p : a.plan.points)
    for (double x :
         {p.pair.wi.x, p.pair.wi.y, p.pair.wi.z, p.pair.wo.x, p.pair.wo.y, p.pair.wo.z}) {
      std::uint64_t bits = 0;
      std::memcpy(&bits, &x, sizeof bits);
      for (int b = 0; b < 8; ++b) h = (h ^ ((bits >> (8 * b)) & 0xff)) * 1099511628211ull;
    }
  return fmt::format("{:016x}", h);
}

}  // namespace

std::string plan_sidecar(const AcquisitionPlan& a, std::string_view measurements) {
  const GonioSetup& s = a.plan.setup;
  if (s.spacing == Spacing::learned && !s.learned)
    throw std::invalid_argument("a plan of the learned spacing without its warps");
  nlohmann::ordered_json j;
  j["format"] = "halfback-plan";
  j["version"] = 1;
  j["measurements"] = std::string(measurements);
  j["instrument"] = std::string(name_of(a.instrument));
  j["instrument_motors"] = a.instrument == Instrument::light_detector
                               ? "the sample fixed: the light along wi at (light_theta, "
                                 "light_phi), the detector along wo at (detector_theta, "
                                 "detector_phi), degrees from the sample's normal and about it"
                               : "the light fixed: the sample spun about its normal by "
                                 "sample_spin, then tilted by sample_tilt so that wi points at "
                                 "the light; the detector at detector_zenith from the light and "
                                 "detector_azimuth about it (docs/acquisition.md)";
  const bool grid = s.design != Design::dupuy_jakob && s.design != Design::nielsen;
  if (grid)
    j["setup"] = {{"param", std::string(name_of(s.space))},
                  {"isotropic", s.isotropic},
                  {"design", std::string(name_of(s.design))},
                  {"budget", s.budget},
                  {"spacing", std::string(name_of(s.spacing))},
                  {"seed", s.seed},
                  {"max_theta_deg", s.max_theta_deg}};
  else  // the rest of the setup is the design's own (below)
    j["setup"] = {{"design", std::string(name_of(s.design))},
                  {"budget", s.budget},
                  {"max_theta_deg", s.max_theta_deg}};
  j["cells"] = nlohmann::ordered_json::array();
  for (std::size_t k = 0; k < a.plan.cells.axes.size(); ++k) {
    const GridAxis& ax = a.plan.cells.axes[k];
    j["cells"].push_back({{"name", ax.name},
                          {"lo", ax.lo},
                          {"hi", ax.hi},
                          {"count", ax.count},
                          {"warp", std::string(warp_name(a.plan.warps[k].kind()))}});
  }
  // The learned spacing's warps (a sequential main stage's): enough to plan it again.
  if (s.spacing == Spacing::learned) {
    j["learned_warps"] = nlohmann::ordered_json::array();
    for (const AxisWarp& w : s.learned->axes)
      j["learned_warps"].push_back({{"lo", w.lo()}, {"hi", w.hi()}, {"cdf", w.cdf()}});
  }
  if (a.sequential)
    j["sequential"] = {{"budget", a.sequential->budget},
                       {"stage", a.sequential->main ? "main" : "pilot"}};
  if (a.dupuy_jakob) {
    const DupuyJakobLayout l = dupuy_jakob_layout(a.dupuy_jakob->budget);
    auto& d = j["dupuy_jakob"];
    d = {{"stage", a.dupuy_jakob->main ? "slices" : "retro-reflection"},
         {"layout",
          {{"theta_i", l.theta_i}, {"resolution", l.resolution}, {"ndf_nodes", l.ndf_nodes}}}};
    // The slices' pairs follow from these values (one per point of the retro-reflection).
    if (a.dupuy_jakob->main) {
      d["retro_values"] = nlohmann::ordered_json::array();
      for (const Rgb& v : a.dupuy_jakob->retro) d["retro_values"].push_back({v.r, v.g, v.b});
    }
  }
  if (a.nielsen) {
    const NielsenOptions& o = a.nielsen->basis->database().options();
    // The database's options besides its members: what it is built with again to read the plan.
    j["nielsen"] = {{"database", a.nielsen->database},
                    {"options",
                     {{"theta_h", o.theta_h},
                      {"theta_d", o.theta_d},
                      {"phi_d", o.phi_d},
                      {"max_theta_deg", o.max_theta_deg},
                      {"eta", o.eta},
                      {"candidates_per_step", o.candidates_per_step},
                      {"seed", o.seed}}},
                    {"configurations", a.nielsen->configurations}};
  }
  if (!grid) j["pairs_digest"] = pairs_digest(a);
  j["points"] = a.plan.points.size();
  j["rows"] = a.measured.size();
  j["travel_deg"] = {{"serpentine", a.travel * kDegree},
                     {"cell_order", a.cell_order_travel * kDegree}};
  j["row_of_point"] = a.row_of_point;
  return j.dump() + "\n";
}

namespace {

// A field of the sidecar, of the kind asked for; FormatError naming it otherwise.
// Whole numbers must be written as non-negative integers: nlohmann converts a float (2e115) to
// an integer type by a cast whose overflow is undefined behaviour.
template <class T>
T field(const nlohmann::json& j, const char* key, const std::string& file) {
  const auto it = j.find(key);
  if (it == j.end()) throw FormatError(file, key, "missing");
  const auto whole = [](const nlohmann::json& v) { return v.is_number_unsigned(); };
  bool fits = true;
  if constexpr (std::is_same_v<T, std::vector<std::size_t>>)
    fits = it->is_array() && std::all_of(it->begin(), it->end(), whole);
  else if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>)
    fits = whole(*it) &&
           it->template get<std::uint64_t>() <= std::uint64_t(std::numeric_limits<T>::max());
  if (!fits) throw FormatError(file, key, "not a whole number >= 0 (or a list of them)");
  try {
    return it->get<T>();
  } catch (const nlohmann::json::exception&) {
    throw FormatError(file, key, "not of the expected kind");
  }
}

// The sidecar's "setup" as settings (plan_setup checks them).
PlanSettings settings_from(const nlohmann::json& j, const std::string& file) {
  PlanSettings o;
  o.param = field<std::string>(j, "param", file);
  o.design = field<std::string>(j, "design", file);
  o.spacing = field<std::string>(j, "spacing", file);
  o.full = !field<bool>(j, "isotropic", file);
  o.budget = field<std::size_t>(j, "budget", file);
  o.seed = field<std::uint64_t>(j, "seed", file);
  o.max_theta = field<double>(j, "max_theta_deg", file);
  return o;
}

// The sidecar's instrument; plans written before there were two hold a description of the
// light/detector one there.
Instrument instrument_of(const nlohmann::json& j, const std::string& file) {
  const auto name = field<std::string>(j, "instrument", file);
  if (const auto i = parse_instrument(name)) return *i;
  if (name.starts_with("four-axis light/detector")) return Instrument::light_detector;
  throw FormatError(file, "instrument", "expected light-detector or sample-turning");
}

// The learned spacing's warps of a sidecar ("learned_warps": per axis lo, hi and the CDF's nodes).
LearnedWarps learned_warps_of(const nlohmann::json& j, const PlanSettings& settings,
                              const std::string& file) {
  const auto it = j.find("learned_warps");
  if (it == j.end() || !it->is_array() || it->size() != 3)
    throw FormatError(file, "learned_warps", "missing, or not three axes");
  const auto space = space_from_name(settings.param);
  if (!space || space->is_dirs()) throw FormatError(file, "setup.param", "not a parameterization");
  LearnedWarps w;
  w.space = *space;
  const GridSpec axes = default_grid(*space, GridKind::isotropic, {1});
  for (std::size_t k = 0; k < 3; ++k) {
    const nlohmann::json& axis = (*it)[k];
    if (!axis.is_object()) throw FormatError(file, "learned_warps", "an axis is not an object");
    const auto cdf = field<std::vector<double>>(axis, "cdf", file);
    if (cdf.size() < 2 || cdf.size() > 4097)
      throw FormatError(file, "learned_warps.cdf", "2 to 4097 nodes expected");
    const double lo = field<double>(axis, "lo", file), hi = field<double>(axis, "hi", file);
    if (lo != axes.axes[k].lo || hi != axes.axes[k].hi)
      throw FormatError(file, "learned_warps",
                        fmt::format("axis {} does not span the parameterization's range", k));
    w.axes[k] = AxisWarp::from_cdf(lo, hi, cdf);  // invalid_argument: not increasing from 0 to 1
  }
  return w;
}

// A sequential stage's "sequential" field, checked against the plan's setup: a pilot is the
// sequential pilot of the design's budget, a main stage is of the learned spacing.
std::optional<AcquisitionPlan::SequentialStage> sequential_stage_of(const nlohmann::json& j,
                                                                    const GonioSetup& setup,
                                                                    const std::string& file,
                                                                    std::size_t max_budget) {
  const auto it = j.find("sequential");
  if (it == j.end()) return std::nullopt;
  if (!it->is_object()) throw FormatError(file, "sequential", "not an object");
  AcquisitionPlan::SequentialStage stage;
  stage.budget = field<std::size_t>(*it, "budget", file);
  const auto name = field<std::string>(*it, "stage", file);
  if (name != "pilot" && name != "main")
    throw FormatError(file, "sequential.stage", "expected pilot or main");
  stage.main = name == "main";
  if (stage.budget < 1 || stage.budget > max_budget)
    throw FormatError(file, "sequential.budget", fmt::format("expected 1 to {}", max_budget));
  GonioSetup whole = setup;
  whole.design = Design::sequential;
  whole.budget = stage.budget;
  const bool fits = stage.main ? setup.spacing == Spacing::learned
                               : setup.spacing == Spacing::own && setup.design == Design::regular &&
                                     sequential_pilot(whole).budget == setup.budget;
  if (!fits)
    throw FormatError(file, "sequential",
                      "the setup is not this stage of a sequential design (edited?)");
  return stage;
}

// The values of a Dupuy & Jakob slices' sidecar ("retro_values": one [r, g, b] per point of the
// retro-reflection), each finite and >= 0.
std::vector<Rgb> retro_values_of(const nlohmann::json& d, const std::string& file) {
  const auto it = d.find("retro_values");
  if (it == d.end() || !it->is_array())
    throw FormatError(file, "dupuy_jakob.retro_values", "missing, or not a list");
  std::vector<Rgb> values;
  for (const nlohmann::json& v : *it) {
    if (!v.is_array() || v.size() != 3 || !std::all_of(v.begin(), v.end(), [](const auto& x) {
          return x.is_number() && x.template get<double>() >= 0;
        }))
      throw FormatError(file, "dupuy_jakob.retro_values",
                        "a value is not three numbers >= 0 (r, g, b)");
    values.push_back(Rgb{v[0].get<double>(), v[1].get<double>(), v[2].get<double>()});
  }
  return values;
}

// A sidecar of one of the literature's designs, planned again from what it says it was planned
// with (Nielsen's: in `database`, which must be the same).
AcquisitionPlan literature_plan_of(const nlohmann::json& j, Design design, const std::string& file,
                                   std::size_t max_budget,
                                   const std::shared_ptr<const NielsenDatabase>& database) {
  const nlohmann::json& setup = j["setup"];
  const auto budget = field<std::size_t>(setup, "budget", file);
  if (budget > max_budget)
    throw FormatError(file, "setup.budget", fmt::format("above {}", max_budget));
  const Instrument instrument = instrument_of(j, file);
  if (design == Design::dupuy_jakob) {
    const auto it = j.find("dupuy_jakob");
    if (it == j.end() || !it->is_object()) throw FormatError(file, "dupuy_jakob", "missing");
    const auto stage = field<std::string>(*it, "stage", file);
    if (stage != "retro-reflection" && stage != "slices")
      throw FormatError(file, "dupuy_jakob.stage", "expected retro-reflection or slices");
    if (stage == "retro-reflection") return dupuy_jakob_pilot_plan(budget, instrument);
    std::vector<Rgb> retro = retro_values_of(*it, file);
    if (retro.size() != dupuy_jakob_retro_pairs(dupuy_jakob_layout(budget)).size())
      throw FormatError(file, "dupuy_jakob.retro_values",
                        "not one value per point of the budget's retro-reflection");
    return dupuy_jakob_slices(budget, std::move(retro), instrument);
  }
  const auto it = j.find("nielsen");
  if (it == j.end() || !it->is_object()) throw FormatError(file, "nielsen", "missing");
  const auto planned_in = field<std::string>(*it, "database", file);
  if (!database)
    throw FormatError(file, "nielsen.database",
                      fmt::format("a plan of Nielsen's design is read with the database it was "
                                  "planned in ({}); none was given",
                                  planned_in));
  const std::string given = nielsen_fingerprint(*database);
  if (given != planned_in)
    throw FormatError(file, "nielsen.database",
                      fmt::format("planned in the database '{}', not in the one given ('{}': other "
                                  "members, or another reach or seed)",
                                  planned_in, given));
  AcquisitionPlan a = nielsen_plan(database, budget, instrument);
  if (field<std::vector<std::size_t>>(*it, "configurations", file) != a.nielsen->configurations)
    throw FormatError(file, "nielsen.configurations",
                      "not the database's directions (a plan of another version of halfback, or "
                      "edited)");
  return a;
}

// The plan planned again must be the one the sidecar describes.
void require_same_rows(const nlohmann::json& j, const AcquisitionPlan& a, const std::string& file) {
  if (field<std::size_t>(j, "points", file) != a.plan.points.size() ||
      field<std::size_t>(j, "rows", file) != a.measured.size() ||
      field<std::vector<std::size_t>>(j, "row_of_point", file) != a.row_of_point ||
      (j.contains("pairs_digest") &&
       field<std::string>(j, "pairs_digest", file) != pairs_digest(a)))
    throw FormatError(file, "row_of_point",
                      "the setup, planned again, gives other points or rows (a plan of another "
                      "version of halfback, or edited)");
}

AcquisitionPlan plan_of(const nlohmann::json& j, const std::string& file, std::size_t max_budget,
                        const std::shared_ptr<const NielsenDatabase>& database) {
  if (!j.is_object() || j.value("format", "") != "halfback-plan")
    throw FormatError(file, "format", "not a halfback plan (no \"format\": \"halfback-plan\")");
  if (field<int>(j, "version", file) != 1)
    throw FormatError(file, "version", "a version this halfback does not read (1)");
  const auto setup = j.find("setup");
  if (setup == j.end() || !setup->is_object()) throw FormatError(file, "setup", "missing");
  try {
    const auto design = parse_design(field<std::string>(*setup, "design", file));
    if (design == Design::dupuy_jakob || design == Design::nielsen) {
      AcquisitionPlan a = literature_plan_of(j, *design, file, max_budget, database);
      if (!j.contains("pairs_digest")) throw FormatError(file, "pairs_digest", "missing");
      require_same_rows(j, a, file);
      return a;
    }
    PlanSettings settings = settings_from(*setup, file);
    if (settings.budget > max_budget)
      throw FormatError(file, "setup.budget", fmt::format("above {}", max_budget));
    if (settings.spacing == "learned") settings.learned = learned_warps_of(j, settings, file);
    AcquisitionPlan a = acquisition_plan(plan_setup(settings), instrument_of(j, file));
    a.sequential = sequential_stage_of(j, a.plan.setup, file, max_budget);
    require_same_rows(j, a, file);
    return a;
  } catch (const std::invalid_argument& e) {  // plan_setup's: a bad name, budget or reach
    throw FormatError(file, "setup", e.what());
  }
}

}  // namespace

namespace {

std::string sidecar_text(const std::filesystem::path& path) {
  // 10⁷ points at most: under 100 MB, on one line (plan_sidecar writes one): the bound on the
  // file is the bound on its line.
  constexpr std::uint64_t kMaxSidecarBytes = std::uint64_t(256) << 20;
  TextLines lines(path, kMaxSidecarBytes, kMaxSidecarBytes);
  std::string text;
  for (std::string_view line; lines.next(line);) (text += line) += '\n';
  return text;
}

}  // namespace

std::optional<NielsenOptions> sidecar_nielsen_options(const std::filesystem::path& path) {
  const std::string file = path.string();
  try {
    const nlohmann::json j = nlohmann::json::parse(sidecar_text(path));
    const auto it = j.find("nielsen");
    if (it == j.end()) return std::nullopt;
    if (!it->is_object() || !it->contains("options") || !(*it)["options"].is_object())
      throw FormatError(file, "nielsen.options", "missing");
    const nlohmann::json& o = (*it)["options"];
    NielsenOptions options;
    options.theta_h = field<int>(o, "theta_h", file);
    options.theta_d = field<int>(o, "theta_d", file);
    options.phi_d = field<int>(o, "phi_d", file);
    options.max_theta_deg = field<double>(o, "max_theta_deg", file);
    options.eta = field<double>(o, "eta", file);
    options.candidates_per_step = field<std::size_t>(o, "candidates_per_step", file);
    options.seed = field<std::uint64_t>(o, "seed", file);
    try {
      options.validate();
    } catch (const std::invalid_argument& e) {
      throw FormatError(file, "nielsen.options", e.what());
    }
    return options;
  } catch (const nlohmann::json::exception& e) {
    throw FormatError(file, "json", e.what());
  }
}

AcquisitionPlan read_plan_sidecar(const std::filesystem::path& path,
                                  std::shared_ptr<const NielsenDatabase> database) {
  return parse_plan_sidecar(sidecar_text(path), path.string(), kMaxSampleBudget,
                            std::move(database));
}

AcquisitionPlan parse_plan_sidecar(std::string_view text, const std::string& file,
                                   std::size_t max_budget,
                                   std::shared_ptr<const NielsenDatabase> database) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {  // malformed, or a number out of range
    throw FormatError(file, "json", e.what());
  }
  try {
    return plan_of(j, file, max_budget, database);
  } catch (const nlohmann::json::exception& e) {  // a field of another kind deep inside
    throw FormatError(file, "json", e.what());
  }
}

GonioReconstruction reconstruct(const AcquisitionPlan& a, std::span<const Rgb> row_values,
                                std::string name) {
  check_row_values(a, row_values);
  return GonioReconstruction(a.plan, point_values(a, row_values), std::move(name));
}

std::vector<TensorFieldData> dupuy_jakob_plan_fields(const AcquisitionPlan& a,
                                                     std::span<const Rgb> row_values, int threads) {
  if (!a.dupuy_jakob || !a.dupuy_jakob->main)
    throw std::invalid_argument(
        "the retro-reflection's stage of Dupuy & Jakob's layout is not a material: plan the "
        "slices from its values (the main stage), measure them and reconstruct those");
  check_row_values(a, row_values);
  require_every_row(row_values, "Dupuy & Jakob's tables");
  return dupuy_jakob_fields(dupuy_jakob_layout(a.dupuy_jakob->budget), a.dupuy_jakob->retro,
                            point_values(a, row_values), threads);
}

std::shared_ptr<const Brdf> reconstruct_any(const AcquisitionPlan& a,
                                            std::span<const Rgb> row_values, std::string name) {
  if (a.plan.setup.design == Design::dupuy_jakob)
    return dupuy_jakob_material(dupuy_jakob_plan_fields(a, row_values), name);
  if (a.plan.setup.design != Design::nielsen)
    return std::make_shared<GonioReconstruction>(reconstruct(a, row_values, std::move(name)));
  check_row_values(a, row_values);
  const std::vector<Rgb> values = point_values(a, row_values);
  const NielsenBasis& basis = *a.nielsen->basis;
  return std::make_shared<NielsenReconstruction>(
      basis.database_ptr(),
      basis.solve(a.nielsen->configurations, values, basis.database().options().eta),
      std::move(name), finite_values(values));
}

}  // namespace halfback::acquire
