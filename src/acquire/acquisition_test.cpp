// Measurement plans for a real instrument (acquisition.hpp): each configuration once, by isotropy
// and reciprocity; the value of every point of the plan is the value at its measured row; the
// serpentine order shortens the motors' travel; a reconstruction from the plan's rows is the
// virtual gonio-reflectometer's.
#include "halfback/acquire/acquisition.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "halfback/acquire/sequential_design.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/models/analytic.hpp"
#include "halfback/util/format_error.hpp"

namespace halfback::acquire {
namespace {

// An isotropic, reciprocal BRDF without the mirror symmetry about the plane of incidence would
// show a wrong turn; GGX plus a Lambert term has both symmetries, so the test also checks the
// rows' configurations directly.
const models::Sum& truth() {
  static const models::Sum sum({std::make_shared<models::Lambert>(Rgb{0.2, 0.3, 0.4}),
                                std::make_shared<models::Microfacet>(models::MicrofacetParams{})});
  return sum;
}

double cos_between(const DirPair<double>& p) {  // invariant under a turn about the normal
  return p.wi.x * p.wo.x + p.wi.y * p.wo.y + p.wi.z * p.wo.z;
}

TEST(AcquisitionPlan, EveryPointIsItsRowsConfiguration) {
  for (Space space : {space_of<HalfDiff>, space_of<Hybrid>, space_of<Spherical>}) {
    for (bool iso : {true, false}) {
      GonioSetup s;
      s.space = space;
      s.isotropic = iso;
      s.budget = iso ? 3000 : 6000;
      const AcquisitionPlan a = acquisition_plan(s);
      ASSERT_EQ(a.row_of_point.size(), a.plan.points.size());
      ASSERT_EQ(a.positions.size(), a.measured.size());
      for (std::size_t k = 0; k < a.plan.points.size(); ++k) {
        const DirPair<double>& p = a.plan.points[k].pair;
        const DirPair<double>& m = a.measured[a.row_of_point[k]];
        // The same zeniths (or swapped) and the same angle between the directions.
        const double ti = std::acos(std::clamp(p.wi.z, -1.0, 1.0)),
                     to = std::acos(std::clamp(p.wo.z, -1.0, 1.0));
        const double mi = a.positions[a.row_of_point[k]].angle[0],  // θl
            mo = a.positions[a.row_of_point[k]].angle[2];           // θv
        const bool same = std::abs(ti - mi) < 1e-7 && std::abs(to - mo) < 1e-7;
        const bool swapped = std::abs(ti - mo) < 1e-7 && std::abs(to - mi) < 1e-7;
        ASSERT_TRUE(same || swapped) << name_of(space) << " point " << k;
        ASSERT_NEAR(cos_between(p), cos_between(m), 1e-9) << name_of(space) << " point " << k;
        if (!iso) {  // no turn: the pair itself, or its swap
          const bool exact = std::abs(p.wi.x - m.wi.x) + std::abs(p.wi.y - m.wi.y) < 1e-9 ||
                             std::abs(p.wi.x - m.wo.x) + std::abs(p.wi.y - m.wo.y) < 1e-9;
          ASSERT_TRUE(exact) << name_of(space) << " point " << k;
        }
      }
      for (const GonioPosition& g : a.positions) {
        if (iso) {
          EXPECT_EQ(g.angle[1], 0.0);  // φl = 0: a three-axis instrument suffices
        }
        EXPECT_LE(g.angle[0], g.angle[2] + 1e-9);  // the swap nearer the normal
      }
    }
  }
}

// Both instruments' motor angles map back to the pair to 1e-12, on random pairs and on a plan's
// rows; the sample-turning instrument's angles are what its geometry says.
TEST(AcquisitionPlan, MotorAnglesMapBackToThePair) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  auto dir = [&] {
    const double t = 1.5 * u(rng), f = 6.283185307179586 * u(rng);
    return Vec3<double>{std::sin(t) * std::cos(f), std::sin(t) * std::sin(f), std::cos(t)};
  };
  auto expect_same = [](const DirPair<double>& a, const DirPair<double>& b, const char* what) {
    const double d = std::abs(a.wi.x - b.wi.x) + std::abs(a.wi.y - b.wi.y) +
                     std::abs(a.wi.z - b.wi.z) + std::abs(a.wo.x - b.wo.x) +
                     std::abs(a.wo.y - b.wo.y) + std::abs(a.wo.z - b.wo.z);
    EXPECT_LT(d, 1e-12) << what;
  };
  for (Instrument instrument : {Instrument::light_detector, Instrument::sample_turning}) {
    for (int k = 0; k < 2000; ++k) {
      const DirPair<double> p{dir(), dir()};
      expect_same(pair_at(position_of(p, instrument), instrument), p, "random pair");
    }
    GonioSetup s;
    s.space = space_of<Hybrid>;
    s.budget = 3000;
    const AcquisitionPlan a = acquisition_plan(s, instrument);
    EXPECT_EQ(a.instrument, instrument);
    for (std::size_t r = 0; r < a.measured.size(); ++r)
      expect_same(pair_at(a.positions[r], instrument), a.measured[r], "a plan's row");
    EXPECT_LT(a.travel, 0.6 * a.cell_order_travel) << name_of(instrument);
  }
  // The sample tilted by θi, its spin bringing ωi into the tilt's plane; the detector at the
  // angle between the directions from the light; the mirror direction at 2θi, azimuth 180°.
  const double t = 0.4, f = 1.1;
  const Vec3<double> wi{std::sin(t) * std::cos(f), std::sin(t) * std::sin(f), std::cos(t)};
  const Vec3<double> mirror{-wi.x, -wi.y, wi.z};
  const auto g = position_of({wi, mirror}, Instrument::sample_turning).angle;
  EXPECT_NEAR(g[0], t, 1e-12);
  EXPECT_NEAR(g[1], 2 * 3.141592653589793 - f, 1e-12);
  EXPECT_NEAR(g[2], 2 * t, 1e-12);
  EXPECT_NEAR(g[3], 3.141592653589793, 1e-12);
  EXPECT_EQ(parse_instrument("sample-turning"), Instrument::sample_turning);
  EXPECT_EQ(parse_instrument("turntable"), std::nullopt);
}

// Reciprocity halves a halfdiff plan (φd and φd + π are each other's swap); the serpentine order
// travels less than the cells' order.
TEST(AcquisitionPlan, ReciprocityAndOrderSaveWork) {
  GonioSetup s;
  s.space = space_of<HalfDiff>;
  s.budget = 4000;
  const AcquisitionPlan a = acquisition_plan(s);
  EXPECT_LT(double(a.measured.size()), 0.6 * double(a.plan.points.size()));
  EXPECT_GT(double(a.measured.size()), 0.4 * double(a.plan.points.size()));
  EXPECT_LT(a.travel, 0.5 * a.cell_order_travel) << a.travel << " vs " << a.cell_order_travel;
  double sum = 0;
  for (std::size_t k = 1; k < a.positions.size(); ++k)
    sum += travel(a.positions[k - 1], a.positions[k]);
  EXPECT_NEAR(a.travel, sum, 1e-9 * sum);
}

// Values measured at the plan's rows, spread back to its points, give the reconstruction of the
// virtual instrument (the BRDF is isotropic and reciprocal); a missing row is filled, not zero.
TEST(AcquisitionPlan, ReconstructionFromTheRowsIsTheVirtualOne) {
  GonioSetup s;
  s.space = space_of<Hybrid>;
  s.design = Design::stratified;
  s.budget = 2000;
  const AcquisitionPlan a = acquisition_plan(s);
  std::vector<Rgb> rows(a.measured.size());
  truth().eval_batch(a.measured, rows);
  std::vector<Rgb> values(a.plan.points.size());
  for (std::size_t k = 0; k < values.size(); ++k) values[k] = rows[a.row_of_point[k]];
  const GonioReconstruction from_rows(a.plan, values, "lab");
  const GonioReconstruction virtual_one(truth(), s);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int k = 0; k < 200; ++k) {
    const double t1 = 1.4 * u(rng), t2 = 1.4 * u(rng), f = 6.28 * u(rng);
    const DirPair<double> p{{std::sin(t1), 0, std::cos(t1)},
                            {std::sin(t2) * std::cos(f), std::sin(t2) * std::sin(f), std::cos(t2)}};
    const Rgb x = from_rows.eval(p), y = virtual_one.eval(p);
    ASSERT_NEAR(x.g, y.g, 1e-9 * (1 + y.g)) << k;
  }
  values[0] = Rgb{NAN, NAN, NAN};
  const GonioReconstruction missing(a.plan, values, "lab");
  EXPECT_EQ(missing.samples(), virtual_one.samples() - 1);
  EXPECT_THROW(GonioReconstruction(a.plan, std::span(values).first(3), "lab"),
               std::invalid_argument);
  // A negative measurement is a data error naming its row (it became 0 in 35 613 bins, silently).
  rows[3] = Rgb{0.1, -0.5, 0.1};
  try {
    reconstruct(a, rows, "lab");
    ADD_FAILURE() << "a negative measurement was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("row 3"), std::string::npos) << e.what();
  }
  rows[3] = Rgb{NAN, NAN, NAN};  // not measured: accepted
  EXPECT_NO_THROW(reconstruct(a, rows, "lab"));
}

