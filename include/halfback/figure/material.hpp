// Figures 3-5 of Barla et al. 2015 for any BRDF: the material rendered on a sphere under several
// environments (top row), then its 2D slices in each parameterization (slices.hpp, generic mode).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "halfback/figure/scene.hpp"
#include "halfback/figure/slices.hpp"
#include "halfback/render/envmap.hpp"
#include "halfback/render/image.hpp"

namespace halfback::figure {

// A rendering drawn as a size × size image item at (x, y), tone mapped to 8-bit sRGB at exposure
// 0 (render::tonemap_srgb8), smoothly interpolated.
ImageItem rendering_item(const render::Image& image, double x, double y, double size);

struct MaterialFigureOptions {
  BrdfPtr brdf;
  std::string heading;  // the figure's title ("Figure 3, ..."); empty: the BRDF's name
  std::vector<render::Environment> environments =
      render::default_environments();  // one rendering each
  int render_pixels = 176;             // width and height of each sphere rendering
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

// Throws std::invalid_argument for a missing BRDF or an empty environment list.
MaterialFigure material_figure(const MaterialFigureOptions& options);

}  // namespace halfback::figure
