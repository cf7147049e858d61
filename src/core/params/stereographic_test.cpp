// Stereographic projections of ωi and ωo (ALTA's STEREOGRAPHIC): their facts for the generic
// property tests (core/param_test.cpp).
#include "halfback/core/params/stereographic.hpp"

#include <gtest/gtest.h>

#include "param_facts.hpp"

namespace halfback::test {
namespace {

ParamFacts stereographic_facts() {
  ParamFacts f;
  f.condition = [](const DirPair<double>&) { return 1.0; };
  // Two unit disks.
  f.reference_valid = [](const Tuple4<long double>& q) {
    return q[0] * q[0] + q[1] * q[1] <= 1 && q[2] * q[2] + q[3] * q[3] <= 1;
  };
  return f;
}
const RegisterParamFacts kStereographicFacts(Stereographic::name, stereographic_facts());

}  // namespace
}  // namespace halfback::test
