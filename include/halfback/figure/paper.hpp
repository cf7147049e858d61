// The paper's Figures 1-5 on their default settings, written as PNG, SVG and PDF.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/figure/material.hpp"

namespace halfback::figure {

// A material of Figures 3-5: the file stem, a BRDF SPEC and what it shows; `brdf`, when set, is
// the BRDF already loaded from `spec` (so that a caller that checked it does not load it twice).
struct PaperMaterial {
  std::string stem, spec, description;
  BrdfPtr brdf = nullptr;
};

// The defaults: the paper's three MERL materials (gold-metallic-paint3, colonial-maple-223,
// pink-felt) as the neural fits of Sztrajman et al. 2021 embedded in the library, then as
// additional figures three RGL measurements (a metallic paint, a wall paint, a felt;
// data/README.md) and three analytic models with comparable behaviour (a glossy metal, a diffuse
// with sheen, a textile-like grazing lobe).
std::vector<PaperMaterial> default_paper_materials();

struct PaperFigureOptions {
  int threads = 0;
  bool png = true, svg = true, pdf = true;
  std::vector<PaperMaterial> materials = default_paper_materials();  // empty: Figures 1-2 only
  std::vector<render::Environment> environments;  // empty: render::default_environments()
  int render_pixels = 176, spp = 48;
};

struct WrittenFigure {
  std::string description;
  std::vector<std::filesystem::path> files;
};

// Writes into `dir` (created if missing):
//   fig1-hemisphere.{png,svg,pdf}         Figure 1, disks centred on n (equal-area)
//   fig1-hemisphere-mirror.{png,svg,pdf}  the same, centred on the mirror direction
//   fig1-hemisphere-back.{png,svg,pdf}    the same, centred on the back direction ωo
//   fig2-slices.{png,svg,pdf}             Figure 2, S, G, F on slices at 0°, 45°, 90°
//   STEM.{png,svg,pdf}                    Figures 3-5, one per material (material.hpp)
// Each file is written atomically. Throws std::runtime_error when the directory cannot be
// created or a file cannot be written.
std::vector<WrittenFigure> write_paper_figures(const std::filesystem::path& dir,
                                               const PaperFigureOptions& options = {});

}  // namespace halfback::figure
