// Mixture weights for sampling a sum of lobes: each lobe's directional albedo (luminance) on a grid
// of cos θo, estimated once with the lobe's own sampler, interpolated linearly in cos θo. The
// weights depend on ωo only, so the mixture's pdf Σ w_j(ωo) p_j(ωi | ωo) stays exact.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "halfback/models/analytic.hpp"

namespace halfback::models::detail {

class MixtureWeights {
 public:
  static constexpr int kNodes = 16;   // cos θo = (k + 0.5) / kNodes
  static constexpr int kStrata = 12;  // kStrata² samples per albedo estimate

  // albedo(lobe, wo) -> the lobe's directional albedo (luminance) at wo.
  MixtureWeights(std::size_t lobes,
                 const std::function<double(std::size_t, const Vec3<double>&)>& albedo);

  std::size_t lobes() const { return lobes_; }
  // Normalized weights at cos θo, into out (size lobes()).
  void weights(double cos_o, std::span<double> out) const;

  // The luminance albedo of ρ at wo by sampling with `sampler` (stratified, deterministic).
  static double albedo(const Brdf& brdf, const Brdf& sampler, const Vec3<double>& wo);

 private:
  std::size_t lobes_;
  std::vector<double> table_;  // kNodes × lobes
};

// Picks a lobe from the weights with u and rescales u to [0, 1) within the lobe's share.
inline std::size_t pick_lobe(std::span<const double> w, double& u) {
  double acc = 0;
  for (std::size_t j = 0; j < w.size(); ++j) {
    if (w[j] <= 0) continue;
    if (u < acc + w[j] || j + 1 == w.size()) {
      u = std::clamp((u - acc) / w[j], 0.0, 0x1.fffffffffffffp-1);
      return j;
    }
    acc += w[j];
  }
  // Only reached when the last weights are 0: the last lobe of positive weight.
  std::size_t j = w.size() - 1;
  while (j > 0 && w[j] <= 0) --j;
  u = std::clamp(u, 0.0, 0x1.fffffffffffffp-1);
  return j;
}

}  // namespace halfback::models::detail
