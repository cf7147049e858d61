// The training of a neural BRDF's network (private header of src/neural; the public entry is
// halfback/neural/train.hpp): the training pairs of a BRDF, the loss and its gradient over a
// batch, parallel over fixed chunks of the batch, and Adam's steps.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "halfback/brdf/brdf.hpp"
#include "halfback/core/space.hpp"
#include "neural/mlp.hpp"

namespace halfback::neural {

// The losses (NbrdfTrainOptions::loss): Sztrajman et al.'s (log_loss_sum) on their pairs, or
// halfback's in the study's log measure (study_log_loss_sum) on pairs weighted to μ.
enum class Loss { sztrajman, study_log };
// Throws std::invalid_argument naming --loss and the names it takes.
Loss loss_of(const std::string& name);

// Training pairs, one column each: the network's input x (6), the target ρ (3), the loss's cosine
// weight c (Sztrajman et al.'s loss) or the pair's weight (the study's log loss), and the loss
// they were drawn for.
struct TrainingSet {
  Matrix inputs, targets;
  Vector cosine, weight;
  Loss loss = Loss::sztrajman;
  std::size_t size() const { return std::size_t(inputs.cols()); }
};

// Sztrajman et al.'s cosine weight of an input x = (h, d): the z of the direction d stands for
// (d rotated back by θh about the binormal), clamped to [0, 1]: c = clamp(hz dz − hx dx, 0, 1).
double cosine_weight(const double* x);

// The training pairs of `loss`, `drawn` of them drawn. Sztrajman et al.'s: θh, θd uniform in
// [0, π/2], φd uniform in [0, 2π), φh = 0, the pair of those angles (d is ωo, formats/nbrdf.hpp);
// those with a direction at or below the horizon are dropped (the authors drop MERL's unmeasured
// values, which are those). The study's log loss: each pair, with probability ½, either drawn
// from μ = cos θi cos θo dωi dωo (ωi and ωo independent, of density cos θ / π on the hemisphere)
// or as the authors draw theirs (dropped when below the horizon), and weighted by
// f_μ / (½ f_μ + ½ f_a), the densities in (θh, θd, φd) of μ (normalized, study_log_density) and of
// the authors' sampling (2/π³), times kept / drawn: the mean of the weighted terms over the kept
// pairs estimates their mean over μ without bias, with the authors' density of pairs near the
// specular peak (docs/neural.md, "The losses"). Each pair gets the input the reader computes for
// it (nbrdf::encode, rounded to float as the reader evaluates it) and ρ = brdf.eval_batch(pair).
// Throws std::domain_error for an anisotropic BRDF, naming the pair when ρ is NaN, infinite or
// negative there, or when it is 0 at every kept pair. With `param`, the input is the pair's
// isotropic coordinates in it (rounded to float) and c the view direction's cosine (the same
// direction, computed from the pair).
TrainingSet sample_training_set(const Brdf& brdf, std::size_t drawn, std::uint64_t seed,
                                std::optional<Space> param = std::nullopt,
                                Loss loss = Loss::sztrajman);

// The density of μ = cos θi cos θo dωi dωo / π² (a probability) in Rusinkiewicz's (θh, θd, φd)
// of an isotropic pair (φh integrated out): with dωi dωo = 4 cos θd dωh dωd,
// f_μ = (8/π) cos θi cos θo cos θd sin θh sin θd; 0 for a pair with a direction below the horizon.
double study_log_density(const DirPair<double>& pair);

// Samples per chunk of a batch: each chunk's loss and gradient are computed apart (in parallel)
// and summed in the chunks' order, so the result depends on neither the thread count nor the
// schedule.
inline constexpr std::size_t kChunk = 64;

// The mean loss of set.loss over the columns `batch` of `set` (log_loss_sum's over the columns
// and the 3 channels; study_log_loss_sum's over the columns), and (when
// `gradient` is not null) its gradient with respect to the parameters, resized to the layout.
double loss_and_gradient(const MlpLayout& layout, const Vector& params, const TrainingSet& set,
                         std::span<const std::size_t> batch, int threads, Vector* gradient);

// The mean loss over all of `set` (chunks of kChunk, summed in order).
double mean_loss(const MlpLayout& layout, const Vector& params, const TrainingSet& set,
                 int threads);

class Trainer {
 public:
  Trainer(MlpLayout layout, Vector params, AdamSettings adam, int threads);
  // One Adam step on the columns `batch` of `set`; returns the batch's mean loss before the step.
  double step(const TrainingSet& set, std::span<const std::size_t> batch);
  const Vector& parameters() const { return params_; }
  void set_learning_rate(double rate) { adam_.set_learning_rate(rate); }
  const MlpLayout& layout() const { return layout_; }

 private:
  MlpLayout layout_;
  Vector params_, gradient_;
  Adam adam_;
  int threads_;
};

}  // namespace halfback::neural
