// The formats' block loops that the compiler vectorizes (MERL, RGL, neural BRDFs) are compiled in
// three versions, AVX-512, AVX2 and the x86-64 baseline, and run the one that the library's one
// instruction-set choice names: simd_isa() (core/simd.hpp: the CPU's best, or HALFBACK_ISA's), as
// the batch engine and the MERL AVX-512 kernels do. avx512 runs the AVX-512 version, avx2 the AVX2
// one, sse2 and scalar the baseline (which GCC vectorizes with SSE2: these loops have no scalar
// build). The versions are one always-inlined body under three target attributes, the code that
// GCC's target_clones made, without its resolver, which asked the CPU alone.
//
// HALFBACK_ISA_VERSIONS(name, (parameters), (arguments)) defines `void name(parameters)` from
// `name_body`, with the versions "avx512f" and "avx2"; HALFBACK_ISA_VERSIONS_FOR adds the two
// target strings and the Version to run. Where the versions are not built (not GCC on x86-64, or
// AddressSanitizer), `name` runs the body as compiled for the build.
#pragma once

#include "halfback/core/simd.hpp"

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(__SANITIZE_ADDRESS__)
#define HALFBACK_FORMATS_ISA_VERSIONS 1
#endif

namespace halfback::formats_isa {

enum class Version { baseline, avx2, avx512 };

// The version simd_isa() asks for.
inline Version version() {
  switch (simd_isa()) {
    case SimdIsa::avx512:
      return Version::avx512;
    case SimdIsa::avx2:
      return Version::avx2;
    default:
      return Version::baseline;
  }
}

}  // namespace halfback::formats_isa

#if defined(HALFBACK_FORMATS_ISA_VERSIONS)
#define HALFBACK_ISA_VERSIONS_FOR(name, params, args, target512, target2, chosen) \
  __attribute__((target(target512))) static void name##_avx512 params {           \
    name##_body args;                                                             \
  }                                                                               \
  __attribute__((target(target2))) static void name##_avx2 params {               \
    name##_body args;                                                             \
  }                                                                               \
  static void name##_baseline params {                                            \
    name##_body args;                                                             \
  }                                                                               \
  void name params {                                                              \
    switch (chosen) {                                                             \
      case ::halfback::formats_isa::Version::avx512:                              \
        return name##_avx512 args;                                                \
      case ::halfback::formats_isa::Version::avx2:                                \
        return name##_avx2 args;                                                  \
      default:                                                                    \
        return name##_baseline args;                                              \
    }                                                                             \
  }
#else
#define HALFBACK_ISA_VERSIONS_FOR(name, params, args, target512, target2, chosen) \
  void name params {                                                              \
    name##_body args;                                                             \
  }
#endif

#define HALFBACK_ISA_VERSIONS(name, params, args)                  \
  HALFBACK_ISA_VERSIONS_FOR(name, params, args, "avx512f", "avx2", \
                            ::halfback::formats_isa::version())
