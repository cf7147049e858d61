// docs/reliability/readers.md, "One bound on a BRDF's value": the one bound on a BRDF's value, its
// message, and the probe set that finds a value above it.
#include "halfback/brdf/rho_bound.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "halfback/core/param.hpp"
#include "support/test_brdfs.hpp"

namespace halfback {
namespace {

TEST(RhoBound, OneBoundOneMessage) {
  EXPECT_TRUE(rho_within_bound(1e10));
  EXPECT_FALSE(rho_within_bound(1.0000001e10));
  EXPECT_FALSE(rho_within_bound(std::numeric_limits<double>::infinity()));
  EXPECT_TRUE(rho_within_bound(std::numeric_limits<double>::quiet_NaN()));  // missing
  EXPECT_TRUE(rho_within_bound(Rgb{1, -2, 3}));
  EXPECT_FALSE(rho_within_bound(Rgb{1, 2e10, 3}));
  EXPECT_EQ(rho_above_bound(1e31),
            "ρ = 1e+31 sr⁻¹, above the bound of 1e+10 sr⁻¹ on a BRDF's value");
  EXPECT_EQ(rho_above_bound(INFINITY, "line 4", "ρ·cos θo"),
            "ρ·cos θo overflows to infinity at line 4, above the bound of 1e+10 sr⁻¹ on a BRDF's "
            "value");
}

// A spike above the bound in a small region the probe set reaches (near the specular peak, where
// its θh nodes are densest), and a BRDF just within the bound everywhere.
TEST(RhoBound, ProbeFindsAValueAboveTheBoundAndNamesTheBrdf) {
  const test::FunctionBrdf spike([](const DirPair<double>& p) {
    const double theta_h = HalfDiff::forward(p)[0];
    return theta_h < 0.01 ? 1e12 : 0.5;
  });
  const auto excess = find_rho_above_bound(spike);
  ASSERT_TRUE(excess.has_value());
  EXPECT_EQ(excess->rho.r, 1e12);
  EXPECT_LT(HalfDiff::forward(excess->pair)[0], 0.01);
  try {
    require_rho_bound(spike, "what the test says");
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("function: ρ = 1e+12 sr⁻¹ at θh = 0°", 0), 0u) << what;
    EXPECT_NE(what.find("above the bound of 1e+10 sr⁻¹ on a BRDF's value (what the test says)"),
              std::string::npos)
        << what;
  }
  const test::FunctionBrdf within([](const DirPair<double>&) { return 1e10; });
  EXPECT_FALSE(find_rho_above_bound(within).has_value());
  EXPECT_EQ(probe_rho(within).largest, 1e10);
  EXPECT_EQ(probe_rho(spike).largest, 1e12);
  EXPECT_NO_THROW(require_rho_bound(within, ""));
}

}  // namespace
}  // namespace halfback
