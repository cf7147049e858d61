// The paper's orthographic parameterization (‖h̄‖, φh, ‖k̄‖, φk): its facts for the generic
// property tests (core/param_test.cpp) and a tuple outside its domain.
#include "halfback/core/params/ortho.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "halfback/core/param.hpp"
#include "param_facts.hpp"
#include "support/test_util.hpp"

namespace halfback::test {
namespace {

ParamFacts ortho_facts() {
  ParamFacts f;
  f.condition = [](const DirPair<double>& p) { return std::min(p.wi.z, p.wo.z); };
  // Both projected directions h̄ ± k̄ inside the unit disk.
  f.reference_valid = [](const Tuple4<long double>& q) {
    if (!(q[0] >= 0 && q[0] <= 1 && q[2] >= 0 && q[2] <= 1 && reference_azimuths_ok(q)))
      return false;
    const long double hx = q[0] * cosl(q[1]), hy = q[0] * sinl(q[1]);
    const long double kx = q[2] * cosl(q[3]), ky = q[2] * sinl(q[3]);
    return (hx + kx) * (hx + kx) + (hy + ky) * (hy + ky) <= 1 &&
           (hx - kx) * (hx - kx) + (hy - ky) * (hy - ky) <= 1;
  };
  return f;
}
const RegisterParamFacts kOrthoFacts(Ortho::name, ortho_facts());

// Outside the disk: |h̄ + k̄| = 1.2; at φk = 90° the same lengths are inside.
TEST(Domain, OrthoSpecificInvalidTuple) {
  EXPECT_FALSE((valid<Ortho>(Tuple4<double>{0.6, 0, 0.6, 0})));
  EXPECT_TRUE((valid<Ortho>(Tuple4<double>{0.6, 0, 0.6, kPi / 2})));
}

}  // namespace
}  // namespace halfback::test
