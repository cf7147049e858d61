// The instruction set of halfback's hand-vectorized kernels: the batch conversions (core/batch.hpp)
// and the MERL lookups. One choice for all of them: the best this CPU (and OS) supports, or the
// one the environment variable HALFBACK_ISA names (scalar, sse2, avx2, avx512) when this CPU has
// it. A lower one is for comparing speeds and results: the instruction sets agree within the
// conversions' tested accuracy, not bit for bit (their atan2 and sincos differ). (Loops that
// GCC vectorizes with target_clones, such as the MERL and RGL portable loops and the neural BRDFs,
// are chosen by the CPU alone.)
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
