#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>

#include "formats/nbrdf_kernel.hpp"
#include "halfback/brdf/rho_bound.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/neural/train.hpp"
#include "halfback/util/format_error.hpp"
#include "neural/trainer.hpp"

namespace halfback {
namespace neural {
namespace {

constexpr double kDegrees = 180.0 / std::numbers::pi;

// The pair of Rusinkiewicz's angles with φh = 0 and d = ωo (formats/nbrdf.hpp): ωo is d rotated
// by θh about the binormal, ωi its mirror about h.
DirPair<double> pair_of_angles(double theta_h, double theta_d, double phi_d) {
  const double sh = std::sin(theta_h), ch = std::cos(theta_h);
  const double dx = std::sin(theta_d) * std::cos(phi_d), dy = std::sin(theta_d) * std::sin(phi_d),
               dz = std::cos(theta_d);
  const Vec3<double> wo{ch * dx + sh * dz, dy, -sh * dx + ch * dz};
  const double h_dot = sh * wo.x + ch * wo.z;
  const Vec3<double> wi{2 * h_dot * sh - wo.x, -wo.y, 2 * h_dot * ch - wo.z};
  return {wi, wo};
}

std::string describe(const DirPair<double>& pair, const Rgb& rho) {
  const auto x = nbrdf::encode(pair);
  return fmt::format("θh = {:.2f}°, θd = {:.2f}°, φd = {:.2f}° (ρ = {}, {}, {})",
                     std::atan2(x[0], x[2]) * kDegrees,
                     std::atan2(std::hypot(x[3], x[4]), x[5]) * kDegrees,
                     std::atan2(x[4], x[3]) * kDegrees, rho.r, rho.g, rho.b);
}

void require_valid(const Brdf& brdf, const DirPair<double>& pair, const Rgb& rho) {
  for (const double v : {rho.r, rho.g, rho.b})
    if (!std::isfinite(v) || v < 0)
      throw std::domain_error(fmt::format(
          "{} is {} at {}: a network can only be trained on finite, non-negative values",
          brdf.name(),
          std::isnan(v)   ? "NaN"
          : std::isinf(v) ? "infinite"
                          : "negative",
          describe(pair, rho)));
  if (!rho_within_bound(rho))  // a network that learnt it would be refused by the reader
    throw std::domain_error(brdf.name() + ": " +
                            rho_above_bound(std::max({rho.r, rho.g, rho.b}), describe(pair, rho)));
}

}  // namespace

Loss loss_of(const std::string& name) {
  if (name == kNbrdfLosses[0]) return Loss::sztrajman;
  if (name == kNbrdfLosses[1]) return Loss::study_log;
  throw std::invalid_argument(
      fmt::format("--loss '{}': expected {} (the authors') or {} (the study's log measure)", name,
                  kNbrdfLosses[0], kNbrdfLosses[1]));
}

double study_log_density(const DirPair<double>& pair) {
  const Vec3<double>&wi = pair.wi, &wo = pair.wo;
  if (!(wi.z > 0 && wo.z > 0)) return 0;
  Vec3<double> h{wi.x + wo.x, wi.y + wo.y, wi.z + wo.z};
  const double norm = std::sqrt(h.x * h.x + h.y * h.y + h.z * h.z);
  h = {h.x / norm, h.y / norm, h.z / norm};
  const double cos_h = std::min(h.z, 1.0), sin_h = std::sqrt(1 - cos_h * cos_h);
  const double cos_d = std::min(wi.x * h.x + wi.y * h.y + wi.z * h.z, 1.0),
               sin_d = std::sqrt(1 - cos_d * cos_d);
  return 8 / std::numbers::pi * wi.z * wo.z * cos_d * sin_h * sin_d;
}

double cosine_weight(const double* x) {
  return std::clamp(x[2] * x[5] - x[0] * x[3], 0.0, 1.0);
}

TrainingSet sample_training_set(const Brdf& brdf, std::size_t drawn, std::uint64_t seed,
                                std::optional<Space> param, Loss loss) {
  if (!brdf.isotropic())
    throw std::domain_error(brdf.name() +
                            " is anisotropic: a neural BRDF of this form is isotropic (its "
                            "pairs have φh = 0), it would hold one azimuthal slice");
  Rng rng(seed);
  std::vector<DirPair<double>> pairs;
  pairs.reserve(drawn);
  // A direction of density cos θ / π on the hemisphere, above the horizon (z ≥ 2^−26.5).
  auto cosine_direction = [&rng] {
    const double u = rng.uniform(), phi = 2 * std::numbers::pi * rng.uniform();
    const double r = std::sqrt(u);
    return Vec3<double>{r * std::cos(phi), r * std::sin(phi), std::sqrt(1 - u)};
  };
  for (std::size_t i = 0; i < drawn; ++i) {
    if (loss == Loss::study_log && rng.uniform() < 0.5) {
      const Vec3<double> wi = cosine_direction();
      pairs.push_back({wi, cosine_direction()});
      continue;
    }
    const double theta_h = rng.uniform() * std::numbers::pi / 2;
    const double theta_d = rng.uniform() * std::numbers::pi / 2;
    const double phi_d = rng.uniform() * 2 * std::numbers::pi;
    const DirPair<double> pair = pair_of_angles(theta_h, theta_d, phi_d);
    if (pair.wi.z > 0 && pair.wo.z > 0) pairs.push_back(pair);
  }
  if (pairs.empty())
    throw std::domain_error(
        fmt::format("none of the {} pairs drawn has both directions above the horizon", drawn));
  std::vector<Rgb> rho(pairs.size());
  brdf.eval_batch(pairs, rho);
  TrainingSet set;
  set.loss = loss;
  const auto n = Eigen::Index(pairs.size());
  set.inputs.resize(param ? 3 : nbrdf::kInputs, n);
  set.targets.resize(nbrdf::kOutputs, n);
  set.cosine.resize(n);
  if (loss == Loss::study_log) {
    // f_μ / q with q = ½ f_μ + ½ f_a, f_a = 2/π³ the authors' density, times kept / drawn.
    const double authors = 2 / std::pow(std::numbers::pi, 3);
    const double kept = double(pairs.size()) / double(drawn);
    set.weight.resize(n);
    for (Eigen::Index j = 0; j < n; ++j) {
      const double f = study_log_density(pairs[std::size_t(j)]);
      set.weight[j] = kept * f / (0.5 * f + 0.5 * authors);
    }
  }
  bool any_nonzero = false;
  for (Eigen::Index j = 0; j < n; ++j) {
    const DirPair<double>& pair = pairs[std::size_t(j)];
    const Rgb& value = rho[std::size_t(j)];
    require_valid(brdf, pair, value);
    any_nonzero = any_nonzero || value.r > 0 || value.g > 0 || value.b > 0;
    set.targets.col(j) << value.r, value.g, value.b;
    if (param) {
      const auto q = param->param().forward_iso(pair);
      for (std::size_t i = 0; i < 3; ++i) set.inputs(Eigen::Index(i), j) = float(q[i]);
      set.cosine[j] = std::clamp(pair.wo.z, 0.0, 1.0);
      continue;
    }
    const auto x = nbrdf::encode(pair);
    for (std::size_t i = 0; i < nbrdf::kInputs; ++i) set.inputs(Eigen::Index(i), j) = float(x[i]);
    set.cosine[j] = cosine_weight(set.inputs.col(j).data());
  }
  if (!any_nonzero)
    throw std::domain_error(fmt::format("{} is 0 at all {} pairs drawn: nothing to train on",
                                        brdf.name(), pairs.size()));
  return set;
}

namespace {

// One chunk's loss sum and gradient (of the sum, scaled by `scale`).
double chunk_loss(const MlpLayout& layout, const Vector& params, const TrainingSet& set,
                  std::span<const std::size_t> columns, double scale, Vector* gradient) {
  const auto n = Eigen::Index(columns.size());
  Matrix x(set.inputs.rows(), n), target(set.targets.rows(), n);
  Vector cosine(n), weight(set.weight.size() > 0 ? n : 0);
  for (Eigen::Index j = 0; j < n; ++j) {
    const auto c = Eigen::Index(columns[std::size_t(j)]);
    x.col(j) = set.inputs.col(c);
    target.col(j) = set.targets.col(c);
    cosine[j] = set.cosine[c];
    if (weight.size() > 0) weight[j] = set.weight[c];
  }
  Activations act;
  forward(layout, params, x, act);
  auto loss_sum = [&](Matrix* dy) {
    return set.loss == Loss::study_log ? study_log_loss_sum(act.outputs(), target, weight, dy)
                                       : log_loss_sum(act.outputs(), target, cosine, dy);
  };
  if (!gradient) return loss_sum(nullptr);
  Matrix dy;
  const double sum = loss_sum(&dy);
  dy *= scale;
  gradient->setZero(Eigen::Index(layout.size()));
  backward(layout, params, act, dy, *gradient);
  return sum;
}

}  // namespace

double loss_and_gradient(const MlpLayout& layout, const Vector& params, const TrainingSet& set,
                         std::span<const std::size_t> batch, int threads, Vector* gradient) {
  if (batch.empty()) throw std::invalid_argument("an empty batch");
  const std::size_t chunks = (batch.size() + kChunk - 1) / kChunk;
  // Sztrajman et al.'s loss is a mean over the channels too; the study's log loss sums its terms.
  const double per_column = set.loss == Loss::study_log ? 1.0 : double(set.targets.rows());
  const double scale = 1.0 / (double(batch.size()) * per_column);
  std::vector<double> sums(chunks);
  std::vector<Vector> gradients(gradient ? chunks : 0);
  parallel_for(
      chunks, 1,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t c = begin; c < end; ++c) {
          const std::size_t first = c * kChunk, count = std::min(kChunk, batch.size() - first);
          sums[c] = chunk_loss(layout, params, set, batch.subspan(first, count), scale,
                               gradient ? &gradients[c] : nullptr);
        }
      },
      threads);
  // The reduction in the chunks' order: the same sums whatever ran where.
  double sum = 0;
  for (std::size_t c = 0; c < chunks; ++c) sum += sums[c];
  if (gradient) {
    *gradient = gradients[0];
    for (std::size_t c = 1; c < chunks; ++c) *gradient += gradients[c];
  }
  return sum * scale;
}

