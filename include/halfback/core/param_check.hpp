// The checks a parameterization must pass before halfback uses it (a Python user's, a registered
// one, or a built-in one in the tests): its maps are checked against each other and against the
// geometry of pairs of directions, through the descriptor's row maps (so a vectorized Python map is
// called once per check, not once per pair).
//   vectorized   the row maps give as many finite rows as asked
//   range        the forward map stays in the axes' declared ranges
//   round trip   pair -> q -> pair gives the same *ordered* pair (a swapped inverse is named)
//   domain       every tuple of the box that the inverse accepts gives two unit directions of the
//                upper hemisphere, and maps back to itself (q -> pair -> q -> the same pair)
//   jacobian     J against the volume of finite differences of the inverse, and the Monte-Carlo
//                integrals ∫ J 1[valid] dq = (2π)² and ∫ J cos θi cos θo 1[valid] dq = π²
//   isotropic    the isotropic form is rotation invariant and its inverse a rotation of the pair
//   reciprocity  the reciprocity map gives the coordinates of the swapped pair
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "halfback/core/parameterization.hpp"

namespace halfback {

struct ParamCheck {
  std::string name;  // "round trip", "range", ...
  bool passed = false;
  std::string detail;  // what was measured, and where it failed
};

struct ParamCheckReport {
  std::string parameterization;
  std::vector<ParamCheck> checks;
  bool passed() const;
  // "NAME: CHECK: DETAIL" of the first failed check; empty when all passed.
  std::string first_failure() const;
  std::string text() const;  // one line per check
};

struct ParamCheckOptions {
  std::size_t pairs = 20000;          // random pairs for the round trips and invariances
  std::size_t box_samples = 200000;   // tuples of the box, for the domain and the integrals
  std::size_t jacobian_points = 500;  // points of the finite-difference check
  std::uint64_t seed = 1;
  double tolerance = 1e-8;  // on directions (unit vectors) of the round trips
};

// √det(AᵀA) for the 6×4 derivative A of q ↦ (ωi, ωo) ∈ R⁶ given by its columns a[k]: the volume
// element dωi dωo / dq, since S²×S² sits isometrically in R⁶.
double gram_volume(const double (&a)[4][6]);

ParamCheckReport check_parameterization(const ParamDescriptor& param,
                                        const ParamCheckOptions& options = {});

}  // namespace halfback
