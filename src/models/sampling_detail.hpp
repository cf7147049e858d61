// Mixture weights for sampling a sum of lobes: each lobe's directional albedo (luminance) on a grid
// of cos θo, estimated once with the lobe's own sampler, interpolated linearly in cos θo. The
// weights depend on ωo only, so the mixture's pdf Σ w_j(ωo) p_j(ωi | ωo) stays exact.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <numbers>
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

// sin and cos of 2πu for u in [0, 1] without libm or tables (so that loops over it vectorize):
// the octant k = ⌊8u⌋ and the angle t from the octant's middle (2k + 1)π/8, |t| ≤ π/8, whose
// sine and cosine series to t¹³ and t¹⁴ leave a remainder below 10⁻¹⁸; then the angle-sum
// formulas with the middle's sine and cosine, ±sin(π/8) or ±cos(π/8) by the octant.
// 8u − k − 1/2 is exact, so the only error is the rounding of about twenty operations.
[[gnu::always_inline]] inline void sincos_turns(double u, double& sin_out, double& cos_out) {
  constexpr double s8 = 0.38268343236508977173, c8 = 0.92387953251128675613;  // of π/8
  // k = ⌊8u⌋ clamped to [0, 7] (0 for NaN), by comparisons rather than a conversion to int, so
  // that loops over it vectorize.
  const double v = 8 * u;
  const double k = double(v >= 1) + double(v >= 2) + double(v >= 3) + double(v >= 4) +
                   double(v >= 5) + double(v >= 6) + double(v >= 7);
  const double t = (8 * u - k - 0.5) * (std::numbers::pi / 4), t2 = t * t;
  const double st =
      t * (1 - t2 * (1.0 / 6) *
                   (1 - t2 * (1.0 / 20) *
                            (1 - t2 * (1.0 / 42) *
                                     (1 - t2 * (1.0 / 72) *
                                              (1 - t2 * (1.0 / 110) * (1 - t2 * (1.0 / 156)))))));
  const double ct =
      1 -
      t2 * 0.5 *
          (1 - t2 * (1.0 / 12) *
                   (1 - t2 * (1.0 / 30) *
                            (1 - t2 * (1.0 / 56) *
                                     (1 - t2 * (1.0 / 90) *
                                              (1 - t2 * (1.0 / 132) * (1 - t2 * (1.0 / 182)))))));
  // The middle's angle is within π/4 of the y axis in octants 1, 2, 5, 6; sin < 0 in the lower
  // half (k ≥ 4), cos < 0 in the left half (2 ≤ k < 6).
  const bool near_y = (k == 1) | (k == 2) | (k == 5) | (k == 6);
  const double ms = (near_y ? c8 : s8) * (k >= 4 ? -1.0 : 1.0);
  const double mc = (near_y ? s8 : c8) * ((k >= 2 && k < 6) ? -1.0 : 1.0);
  sin_out = ms * ct + mc * st;
  cos_out = mc * ct - ms * st;
}

}  // namespace halfback::models::detail
