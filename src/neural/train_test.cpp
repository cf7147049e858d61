// Training a network from a BRDF: the result read back by the reader, its independence of the
// thread count, and the BRDFs it refuses.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include "halfback/core/space.hpp"
#include "halfback/formats/nbrdf.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/neural/train.hpp"
#include "neural/mlp.hpp"
#include "neural/trainer.hpp"
#include "support/test_support.hpp"

namespace halfback {
namespace {

NbrdfTrainOptions small_options(std::size_t samples = 4000, std::size_t epochs = 3) {
  NbrdfTrainOptions o;
  o.samples = samples;
  o.epochs = epochs;
  o.batch = 256;
  o.seed = 5;
  return o;
}

// A BRDF that is `value` where θo (the view direction's) exceeds `from` degrees, else Lambert's
// 0.5/π.
class OddBrdf final : public Brdf {
 public:
  OddBrdf(double value, double from) : value_(value), from_(from) {}
  std::string name() const override { return "odd"; }
  std::string description() const override { return "a test BRDF"; }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return false; }
  Rgb eval(const DirPair<double>& p) const override {
    if (p.wi.z < 0 || p.wo.z < 0) return {};
    const double v =
        std::acos(p.wo.z) * 180 / std::numbers::pi > from_ ? value_ : 0.5 / std::numbers::pi;
    return {v, v, v};
  }

 private:
  double value_, from_;
};

template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}

TEST(NbrdfTrain, WrittenNetworkReadsBackAndEvaluatesAsTrained) {
  const BrdfPtr ggx = load_brdf("ggx:alpha=0.3");
  const NbrdfTrainResult r = train_nbrdf(*ggx, small_options());
  EXPECT_EQ(r.epoch_losses.size(), 3u);
  EXPECT_LT(r.epoch_losses.back(), r.epoch_losses.front());
  EXPECT_GT(r.pairs, 2000u);  // about 2/3 of the pairs have both directions up
  EXPECT_LT(r.pairs, 4000u);
  test::TempDir tmp;
  write_nbrdf(tmp / "g.h5", r.network, nbrdf_train_notes(*ggx, {}, r));
  ASSERT_TRUE(std::filesystem::exists(tmp / "g.json"));
  const auto read = load_nbrdf(tmp / "g.h5");
  EXPECT_EQ(read->architecture(), "6-21-21-3");
  ASSERT_EQ(read->network().layers.size(), 3u);
  for (std::size_t l = 0; l < 3; ++l) {
    EXPECT_EQ(read->network().layers[l].kernel, r.network.layers[l].kernel);
    EXPECT_EQ(read->network().layers[l].bias, r.network.layers[l].bias);
  }
  // The reader (float32) against the trained weights in double, on the reader's float inputs.
  const neural::MlpLayout layout = neural::layout_of(r.network);
  const neural::Vector params = neural::parameters_of(layout, r.network);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  double worst = 0;
  for (int i = 0; i < 2000; ++i) {
    const double ti = std::acos(u(rng)), to = std::acos(u(rng)), pi = 2 * std::numbers::pi * u(rng);
    const DirPair<double> pair{
        {std::sin(ti) * std::cos(pi), std::sin(ti) * std::sin(pi), std::cos(ti)},
        {std::sin(to), 0, std::cos(to)}};
    const auto x = nbrdf::encode(pair);
    neural::Matrix input(6, 1);
    for (int k = 0; k < 6; ++k) input(k, 0) = float(x[std::size_t(k)]);
    neural::Activations act;
    neural::forward(layout, params, input, act);
    const Rgb got = read->eval(pair);
    const double want[3] = {std::max(std::expm1(act.outputs()(0, 0)), 0.0),
                            std::max(std::expm1(act.outputs()(1, 0)), 0.0),
                            std::max(std::expm1(act.outputs()(2, 0)), 0.0)};
    const double have[3] = {got.r, got.g, got.b};
    for (int k = 0; k < 3; ++k)
      worst = std::max(worst, std::abs(have[k] - want[k]) / (1 + want[k]));
  }
  EXPECT_LE(worst, 1e-6);  // float32 evaluation against double, relative to 1 + ρ
}

