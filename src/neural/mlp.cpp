#include "neural/mlp.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "halfback/core/rgb.hpp"

namespace halfback::neural {

MlpLayout::MlpLayout(std::vector<std::size_t> widths) : widths_(std::move(widths)) {
  if (widths_.size() < 2) throw std::invalid_argument("a network needs inputs and outputs");
  offsets_.push_back(0);
  for (std::size_t l = 0; l + 1 < widths_.size(); ++l) {
    if (widths_[l] == 0 || widths_[l + 1] == 0)
      throw std::invalid_argument("a layer of a network has width 0");
    offsets_.push_back(offsets_.back() + widths_[l] * widths_[l + 1] + widths_[l + 1]);
  }
}

std::uint64_t Rng::next() {
  std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

double Rng::uniform() {
  return double(next() >> 11) * 0x1.0p-53;
}

std::size_t Rng::below(std::size_t n) {
  const std::uint64_t limit =
      std::numeric_limits<std::uint64_t>::max() - std::numeric_limits<std::uint64_t>::max() % n;
  std::uint64_t r = next();
  while (r >= limit) r = next();
  return std::size_t(r % n);
}

Vector sztrajman_initial_parameters(const MlpLayout& layout, Rng& rng) {
  Vector p = Vector::Zero(Eigen::Index(layout.size()));
  for (std::size_t l = 0; l < layout.layers(); ++l) {
    auto w = layout.weight(p, l);
    for (Eigen::Index i = 0; i < w.size(); ++i) w.data()[i] = -0.05 + 0.1 * rng.uniform();
  }
  return p;
}

void forward(const MlpLayout& layout, const Vector& params, const Eigen::Ref<const Matrix>& inputs,
             Activations& act) {
  const std::size_t n = layout.layers();
  act.a.resize(n + 1);
  act.a[0] = inputs;
  for (std::size_t l = 0; l < n; ++l) {
    Matrix& out = act.a[l + 1];
    out.noalias() = layout.weight(params, l) * act.a[l];
    out.colwise() += layout.bias(params, l);
    if (l + 1 < n) out = out.cwiseMax(0.0);
  }
}

void backward(const MlpLayout& layout, const Vector& params, const Activations& act, Matrix& dy,
              Vector& gradient) {
  Matrix next;
  for (std::size_t l = layout.layers(); l-- > 0;) {
    layout.weight(gradient, l).noalias() += dy * act.a[l].transpose();
    layout.bias(gradient, l) += dy.rowwise().sum();
    if (l == 0) break;
    next.noalias() = layout.weight(params, l).transpose() * dy;
    // ReLU: the gradient passes where the unit's output was positive.
    dy = (act.a[l].array() > 0.0).select(next, 0.0);
  }
}

double log_loss_sum(const Matrix& y, const Matrix& target, const Vector& cosine, Matrix* dy) {
  if (dy) dy->resize(y.rows(), y.cols());
  double sum = 0;
  for (Eigen::Index j = 0; j < y.cols(); ++j) {
    const double c = cosine[j];
    for (Eigen::Index k = 0; k < y.rows(); ++k) {
      const double e = std::exp(y(k, j));
      const double predicted = 1.0 + (e - 1.0) * c;  // > 0: e − 1 > −1 and c ≤ 1
      const double diff = std::log(predicted) - std::log1p(target(k, j) * c);
      sum += std::abs(diff);
      if (dy) {
        const double sign = diff > 0 ? 1.0 : diff < 0 ? -1.0 : 0.0;
        (*dy)(k, j) = sign * c * e / predicted;
      }
    }
  }
  return sum;
}

double study_log_loss_sum(const Matrix& y, const Matrix& target, const Vector& weight, Matrix* dy) {
  if (y.rows() != 3 || target.rows() != 3 || target.cols() != y.cols() || weight.size() != y.cols())
    throw std::invalid_argument("study_log_loss_sum: 3 channels, one target and weight per column");
  const double w[3] = {Rgb{1, 0, 0}.luminance(), Rgb{0, 1, 0}.luminance(),
                       Rgb{0, 0, 1}.luminance()};
  if (dy) dy->resize(y.rows(), y.cols());
  double sum = 0;
  for (Eigen::Index j = 0; j < y.cols(); ++j) {
    // ln(1 + Ŷ) = ln Σ w_k e^{y_k}, shifted by the largest y against overflow.
    const double top = y.col(j).maxCoeff();
    double e[3], s = 0;
    for (int k = 0; k < 3; ++k) s += w[k] * (e[k] = std::exp(y(k, j) - top));
    const Rgb rho{target(0, j), target(1, j), target(2, j)};
    const double dlum = top + std::log(s) - std::log1p(rho.luminance());
    double channels = 0;
    for (int k = 0; k < 3; ++k) {
      const double dk = y(k, j) - std::log1p(target(k, j));
      channels += dk * dk;
      if (dy) (*dy)(k, j) = weight[j] * (2 * dlum * w[k] * e[k] / s + 2.0 / 3.0 * dk);
    }
    sum += weight[j] * (dlum * dlum + channels / 3);
  }
  return sum;
}

Adam::Adam(std::size_t parameters, AdamSettings settings)
    : s_(settings),
      m_(Vector::Zero(Eigen::Index(parameters))),
      v_(Vector::Zero(Eigen::Index(parameters))) {}

void Adam::step(Vector& params, const Vector& g) {
  ++t_;
  const double t = double(t_);
  const double lr_t =
      s_.learning_rate * std::sqrt(1.0 - std::pow(s_.beta2, t)) / (1.0 - std::pow(s_.beta1, t));
  m_ = s_.beta1 * m_ + (1.0 - s_.beta1) * g;
  v_ = s_.beta2 * v_ + (1.0 - s_.beta2) * g.cwiseAbs2();
  params.array() -= lr_t * m_.array() / (v_.array().sqrt() + s_.epsilon);
}

MlpLayout layout_of(const NbrdfNetwork& network) {
  std::vector<std::size_t> widths;
  if (network.layers.empty()) throw std::invalid_argument("a network without layers");
  widths.push_back(network.layers.front().inputs);
  for (const NbrdfLayer& layer : network.layers) widths.push_back(layer.outputs);
  return MlpLayout(std::move(widths));
}

Vector parameters_of(const MlpLayout& layout, const NbrdfNetwork& network) {
  if (layout.layers() != network.layers.size())
    throw std::invalid_argument("the network's layers differ from the layout's");
  Vector p(Eigen::Index(layout.size()));
  for (std::size_t l = 0; l < layout.layers(); ++l) {
    const NbrdfLayer& layer = network.layers[l];
    if (layer.inputs != layout.inputs(l) || layer.outputs != layout.outputs(l))
      throw std::invalid_argument("the network's layer " + std::to_string(l + 1) +
                                  " differs from the layout's");
    auto w = layout.weight(p, l);
    for (Eigen::Index i = 0; i < w.size(); ++i) w.data()[i] = layer.kernel[std::size_t(i)];
    auto b = layout.bias(p, l);
    for (Eigen::Index i = 0; i < b.size(); ++i) b[i] = layer.bias[std::size_t(i)];
  }
  return p;
}

NbrdfNetwork network_of(const MlpLayout& layout, const Vector& params) {
  NbrdfNetwork network;
  for (std::size_t l = 0; l < layout.layers(); ++l) {
    NbrdfLayer layer;
    layer.inputs = layout.inputs(l);
    layer.outputs = layout.outputs(l);
    const auto w = layout.weight(params, l);
    // Column-major outputs × inputs is the kernel inputs × outputs in row-major order.
    for (Eigen::Index i = 0; i < w.size(); ++i) layer.kernel.push_back(float(w.data()[i]));
    const auto b = layout.bias(params, l);
    for (Eigen::Index i = 0; i < b.size(); ++i) layer.bias.push_back(float(b[i]));
    network.layers.push_back(std::move(layer));
  }
  network.form = "trained by halfback";
  return network;
}

}  // namespace halfback::neural
