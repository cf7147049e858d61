// Spherical coordinates (θi, φi, θo, φo): their facts for the generic property tests
// (core/param_test.cpp).
#include "halfback/core/params/spherical.hpp"

#include <gtest/gtest.h>

#include "param_facts.hpp"
#include "support/test_util.hpp"

namespace halfback::test {
namespace {

ParamFacts spherical_facts() {
  ParamFacts f;
  f.condition = [](const DirPair<double>&) { return 1.0; };
  f.reference_valid = [](const Tuple4<long double>& q) {
    return q[0] >= 0 && q[0] <= kPi / 2 && q[2] >= 0 && q[2] <= kPi / 2 && reference_azimuths_ok(q);
  };
  f.float_accurate_wherever_z_above_001 = true;
  return f;
}
const RegisterParamFacts kSphericalFacts(Spherical::name, spherical_facts());

}  // namespace
}  // namespace halfback::test
