// The one bound on the sample pairs of a fit (docs/reliability/cli.md, "Option values").
//
// fit() holds several arrays per pair (targets, weights, each term's values, residuals): 10⁷
// pairs peak at about 5.3 GB. Every entry point that takes a count of pairs from outside (the
// CLI's `fit --samples`, Python's fit, fit_loss and fit_samples) checks it here.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace halfback::fit {

inline constexpr std::size_t kMaxFitSamples = 10'000'000;

// Throws std::invalid_argument naming `what` unless 1 <= n <= kMaxFitSamples.
inline void check_fit_samples(std::size_t n, std::string_view what) {
  if (n < 1 || n > kMaxFitSamples)
    throw std::invalid_argument(std::string(what) + " " + std::to_string(n) + ": expected 1 to " +
                                std::to_string(kMaxFitSamples) +
                                " sample pairs (more would need over 5 GB)");
}

}  // namespace halfback::fit
