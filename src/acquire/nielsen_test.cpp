#include "halfback/acquire/nielsen.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

#include "halfback/acquire/gonio.hpp"
#include "halfback/loader/load.hpp"
#include "support/test_brdfs.hpp"

namespace halfback::acquire {
namespace {

using BrdfList = std::vector<std::shared_ptr<const Brdf>>;

BrdfList family(const std::vector<std::string>& specs) {
  BrdfList out;
  for (const std::string& s : specs) out.push_back(load_brdf(s));
  return out;
}

// Six BRDFs of different colours and lobes: 18 linearly independent observations.
const std::vector<std::string> kSpecs{
    "lambert:albedo_r=0.8,albedo_g=0.5,albedo_b=0.2",
    "lambert:albedo_r=0.2,albedo_g=0.3,albedo_b=0.6+ggx:alpha=0.3,f0=0.5",
    "lambert:albedo_r=0.1,albedo_g=0.15,albedo_b=0.05+ggx:alpha=0.1,f0=0.9",
    "lambert:albedo_r=0.4,albedo_g=0.45,albedo_b=0.3+beckmann:alpha=0.25,f0=0.6",
    "lambert:albedo_r=0.02,albedo_g=0.05,albedo_b=0.1+ggx:alpha=0.5",
    "lambert:albedo_r=0.6,albedo_g=0.3,albedo_b=0.1+ggx:alpha=0.2,f0=0.3"};

NielsenOptions small_grid() {
  NielsenOptions o;
  o.theta_h = o.theta_d = o.phi_d = 16;
  o.max_theta_deg = 85;
  o.candidates_per_step = 200;
  return o;
}

std::vector<DirPair<double>> random_pairs(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  auto dir = [&] {
    const double z = 0.05 + 0.95 * u(rng), r = std::sqrt(1 - z * z), phi = 6.283185307 * u(rng);
    return Vec3<double>{r * std::cos(phi), r * std::sin(phi), z};
  };
  std::vector<DirPair<double>> pairs(n);
  for (auto& p : pairs) p = {dir(), dir()};
  return pairs;
}

TEST(Nielsen, MappingRoundTrips) {
  const DirPair<double> p{{0.6, 0, 0.8}, {0, 0.28, 0.96}};
  for (double rho : {0.0, 1e-4, 0.3, 25.0})
    EXPECT_NEAR(nielsen_unmap(nielsen_map(rho, p), p), rho, 1e-12 * (1 + rho));
  // Their constants: ln(ρ c + ε), c = cos θi cos θo clamped at 0.01.
  EXPECT_NEAR(nielsen_map(2, p), std::log(2 * 0.8 * 0.96 + 0.001), 1e-15);
  const DirPair<double> grazing{{1, 0, 0.001}, {0, 1, 0.5}};
  EXPECT_NEAR(nielsen_map(2, grazing), std::log(2 * 0.01 + 0.001), 1e-15);
}

TEST(Nielsen, MemberInTheBasisIsExactAtAsManyMeasurementsAsComponents) {
  auto db = std::make_shared<NielsenDatabase>(family(kSpecs), small_grid());
  const NielsenBasis basis(db, {});
  // 18 observations, centred: 17 components (the six BRDFs' channels are independent).
  ASSERT_EQ(basis.components(), 17u);
  const std::vector<std::size_t> dirs = basis.directions(basis.components());
  const Brdf& member = db->member(3);
  std::vector<Rgb> values;
  for (std::size_t k : dirs) values.push_back(member.eval(db->configurations()[k]));
  const auto weights = basis.solve(dirs, values, 0.0);
  // The reconstruction is the member itself: weight 1 on its own channel, 0 elsewhere...
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t o = 0; o < db->observations(); ++o)
      EXPECT_NEAR(weights[c][o], o == 3 * 3 + c ? 1.0 : 0.0, 1e-6) << c << " " << o;
  // ...so it equals the member everywhere, not only at the candidates.
  const NielsenReconstruction rec(db, weights, member.name(), dirs.size());
  const auto pairs = random_pairs(500, 7);
  for (const auto& p : pairs) {
    const Rgb a = rec.eval(p), b = member.eval(p);
    EXPECT_NEAR(a.r, b.r, 1e-5 * (1 + b.r));
    EXPECT_NEAR(a.b, b.b, 1e-5 * (1 + b.b));
  }
  // One measurement fewer is not exact.
  const auto fewer = basis.solve(std::span(dirs).first(dirs.size() - 1),
                                 std::span(values).first(dirs.size() - 1), 0.0);
  double off = 0;
  for (std::size_t o = 0; o < db->observations(); ++o)
    off = std::max(off, std::abs(fewer[0][o] - (o == 9 ? 1.0 : 0.0)));
  EXPECT_GT(off, 1e-3);
}

TEST(Nielsen, WeightsAreAnAffineCombination) {
  auto db = std::make_shared<NielsenDatabase>(family(kSpecs), small_grid());
  const NielsenBasis basis(db, {1});
  const auto dirs = basis.directions(5);
  const auto other = load_brdf("lambert:albedo=0.3+ggx:alpha=0.15,f0=0.7");
  std::vector<Rgb> values;
  for (std::size_t k : dirs) values.push_back(other->eval(db->configurations()[k]));
  for (const auto& w : basis.solve(dirs, values, 40)) {
    EXPECT_NEAR(std::accumulate(w.begin(), w.end(), 0.0), 1.0, 1e-9);
    for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(w[3 + c], 0.0);  // member 1 is left out
  }
}

TEST(Nielsen, LeaveOneOutIsLeaveOneOut) {
  auto db = std::make_shared<NielsenDatabase>(family(kSpecs), small_grid());
  std::vector<std::string> without(kSpecs);
  without.erase(without.begin() + 2);
  auto db_without = std::make_shared<NielsenDatabase>(family(without), small_grid());
  const auto tested = load_brdf(kSpecs[2]);
  // The member like the tested BRDF is found by its values, whatever its name.
  EXPECT_EQ(db->members_like(*tested), std::vector<std::size_t>{2});
  EXPECT_TRUE(db_without->members_like(*tested).empty());
  const std::size_t counts[] = {1, 5, 10};
  const NielsenAcquisition a = nielsen_acquisition(db, *tested, counts);
  const NielsenAcquisition b = nielsen_acquisition(db_without, *tested, counts);
  ASSERT_EQ(a.left_out, std::vector<std::size_t>{2});
  // The same directions and the same reconstruction as a database that never held it.
  for (std::size_t k = 0; k < a.directions.size(); ++k)
    EXPECT_EQ(db->configurations()[a.directions[k]].wi.z,
              db_without->configurations()[b.directions[k]].wi.z);
  const auto pairs = random_pairs(300, 3);
  std::vector<Rgb> ra(pairs.size()), rb(pairs.size());
  for (std::size_t i = 0; i < 3; ++i) {
    a.reconstructions[i]->eval_batch(pairs, ra);
    b.reconstructions[i]->eval_batch(pairs, rb);
    for (std::size_t k = 0; k < pairs.size(); ++k)
      EXPECT_NEAR(ra[k].g, rb[k].g, 1e-6 * (1 + rb[k].g));
  }
  // And it is not exact at 10 measurements, where the member itself in the basis would be.
  const TestPairs test = draw_test_pairs(*tested, 20000, 1, ErrorSpace::log, 85);
  EXPECT_GT(reconstruction_error(*a.reconstructions[2], test), 1e-3);
}

// A database that holds the tested material twice leaves out both copies: its directions and
// reconstruction are those of the database without it (one copy stayed in, and made the error 0).
TEST(Nielsen, LeaveOneOutLeavesOutEveryCopy) {
  std::vector<std::string> twice(kSpecs), without(kSpecs);
  twice.push_back(kSpecs[2]);
  without.erase(without.begin() + 2);
  auto db_twice = std::make_shared<NielsenDatabase>(family(twice), small_grid());
  auto db_without = std::make_shared<NielsenDatabase>(family(without), small_grid());
  const auto tested = load_brdf(kSpecs[2]);
  EXPECT_EQ(db_twice->members_like(*tested), (std::vector<std::size_t>{2, twice.size() - 1}));
  const std::size_t counts[] = {5};
  const NielsenAcquisition a = nielsen_acquisition(db_twice, *tested, counts);
  const NielsenAcquisition b = nielsen_acquisition(db_without, *tested, counts);
  ASSERT_EQ(a.directions.size(), b.directions.size());
  for (std::size_t k = 0; k < a.directions.size(); ++k)
    EXPECT_EQ(db_twice->configurations()[a.directions[k]].wi.z,
              db_without->configurations()[b.directions[k]].wi.z);
  const auto pairs = random_pairs(300, 5);
  std::vector<Rgb> ra(pairs.size()), rb(pairs.size());
  a.reconstructions[0]->eval_batch(pairs, ra);
  b.reconstructions[0]->eval_batch(pairs, rb);
  for (std::size_t k = 0; k < pairs.size(); ++k)
    EXPECT_NEAR(ra[k].g, rb[k].g, 1e-6 * (1 + rb[k].g));
}

TEST(Nielsen, GreedyDirectionsConditionBetterThanRandomOnes) {
  auto db = std::make_shared<NielsenDatabase>(family(kSpecs), small_grid());
  const NielsenBasis basis(db, {});
  std::vector<double> conditions;
  const auto dirs = basis.directions(10, &conditions);
  // The condition numbers the selection computed by its rank-one update are those of the rows.
  ASSERT_EQ(conditions.size(), dirs.size());
  for (std::size_t n = 1; n <= dirs.size(); ++n)
    EXPECT_NEAR(conditions[n - 1], basis.condition_number(std::span(dirs).first(n)),
                1e-6 * conditions[n - 1])
        << n;
  // The first is where the database varies most.
  double best = 0;
  std::size_t argbest = 0;
  for (std::size_t k = 0; k < db->configurations().size(); ++k) {
    const auto g = db->mapped_at(k);
    const double mean = std::accumulate(g.begin(), g.end(), 0.0) / double(g.size());
    double v = 0;
    for (double x : g) v += (x - mean) * (x - mean);
    if (v > best) best = v, argbest = k;
  }
  EXPECT_EQ(dirs[0], argbest);
  const double greedy = basis.condition_number(dirs);
  std::mt19937_64 rng(5);
  std::vector<double> random;
  for (int t = 0; t < 21; ++t) {
    std::vector<std::size_t> r(10);
    for (auto& k : r) k = rng() % db->configurations().size();
    random.push_back(basis.condition_number(r));
  }
  std::nth_element(random.begin(), random.begin() + 10, random.end());
  EXPECT_LT(greedy, random[10]);
}

TEST(Nielsen, ErrorFallsWithMeasurementsOnABrdfOutsideTheDatabase) {
  auto db = std::make_shared<NielsenDatabase>(family(kSpecs), small_grid());
  const auto tested = load_brdf("lambert:albedo=0.3+ggx:alpha=0.22,f0=0.6");
  const std::size_t counts[] = {1, 5, 17};
  const NielsenAcquisition a = nielsen_acquisition(db, *tested, counts);
  EXPECT_TRUE(a.left_out.empty());
  const TestPairs test = draw_test_pairs(*tested, 20000, 1, ErrorSpace::log, 85);
  const double e1 = reconstruction_error(*a.reconstructions[0], test);
  const double e17 = reconstruction_error(*a.reconstructions[2], test);
  EXPECT_LT(e17, 0.5 * e1) << e1 << " " << e17;
}

TEST(Nielsen, CachedPairsGiveTheValuesEvaluatedOnes) {
  const auto pairs = random_pairs(200, 11);
  auto cached = std::make_shared<NielsenDatabase>(family(kSpecs), small_grid(), pairs);
  auto plain = std::make_shared<NielsenDatabase>(family(kSpecs), small_grid());
  std::array<std::vector<double>, 3> w;
  for (auto& v : w) {
    v.assign(cached->observations(), 0.0);
    v[4] = 0.7, v[9] = 0.3;
  }
  const NielsenReconstruction a(cached, w, "x", 1), b(plain, w, "x", 1);
  std::vector<Rgb> ra(pairs.size()), rb(pairs.size());
  a.eval_batch(pairs, ra);
  b.eval_batch(pairs, rb);
  // The cache is in single precision: ln values to 2^-24 relative.
  for (std::size_t i = 0; i < pairs.size(); ++i) EXPECT_NEAR(ra[i].r, rb[i].r, 2e-6 * rb[i].r);
}

TEST(Nielsen, RefusesWhatItCannotDo) {
  EXPECT_THROW(NielsenDatabase(family({"lambert"}), small_grid()), std::invalid_argument);
  EXPECT_THROW(NielsenDatabase(family({"lambert", "ggx:alpha_x=0.1,alpha_y=0.4"}), small_grid()),
               std::invalid_argument);
  // A member with a value that is not finite somewhere: refused, naming it.
  BrdfList with_nan = family({"lambert", "ggx:alpha=0.3"});
  with_nan.push_back(std::make_shared<test::FunctionBrdf>(
      [](const DirPair<double>& p) { return p.wo.z > 0.9 ? NAN : 0.2; }));
  try {
    NielsenDatabase(with_nan, small_grid());
    ADD_FAILURE() << "a member with NaN values was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("function has a value that is not finite"),
              std::string::npos)
        << e.what();
  }
  NielsenOptions bad = small_grid();
  bad.eta = -1;
  EXPECT_THROW(NielsenDatabase(family(kSpecs), bad), std::invalid_argument);
  auto db = std::make_shared<NielsenDatabase>(family(kSpecs), small_grid());
  const NielsenBasis basis(db, {});
  EXPECT_THROW(basis.directions(db->configurations().size() + 1), std::invalid_argument);
  const std::size_t dirs[] = {0, 1};
  const Rgb nan{NAN, NAN, NAN};
  const Rgb none[] = {nan, nan};
  EXPECT_THROW(basis.solve(dirs, none, 40), std::runtime_error);
  const Rgb one[] = {nan};
  EXPECT_THROW(basis.solve(dirs, one, 40), std::invalid_argument);
  const std::size_t zero[] = {0};
  EXPECT_THROW(nielsen_acquisition(db, *load_brdf("lambert"), zero), std::invalid_argument);
  const std::size_t two[] = {2};
  EXPECT_THROW(nielsen_acquisition(db, *load_brdf("ggx:alpha_x=0.1,alpha_y=0.4"), two),
               std::invalid_argument);
}

