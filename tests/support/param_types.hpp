// The built-in parameterizations (BuiltinParams) as GoogleTest's type list, so that the typed
// tests of the maps run on every parameterization of the list, including one added later.
#pragma once

#include <gtest/gtest.h>

#include "halfback/core/parameterization.hpp"

namespace halfback::test {

template <class List>
struct GtestTypesOf;
template <class... Ps>
struct GtestTypesOf<ParamList<Ps...>> {
  using type = ::testing::Types<Ps...>;
};

using BuiltinParamTypes = GtestTypesOf<BuiltinParams>::type;

}  // namespace halfback::test
