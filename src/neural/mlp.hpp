// The multilayer perceptron of a neural BRDF, in double, for training (private header of
// src/neural): dense layers with ReLU after each but the last, the last linear (its outputs y;
// the file's output layer, ρ = exp(y) − 1, belongs to the loss). The parameters are one flat
// vector so that Adam, the reduction of gradients and the gradient check see one vector; the
// layers are Eigen maps into it. A batch is a matrix with one column per sample.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "halfback/formats/nbrdf.hpp"

namespace halfback::neural {

using Matrix = Eigen::MatrixXd;
using Vector = Eigen::VectorXd;

// Where each layer's weights (outputs × inputs, column-major: the Keras kernel inputs × outputs
// in row-major order, element for element) and biases are in the flat vector.
class MlpLayout {
 public:
  // widths: inputs, the hidden widths, outputs (at least two entries, each ≥ 1).
  explicit MlpLayout(std::vector<std::size_t> widths);
  std::size_t layers() const { return widths_.size() - 1; }
  std::size_t inputs(std::size_t l) const { return widths_[l]; }
  std::size_t outputs(std::size_t l) const { return widths_[l + 1]; }
  std::size_t weight_offset(std::size_t l) const { return offsets_[l]; }
  std::size_t bias_offset(std::size_t l) const { return offsets_[l] + inputs(l) * outputs(l); }
  std::size_t size() const { return offsets_.back(); }
  const std::vector<std::size_t>& widths() const { return widths_; }

  Eigen::Map<const Matrix> weight(const Vector& p, std::size_t l) const {
    return {p.data() + weight_offset(l), Eigen::Index(outputs(l)), Eigen::Index(inputs(l))};
  }
  Eigen::Map<Matrix> weight(Vector& p, std::size_t l) const {
    return {p.data() + weight_offset(l), Eigen::Index(outputs(l)), Eigen::Index(inputs(l))};
  }
  Eigen::Map<const Vector> bias(const Vector& p, std::size_t l) const {
    return {p.data() + bias_offset(l), Eigen::Index(outputs(l))};
  }
  Eigen::Map<Vector> bias(Vector& p, std::size_t l) const {
    return {p.data() + bias_offset(l), Eigen::Index(outputs(l))};
  }

 private:
  std::vector<std::size_t> widths_;
  std::vector<std::size_t> offsets_;  // layers() + 1 entries: each layer's start, then the end
};

// A generator of the trainer's random numbers, the same on every platform: SplitMix64
// (Steele, Lea, Flood 2014), whose whole state is one 64-bit word.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next();
  double uniform();                  // [0, 1), 53 bits
  std::size_t below(std::size_t n);  // [0, n), n ≥ 1 (rejection: no modulo bias)

 private:
  std::uint64_t state_;
};

// Sztrajman et al.'s initialization (Keras 2.2's defaults for their layers): every weight
// uniform in [−0.05, 0.05], every bias 0.
Vector sztrajman_initial_parameters(const MlpLayout& layout, Rng& rng);

// The activations of a batch: a[0] the inputs, a[l + 1] the outputs of layer l (after ReLU for
// the hidden layers; the last is y).
struct Activations {
  std::vector<Matrix> a;
  const Matrix& outputs() const { return a.back(); }
};
void forward(const MlpLayout& layout, const Vector& params, const Eigen::Ref<const Matrix>& inputs,
             Activations& act);

// Adds to `gradient` (the flat layout) the gradient of Σ dL/dy · y over the batch, given
// dL/dy (outputs × columns), by back-propagation through the activations of forward().
// A ReLU's derivative at 0 is taken as 0. `dy` is consumed (used as scratch).
void backward(const MlpLayout& layout, const Vector& params, const Activations& act, Matrix& dy,
              Vector& gradient);

// Sztrajman et al.'s loss term of a batch, summed (not averaged) over its columns and the three
// channels: Σ |log(1 + ρ̂ c) − log(1 + ρ c)| with ρ̂ = exp(y) − 1 the network's value, ρ the
// target (3 × n) and c (n) the cosine weight. Writes d(sum)/dy into `dy` when it is not null,
// with sign(0) = 0 (as TensorFlow's derivative of |x|).
double log_loss_sum(const Matrix& y, const Matrix& target, const Vector& cosine, Matrix* dy);

// halfback's loss term in the study's log measure (docs/neural.md, "The losses"), summed over the
// columns with the weights `weight` (n): Σ_j weight_j [(ln(1 + Ŷ) − ln(1 + Y))² + ⅓ Σ_k (ln(1 +
// ρ̂_k) − ln(1 + ρ_k))²], with ρ̂ = exp(y) − 1 (so ln(1 + ρ̂_k) = y_k and ln(1 + Ŷ) = ln Σ_k w_k
// exp(y_k)), ρ the target (3 × n) and Ŷ, Y the luminances (Rgb::luminance's weights w, which sum
// to 1). Writes d(sum)/dy into `dy` when it is not null.
double study_log_loss_sum(const Matrix& y, const Matrix& target, const Vector& weight, Matrix* dy);

// Adam (Kingma and Ba 2015) as Keras 2.2 implements it, the optimizer of Sztrajman et al.: at step
// t, lr_t = lr √(1 − β2^t) / (1 − β1^t), m ← β1 m + (1 − β1) g, v ← β2 v + (1 − β2) g²,
// p ← p − lr_t m / (√v + ε), with ε = 1e-7 (Keras's K.epsilon(), their epsilon=None).
struct AdamSettings {
  double learning_rate = 5e-4, beta1 = 0.9, beta2 = 0.999, epsilon = 1e-7;
};
class Adam {
 public:
  Adam(std::size_t parameters, AdamSettings settings);
  void step(Vector& params, const Vector& gradient);
  std::size_t steps() const { return t_; }
  // The learning rate of the next steps (a schedule's).
  void set_learning_rate(double rate) { s_.learning_rate = rate; }

 private:
  AdamSettings s_;
  Vector m_, v_;
  std::size_t t_ = 0;
};

// The network of a file (its layers as NbrdfNetwork holds them) and back, float32 ↔ double.
Vector parameters_of(const MlpLayout& layout, const NbrdfNetwork& network);
NbrdfNetwork network_of(const MlpLayout& layout, const Vector& params);
MlpLayout layout_of(const NbrdfNetwork& network);

}  // namespace halfback::neural