double mean_loss(const MlpLayout& layout, const Vector& params, const TrainingSet& set,
                 int threads) {
  std::vector<std::size_t> all(set.size());
  std::iota(all.begin(), all.end(), std::size_t{0});
  return loss_and_gradient(layout, params, set, all, threads, nullptr);
}

Trainer::Trainer(MlpLayout layout, Vector params, AdamSettings adam, int threads)
    : layout_(std::move(layout)),
      params_(std::move(params)),
      adam_(layout_.size(), adam),
      threads_(threads) {}

double Trainer::step(const TrainingSet& set, std::span<const std::size_t> batch) {
  const double loss = loss_and_gradient(layout_, params_, set, batch, threads_, &gradient_);
  adam_.step(params_, gradient_);
  return loss;
}

}  // namespace neural

void check_nbrdf_train_options(const NbrdfTrainOptions& o) {
  auto fail = [](const std::string& message) { throw std::invalid_argument(message); };
  if (o.hidden.empty() || o.hidden.size() + 1 > nbrdf::kMaxLayers)
    fail(fmt::format("--hidden: {} hidden layers, expected 1 to {}", o.hidden.size(),
                     nbrdf::kMaxLayers - 1));
  for (const std::size_t width : o.hidden)
    if (width == 0 || width > nbrdf::kMaxWidth)
      fail(fmt::format("--hidden: a layer of {} units, expected 1 to {} (the reader's widest)",
                       width, nbrdf::kMaxWidth));
  if (!o.param.empty()) {
    try {
      nbrdf::input_space(o.param, "--param");
    } catch (const std::exception&) {
      fail(fmt::format("--param '{}': expected {} (a built-in parameterization)", o.param,
                       parameterization_names()));
    }
  }
  if (o.samples == 0 || o.samples > 10'000'000)
    fail(fmt::format("--samples: {}, expected 1 to 10000000", o.samples));
  if (o.epochs == 0 || o.epochs > 1'000'000)
    fail(fmt::format("--epochs: {}, expected 1 to 1000000", o.epochs));
  if (o.batch == 0 || o.batch > 65536)
    fail(fmt::format("--batch: {}, expected 1 to 65536", o.batch));
  if (!(o.learning_rate > 0 && o.learning_rate <= 1))
    fail(fmt::format("--learning-rate: {}, expected a number in (0, 1]", o.learning_rate));
  if (!(o.final_learning_rate >= 0 && o.final_learning_rate <= o.learning_rate))
    fail(fmt::format("--final-learning-rate: {}, expected 0 (none) or a number in (0, {}]",
                     o.final_learning_rate, o.learning_rate));
  if (o.restarts == 0 || o.restarts > 64)
    fail(fmt::format("--restarts: {}, expected 1 to 64", o.restarts));
  if (o.restart_epochs == 0 || o.restart_epochs > 1'000'000)
    fail(fmt::format("--restart-epochs: {}, expected 1 to 1000000", o.restart_epochs));
  neural::loss_of(o.loss);  // names --loss when unknown
  if (o.threads < 0) fail(fmt::format("--threads: {}, expected 0 or more", o.threads));
}

