// Stereographic half and difference vectors (s(ĥ), s(d)): their facts for the generic property
// tests (core/param_test.cpp).
#include "halfback/core/params/stereographic.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "param_facts.hpp"

namespace halfback::test {
namespace {

ParamFacts stereo_halfdiff_facts() {
  ParamFacts f;
  // halfdiff's (‖h‖ = cos θd), halved for the projection's own rounding.
  f.condition = [](const DirPair<double>& p) {
    return std::sqrt(std::max(0.0, 0.5 * (1 + detail::dot(p.wi, p.wo)))) / 2;
  };
  // Two unit disks, and halfdiff's condition in half-angle form (1 − ρh²)(1 − ρd²) ≥ 4ρh|sd_x|.
  f.reference_valid = [](const Tuple4<long double>& q) {
    const long double rh2 = q[0] * q[0] + q[1] * q[1], rd2 = q[2] * q[2] + q[3] * q[3];
    return rh2 <= 1 && rd2 <= 1 && (1 - rh2) * (1 - rd2) >= 4 * sqrtl(rh2) * fabsl(q[2]);
  };
  return f;
}
const RegisterParamFacts kStereoHalfDiffFacts(StereoHalfDiff::name, stereo_halfdiff_facts());

}  // namespace
}  // namespace halfback::test