// The sequential design through the instrument's two plans: the pilot measured at its rows, the
// main stage planned from those values, measured and reconstructed, is the study's sequential
// design (sequential_acquisition) to 1e-9.
TEST(AcquisitionPlan, SequentialPlansAreTheStudysSequentialDesign) {
  GonioSetup s;
  s.space = space_of<HalfDiff>;
  s.design = Design::sequential;
  s.budget = 6000;
  s.max_theta_deg = 85;
  EXPECT_THROW(acquisition_plan(s), std::invalid_argument);
  auto measure = [](const AcquisitionPlan& a) {
    std::vector<Rgb> rows(a.measured.size());
    truth().eval_batch(a.measured, rows);
    return rows;
  };
  const AcquisitionPlan pilot = sequential_pilot_plan(s);
  ASSERT_TRUE(pilot.sequential && !pilot.sequential->main);
  const AcquisitionPlan main = sequential_main_plan(pilot, measure(pilot));
  ASSERT_TRUE(main.sequential && main.sequential->main);
  const GonioReconstruction lab = reconstruct(main, measure(main), "lab");
  const SequentialAcquisition virtual_one = sequential_acquisition(truth(), s, ErrorSpace::log);
  // The same warps (the rows' values are the points' up to the rounding of the isotropic turn).
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const auto& x = main.plan.setup.learned->axes[axis].cdf();
    const auto& y = virtual_one.warps.axes[axis].cdf();
    ASSERT_EQ(x.size(), y.size());
    for (std::size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(x[i], y[i], 1e-12);
  }
  const TestPairs test = draw_test_pairs(truth(), 20000, 2, ErrorSpace::log, 85);
  const double a = reconstruction_error(lab, test),
               b = reconstruction_error(*virtual_one.reconstruction, test);
  EXPECT_NEAR(a, b, 1e-9 * b);
  EXPECT_EQ(pilot.plan.points.size() + main.plan.points.size(), virtual_one.samples);

  // Both sidecars plan again to the same rows; the main one carries its warps.
  for (const AcquisitionPlan* p : {&pilot, &main}) {
    const AcquisitionPlan back = parse_plan_sidecar(plan_sidecar(*p, "x.csv"), "p.json");
    EXPECT_EQ(back.row_of_point, p->row_of_point);
    ASSERT_TRUE(back.sequential);
    EXPECT_EQ(back.sequential->main, p->sequential->main);
    EXPECT_EQ(back.sequential->budget, 6000u);
  }
  EXPECT_EQ(*parse_plan_sidecar(plan_sidecar(main, "x.csv"), "p.json").plan.setup.learned,
            *main.plan.setup.learned);
  // Edited: a CDF that decreases, a pilot claimed for another budget, a main stage's stage.
  std::string text = plan_sidecar(main, "x.csv");
  const std::size_t cdf = text.find("\"cdf\":[0.0,") + 13;
  ASSERT_NE(cdf, std::string::npos + 13) << text.substr(0, 400);
  text.insert(cdf, "0.9,");
  EXPECT_THROW(parse_plan_sidecar(text, "p.json"), FormatError);
  // A warp's range that is not its axis's.
  std::string range = plan_sidecar(main, "x.csv");
  range.replace(range.find("\"lo\":0.0"), 9, "\"lo\":0.1");
  EXPECT_THROW(parse_plan_sidecar(range, "p.json"), FormatError);
  std::string other = plan_sidecar(pilot, "x.csv");
  other.replace(other.find("\"budget\":6000"), 13, "\"budget\":7000");
  EXPECT_THROW(parse_plan_sidecar(other, "p.json"), FormatError);
  std::string stage = plan_sidecar(main, "x.csv");
  stage.replace(stage.find("\"stage\":\"main\""), 14, "\"stage\":\"pilot\"");
  EXPECT_THROW(parse_plan_sidecar(stage, "p.json"), FormatError);
  // The main stage from anything but a pilot, or from the wrong count of values.
  EXPECT_THROW(sequential_main_plan(main, measure(main)), std::invalid_argument);
  EXPECT_THROW(sequential_main_plan(pilot, std::vector<Rgb>(3)), std::invalid_argument);
}

