// The evaluation of a neural BRDF's network (private header of src/formats): one pair with fixed
// arrays (no allocation), and blocks of kBlock pairs as small matrix products, one column per
// pair, vectorized across the pairs of a block.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

#include "halfback/formats/nbrdf.hpp"

namespace halfback::nbrdf_detail {

// Pairs per block: the activations of a block (kMaxWidth × kBlock floats, twice) stay in L1.
inline constexpr std::size_t kBlock = 32;

// The network input of a pair (nbrdf::encode, which calls this): written once for the scalar
// path and the block kernel, which inlines it into loops over the pairs of a block.
struct Encoded {
  double x0, x2, d0, d1, d2;  // sin θh, cos θh, d (x1 is always 0)
};
[[gnu::always_inline]] inline Encoded encode_pair(double ix, double iy, double iz, double ox,
                                                  double oy, double oz) {
  double hx = ix + ox, hy = iy + oy, hz = iz + oz;
  const double norm = std::sqrt(hx * hx + hy * hy + hz * hz);
  // ωo = −ωi (both grazing): h is undefined, its limit from above the surface is n.
  // (Selects on the divisors rather than around the divisions, so that a loop of this
  // vectorizes: a compiler may not speculate a division that could trap.)
  const bool degenerate = !(norm > 0);
  const double inv = degenerate ? 0.0 : 1.0 / (degenerate ? 1.0 : norm);
  hx *= inv, hy *= inv, hz = degenerate ? 1.0 : hz * inv;
  const double sin_h = std::sqrt(hx * hx + hy * hy);
  const double inv_sin = 1.0 / (sin_h > 0 ? sin_h : 1.0);  // hx = hy = 0 when sin_h = 0
  const double cos_phi = sin_h > 0 ? hx * inv_sin : 1.0, sin_phi = hy * inv_sin;
  // ωo (the view direction: docs/formats.md, "Neural BRDFs", on why not ωi) rotated by −φh about
  // n, then by −θh about the binormal.
  const double ax = cos_phi * ox + sin_phi * oy;
  const double ay = -sin_phi * ox + cos_phi * oy;
  return {sin_h, hz, hz * ax - sin_h * oz, ay, sin_h * ax + hz * oz};
}

// The network's output for one input: ρ = max(exp(y) − 1, 0) per channel.
std::array<float, nbrdf::kOutputs> evaluate_one(const NbrdfNetwork& network,
                                                const std::array<float, nbrdf::kInputs>& input);

// The same for a block of pairs: `pairs` holds 6 rows of kBlock values (ωi.x, ωi.y, ωi.z, ωo.x,
// ωo.y, ωo.z of every pair), `outputs` receives kOutputs rows of kBlock values. All kBlock
// columns are evaluated (callers fill unused columns with any finite pair above the horizon).
void evaluate_block(const NbrdfNetwork& network, const double* pairs, float* outputs);

}  // namespace halfback::nbrdf_detail