TEST(NbrdfTrain, NetworkOfAParameterizationsCoordinatesReadsBackAndEvaluatesAsTrained) {
  const BrdfPtr ggx = load_brdf("ggx:alpha=0.3");
  NbrdfTrainOptions o = small_options(4000, 3);
  o.param = "hybrid";
  const NbrdfTrainResult r = train_nbrdf(*ggx, o);
  EXPECT_LT(r.epoch_losses.back(), r.epoch_losses.front());
  test::TempDir tmp;
  write_nbrdf(tmp / "h.h5", r.network);
  const auto read = load_nbrdf(tmp / "h.h5");
  EXPECT_EQ(read->architecture(), "3-21-21-3");
  EXPECT_EQ(read->network().input, "hybrid");
  const neural::MlpLayout layout = neural::layout_of(r.network);
  const neural::Vector params = neural::parameters_of(layout, r.network);
  const ParamDescriptor& hybrid = space_from_name("hybrid")->param();
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(0, 1);
  double worst = 0;
  for (int i = 0; i < 500; ++i) {
    const double ti = std::acos(u(rng)), to = std::acos(u(rng)), pi = 2 * std::numbers::pi * u(rng);
    const DirPair<double> pair{
        {std::sin(ti) * std::cos(pi), std::sin(ti) * std::sin(pi), std::cos(ti)},
        {std::sin(to), 0, std::cos(to)}};
    const auto q = hybrid.forward_iso(pair);
    neural::Matrix input(3, 1);
    for (int k = 0; k < 3; ++k) input(k, 0) = float(q[std::size_t(k)]);
    neural::Activations act;
    neural::forward(layout, params, input, act);
    const Rgb got = read->eval(pair);
    const double have[3] = {got.r, got.g, got.b};
    for (int k = 0; k < 3; ++k) {
      const double want = std::max(std::expm1(act.outputs()(k, 0)), 0.0);
      worst = std::max(worst, std::abs(have[k] - want) / (1 + want));
    }
  }
  EXPECT_LE(worst, 1e-6);
  o.param = "dupuy-jakob:ggx";
  EXPECT_NE(error_of([&] { check_nbrdf_train_options(o); }).find("--param 'dupuy-jakob:ggx'"),
            std::string::npos);
}

TEST(NbrdfTrain, ResultDependsOnTheSeedNotOnTheThreads) {
  const BrdfPtr ggx = load_brdf("ggx:alpha=0.2");
  NbrdfTrainOptions o = small_options(2000, 2);
  o.threads = 1;
  const NbrdfTrainResult one = train_nbrdf(*ggx, o);
  o.threads = 2;
  const NbrdfTrainResult two = train_nbrdf(*ggx, o);
  o.seed = 6;
  const NbrdfTrainResult other = train_nbrdf(*ggx, o);
  for (std::size_t l = 0; l < 3; ++l) {
    EXPECT_EQ(one.network.layers[l].kernel, two.network.layers[l].kernel);
    EXPECT_EQ(one.network.layers[l].bias, two.network.layers[l].bias);
  }
  EXPECT_EQ(one.loss, two.loss);
  EXPECT_NE(one.network.layers[0].kernel, other.network.layers[0].kernel);
}

TEST(NbrdfTrain, RefusesValuesItCannotTrainOn) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const NbrdfTrainOptions o = small_options(500, 1);
  std::string e = error_of([&] { train_nbrdf(OddBrdf(nan, 60), o); });
  EXPECT_NE(e.find("odd is NaN at θh = "), std::string::npos) << e;
  e = error_of([&] { train_nbrdf(OddBrdf(inf, 80), o); });
  EXPECT_NE(e.find("odd is infinite at"), std::string::npos) << e;
  e = error_of([&] { train_nbrdf(OddBrdf(1e30, 70), o); });
  EXPECT_NE(e.find("odd: ρ = 1e+30 sr⁻¹ at θh = "), std::string::npos) << e;
  EXPECT_NE(e.find("above the bound of 1e+10 sr⁻¹"), std::string::npos) << e;
  e = error_of([&] { train_nbrdf(OddBrdf(-1, 85), o); });
  EXPECT_NE(e.find("odd is negative at"), std::string::npos) << e;
  e = error_of([&] { train_nbrdf(*load_brdf("lambert:albedo=0"), o); });
  EXPECT_NE(e.find("is 0 at all"), std::string::npos) << e;
  e = error_of([&] { train_nbrdf(*load_brdf("ggx:alpha_x=0.1,alpha_y=0.4"), o); });
  EXPECT_NE(e.find("is anisotropic"), std::string::npos) << e;
}

