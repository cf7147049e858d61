// libFuzzer target for the reader of measurement plans' sidecars (acquire/acquisition.hpp,
// `halfback reconstruct`; see fuzz/run.sh): JSON of any shape, fields of any kind, plans that do
// not match their setup. Budgets above 5000 are refused by the reader (max_budget) so that one
// input plans in milliseconds.
#include <cstdint>
#include <string_view>

#include "halfback/acquire/acquisition.hpp"
#include "halfback/util/format_error.hpp"

using namespace halfback;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const acquire::AcquisitionPlan plan = acquire::parse_plan_sidecar(text, "fuzz.json", 5000);
    if (plan.row_of_point.size() != plan.plan.points.size()) __builtin_trap();
  } catch (const FormatError&) {
  }
  return 0;
}
