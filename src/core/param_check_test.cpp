// The checks of a parameterization (param_check.hpp): every built-in one passes them, and a wrong
// one fails the check that names its fault.
#include "halfback/core/param_check.hpp"

#include <gtest/gtest.h>

#include "halfback/core/space.hpp"

namespace halfback {
namespace {

ParamCheckOptions quick() {
  ParamCheckOptions o;
  o.pairs = 4000;
  o.box_samples = 100000;
  o.jacobian_points = 200;
  return o;
}

TEST(ParamCheck, EveryBuiltinParameterizationPasses) {
  for (Space s : kBuiltinSpaces) {
    ParamCheckOptions o = quick();
    if (s == space_of<StereoHalfDiff> || s == space_of<HalfwayDisk>)
      o.box_samples = 800000;  // their integrals' estimators have the larger variance
    const ParamCheckReport r = check_parameterization(s.param(), o);
    EXPECT_TRUE(r.passed()) << r.first_failure() << "\n" << r.text();
    EXPECT_EQ(r.checks.size(), 7u);
  }
}

// Hybrid with one fault at a time.
template <int Fault>
struct Faulty : Hybrid {
  static constexpr std::string_view name = "faulty";
  template <class T>
  static Solved<T> inverse_raw(const Tuple4<T>& q) {
    Solved<T> r = Hybrid::inverse_raw(q);
    if constexpr (Fault == 0) std::swap(r.pair.wi, r.pair.wo);  // the classic bug
    return r;
  }
  template <class T>
  static T jacobian(const Tuple4<T>& q) {
    return Hybrid::jacobian(q) * (Fault == 1 ? T(1.02) : T(1));  // 2 % off
  }
  template <class T>
  static Solved<T> inverse_iso_raw(const Tuple3<T>& q) {
    return inverse_raw(lift_iso(q));
  }
  template <class T>
  static Tuple4<T> reciprocal(const Tuple4<T>& q) {
    return Fault == 2 ? q : Hybrid::reciprocal(q);
  }
};
// The range of ‖k‖ declared as [0, 0.5].
struct NarrowRange : Hybrid {
  static constexpr std::string_view name = "narrow";
  static constexpr std::array<Axis, 4> axes{Hybrid::axes[0], Hybrid::axes[1],
                                            Axis{"k", "‖k‖", AxisKind::length, 0, 0.5},
                                            Hybrid::axes[3]};
};

std::string failure_of(const ParamDescriptor& d) {
  const ParamCheckReport r = check_parameterization(d, quick());
  EXPECT_FALSE(r.passed());
  return r.first_failure();
}

TEST(ParamCheck, FaultsAreNamed) {
  EXPECT_NE(failure_of(CompiledParam<Faulty<0>>())
                .find("round trip: the inverse returns the pair "
                      "swapped"),
            std::string::npos);
  EXPECT_NE(failure_of(CompiledParam<Faulty<1>>())
                .find("jacobian: J differs from the "
                      "finite-difference volume"),
            std::string::npos);
  EXPECT_NE(failure_of(CompiledParam<Faulty<2>>()).find("reciprocity:"), std::string::npos);
  EXPECT_NE(failure_of(CompiledParam<NarrowRange>()).find("range: coordinate 2 ('k')"),
            std::string::npos);
}

}  // namespace
}  // namespace halfback