TEST(NbrdfTrain, RefusesOptionsOutOfRange) {
  const BrdfPtr lambert = load_brdf("lambert");
  auto with = [](auto change) {
    NbrdfTrainOptions o;
    change(o);
    return error_of([&] { check_nbrdf_train_options(o); });
  };
  EXPECT_EQ(with([](auto&) {}), "no error");
  EXPECT_NE(with([](auto& o) {
              o.hidden = {21, 0};
            }).find("--hidden: a layer of 0 units"),
            std::string::npos);
  EXPECT_NE(with([](auto& o) { o.hidden = {65}; }).find("expected 1 to 64"), std::string::npos);
  EXPECT_NE(with([](auto& o) { o.hidden.assign(16, 4); }).find("16 hidden layers"),
            std::string::npos);
  EXPECT_NE(with([](auto& o) { o.samples = 0; }).find("--samples: 0"), std::string::npos);
  EXPECT_NE(with([](auto& o) { o.epochs = 0; }).find("--epochs: 0"), std::string::npos);
  EXPECT_NE(with([](auto& o) { o.batch = 100000; }).find("--batch: 100000"), std::string::npos);
  EXPECT_NE(with([](auto& o) { o.learning_rate = std::nan(""); }).find("--learning-rate"),
            std::string::npos);
  EXPECT_NE(with([](auto& o) { o.final_learning_rate = 1e-3; }).find("--final-learning-rate"),
            std::string::npos);  // above the learning rate
  EXPECT_NE(with([](auto& o) { o.final_learning_rate = -1; }).find("--final-learning-rate"),
            std::string::npos);
  EXPECT_NE(with([](auto& o) { o.restarts = 0; }).find("--restarts: 0"), std::string::npos);
  EXPECT_NE(with([](auto& o) { o.restarts = 65; }).find("--restarts: 65"), std::string::npos);
  EXPECT_NE(with([](auto& o) { o.restart_epochs = 0; }).find("--restart-epochs: 0"),
            std::string::npos);
  EXPECT_EQ(with([](auto& o) { o.loss = "study-log"; }), "no error");
  EXPECT_NE(with([](auto& o) { o.loss = "l2"; }).find("--loss 'l2': expected sztrajman"),
            std::string::npos);
  // train_nbrdf_on: an input space and --param at once, or the dirs space.
  NbrdfTrainOptions o = small_options();
  o.param = "hybrid";
  EXPECT_THROW(train_nbrdf_on(*lambert, o, *space_from_name("halfdiff")), std::invalid_argument);
  o.param.clear();
  EXPECT_THROW(train_nbrdf_on(*lambert, o, Space::dirs), std::invalid_argument);
}

// The study's log loss: half its pairs from μ = cos θi cos θo dωi dωo, half the authors' way, and
// weights that make a mean over the kept pairs a mean over μ. Weighted, the two cosines (from the
// reader's input: cos θo = hz dz − hx dx, cos θi = hz dz + hx dx) have μ's moments: mean 2/3
// each, mean square 1/2, mean product 4/9 (independent, each of density 2 cos θ), and the weights
// mean 1 (f_μ is a probability density); unweighted they do not (the authors' half draws more
// pairs near the peak and the horizon). study_log_density is μ's density: its mean over the
// authors' box, times the box's volume π³/2, is 1.
TEST(NbrdfTrain, StudyLogPairsAreWeightedToTheMeasure) {
  const BrdfPtr lambert = load_brdf("lambert");
  const std::size_t n = 100000;
  const neural::TrainingSet set =
      neural::sample_training_set(*lambert, n, 3, std::nullopt, neural::Loss::study_log);
  EXPECT_NEAR(double(set.size()) / double(n), 0.5 + 0.5 * 0.617, 0.01);
  ASSERT_EQ(set.weight.size(), Eigen::Index(set.size()));
  double w = 0, ci = 0, co = 0, co2 = 0, product = 0, plain_co = 0;
  for (Eigen::Index j = 0; j < Eigen::Index(set.size()); ++j) {
    const double* x = set.inputs.col(j).data();
    const double i = x[2] * x[5] + x[0] * x[3], o = x[2] * x[5] - x[0] * x[3], v = set.weight[j];
    w += v, ci += v * i, co += v * o, co2 += v * o * o, product += v * i * o, plain_co += o;
  }
  const double m = double(set.size());
  // Standard errors about 0.002 (weights of spread about 1, cosines of 0.24, 80,000 pairs): the
  // bounds are about 4 of them.
  EXPECT_NEAR(w / m, 1.0, 0.01);
  EXPECT_NEAR(ci / m, 2.0 / 3, 0.008);
  EXPECT_NEAR(co / m, 2.0 / 3, 0.008);
  EXPECT_NEAR(co2 / m, 0.5, 0.008);
  EXPECT_NEAR(product / m, 4.0 / 9, 0.008);
  EXPECT_GT(std::abs(plain_co / m - 2.0 / 3), 0.03);  // the weights matter

  neural::Rng rng(8);
  double integral = 0;
  const std::size_t boxes = 200000;
  for (std::size_t k = 0; k < boxes; ++k) {
    const double th = rng.uniform() * std::numbers::pi / 2,
                 td = rng.uniform() * std::numbers::pi / 2,
                 pd = rng.uniform() * 2 * std::numbers::pi;
    const double sh = std::sin(th), ch = std::cos(th), dx = std::sin(td) * std::cos(pd),
                 dy = std::sin(td) * std::sin(pd), dz = std::cos(td);
    const Vec3<double> wo{ch * dx + sh * dz, dy, -sh * dx + ch * dz};
    const double hw = sh * wo.x + ch * wo.z;
    const Vec3<double> wi{2 * hw * sh - wo.x, -wo.y, 2 * hw * ch - wo.z};
    integral += neural::study_log_density({wi, wo});
  }
  EXPECT_NEAR(integral / double(boxes) * std::pow(std::numbers::pi, 3) / 2, 1.0, 0.01);
}

