// A BRDF B against a reference A (`halfback compare -o`): the same slices of both (slices.hpp's
// isotropic forms at fixed relative azimuth, false colour of log10 luminance on one shared
// scale), the log ratio of their luminances log10(Y_B / Y_A) on a diverging scale, and their
// directional albedos (luminance) against θi.
#pragma once

#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/core/space.hpp"
#include "halfback/figure/scene.hpp"

namespace halfback::figure {

struct CompareFigureOptions {
  BrdfPtr reference, compared;  // A, B
  Space param = space_of<HalfDiff>;
  std::vector<double> azimuths_deg{0, 45, 90};  // one column of slices each
  double albedo_step_deg = 2;                   // θi from 0 to 88° (89° at most)
  int albedo_samples = 96;                      // per axis of each estimate (albedo.hpp)
  double panel_size = 150;                      // points
  double pixels_per_point = 2;
  int threads = 0;
};

struct CompareFigure {
  Scene scene;
  double log_lo = 0, log_hi = 0;  // the shared scale of the slices of A and B (log10 luminance)
  double ratio_range = 0;  // the log ratio's scale: −ratio_range … +ratio_range (log10 units)
  // The albedo curves: θi (degrees) and the luminance of each BRDF's directional albedo (NaN
  // where no ωo was measured).
  std::vector<double> albedo_theta_deg, albedo_reference, albedo_compared;
};

// Throws std::invalid_argument for a missing BRDF, no azimuth, Space::dirs, a step outside
// (0, 45], or a figure larger than an image can be (FigureSizeError).
CompareFigure compare_figure(const CompareFigureOptions& options);

}  // namespace halfback::figure