namespace {

// One pass over the pairs in a new shuffle of `order`; returns the mean of the batch losses and
// adds the steps to `steps`.
double run_epoch(neural::Trainer& trainer, const neural::TrainingSet& set,
                 std::vector<std::size_t>& order, neural::Rng& rng, std::size_t batch,
                 std::size_t& steps) {
  for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng.below(i)]);
  double sum = 0;
  std::size_t batches = 0;
  for (std::size_t first = 0; first < order.size(); first += batch, ++batches) {
    const std::size_t count = std::min(batch, order.size() - first);
    sum += trainer.step(set, std::span(order).subspan(first, count));
  }
  steps += batches;
  return sum / double(batches);
}

// What is written must read back: every weight finite and ρ within the reader's bound
// (NbrdfBrdf's checks). A guard: with the targets within the bound and Adam's steps of about the
// learning rate at most, no training of the tests reaches it.
void require_readable(const NbrdfNetwork& network, const NbrdfTrainOptions& options) {
  try {
    NbrdfBrdf(network, "trained");
  } catch (const FormatError& e) {
    throw std::domain_error(
        fmt::format("the trained network (learning rate {}) is not one the reader takes: {}",
                    options.learning_rate, e.what()));
  }
}

// The training of train_nbrdf and train_nbrdf_on: the network's input from `param` (none:
// Sztrajman et al.'s); `input_name` goes to result.network.input.
NbrdfTrainResult train(const Brdf& brdf, const NbrdfTrainOptions& options,
                       const std::optional<Space>& param, const std::string& input_name,
                       bool readable) {
  using namespace neural;
  const TrainingSet set =
      sample_training_set(brdf, options.samples, options.seed, param, loss_of(options.loss));
  std::vector<std::size_t> widths{std::size_t(set.inputs.rows())};
  widths.insert(widths.end(), options.hidden.begin(), options.hidden.end());
  widths.push_back(nbrdf::kOutputs);
  MlpLayout layout(widths);
  AdamSettings adam;
  adam.learning_rate = options.learning_rate;
  // One candidate per restart, each with its own stream for the weights and shuffles apart from
  // the pairs' (the first one's is that of a training without restarts).
  struct Candidate {
    Rng rng;
    Trainer trainer;
    std::vector<std::size_t> order;
    std::vector<double> epoch_losses;
  };
  std::vector<Candidate> candidates;
  for (std::size_t r = 0; r < options.restarts; ++r) {
    Rng rng(options.seed ^ 0x6e62726466ULL ^ (r * 0x9e3779b97f4a7c15ULL));  // "nbrdf"
    Vector initial = sztrajman_initial_parameters(layout, rng);
    std::vector<std::size_t> order(set.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    candidates.push_back(
        {rng, Trainer(layout, std::move(initial), adam, options.threads), std::move(order), {}});
  }

  NbrdfTrainResult result;
  result.drawn = options.samples;
  result.pairs = set.size();
  const auto start = std::chrono::steady_clock::now();
  auto report = [&](std::size_t epoch, double loss) {
    if (!options.progress) return;
    NbrdfTrainProgress p;
    p.epoch = epoch;
    p.epochs = options.epochs;
    p.loss = loss;
    p.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    options.progress(p);
  };
  // The schedule (NbrdfTrainOptions::final_learning_rate).
  auto rate_of = [&](std::size_t epoch) {
    if (!(options.final_learning_rate > 0) || options.epochs < 2) return options.learning_rate;
    const double f = double(epoch) / double(options.epochs - 1);
    return options.learning_rate * std::pow(options.final_learning_rate / options.learning_rate, f);
  };
  // With restarts, every candidate runs restart_epochs epochs and the one of the lowest loss on
  // all the pairs goes on (ties: the first).
  const std::size_t probe =
      options.restarts > 1 ? std::min(options.restart_epochs, options.epochs) : 0;
  std::size_t best = 0;
  if (probe > 0) {
    double lowest = INFINITY;
    for (std::size_t r = 0; r < candidates.size(); ++r) {
      Candidate& c = candidates[r];
      for (std::size_t epoch = 0; epoch < probe; ++epoch) {
        c.trainer.set_learning_rate(rate_of(epoch));
        c.epoch_losses.push_back(
            run_epoch(c.trainer, set, c.order, c.rng, options.batch, result.steps));
      }
      const double loss = mean_loss(layout, c.trainer.parameters(), set, options.threads);
      if (loss < lowest) lowest = loss, best = r;
    }
    report(probe, candidates[best].epoch_losses.back());
  }
  Candidate& chosen = candidates[best];
  for (std::size_t epoch = probe; epoch < options.epochs; ++epoch) {
    chosen.trainer.set_learning_rate(rate_of(epoch));
    chosen.epoch_losses.push_back(
        run_epoch(chosen.trainer, set, chosen.order, chosen.rng, options.batch, result.steps));
    report(epoch + 1, chosen.epoch_losses.back());
  }
  result.epoch_losses = chosen.epoch_losses;
  const Trainer& trainer = chosen.trainer;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.network = network_of(layout, trainer.parameters());
  result.network.source = brdf.name();
  result.network.input = input_name;
  if (readable) require_readable(result.network, options);
  const Vector rounded = parameters_of(layout, result.network);
  result.loss = mean_loss(layout, rounded, set, options.threads);
  return result;
}

// The network of a trained result evaluated as the reader evaluates it, with any input space.
class TrainedNbrdf final : public Brdf {
 public:
  TrainedNbrdf(NbrdfNetwork network, std::optional<Space> input, std::string label)
      : network_(std::move(network)), input_(input), label_(std::move(label)) {
    const std::size_t inputs = input_ ? 3 : nbrdf::kInputs;
    if (network_.layers.empty() || network_.layers.front().inputs != inputs ||
        network_.layers.back().outputs != nbrdf::kOutputs ||
        network_.layers.size() > nbrdf::kMaxLayers)
      throw std::invalid_argument(fmt::format(
          "trained_nbrdf_brdf: a network of {} layers from {} to {} values, expected {} to {}",
          network_.layers.size(), network_.layers.empty() ? 0 : network_.layers.front().inputs,
          network_.layers.empty() ? 0 : network_.layers.back().outputs, inputs, nbrdf::kOutputs));
    for (const NbrdfLayer& l : network_.layers)
      if (l.outputs > nbrdf::kMaxWidth || l.inputs > nbrdf::kMaxWidth)
        throw std::invalid_argument(
            fmt::format("trained_nbrdf_brdf: a layer of {} units, expected at most {}", l.outputs,
                        nbrdf::kMaxWidth));
  }
  std::string name() const override { return label_; }
  std::string description() const override {
    return fmt::format("a trained network of {} layers on {}", network_.layers.size(),
                       input_ ? std::string(name_of(*input_)) : "Sztrajman et al.'s input");
  }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return false; }
  Rgb eval(const DirPair<double>& pair) const override {
    const double v[6] = {pair.wi.x, pair.wi.y, pair.wi.z, pair.wo.x, pair.wo.y, pair.wo.z};
    for (const double c : v)
      if (std::isnan(c)) return {NAN, NAN, NAN};
    if (!(pair.wi.z >= 0 && pair.wo.z >= 0)) return {0, 0, 0};
    std::array<float, nbrdf::kInputs> x{};
    if (input_) {
      const auto q = input_->param().forward_iso(pair);
      for (std::size_t i = 0; i < 3; ++i) x[i] = float(q[i]);
    } else {
      const auto e = nbrdf::encode(pair);
      for (std::size_t i = 0; i < nbrdf::kInputs; ++i) x[i] = float(e[i]);
    }
    const auto rho = nbrdf_detail::evaluate_one(network_, x);
    return {rho[0], rho[1], rho[2]};
  }
  void eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const override {
    if (out.size() != pairs.size())
      throw std::invalid_argument("trained network: output size differs from the pairs'");
    parallel_for(pairs.size(), 4096, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) out[i] = eval(pairs[i]);
    });
  }

 private:
  NbrdfNetwork network_;
  std::optional<Space> input_;
  std::string label_;
};

}  // namespace

