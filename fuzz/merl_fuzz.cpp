// libFuzzer target for the MERL reader and lookups (see fuzz/run.sh): (1) the raw bytes as a file
// (header and size checks: every input short of 34,992,012 bytes must be rejected cleanly);
// (2) the first 48 bytes as a direction pair (any bit pattern: NaN, inf, denormals, non-unit
// vectors) evaluated on a fixed table with unmeasured bins, with both lookups, and as raw
// (θh, θd, φd) for the bin formulas, whose indices must stay in range.
// Full-size files are not built here: under ASan each costs ~0.5 s (70 MB of fresh pages), which
// would starve the fuzzer; the value checks they would reach are covered by src/io/merl_test.cpp.
#include <cstdint>
#include <cstring>

#include "halfback/formats/merl.hpp"
#include "halfback/util/format_error.hpp"

using namespace halfback;

namespace {

const MerlBrdf& table(MerlLookup lookup) {
  static const MerlData data = [] {
    MerlData d;
    d.values.resize(3 * merl::kBins);
    for (std::size_t i = 0; i < d.values.size(); ++i)
      d.values[i] = (i * 2654435761u) % 97 == 0 ? -1.0 : double(i % 1000);
    return d;
  }();
  static const MerlBrdf nearest(data, {MerlLookup::nearest});
  static const MerlBrdf trilinear(data, {MerlLookup::trilinear});
  return lookup == MerlLookup::nearest ? nearest : trilinear;
}

volatile double sink;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto* bytes = reinterpret_cast<const std::byte*>(data);
  try {
    (void)parse_merl({bytes, size}, "fuzz");
  } catch (const FormatError&) {
  }
  if (size >= 48) {
    double v[6];
    std::memcpy(v, data, sizeof v);
    const DirPair<double> pair{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
    for (MerlLookup lookup : {MerlLookup::nearest, MerlLookup::trilinear}) {
      const Rgb c = table(lookup).eval(pair);
      sink = c.r + c.g + c.b;
    }
    const merl::BinIndex b = merl::bin_of(v[0], v[1], v[2]);
    if (b.theta_h < 0 || b.theta_h >= merl::kThetaH || b.theta_d < 0 ||
        b.theta_d >= merl::kThetaD || b.phi_d < 0 || b.phi_d >= merl::kPhiD)
      __builtin_trap();
  }
  return 0;
}
