// Figures 3-5 (material.hpp): the renderings are physically right where the answer is known, and
// the composed scene holds the renderings and the slices.
#include "halfback/figure/material.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "halfback/loader/load.hpp"

namespace halfback::figure {
namespace {

MaterialFigureOptions small(const std::string& spec) {
  MaterialFigureOptions o;
  o.brdf = load_brdf(spec);
  o.render_pixels = 32;
  o.spp = 16;
  o.slices.panel_size = 40;
  o.slices.pixels_per_point = 1;
  return o;
}

// A white furnace: Lambert of albedo a under a constant environment of radiance 1 reflects a in
// every direction, so every sphere pixel is a up to Monte-Carlo noise (16 samples of an estimator
// whose relative spread is below 1: a few 0.1 %), and the corners show the background, exactly 1.
TEST(MaterialFigure, FurnaceRenderingIsTheAlbedo) {
  MaterialFigureOptions o = small("lambert:albedo=0.3");
  o.environments = {render::load_environment("constant:1"), render::load_environment("constant:0")};
  const MaterialFigure f = material_figure(o);
  ASSERT_EQ(f.renders.size(), 2u);
  const render::Image& white = f.renders[0];
  const float* centre = white.pixel(16, 16);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(centre[c], 0.3, 0.01);
  EXPECT_NEAR(white.pixel(0, 0)[0], 1.0, 1e-6);
  for (float v : f.renders[1].rgb) EXPECT_EQ(v, 0.f);
}

TEST(MaterialFigure, SceneHoldsTheRenderingsAndTheSlices) {
  MaterialFigureOptions o = small("ggx:alpha=0.3");
  o.heading = "Figure 3, a_test";
  const MaterialFigure f = material_figure(o);
  std::size_t images = 0, render_images = 0;
  bool heading = false;
  for (const Item& item : f.scene.items) {
    if (const auto* im = std::get_if<ImageItem>(&item)) {
      ++images;
      if (im->px_width == 32 && im->px_height == 32) ++render_images;
      EXPECT_GE(im->x, 0);
      EXPECT_LE(im->x + im->width, f.scene.width + 1e-9);
      EXPECT_LE(im->y + im->height, f.scene.height + 1e-9);
    }
    if (const auto* t = std::get_if<TextItem>(&item))
      heading |= plain_text(t->text) == "Figure 3, a_test";  // markup escaped: '_' kept
  }
  EXPECT_EQ(render_images, 3u);
  // Each rendering is captioned with its environment.
  for (const char* caption : {"sky (built-in)", "studio (built-in)", "sunset (built-in)"}) {
    bool found = false;
    for (const Item& item : f.scene.items)
      if (const auto* t = std::get_if<TextItem>(&item)) found |= plain_text(t->text) == caption;
    EXPECT_TRUE(found) << caption;
  }
  EXPECT_GE(images, 3u + f.slices.panels.size());
  EXPECT_TRUE(heading);
  EXPECT_EQ(f.slices.panels.size(), 9u);
  EXPECT_GT(f.scene.height, f.slices.scene.height);
}

TEST(MaterialFigure, BadInput) {
  MaterialFigureOptions o = small("lambert");
  o.environments = {};
  EXPECT_THROW(material_figure(o), std::invalid_argument);
  EXPECT_ANY_THROW(render::load_environment("no-such-map.hdr"));
  o.environments = {{"no map", nullptr}};
  EXPECT_THROW(material_figure(o), std::invalid_argument);
  o = small("lambert");
  o.brdf = nullptr;
  EXPECT_THROW(material_figure(o), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::figure