// A material without a value at Nielsen's first direction (an ALTA file measured on part of the
// hemisphere; the whole-data study stopped on one with "no finite measurement"): the count 1 has
// nothing to solve and gives no reconstruction, the larger count does; a material without any
// value gives none.
TEST(Nielsen, ACountWithoutAFiniteMeasurementGivesNoReconstruction) {
  auto db = std::make_shared<NielsenDatabase>(family(kSpecs), small_grid());
  const std::size_t first = NielsenBasis(db, {}).directions(1).front();
  const DirPair<double> at = db->configurations()[first];
  const auto same = [](const Vec3<double>& a, const Vec3<double>& b) {
    return std::abs(a.x - b.x) + std::abs(a.y - b.y) + std::abs(a.z - b.z) < 1e-12;
  };
  const test::FunctionBrdf partial(
      [&](const DirPair<double>& p) { return same(p.wi, at.wi) && same(p.wo, at.wo) ? NAN : 0.2; });
  const std::size_t counts[] = {1, 5};
  const NielsenAcquisition a = nielsen_acquisition(db, partial, counts);
  ASSERT_TRUE(a.left_out.empty());
  ASSERT_EQ(a.directions.front(), first);
  EXPECT_EQ(a.unmeasured, std::vector<std::size_t>{1});
  ASSERT_EQ(a.reconstructions.size(), 1u);
  EXPECT_EQ(a.reconstructions[0]->measurements(), 5u);
  const Rgb v = a.reconstructions[0]->eval(at);
  EXPECT_TRUE(std::isfinite(v.r) && std::isfinite(v.g) && std::isfinite(v.b));

  const test::FunctionBrdf none([](const DirPair<double>&) { return NAN; });
  const NielsenAcquisition b = nielsen_acquisition(db, none, counts);
  EXPECT_TRUE(b.reconstructions.empty());
  EXPECT_EQ(b.unmeasured, (std::vector<std::size_t>{1, 5}));
}

}  // namespace
}  // namespace halfback::acquire
