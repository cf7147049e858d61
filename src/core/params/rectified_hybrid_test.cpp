// Rectified hybrid (hybrid on a box domain): its facts for the generic property tests
// (core/param_test.cpp).
#include "halfback/core/params/rectified_hybrid.hpp"

#include <gtest/gtest.h>

#include "param_facts.hpp"

namespace halfback::test {
namespace {

ParamFacts rectified_hybrid_facts() {
  ParamFacts f;
  f.condition = [](const DirPair<double>& p) { return 0.5 * (p.wi.z + p.wo.z); };  // hybrid's
  // A box-domain map: its domain is the box of its ranges.
  f.reference_valid = [](const Tuple4<long double>& q) {
    return q[0] >= 0 && q[0] <= 1 && q[2] >= 0 && q[2] <= 1 && reference_azimuths_ok(q);
  };
  // The rectified ‖h̄‖ is divided by a function of the relative azimuth: it inherits that
  // azimuth's rounding.
  f.iso_rotation_tolerance = 1e-9;
  return f;
}
const RegisterParamFacts kRectifiedHybridFacts(RectifiedHybrid::name, rectified_hybrid_facts());

}  // namespace
}  // namespace halfback::test
