// Rusinkiewicz's half and difference angles (θh, φh, θd, φd): their facts for the generic property
// tests (core/param_test.cpp) and a pair outside their domain.
#include "halfback/core/params/halfdiff.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "halfback/core/param.hpp"
#include "param_facts.hpp"
#include "support/test_util.hpp"

namespace halfback::test {
namespace {

ParamFacts halfdiff_facts() {
  ParamFacts f;
  f.condition = [](const DirPair<double>& p) {
    return std::sqrt(std::max(0.0, 0.5 * (1 + detail::dot(p.wi, p.wo))));  // ‖h‖ = cos θd
  };
  f.reference_valid = [](const Tuple4<long double>& q) {
    if (!(q[0] >= 0 && q[0] <= kPi / 2 && q[2] >= 0 && q[2] <= kPi / 2 && reference_azimuths_ok(q)))
      return false;
    const long double a = cosl(q[2]) * cosl(q[0]), b = sinl(q[2]) * cosl(q[3]) * sinl(q[0]);
    return a - b >= 0 && a + b >= 0;
  };
  f.float_accurate_wherever_z_above_001 = true;
  return f;
}
const RegisterParamFacts kHalfDiffFacts(HalfDiff::name, halfdiff_facts());

// Outside the hemisphere: θh = θd = 60°, φd = 0 puts ωi below the horizon; φd = 90° does not.
TEST(Domain, HalfDiffSpecificInvalidTuple) {
  EXPECT_FALSE((valid<HalfDiff>(Tuple4<double>{kPi / 3, 0, kPi / 3, 0})));
  EXPECT_TRUE((valid<HalfDiff>(Tuple4<double>{kPi / 3, 0, kPi / 3, kPi / 2})));
}

}  // namespace
}  // namespace halfback::test
