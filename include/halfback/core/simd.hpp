// The instruction set of halfback's SIMD code: the batch conversions (core/batch.hpp), the MERL
// AVX-512 kernels, and the block loops of the MERL, RGL and neural-BRDF lookups, which the
// compiler vectorizes in versions for AVX-512, AVX2 and the baseline (src/formats/
// isa_versions.hpp; scalar and sse2 run the baseline version there). One choice for all of them:
// the best this CPU (and OS) supports, or the one the environment variable HALFBACK_ISA names
// (scalar, sse2, avx2, avx512) when this CPU has it. A lower one is for comparing speeds and
// results: the conversions agree within their tested accuracy, not bit for bit (their atan2 and
// sincos differ); the MERL and RGL loops give the same bits in every version, the neural BRDFs'
// agree within float rounding (FMA contraction).
#pragma once

#include <string_view>

namespace halfback {

enum class SimdIsa { scalar, sse2, avx2, avx512 };

// The instruction set in use (read HALFBACK_ISA once).
SimdIsa simd_isa();

// "scalar", "sse2", "avx2" or "avx512".
std::string_view simd_isa_name(SimdIsa isa);

// HALFBACK_ISA's value when it is set but not used (it names no instruction set, or one this CPU
// does not run: the best is used instead); empty when it is unset or used.
std::string_view simd_isa_request_ignored();

}  // namespace halfback
