// The built-in parameterizations (KernelParams and PortableParams) as GoogleTest's type list, so
// that the typed tests of the maps run on every parameterization of the list, including one added
// later.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <string_view>

#include "halfback/core/parameterization.hpp"

namespace halfback::test {

template <class Kernels, class Portable>
struct GtestTypesOf;
template <class... Ks, class... Ps>
struct GtestTypesOf<ParamList<Ks...>, ParamList<Ps...>> {
  using type = ::testing::Types<Ks..., Ps...>;
};

// KernelParams, then PortableParams.
using BuiltinParamTypes = GtestTypesOf<KernelParams, PortableParams>::type;

// A parameterization's name as a test name: '-' would start a negative pattern in --gtest_filter
// (and so in ctest's per-test runs), leaving the test unrun.
inline std::string gtest_name(std::string_view name) {
  std::string s(name);
  for (char& c : s)
    if (c == '-') c = '_';
  return s;
}

}  // namespace halfback::test
