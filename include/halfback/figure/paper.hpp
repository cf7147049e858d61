// The paper's Figures 1 and 2 on their default settings, written as PNG, SVG and PDF.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace halfback::figure {

struct PaperFigureOptions {
  unsigned threads = 0;
  bool png = true, svg = true, pdf = true;
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
// Each file is written atomically. Throws std::runtime_error when the directory cannot be
// created or a file cannot be written.
std::vector<WrittenFigure> write_paper_figures(const std::filesystem::path& dir,
                                               const PaperFigureOptions& options = {});

}  // namespace halfback::figure
