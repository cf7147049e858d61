// The parameterizations of a pair of directions (ωi, ωo), as generic kernels: one header each in
// params/ (the conventions and the contract: params/common.hpp), their list and their run-time
// form in parameterization.hpp.
#pragma once

#include "halfback/core/parameterization.hpp"
