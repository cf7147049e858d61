// The halfway disk (Edwards et al. 2006): its facts for the generic property tests
// (core/param_test.cpp). The disk is built at ωi's height, so its inverse is conditioned by zi and
// is no bijection at a grazing ωi.
#include "halfback/core/params/halfway_disk.hpp"

#include <gtest/gtest.h>

#include "param_facts.hpp"
#include "support/test_util.hpp"

namespace halfback::test {
namespace {

ParamFacts halfway_disk_facts() {
  ParamFacts f;
  f.condition = [](const DirPair<double>& p) { return p.wi.z / 4; };  // ~30 ε / zi
  f.reference_valid = [](const Tuple4<long double>& q) {
    return q[0] >= 0 && q[0] <= kPi / 2 && q[2] >= 0 && q[2] <= 1 && reference_azimuths_ok(q);
  };
  // At a grazing ωi every disk point maps to a grazing ωo.
  f.degenerate = [](const DirPair<double>& p) { return p.wi.z < 1e-6; };
  // Its error keeps growing like ε / zi (no bijection at zi = 0); the pose turns a pair known to
  // ε / zi by an angle known to (ε / zi) / ‖h̄‖.
  f.error_grows_below_sqrt_eps = true;
  f.pose_conditioning_multiplies = true;
  return f;
}
const RegisterParamFacts kHalfwayDiskFacts(HalfwayDisk::name, halfway_disk_facts());

}  // namespace
}  // namespace halfback::test