// Restarts: the first candidate is the training without restarts (the same stream), so the
// chosen one's loss is at most its loss, over seeds where another candidate was chosen too; a
// schedule ending at the learning rate is no schedule, a falling one changes the result.
TEST(NbrdfTrain, RestartsKeepTheLowestLossAndAFlatScheduleChangesNothing) {
  const BrdfPtr brdf = load_brdf("lambert:albedo=0.2+ggx:alpha=0.2,f0=0.8");
  int other_chosen = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    NbrdfTrainOptions one = small_options(3000, 2);
    one.seed = seed;
    one.learning_rate = 3e-3;
    const NbrdfTrainResult plain = train_nbrdf(*brdf, one);
    NbrdfTrainOptions four = one;
    four.restarts = 4;
    four.restart_epochs = 2;
    const NbrdfTrainResult best = train_nbrdf(*brdf, four);
    EXPECT_EQ(best.steps, 4 * plain.steps);
    EXPECT_LE(best.loss, plain.loss * (1 + 1e-6)) << seed;
    other_chosen += best.network.layers[0].kernel != plain.network.layers[0].kernel;
  }
  EXPECT_GT(other_chosen, 0);  // else the test would not see a choice
  const NbrdfTrainOptions one = small_options(3000, 2);
  const NbrdfTrainResult plain = train_nbrdf(*brdf, one);
  NbrdfTrainOptions flat = one;
  flat.final_learning_rate = flat.learning_rate;
  EXPECT_EQ(train_nbrdf(*brdf, flat).network.layers[0].kernel, plain.network.layers[0].kernel);
  NbrdfTrainOptions falling = one;
  falling.final_learning_rate = one.learning_rate / 100;
  EXPECT_NE(train_nbrdf(*brdf, falling).network.layers[0].kernel, plain.network.layers[0].kernel);
}

// Any parameterization's space as the input: for a built-in one the same network as --param, and
// trained_nbrdf_brdf evaluates it as the reader does; a family's member (Dupuy & Jakob's warp of
// a BRDF) trains and evaluates too, though no file can carry it.
TEST(NbrdfTrain, AnySpaceAsTheInputTrainsAndEvaluatesInMemory) {
  const BrdfPtr brdf = load_brdf("lambert:albedo=0.2+ggx:alpha=0.3,f0=0.8");
  NbrdfTrainOptions by_name = small_options();
  by_name.param = "hybrid";
  const NbrdfTrainResult named = train_nbrdf(*brdf, by_name);
  const NbrdfTrainResult spaced =
      train_nbrdf_on(*brdf, small_options(), *space_from_name("hybrid"));
  ASSERT_EQ(spaced.network.input, "hybrid");
  for (std::size_t l = 0; l < named.network.layers.size(); ++l)
    EXPECT_EQ(named.network.layers[l].kernel, spaced.network.layers[l].kernel);
  const NbrdfBrdf reader(named.network, "named");
  const BrdfPtr memory = trained_nbrdf_brdf(spaced.network, space_from_name("hybrid"), "memory");
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  auto direction = [&] {
    const double z = u(rng), phi = 2 * std::numbers::pi * u(rng), s = std::sqrt(1 - z * z);
    return Vec3<double>{s * std::cos(phi), s * std::sin(phi), z};
  };
  for (int i = 0; i < 500; ++i) {
    const DirPair<double> p{direction(), direction()};
    const Rgb a = reader.eval(p), b = memory->eval(p);
    EXPECT_EQ(a.r, b.r);
    EXPECT_EQ(a.g, b.g);
    EXPECT_EQ(a.b, b.b);
  }
  register_brdf_parameterization_families();
  const std::optional<Space> warp = space_from_name("dupuy-jakob:ggx:alpha=0.3");
  ASSERT_TRUE(warp);
  const NbrdfTrainResult warped = train_nbrdf_on(*brdf, small_options(), *warp);
  EXPECT_EQ(warped.network.input, name_of(*warp));
  EXPECT_THROW(NbrdfBrdf(warped.network, "warped"), FormatError);  // the reader refuses it
  const BrdfPtr w = trained_nbrdf_brdf(warped.network, warp, "warped");
  const Rgb v = w->eval({{0, 0, 1}, {0, 0, 1}});
  EXPECT_TRUE(std::isfinite(v.r) && v.r > 0);
  // A network whose first layer does not take the input's width.
  EXPECT_THROW(trained_nbrdf_brdf(warped.network, std::nullopt, "x"), std::invalid_argument);
}

}  // namespace
}  // namespace halfback
