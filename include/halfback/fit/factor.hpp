// A data-driven factored model of a BRDF in a parameterization (docs/fit.md,
// "Factored models"): the FactoredModel (formats/factored.hpp) of `rank` separable terms in
// log(1 + ρ) that is closest to the BRDF in the μ-weighted L² norm on the cell centres of the
// parameterization's isotropic grid, dμ = cos θi cos θo dωi dωo (the study's measure).
#pragma once

#include <array>
#include <cstddef>

#include "halfback/brdf/brdf.hpp"
#include "halfback/core/space.hpp"
#include "halfback/formats/factored.hpp"

namespace halfback::fit {

struct FactorOptions {
  std::size_t rank = 2;
  std::array<std::size_t, 3> counts{32, 32, 32};
  int sweeps = 60;  // of alternating least squares, at most
  int threads = 0;  // sampling the BRDF (core/parallel.hpp)
};

struct FactorResult {
  FactoredModel model;
  // The fit's μ-weighted relative L² error in log(1 + ρ) on its grid, per channel's mean.
  double relative_error = 0;
  int sweeps = 0;
};

// Throws std::invalid_argument for dirs, a rank or counts out of FactoredModel's range, an
// anisotropic BRDF; std::runtime_error when the BRDF is not finite and ≥ 0 at some grid point
// inside the domain (naming it).
FactorResult factor_brdf(const Brdf& brdf, Space space, const FactorOptions& options = {});

}  // namespace halfback::fit
