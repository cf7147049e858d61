#include "halfback/figure/material.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "halfback/figure/plot.hpp"
#include "halfback/render/renderer.hpp"

namespace halfback::figure {

ImageItem rendering_item(const render::Image& image, double x, double y, double size) {
  const std::vector<std::uint8_t> rgb = render::tonemap_srgb8(image, {});
  ImageItem item;
  item.x = x;
  item.y = y;
  item.width = item.height = size;
  item.px_width = std::size_t(image.width);
  item.px_height = std::size_t(image.height);
  item.rgba.resize(4 * rgb.size() / 3);
  for (std::size_t p = 0; p < rgb.size() / 3; ++p) {
    std::copy_n(&rgb[3 * p], 3, &item.rgba[4 * p]);
    item.rgba[4 * p + 3] = 255;
  }
  item.smooth = true;
  return item;
}

MaterialFigure material_figure(const MaterialFigureOptions& o) {
  if (!o.brdf) throw std::invalid_argument("material figure: no BRDF given");
  if (o.environments.empty()) throw std::invalid_argument("material figure: no environment given");

  MaterialFigure fig;
  SliceOptions so = o.slices;
  so.brdf = o.brdf;
  fig.slices = slice_figure(so);

  // The sphere renderings, one per environment.
  render::RenderSettings rs;
  rs.width = rs.height = o.render_pixels;
  rs.spp = o.spp;
  rs.seed = o.seed;
  rs.threads = int(so.threads);
  for (const render::Environment& env : o.environments) {
    if (!env.map) throw std::invalid_argument("material figure: an environment without a map");
    fig.renders.push_back(render::render(*o.brdf, *env.map, rs).image);
  }

  // Layout: title, the row of renderings with their captions, then the slice figure.
  Scene& sc = fig.scene;
  const Scene& slices = fig.slices.scene;
  const double left = 84, caption = 22, gap = 26;
  const std::size_t n = fig.renders.size();
  const double avail = slices.width - left - 96;
  const double size = snap(std::min(200.0, (avail - double(n - 1) * gap) / double(n)));
  const double row_width = double(n) * size + double(n - 1) * gap;
  const double x0 = snap(left + (avail - row_width) / 2);
  sc.width = slices.width;
  sc.title = o.heading.empty() ? o.brdf->name() : o.heading;
  const std::string name = escape_markup(o.brdf->name());
  sc.text({left, 26}, o.heading.empty() ? name : escape_markup(o.heading), 15, HAlign::left,
          VAlign::baseline, kBlack, 0, true);
  const std::vector<std::string> sub =
      wrap_text(fmt::format("Top: a unit sphere rendered under {} environment{} ({}×{} pixels, {} "
                            "samples per pixel, multiple importance sampling); below: slices.",
                            n, n == 1 ? "" : "s", o.render_pixels, o.render_pixels, o.spp),
                sc.width - left - 12, 9.5);
  for (std::size_t k = 0; k < sub.size(); ++k) sc.text({left, 44 + 12 * double(k)}, sub[k], 9.5);
  const double top = snap(52 + 12 * double(sub.size()));
  sc.height = snap(top + size + caption + 16 + slices.height);
  for (std::size_t k = 0; k < n; ++k) {
    const render::Image& img = fig.renders[k];
    sc.add(rendering_item(img, x0 + double(k) * (size + gap), top, size));
    const double x = x0 + double(k) * (size + gap);
    draw_frame(sc, {x, top, size, size}, 0.6);
    sc.text({x0 + double(k) * (size + gap) + size / 2, top + size + 14},
            escape_markup(o.environments[k].label), 9.5, HAlign::centre);
  }
  append_scene(sc, slices, {0, snap(top + size + caption + 16)});
  return fig;
}

}  // namespace halfback::figure
