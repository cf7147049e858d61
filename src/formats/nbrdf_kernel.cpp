// Compiled with -ffp-contract=fast (src/formats/CMakeLists.txt): the products and sums of a layer
// may fuse into FMA instructions, which only changes their rounding (the networks were trained in
// float32 with whatever their hardware did); and with -fno-math-errno -fno-trapping-math, so that
// the loops of encode_block and of the output's exp, with their selects, vectorize.
#include "formats/nbrdf_kernel.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>

#include "formats/isa_versions.hpp"

namespace halfback::nbrdf_detail {
namespace {

#define HALFBACK_NBRDF_INLINE inline __attribute__((always_inline))

// max(exp(y) − 1, 0) in float without a library call, so that a loop of it vectorizes: y ≤ 0
// gives 0 (and so does a NaN, which only weights that overflow float can produce), y is capped at
// 88 (exp(88) ≈ 1.7e38, near float's largest), and exp(y) = 2^n·e^r with n = round(y/ln 2), r = y −
// n·ln 2 in [−ln2/2, ln2/2] (ln 2 split in two so that n·ln2_hi is exact), e^r by its Taylor
// polynomial of degree 7 (truncation < 6e-9, below float rounding).
HALFBACK_NBRDF_INLINE float exp_minus_one_clamped(float y) {
  const float positive = y > 0.0f ? y : 0.0f;
  const float x = positive < 88.0f ? positive : 88.0f;
  const std::int32_t n = std::int32_t(x * 1.44269504088896341f + 0.5f);
  const float nf = float(n);
  const float r = (x - nf * 0.693145751953125f) - nf * 1.428606765330187e-06f;
  float p = 1.0f / 5040.0f;
  p = p * r + 1.0f / 720.0f;
  p = p * r + 1.0f / 120.0f;
  p = p * r + 1.0f / 24.0f;
  p = p * r + 1.0f / 6.0f;
  p = p * r + 0.5f;
  p = p * r + 1.0f;
  p = p * r + 1.0f;
  // 2^n from its exponent bits (n in [0, 127]).
  const float scale = std::bit_cast<float>((n + 127) << 23);
  const float e = p * scale - 1.0f;
  return e > 0.0f ? e : 0.0f;
}

// Outputs j0 .. j0+G−1 of a dense layer on a block: out[j][p] = act(bias[j] + Σk in[k][p]·W[k][j]).
// G outputs at a time keep G × kBlock accumulators in registers and load each input row once for
// all G (the register blocking of a matrix product).
template <std::size_t G>
HALFBACK_NBRDF_INLINE void dense_outputs(const NbrdfLayer& layer, std::size_t j0, bool relu,
                                         const float* in, float* out) {
  const std::size_t n_in = layer.inputs, n_out = layer.outputs;
  const float* kernel = layer.kernel.data();
  float acc[G][kBlock];
  for (std::size_t g = 0; g < G; ++g)
    for (std::size_t p = 0; p < kBlock; ++p) acc[g][p] = layer.bias[j0 + g];
  for (std::size_t k = 0; k < n_in; ++k) {
    const float* x = in + k * kBlock;
    for (std::size_t g = 0; g < G; ++g) {
      const float w = kernel[k * n_out + j0 + g];
      for (std::size_t p = 0; p < kBlock; ++p) acc[g][p] += w * x[p];
    }
  }
  for (std::size_t g = 0; g < G; ++g) {
    float* o = out + (j0 + g) * kBlock;
    for (std::size_t p = 0; p < kBlock; ++p) o[p] = relu ? std::max(acc[g][p], 0.0f) : acc[g][p];
  }
}

// One dense layer on a block, three outputs at a time (the published widths, 21 and 3, are
// multiples of 3), then the rest one by one.
HALFBACK_NBRDF_INLINE void dense_block(const NbrdfLayer& layer, bool relu, const float* in,
                                       float* out) {
  std::size_t j = 0;
  for (; j + 3 <= layer.outputs; j += 3) dense_outputs<3>(layer, j, relu, in, out);
  for (; j < layer.outputs; ++j) dense_outputs<1>(layer, j, relu, in, out);
}

// The network inputs of a block of pairs (rows of kBlock, as evaluate_block's).
HALFBACK_NBRDF_INLINE void encode_block(const double* pairs, float* inputs) {
  for (std::size_t p = 0; p < kBlock; ++p) {
    const Encoded e =
        encode_pair(pairs[p], pairs[kBlock + p], pairs[2 * kBlock + p], pairs[3 * kBlock + p],
                    pairs[4 * kBlock + p], pairs[5 * kBlock + p]);
    inputs[p] = float(e.x0);
    inputs[kBlock + p] = 0.0f;
    inputs[2 * kBlock + p] = float(e.x2);
    inputs[3 * kBlock + p] = float(e.d0);
    inputs[4 * kBlock + p] = float(e.d1);
    inputs[5 * kBlock + p] = float(e.d2);
  }
}

HALFBACK_NBRDF_INLINE void evaluate_block_impl_body(const NbrdfNetwork& network,
                                                    const double* pairs, float* outputs) {
  alignas(64) float inputs[nbrdf::kInputs * kBlock];
  alignas(64) float ping[nbrdf::kMaxWidth * kBlock];
  alignas(64) float pong[nbrdf::kMaxWidth * kBlock];
  encode_block(pairs, inputs);
  const std::size_t n_layers = network.layers.size();
  const float* in = inputs;
  for (std::size_t l = 0; l < n_layers; ++l) {
    float* out = (l % 2 == 0) ? ping : pong;
    dense_block(network.layers[l], l + 1 < n_layers, in, out);
    in = out;
  }
  for (std::size_t i = 0; i < nbrdf::kOutputs * kBlock; ++i)
    outputs[i] = exp_minus_one_clamped(in[i]);
}

// The version of the block kernel: x86-64-v4 or v3 (AVX-512 or AVX2 with FMA, and the rest of
// their levels, any of which GCC may use) where simd_isa() asks for AVX-512 or AVX2 and the CPU
// runs the whole level (simd_isa() checks AVX-512F, AVX2 and FMA only; a Xeon Phi has AVX-512F
// but not v4), else the level below, down to the baseline.
[[maybe_unused]] formats_isa::Version block_version() {  // unused without the versions
  using formats_isa::Version;
#if defined(HALFBACK_FORMATS_ISA_VERSIONS)
  static const bool v4 = (__builtin_cpu_init(), __builtin_cpu_supports("x86-64-v4"));
  static const bool v3 = (__builtin_cpu_init(), __builtin_cpu_supports("x86-64-v3"));
  const Version v = formats_isa::version();
  if (v == Version::avx512 && v4) return Version::avx512;
  if (v != Version::baseline && v3) return Version::avx2;
#endif
  return Version::baseline;
}

// The block kernel in three versions (isa_versions.hpp); the helpers above are inlined into each.
HALFBACK_ISA_VERSIONS_FOR(evaluate_block_impl,
                          (const NbrdfNetwork& network, const double* pairs, float* outputs),
                          (network, pairs, outputs), "arch=x86-64-v4", "arch=x86-64-v3",
                          block_version())

}  // namespace

std::array<float, nbrdf::kOutputs> evaluate_one(const NbrdfNetwork& network,
                                                const std::array<float, nbrdf::kInputs>& input) {
  std::array<float, nbrdf::kMaxWidth> ping{}, pong{};
  std::copy(input.begin(), input.end(), ping.begin());
  float* in = ping.data();
  float* out = pong.data();
  const std::size_t n_layers = network.layers.size();
  for (std::size_t l = 0; l < n_layers; ++l) {
    const NbrdfLayer& layer = network.layers[l];
    for (std::size_t j = 0; j < layer.outputs; ++j) {
      float acc = layer.bias[j];
      for (std::size_t k = 0; k < layer.inputs; ++k)
        acc += layer.kernel[k * layer.outputs + j] * in[k];
      out[j] = (l + 1 < n_layers) ? std::max(acc, 0.0f) : acc;
    }
    std::swap(in, out);
  }
  return {exp_minus_one_clamped(in[0]), exp_minus_one_clamped(in[1]), exp_minus_one_clamped(in[2])};
}

void evaluate_block(const NbrdfNetwork& network, const double* pairs, float* outputs) {
  evaluate_block_impl(network, pairs, outputs);
}

}  // namespace halfback::nbrdf_detail
