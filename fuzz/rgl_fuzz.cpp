// libFuzzer target for the RGL tensor_file container and material (see fuzz/run.sh): parse, build
// the material (validation, warps), then evaluate and sample at directions taken from the input.
#include <cstdint>
#include <cstring>
#include <vector>

#include "halfback/formats/rgl.hpp"
#include "halfback/util/format_error.hpp"

using namespace halfback;

namespace {
volatile double sink;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::byte> bytes(size);
  if (size) std::memcpy(bytes.data(), data, size);
  try {
    const TensorFile tf = parse_tensor_file(std::move(bytes), "fuzz.bsdf");
    const RglBrdf brdf(tf, "fuzz");
    // Directions from the last 48 bytes (any bit pattern), plus a fixed valid pair.
    double v[6] = {0.3, 0.1, 0.9, -0.2, 0.4, 0.8};
    if (size >= 48) std::memcpy(v, data + size - 48, sizeof v);
    for (const DirPair<double>& p : {DirPair<double>{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}},
                                     DirPair<double>{{0.3, 0.1, 0.9}, {-0.2, 0.4, 0.8}}}) {
      const Rgb c = brdf.eval(p);
      const BrdfSample s = brdf.sample(p.wo, 0.37, 0.61);
      const double pdf = brdf.pdf(p.wo, p.wi);
      const RglWarpPoint q = brdf.vndf_inverse({v[0], v[1]}, v[2], v[3]);
      const RglWarpPoint r = brdf.vndf_forward({v[4], v[5]}, v[2], v[3]);
      sink = c.r + c.g + c.b + s.pdf + pdf + q.x + q.y + r.x + r.y;
    }
  } catch (const FormatError&) {
  }
  return 0;
}
