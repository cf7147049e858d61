// The network's training arithmetic: the backward pass against finite differences, Adam's steps
// against a restatement, the loss decreasing on a fixed batch, and a network of the same shape
// recovered from the outputs of a known random one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <utility>
#include <vector>

#include "neural/mlp.hpp"
#include "neural/trainer.hpp"

namespace halfback::neural {
namespace {

const MlpLayout kSztrajman({6, 21, 21, 3});

// Random parameters with weights uniform in ±w (biases in ±w/4): larger than the authors'
// initial ±0.05, so that the ReLUs are mixed and the outputs vary.
Vector random_parameters(const MlpLayout& layout, double w, std::uint64_t seed) {
  Rng rng(seed);
  Vector p(Eigen::Index(layout.size()));
  for (Eigen::Index i = 0; i < p.size(); ++i) p[i] = w * (2 * rng.uniform() - 1);
  for (std::size_t l = 0; l < layout.layers(); ++l) layout.bias(p, l) *= 0.25;
  return p;
}

// The inputs of `n` pairs drawn as the trainer draws them (θh, θd, φd uniform), without a BRDF:
// x = (sin θh, 0, cos θh, d), and c from them.
TrainingSet inputs_only(std::size_t n, std::uint64_t seed) {
  Rng rng(seed);
  TrainingSet set;
  set.inputs.resize(6, Eigen::Index(n));
  set.targets.resize(3, Eigen::Index(n));
  set.cosine.resize(Eigen::Index(n));
  for (Eigen::Index j = 0; j < Eigen::Index(n); ++j) {
    const double th = rng.uniform() * std::numbers::pi / 2,
                 td = rng.uniform() * std::numbers::pi / 2,
                 pd = rng.uniform() * 2 * std::numbers::pi;
    set.inputs.col(j) << std::sin(th), 0, std::cos(th), std::sin(td) * std::cos(pd),
        std::sin(td) * std::sin(pd), std::cos(td);
    set.cosine[j] = cosine_weight(set.inputs.col(j).data());
  }
  return set;
}

// Targets ρ = exp(y) − 1 of a network (the function the trained network represents).
void set_targets_from(TrainingSet& set, const MlpLayout& layout, const Vector& params) {
  Activations act;
  forward(layout, params, set.inputs, act);
  set.targets = act.outputs().array().exp() - 1.0;
}

std::vector<std::size_t> first(std::size_t n) {
  std::vector<std::size_t> v(n);
  std::iota(v.begin(), v.end(), std::size_t{0});
  return v;
}

// The largest difference between the gradient of the loss of `set` at random parameters and its
// central differences, and the gradient's largest component.
std::pair<double, double> gradient_against_differences(const TrainingSet& set) {
  const Vector params = random_parameters(kSztrajman, 0.5, 1);
  const std::vector<std::size_t> batch = first(set.size());
  Vector gradient;
  loss_and_gradient(kSztrajman, params, set, batch, 1, &gradient);
  if (std::size_t(gradient.size()) != kSztrajman.size())
    throw std::logic_error("the gradient is not of the layout's size");
  double worst = 0;
  for (Eigen::Index i = 0; i < params.size(); ++i) {
    const double h = 1e-6;
    Vector plus = params, minus = params;
    plus[i] += h;
    minus[i] -= h;
    const double fd = (loss_and_gradient(kSztrajman, plus, set, batch, 1, nullptr) -
                       loss_and_gradient(kSztrajman, minus, set, batch, 1, nullptr)) /
                      (2 * h);
    worst = std::max(worst, std::abs(fd - gradient[i]));
  }
  return {worst, gradient.cwiseAbs().maxCoeff()};
}

TEST(NbrdfMlp, BackwardPassMatchesCentralDifferences) {
  TrainingSet set = inputs_only(150, 2);  // three chunks, the last partial
  set_targets_from(set, kSztrajman, random_parameters(kSztrajman, 0.5, 3));
  const auto [worst, scale] = gradient_against_differences(set);
  // Relative to the gradient's largest component (the small ones carry the differences'
  // rounding, ~1e-10 absolute).
  EXPECT_GT(scale, 1e-3);
  EXPECT_LE(worst, 1e-6 * scale) << "largest difference " << worst << ", gradient scale " << scale;
}

TEST(NbrdfMlp, StudyLogBackwardPassMatchesCentralDifferences) {
  TrainingSet set = inputs_only(150, 2);
  set.loss = Loss::study_log;
  set.weight.resize(Eigen::Index(set.size()));
  Rng rng(4);
  for (Eigen::Index j = 0; j < set.weight.size(); ++j) set.weight[j] = 0.2 + 1.8 * rng.uniform();
  set_targets_from(set, kSztrajman, random_parameters(kSztrajman, 0.5, 3));
  set.targets = set.targets.cwiseMax(0.0);  // a BRDF's values: ≥ 0, some 0
  const auto [worst, scale] = gradient_against_differences(set);
  EXPECT_GT(scale, 1e-3);
  EXPECT_LE(worst, 1e-6 * scale) << "largest difference " << worst << ", gradient scale " << scale;
}

// The study's log loss of a fixed batch against its definition restated apart: ρ̂ = e^y − 1 per
// channel, the luminances Ŷ and Y with Rec. 709's weights, and the term
// (ln(1 + Ŷ) − ln(1 + Y))² + ⅓ Σ_k (ln(1 + ρ̂_k) − ln(1 + ρ_k))², its weighted sum over the
// columns; and its derivative in each y against central differences of the restatement.
TEST(NbrdfMlp, StudyLogLossIsItsDefinitionOnAFixedBatch) {
  Rng rng(11);
  const Eigen::Index n = 40;
  Matrix y(3, n), target(3, n), dy;
  Vector weight(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    weight[j] = 0.1 + 2 * rng.uniform();
    for (Eigen::Index k = 0; k < 3; ++k) {
      y(k, j) = -0.8 + 4.0 * rng.uniform();  // ρ̂ from −0.55 (a negative output) to 19
      target(k, j) = j % 7 == 0 ? 0.0 : std::pow(10.0, -3 + 5 * rng.uniform());
    }
  }
  auto restated = [](const Matrix& yy, const Matrix& t, Eigen::Index j) {
    const double lum[3] = {0.2126, 0.7152, 0.0722};
    double y_hat = 0, y_true = 0, channels = 0;
    for (Eigen::Index k = 0; k < 3; ++k) {
      const double rho_hat = std::expm1(yy(k, j));
      y_hat += lum[k] * rho_hat;
      y_true += lum[k] * t(k, j);
      const double d = std::log1p(rho_hat) - std::log1p(t(k, j));
      channels += d * d;
    }
    const double d = std::log1p(y_hat) - std::log1p(y_true);
    return d * d + channels / 3;
  };
  double expected = 0;
  for (Eigen::Index j = 0; j < n; ++j) expected += weight[j] * restated(y, target, j);
  const double sum = study_log_loss_sum(y, target, weight, &dy);
  EXPECT_NEAR(sum, expected, 1e-9 * expected);
  EXPECT_GT(expected, 1.0);  // not a vanishing loss
  double worst = 0, scale = 0;
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index k = 0; k < 3; ++k) {
      const double h = 1e-6;
      Matrix plus = y, minus = y;
      plus(k, j) += h;
      minus(k, j) -= h;
      const double fd =
          weight[j] * (restated(plus, target, j) - restated(minus, target, j)) / (2 * h);
      worst = std::max(worst, std::abs(fd - dy(k, j)));
      scale = std::max(scale, std::abs(dy(k, j)));
    }
  EXPECT_LE(worst, 1e-7 * scale) << "largest difference " << worst << ", scale " << scale;
  // Where the network is exact the term and its derivative vanish.
  Matrix exact = target.array().log1p();
  EXPECT_NEAR(study_log_loss_sum(exact, target, weight, &dy), 0.0, 1e-24);
  EXPECT_LE(dy.cwiseAbs().maxCoeff(), 1e-12);
}

TEST(NbrdfMlp, LossGradientIsSztrajmansAtOnePoint) {
  // One column, one channel by hand: L = |log(1 + (e^y − 1) c) − log(1 + ρ c)| / 3 over the
  // three channels; dL/dy = sign · c e^y / (1 + (e^y − 1) c).
  Matrix y(3, 1), target(3, 1), dy;
  y << 0.3, -0.2, 0.0;
  target << 0.1, 0.5, 0.0;
  Vector c(1);
  c << 0.7;
  const double sum = log_loss_sum(y, target, c, &dy);
  double expected = 0;
  for (int k = 0; k < 3; ++k) {
    const double pred = std::log(1 + (std::exp(y(k)) - 1) * 0.7),
                 truth = std::log(1 + target(k) * 0.7);
    expected += std::abs(pred - truth);
    const double sign = pred > truth ? 1 : pred < truth ? -1 : 0;
    EXPECT_NEAR(dy(k), sign * 0.7 * std::exp(y(k)) / (1 + (std::exp(y(k)) - 1) * 0.7), 1e-15);
  }
  EXPECT_NEAR(sum, expected, 1e-15);
  EXPECT_EQ(dy(2), 0.0);  // equal values: sign(0) = 0
}

TEST(NbrdfMlp, AdamStepsAreKerasForm) {
  // Two steps on one parameter, restated: lr_t = lr √(1 − β2^t) / (1 − β1^t).
  AdamSettings s;
  Adam adam(1, s);
  Vector p(1), g(1);
  p << 1.0;
  double m = 0, v = 0, expected = 1.0;
  for (const double grad : {0.5, -0.25}) {
    g << grad;
    adam.step(p, g);
    const double t = double(adam.steps());
    m = 0.9 * m + 0.1 * grad;
    v = 0.999 * v + 0.001 * grad * grad;
    expected -= 5e-4 * std::sqrt(1 - std::pow(0.999, t)) / (1 - std::pow(0.9, t)) * m /
                (std::sqrt(v) + 1e-7);
  }
  EXPECT_NEAR(p[0], expected, 1e-15);
  EXPECT_NEAR(p[0], 1.0 - 5e-4 - 5e-4 * 0.4 / 0.5, 1e-3);  // ~lr per step at first
}

TEST(NbrdfMlp, ResultDoesNotDependOnTheThreadCount) {
  const Vector params = random_parameters(kSztrajman, 0.5, 4);
  TrainingSet set = inputs_only(512, 5);
  set_targets_from(set, kSztrajman, random_parameters(kSztrajman, 0.5, 6));
  Vector one, two;
  const auto batch = first(set.size());
  const double a = loss_and_gradient(kSztrajman, params, set, batch, 1, &one);
  const double b = loss_and_gradient(kSztrajman, params, set, batch, 2, &two);
  EXPECT_EQ(a, b);
  EXPECT_TRUE(one == two);
}

TEST(NbrdfMlp, LossDecreasesOnAFixedBatch) {
  TrainingSet set = inputs_only(512, 7);
  set_targets_from(set, kSztrajman, random_parameters(kSztrajman, 0.6, 8));
  Rng rng(9);
  Trainer trainer(kSztrajman, sztrajman_initial_parameters(kSztrajman, rng), {}, 0);
  const auto batch = first(set.size());
  const double initial = trainer.step(set, batch);
  double previous = initial, rises = 0;
  for (int i = 0; i < 1000; ++i) {
    const double loss = trainer.step(set, batch);
    rises += loss > previous;
    previous = loss;
  }
  EXPECT_LT(previous, 0.3 * initial) << "initial " << initial;
  EXPECT_LT(rises, 15);  // Adam on one batch: nearly monotone
}

TEST(NbrdfMlp, RecoversANetworkOfTheSameShape) {
  // The targets are a random 6-21-21-3 network's; a 6-21-21-3 network trained from the authors'
  // initialization on 4096 of its pairs must match it on 2048 others.
  const Vector teacher = random_parameters(kSztrajman, 0.6, 10);
  TrainingSet train = inputs_only(4096, 11), test = inputs_only(2048, 12);
  set_targets_from(train, kSztrajman, teacher);
  set_targets_from(test, kSztrajman, teacher);
  Rng rng(13);
  AdamSettings adam;
  adam.learning_rate = 3e-3;
  Trainer trainer(kSztrajman, sztrajman_initial_parameters(kSztrajman, rng), adam, 0);
  const double before = mean_loss(kSztrajman, trainer.parameters(), test, 0);
  std::vector<std::size_t> order = first(train.size());
  auto epochs = [&](Trainer& t, int count) {
    for (int epoch = 0; epoch < count; ++epoch) {
      for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng.below(i)]);
      for (std::size_t b = 0; b < order.size(); b += 256)
        t.step(train, std::span(order).subspan(b, 256));
    }
  };
  epochs(trainer, 300);
  const double after = mean_loss(kSztrajman, trainer.parameters(), test, 0);
  const double on_train = mean_loss(kSztrajman, trainer.parameters(), train, 0);
  // The mean |Δ log(1 + ρ c)| on held-out pairs, 0.29 for the untrained network, must fall
  // below 3% of that (measured: 0.0063, 2.2%; the same on the training pairs: what remains is
  // the optimization's, not overfitting).
  EXPECT_LT(after, 0.03 * before) << "before " << before << ", after " << after;
  EXPECT_LT(after, 1.3 * on_train);
}

}  // namespace
}  // namespace halfback::neural
