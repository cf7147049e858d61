#include "halfback/figure/paper.hpp"

#include <fmt/format.h>

#include <stdexcept>
#include <system_error>
#include <tuple>
#include <utility>

#include "halfback/figure/hemisphere.hpp"
#include "halfback/figure/render.hpp"
#include "halfback/figure/slices.hpp"

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

std::vector<WrittenFigure> write_paper_figures(const std::filesystem::path& dir,
                                               const PaperFigureOptions& o) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw std::runtime_error(fmt::format("cannot create the output directory '{}': {}",
                                         dir.string(),
                                         ec ? ec.message() : "a file of that name exists"));
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
  return written;
}

}  // namespace halfback::figure
