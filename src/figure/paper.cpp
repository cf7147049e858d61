#include "halfback/figure/paper.hpp"

#include <fmt/format.h>

#include <stdexcept>
#include <system_error>
#include <tuple>
#include <utility>

#include "halfback/figure/hemisphere.hpp"
#include "halfback/figure/material.hpp"
#include "halfback/figure/render.hpp"
#include "halfback/figure/slices.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/util/output_dir.hpp"

namespace halfback::figure {

namespace {
std::vector<std::filesystem::path> save_all(const Scene& scene, const std::filesystem::path& dir,
                                            const std::string& stem, const PaperFigureOptions& o) {
  std::vector<std::filesystem::path> out;
  for (const auto& [on, ext] :
       {std::pair{o.png, ".png"}, std::pair{o.svg, ".svg"}, std::pair{o.pdf, ".pdf"}}) {
    if (!on) continue;
    const auto path = dir / (stem + ext);
    save(scene, path);
    out.push_back(path);
  }
  return out;
}
}  // namespace

std::vector<PaperMaterial> default_paper_materials() {
  // The paper's materials first. Titles must fit the figure's width (about 78 characters).
  return {
      {"fig3-gold-metallic-paint3", "embedded:gold-metallic-paint3",
       "Figure 3: MERL gold-metallic-paint3, neural fit (Sztrajman et al. 2021)"},
      {"fig4-colonial-maple-223", "embedded:colonial-maple-223",
       "Figure 4: MERL colonial-maple-223, neural fit (Sztrajman et al. 2021)"},
      {"fig5-pink-felt", "embedded:pink-felt",
       "Figure 5: MERL pink-felt, neural fit (Sztrajman et al. 2021)"},
      {"fig3-metallic", "embedded:ilm_l3_37_metallic",
       "Figure 3, a glossy metallic: metallic paint, measured (RGL ilm_l3_37_metallic)"},
      {"fig4-paint", "embedded:colodur_azure_4e",
       "Figure 4, a diffuse: wall paint, measured (RGL colodur_azure_4e)"},
      {"fig5-felt", "embedded:acrylic_felt_green",
       "Figure 5, a textile: felt, measured (RGL acrylic_felt_green)"},
      {"fig3-analytic-gold", "ggx:alpha=0.15,f0_r=1,f0_g=0.78,f0_b=0.34",
       "Figure 3, analytic: glossy gold (GGX, Schlick Fresnel)"},
      {"fig4-analytic-sheen",
       "lambert:albedo_r=0.55,albedo_g=0.22,albedo_b=0.18+sheen:alpha=0.4,color=0.6",
       "Figure 4, analytic: a diffuse with sheen (Lambert + Charlie sheen)"},
      {"fig5-analytic-textile",
       "sheen:alpha=0.25,color_r=0.35,color_g=0.8,color_b=0.35+lambert:albedo_r=0.04,"
       "albedo_g=0.18,albedo_b=0.05",
       "Figure 5, analytic: a textile-like grazing lobe (Charlie sheen over a dark diffuse)"},
  };
}

std::vector<WrittenFigure> write_paper_figures(const std::filesystem::path& dir,
                                               const PaperFigureOptions& o) {
  create_output_directory(dir);
  std::vector<WrittenFigure> written;
  for (const auto& [centre, stem, what] :
       {std::tuple{ViewCentre::normal, "fig1-hemisphere",
                   "Figure 1, hemisphere views centred on n"},
        std::tuple{ViewCentre::mirror, "fig1-hemisphere-mirror",
                   "Figure 1, views centred on the mirror direction"},
        std::tuple{ViewCentre::back, "fig1-hemisphere-back",
                   "Figure 1, views centred on the back direction"}}) {
    HemisphereOptions h;
    h.centre = centre;
    h.threads = o.threads;
    written.push_back({what, save_all(hemisphere_figure(h).scene, dir, stem, o)});
  }
  SliceOptions s;
  s.threads = o.threads;
  written.push_back({"Figure 2, test functions S, G, F on slices",
                     save_all(slice_figure(s).scene, dir, "fig2-slices", o)});
  const std::vector<render::Environment>& envs =
      o.environments.empty() ? render::default_environments() : o.environments;
  for (const PaperMaterial& m : o.materials) {
    MaterialFigureOptions mo;
    mo.brdf = m.brdf ? m.brdf : load_brdf(m.spec);
    mo.heading = m.description;
    mo.environments = envs;
    mo.render_pixels = o.render_pixels;
    mo.spp = o.spp;
    mo.slices.threads = o.threads;
    mo.slices.colouring = SliceColouring::rgb;
    written.push_back({m.description, save_all(material_figure(mo).scene, dir, m.stem, o)});
  }
  return written;
}

}  // namespace halfback::figure
