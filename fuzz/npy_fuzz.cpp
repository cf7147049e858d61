// libFuzzer target for the .npy reader of neural BRDFs (see fuzz/run.sh): parses the input, and
// when it is a float32 array of 6 × 3 values, evaluates it as a one-layer network (the kernel;
// zero bias) at a pair taken from the input's bytes, NaN and infinities included. The weights
// validation rejects non-finite kernels, which is part of what is fuzzed.
#include <cstdint>
#include <cstring>
#include <span>

#include "halfback/formats/nbrdf.hpp"
#include "halfback/util/format_error.hpp"

using namespace halfback;

namespace {
volatile double sink;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    NpyArray a = parse_npy_float32({reinterpret_cast<const std::byte*>(data), size}, "fuzz.npy");
    if (a.shape != std::vector<std::size_t>{6, 3}) return 0;
    NbrdfNetwork net;
    net.source = "fuzz.npy";
    net.layers.push_back({6, 3, std::move(a.values), std::vector<float>(3, 0.0f)});
    const NbrdfBrdf brdf(std::move(net), "fuzz");
    double v[6] = {0.3, 0.1, 0.9, -0.2, 0.4, 0.8};
    if (size >= 48) std::memcpy(v, data + size - 48, sizeof v);
    const DirPair<double> pairs[2] = {{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}},
                                      {{0.3, 0.1, 0.9}, {-0.2, 0.4, 0.8}}};
    Rgb out[2];
    brdf.eval_batch(pairs, out);
    sink = brdf.eval(pairs[0]).r + out[0].g + out[1].b;
  } catch (const FormatError&) {
  }
  return 0;
}