NbrdfTrainResult train_nbrdf(const Brdf& brdf, const NbrdfTrainOptions& options) {
  check_nbrdf_train_options(options);
  return train(brdf, options, nbrdf::input_space(options.param, "--param"), options.param, true);
}

NbrdfTrainResult train_nbrdf_on(const Brdf& brdf, const NbrdfTrainOptions& options, Space input) {
  if (!options.param.empty())
    throw std::invalid_argument(
        fmt::format("train_nbrdf_on: --param '{}' and an input space: give one", options.param));
  if (input.is_dirs())
    throw std::invalid_argument("train_nbrdf_on: the input must be a parameterization, not dirs");
  check_nbrdf_train_options(options);
  return train(brdf, options, input, std::string(name_of(input)), false);
}

BrdfPtr trained_nbrdf_brdf(NbrdfNetwork network, std::optional<Space> input, std::string label) {
  return std::make_shared<TrainedNbrdf>(std::move(network), input, std::move(label));
}

std::vector<NbrdfNote> nbrdf_train_notes(const Brdf& brdf, const NbrdfTrainOptions& o,
                                         const NbrdfTrainResult& r) {
  std::string hidden;
  for (const std::size_t w : o.hidden) {
    if (!hidden.empty()) hidden += ',';  // (appended apart: GCC 12's false -Wrestrict, bug 105329)
    hidden += std::to_string(w);
  }
  return {{"trained_from", brdf.name()},
          {"trainer", o.loss == kNbrdfLosses[0]
                          ? "halfback nbrdf train (Sztrajman et al. 2021's loss, sampling and Adam)"
                          : "halfback nbrdf train (halfback's loss in the study's log measure, its "
                            "pairs weighted to cos θi cos θo dωi dωo; Sztrajman et al. 2021's "
                            "network and Adam)"},
          {"loss_function", o.loss},
          {"hidden", hidden},
          {"samples", fmt::format("{} drawn, {} kept", r.drawn, r.pairs)},
          {"epochs", std::to_string(o.epochs)},
          {"batch", std::to_string(o.batch)},
          {"learning_rate", fmt::format("{}", o.learning_rate)},
          {"final_learning_rate", fmt::format("{}", o.final_learning_rate)},
          {"restarts", fmt::format("{} of {} epochs", o.restarts, o.restart_epochs)},
          {"seed", std::to_string(o.seed)},
          {"loss", fmt::format("{:.6g}", r.loss)}};
}

}  // namespace halfback
