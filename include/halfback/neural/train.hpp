// Training a neural BRDF (Sztrajman, Rainer, Ritschel, Weyrich 2021, "Neural BRDF Representation
// and Importance Sampling") from any BRDF, on the CPU: the authors' architecture, loss, sampling
// and optimizer by default (docs/neural.md restates them from their paper and code), and a network
// that formats/nbrdf.hpp reads and write_nbrdf writes.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/core/space.hpp"
#include "halfback/formats/nbrdf.hpp"

namespace halfback {

struct NbrdfTrainProgress {
  std::size_t epoch = 0, epochs = 0;  // epochs done, of
  double loss = 0;                    // the mean of the epoch's batch losses
  double seconds = 0;                 // since training began
};

// The names NbrdfTrainOptions::loss takes, the default first.
inline constexpr std::array<std::string_view, 2> kNbrdfLosses{"sztrajman", "study-log"};

struct NbrdfTrainOptions {
  // The input: "" for Sztrajman et al.'s (sin θh, 0, cos θh, d), or a built-in parameterization
  // whose isotropic coordinates (3) the network takes instead (formats/nbrdf.hpp reads both).
  std::string param;
  std::vector<std::size_t> hidden{21, 21};  // hidden widths (1 to 15 layers of 1 to 64 units)
  std::size_t samples = 640000;             // pairs drawn (the authors: 800,000 × 0.8); 1 to 10^7
  std::size_t epochs = 100;                 // passes over the pairs, shuffled each time; 1 to 10^6
  std::size_t batch = 512;                  // pairs per Adam step; 1 to 65,536
  double learning_rate = 5e-4;              // Adam's, in (0, 1]
  // A schedule: when positive (and at most learning_rate), the learning rate of epoch e of E
  // (from 0) is learning_rate · (final_learning_rate / learning_rate)^(e / (E − 1)), falling
  // geometrically to it at the last epoch; 0: constant (the authors').
  double final_learning_rate = 0;
  // Restarts: `restarts` networks from different initial weights each train `restart_epochs`
  // epochs, and the one of the lowest loss on all the pairs goes on to `epochs` in all (1: no
  // restarts, the authors' training). 1 to 64; restart_epochs 1 to 10^6.
  std::size_t restarts = 1;
  std::size_t restart_epochs = 5;
  // The loss and the pairs it is the mean over (docs/neural.md, "The losses"): "sztrajman", the
  // authors' (θh, θd, φd uniform, the pairs with a direction at or below the horizon dropped; the
  // mean over the three channels of |ln(1 + ρ̂ c) − ln(1 + ρ c)|, c = cos θo), or "study-log",
  // halfback's, whose expectation is the study's log measure: half the pairs drawn from
  // μ = cos θi cos θo dωi dωo (both directions cosine-distributed, independently), half the
  // authors' way, weighted to μ; the weighted mean of
  // (ln(1 + Ŷ) − ln(1 + Y))² + ⅓ Σ_k (ln(1 + ρ̂_k) − ln(1 + ρ_k))², Y the luminance.
  std::string loss = "sztrajman";
  std::uint64_t seed = 0;  // the pairs, the initial weights and the shuffles
  int threads = 0;         // core's parallel_for (0: all); the result does not depend on it
  // Called after each epoch (on the calling thread), when set.
  std::function<void(const NbrdfTrainProgress&)> progress;
};

// Throws std::invalid_argument naming the option (by the CLI's name: --hidden, --samples, ...)
// when a value is outside the range above.
void check_nbrdf_train_options(const NbrdfTrainOptions& options);

struct NbrdfTrainResult {
  NbrdfNetwork network;              // float32, as written and read
  std::size_t drawn = 0, pairs = 0;  // pairs drawn, and kept (both directions above the horizon)
  std::size_t steps = 0;             // Adam steps
  std::vector<double> epoch_losses;  // the mean batch loss of each epoch
  double loss = 0;     // the loss of `network` (its float32 weights) over all kept pairs
  double seconds = 0;  // the training steps' wall time
};

// Trains a network on `brdf` (check_nbrdf_train_options first). The result depends only on the
// BRDF's values, the options and the seed, not on the thread count. Throws std::domain_error for
// an anisotropic BRDF (the network is isotropic), naming a pair where ρ is NaN, infinite or
// negative, or when ρ is 0 at every pair drawn.
NbrdfTrainResult train_nbrdf(const Brdf& brdf, const NbrdfTrainOptions& options);

// The same training with the isotropic coordinates of `input` as the network's input: any
// parameterization's space, a registered one or a family's member (dupuy-jakob:BRDF) included,
// for comparisons within one process (the study's neural metric); options.param must be empty.
// result.network.input names the space; a network of a space other than a built-in
// parameterization is not one the reader (or write_nbrdf) takes: evaluate it with
// trained_nbrdf_brdf(). Throws as train_nbrdf, and std::invalid_argument for a non-empty
// options.param or the `dirs` space.
NbrdfTrainResult train_nbrdf_on(const Brdf& brdf, const NbrdfTrainOptions& options, Space input);

// A BRDF that evaluates a trained network in memory, as the reader does (float32, ρ = max(e^y −
// 1, 0), 0 below the horizon, NaN for a NaN pair): its input Sztrajman et al.'s (`input` empty) or
// the isotropic coordinates of `input`. Throws std::invalid_argument when the first layer's width
// is not the input's (6 or 3) or the last's is not 3.
BrdfPtr trained_nbrdf_brdf(NbrdfNetwork network, std::optional<Space> input, std::string label);

// The notes write_nbrdf stores in the .json for a result: the source BRDF and the settings.
std::vector<NbrdfNote> nbrdf_train_notes(const Brdf& brdf, const NbrdfTrainOptions& options,
                                         const NbrdfTrainResult& result);

}  // namespace halfback
