// The evaluation of a neural BRDF's network (private header of src/formats): one pair with fixed
// arrays (no allocation), and blocks of kBlock pairs as small matrix products, one column per
// pair, vectorized across the pairs of a block.
#pragma once

#include <array>
#include <cstddef>

#include "halfback/formats/nbrdf.hpp"

namespace halfback::nbrdf_detail {

// Pairs per block: the activations of a block (kMaxWidth × kBlock floats, twice) stay in L1.
inline constexpr std::size_t kBlock = 32;

// The network's output for one input: ρ = max(exp(y) − 1, 0) per channel.
std::array<float, nbrdf::kOutputs> evaluate_one(const NbrdfNetwork& network,
                                                const std::array<float, nbrdf::kInputs>& input);

// The same for a block: `inputs` holds kInputs rows of kBlock values (row r = input r of every
// pair), `outputs` receives kOutputs rows of kBlock values. All kBlock columns are evaluated
// (callers fill unused columns with any finite input).
void evaluate_block(const NbrdfNetwork& network, const float* inputs, float* outputs);

}  // namespace halfback::nbrdf_detail
