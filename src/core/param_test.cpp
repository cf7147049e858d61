#include "halfback/core/param.hpp"

#include <gtest/gtest.h>

namespace halfback {
namespace {
TEST(Smoke, NormalIncidenceHybrid) {
  const DirPair<double> p{{0, 0, 1}, {0, 0, 1}};
  const auto q = Hybrid::forward(p);
  EXPECT_EQ(q[0], 0.0);
  EXPECT_EQ(q[2], 0.0);
}
}  // namespace
}  // namespace halfback