// The values a laboratory measures at a plan's rows: the truth there.
std::vector<Rgb> measure(const AcquisitionPlan& a) {
  std::vector<Rgb> rows(a.measured.size());
  truth().eval_batch(a.measured, rows);
  return rows;
}

// Dupuy & Jakob's layout through the instrument's two plans: the retro-reflection measured, the
// slices planned from its values, measured and reconstructed, is the study's dupuy-jakob design
// (dupuy_jakob_acquisition at the same budget) to 1e-9 in the study's error.
TEST(AcquisitionPlan, DupuyJakobPlansAreTheStudysLayout) {
  constexpr std::size_t kBudget = 3000;
  const AcquisitionPlan pilot = dupuy_jakob_pilot_plan(kBudget);
  const DupuyJakobLayout layout = dupuy_jakob_layout(kBudget);
  ASSERT_TRUE(pilot.dupuy_jakob && !pilot.dupuy_jakob->main);
  EXPECT_EQ(pilot.plan.points.size(), std::size_t(layout.ndf_nodes));
  const std::vector<Rgb> retro = measure(pilot);
  const AcquisitionPlan main = main_stage_plan(pilot, retro);
  ASSERT_TRUE(main.dupuy_jakob && main.dupuy_jakob->main);
  // The slices' pairs below the horizon are not measured: fewer rows than the layout counts.
  EXPECT_LE(pilot.measured.size() + main.measured.size(), layout.measurements());
  EXPECT_GT(main.measured.size(), layout.slice_measurements() / 2);
  const auto lab = reconstruct_any(main, measure(main), "lab");
  const auto study = dupuy_jakob_acquisition(truth(), layout, 1);
  const TestPairs test = draw_test_pairs(truth(), 20000, 2, ErrorSpace::log, 85);
  const double a = reconstruction_error(*lab, test), b = reconstruction_error(*study, test);
  EXPECT_NEAR(a, b, 1e-9 * b);
  EXPECT_GT(b, 0);

  // Both sidecars plan again to the same rows; the slices' carries the retro-reflection's values.
  for (const AcquisitionPlan* p : {&pilot, &main}) {
    const AcquisitionPlan back = parse_plan_sidecar(plan_sidecar(*p, "x.csv"), "p.json");
    EXPECT_EQ(back.row_of_point, p->row_of_point);
    ASSERT_TRUE(back.dupuy_jakob);
    EXPECT_EQ(back.dupuy_jakob->main, p->dupuy_jakob->main);
    EXPECT_EQ(back.measured.size(), p->measured.size());
  }
  // Edited: a retro-reflection value (the slices would be elsewhere), the stage, the budget.
  std::string text = plan_sidecar(main, "x.csv");
  const std::size_t value = text.find("\"retro_values\":[[") + 17;
  text.insert(value, "2");  // 0.05... becomes 20.05...
  EXPECT_THROW(parse_plan_sidecar(text, "p.json"), FormatError);
  // Values that recover no distribution (all zero), of another kind, negative: FormatError.
  AcquisitionPlan zero = main;
  for (Rgb& v : zero.dupuy_jakob->retro) v = Rgb{};
  EXPECT_THROW(parse_plan_sidecar(plan_sidecar(zero, "x.csv"), "p.json"), FormatError);
  for (const char* bad : {"\"retro_values\":\"x\",", "\"retro_values\":[[-1,0,0]],"}) {
    std::string kind = plan_sidecar(main, "x.csv");
    const std::size_t from = kind.find("\"retro_values\":");
    kind.replace(from, kind.find("]],", from) + 3 - from, bad);
    EXPECT_THROW(parse_plan_sidecar(kind, "p.json"), FormatError) << bad;
  }
  std::string stage = plan_sidecar(main, "x.csv");
  stage.replace(stage.find("\"stage\":\"slices\""), 16, "\"stage\":\"retro-reflection\"");
  EXPECT_THROW(parse_plan_sidecar(stage, "p.json"), FormatError);
  std::string budget = plan_sidecar(pilot, "x.csv");
  budget.replace(budget.find("\"budget\":3000"), 13, "\"budget\":1000");  // 62 nodes, not 128
  EXPECT_THROW(parse_plan_sidecar(budget, "p.json"), FormatError);
  // The wrong stage, a row not measured (the power iteration and the tables need every one).
  EXPECT_THROW(main_stage_plan(main, measure(main)), std::invalid_argument);
  EXPECT_THROW(reconstruct_any(pilot, retro, "lab"), std::invalid_argument);
  std::vector<Rgb> missing = retro;
  missing[2] = Rgb{NAN, NAN, NAN};
  try {
    main_stage_plan(pilot, missing);
    ADD_FAILURE() << "a retro-reflection row not measured was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("row 2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(dupuy_jakob_pilot_plan(47), std::invalid_argument);
}

// Nielsen's design through the instrument: its directions measured and reconstructed in the
// basis are the study's nielsen rows (nielsen_acquisition, the material not in the database) to
// 1e-9 in the study's error; the sidecar is read with its database only.
TEST(AcquisitionPlan, NielsenPlanIsTheStudysMinimalSampling) {
  NielsenOptions o;
  o.theta_h = o.theta_d = o.phi_d = 16;
  o.max_theta_deg = 85;
  o.candidates_per_step = 200;
  std::vector<std::shared_ptr<const Brdf>> members;
  for (const char* spec :
       {"lambert:albedo_r=0.8,albedo_g=0.5,albedo_b=0.2", "lambert:albedo=0.2+ggx:alpha=0.3,f0=0.5",
        "lambert:albedo=0.1+ggx:alpha=0.1,f0=0.9", "lambert:albedo=0.4+beckmann:alpha=0.25,f0=0.6"})
    members.push_back(load_brdf(spec));
  const TestPairs test = draw_test_pairs(truth(), 20000, 2, ErrorSpace::log, 85);
  // As the study builds it: the test pairs' values cached.
  auto database =
      std::make_shared<const NielsenDatabase>(members, o, test_pair_directions(20000, 2, 85));
  const std::size_t counts[] = {5, 12};
  const NielsenAcquisition study = nielsen_acquisition(database, truth(), counts);
  ASSERT_TRUE(study.left_out.empty());
  for (std::size_t i = 0; i < 2; ++i) {
    const AcquisitionPlan a = nielsen_plan(database, counts[i]);
    ASSERT_TRUE(a.nielsen);
    EXPECT_EQ(a.nielsen->configurations,
              std::vector<std::size_t>(study.directions.begin(),
                                       study.directions.begin() + std::ptrdiff_t(counts[i])));
    const auto lab = reconstruct_any(a, measure(a), "lab");
    const double x = reconstruction_error(*lab, test),
                 y = reconstruction_error(*study.reconstructions[i], test);
    EXPECT_NEAR(x, y, 1e-9 * y) << counts[i];
    // The sidecar: with the database, the same plan; without, or with another, refused.
    const std::string text = plan_sidecar(a, "x.csv");
    EXPECT_EQ(parse_plan_sidecar(text, "p.json", kMaxSampleBudget, database).row_of_point,
              a.row_of_point);
    EXPECT_THROW(parse_plan_sidecar(text, "p.json"), FormatError);
    NielsenOptions other = o;
    other.seed = 2;
    EXPECT_THROW(parse_plan_sidecar(text, "p.json", kMaxSampleBudget,
                                    std::make_shared<const NielsenDatabase>(members, other)),
                 FormatError);
    std::string edited = text;
    edited.replace(edited.find("\"configurations\":[") + 18, 0, "0,");
    EXPECT_THROW(parse_plan_sidecar(edited, "p.json", kMaxSampleBudget, database), FormatError);
  }
  EXPECT_THROW(nielsen_plan(database, 0), std::invalid_argument);
  EXPECT_THROW(nielsen_plan(database, database->configurations().size() + 1),
               std::invalid_argument);
}

// The learned spacing (the study's learned design: the regular grid in warps learned from other
// BRDFs' profiles) planned and reconstructed is the study's row to 1e-9.
TEST(AcquisitionPlan, LearnedPlanIsTheStudysLearnedDesign) {
  const IsoGrid grid{16, 16, 16};
  std::vector<DesignProfile> profiles;
  const Space spaces[] = {space_of<HalfDiff>};
  for (const char* spec :
       {"lambert:albedo=0.2+ggx:alpha=0.05,f0=0.9", "lambert:albedo=0.3+ggx:alpha=0.4"})
    profiles.push_back(design_profile(*load_brdf(spec), spaces, grid, ErrorSpace::log));
  PlanSettings settings;
  settings.param = "halfdiff";
  settings.spacing = "learned";
  settings.budget = 4000;
  settings.max_theta = 85;
  settings.learned = learn_warps(profiles, profiles.size()).front();
  const AcquisitionPlan a = acquisition_plan(plan_setup(settings));
  const GonioReconstruction lab = reconstruct(a, measure(a), "lab");
  const GonioReconstruction study(truth(), a.plan.setup);
  const TestPairs test = draw_test_pairs(truth(), 20000, 2, ErrorSpace::log, 85);
  const double x = reconstruction_error(lab, test), y = reconstruction_error(study, test);
  EXPECT_NEAR(x, y, 1e-9 * y);
  const AcquisitionPlan back = parse_plan_sidecar(plan_sidecar(a, "x.csv"), "p.json");
  EXPECT_EQ(*back.plan.setup.learned, *a.plan.setup.learned);
}

// Measurement noise (multiplicative, relative standard deviation σ, as a photometer's): the
// reconstruction's error grows with σ, and by no more than σ itself in quadrature (the error space
// is ln(1 + Y): a relative error σ of Y moves it by at most σ, and interpolation only averages).
TEST(AcquisitionPlan, NoiseRaisesTheErrorByAtMostItsOwnSize) {
  GonioSetup s;
  s.space = space_of<HalfDiff>;
  s.budget = 5000;
  s.max_theta_deg = 85;
  const AcquisitionPlan a = acquisition_plan(s);
  std::vector<Rgb> clean(a.measured.size());
  truth().eval_batch(a.measured, clean);
  const TestPairs test = draw_test_pairs(truth(), 20000, 4, ErrorSpace::log, 85);
  std::vector<double> errors;
  for (double sigma : {0.0, 0.01, 0.03, 0.1}) {
    std::mt19937_64 rng(17);
    std::normal_distribution<double> n(0, 1);
    std::vector<Rgb> noisy = clean;
    for (Rgb& v : noisy) {
      const double f = std::max(0.0, 1 + sigma * n(rng));
      v = Rgb{v.r * f, v.g * f, v.b * f};
    }
    errors.push_back(reconstruction_error(reconstruct(a, noisy, "noisy"), test));
    EXPECT_LE(errors.back(), std::hypot(errors.front(), sigma) * 1.05) << sigma;
  }
  for (std::size_t k = 1; k < errors.size(); ++k) EXPECT_GT(errors[k], errors[k - 1]) << k;
}

}  // namespace
}  // namespace halfback::acquire
