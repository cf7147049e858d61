// libFuzzer target for the factored BRDF's JSON reader and its evaluation (see fuzz/run.sh).
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string_view>

#include "halfback/brdf/rho_bound.hpp"
#include "halfback/formats/factored.hpp"
#include "halfback/util/format_error.hpp"

using namespace halfback;

namespace {
volatile double sink;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const FactoredBrdf brdf(parse_factored(text, "fuzz.json"));
    double v[6] = {0.3, 0.1, 0.9, -0.2, 0.4, 0.8};
    if (size >= 48) std::memcpy(v, data, sizeof v);
    const Rgb a = brdf.eval({{v[0], v[1], v[2]}, {v[3], v[4], v[5]}});
    const Rgb b = brdf.eval({{0.3, 0.1, 0.9}, {-0.2, 0.4, 0.8}});
    // The reader's bound: no value it accepts can exceed the bound on ρ (brdf/rho_bound.hpp).
    if (!rho_within_bound(a) || !rho_within_bound(b)) __builtin_trap();
    sink = a.r + b.g;
  } catch (const FormatError&) {
  } catch (const std::invalid_argument&) {  // a parameterization's own refusal of its arguments
  }
  return 0;
}
