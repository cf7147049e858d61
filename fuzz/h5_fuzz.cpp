// libFuzzer target for the Keras .h5 reader of neural BRDFs (see fuzz/run.sh): the input as an
// HDF5 file image (the embedded materials' path: HDF5's in-memory driver), its declared end checked
// against its size (docs/reliability/readers.md, "A reader reads what the file's header declares,
// and nothing more"), then the network validated (finite weights, the bound on ρ:
// docs/reliability/readers.md, "One bound on a BRDF's value" and evaluated at a pair taken from the
// input's last bytes.
#include <cstdint>
#include <cstring>

#include "halfback/formats/nbrdf.hpp"
#include "halfback/util/format_error.hpp"

using namespace halfback;

namespace {
volatile double sink;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    NbrdfNetwork net = parse_nbrdf_h5({reinterpret_cast<const std::byte*>(data), size}, "fuzz.h5");
    const NbrdfBrdf brdf(std::move(net), "fuzz");
    double v[6] = {0.3, 0.1, 0.9, -0.2, 0.4, 0.8};
    if (size >= 48) std::memcpy(v, data + size - 48, sizeof v);
    sink = brdf.eval({{v[0], v[1], v[2]}, {v[3], v[4], v[5]}}).r;
  } catch (const FormatError&) {
  }
  return 0;
}
