// Figures 3-5 of Barla et al. 2015 for any BRDF: the material rendered on a sphere under several
// environments (top row), then its 2D slices in each parameterization (slices.hpp, generic mode).
#pragma once

#include <string>
#include <vector>

#include "halfback/figure/scene.hpp"
#include "halfback/figure/slices.hpp"
#include "halfback/render/envmap.hpp"
#include "halfback/render/image.hpp"

namespace halfback::figure {

struct MaterialFigureOptions {
  BrdfPtr brdf;
  std::string heading;  // the figure's title ("Figure 3, ..."); empty: the BRDF's name
  // Environment specs (EnvMap::from_spec): a built-in or a file; one render each.
  std::vector<std::string> environments{"default", "studio", "sunset"};
  int render_pixels = 176;  // width and height of each sphere rendering
  int spp = 48;
  std::uint64_t seed = 1;
  // The slices: params, azimuths, colouring, panel size, threads (brdf is set from above).
  SliceOptions slices;
};

struct MaterialFigure {
  Scene scene;
  std::vector<render::Image> renders;  // linear radiance, one per environment
  SliceFigure slices;
};

// Throws std::invalid_argument for a missing BRDF or an empty environment list, and what
// EnvMap::from_spec throws for a bad environment.
MaterialFigure material_figure(const MaterialFigureOptions& options);

}  // namespace halfback::figure
