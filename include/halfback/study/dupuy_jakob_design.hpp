// Dupuy & Jakob 2018's acquisition ("An Adaptive Parameterization for Efficient Material
// Acquisition and Representation") as a design of the virtual gonio-reflectometer, sized to a
// measurement budget (issue 33; docs/acquisition.md, "Dupuy & Jakob's layout"). It is what
// `halfback export-rgl` writes: the retro-reflection ρ(ω, ω) measured at the NDF table's nodes
// (the microfacet distribution is recovered from it by power iteration), then resolution²
// pairs in each of the incidence slices, evenly spaced in σ, laid out through the visible-normal
// warp of that distribution; the reconstruction is the RGL file's own interpolation. Every
// measurement counts against the budget, the retro-reflection ones included.
#pragma once

#include <cstddef>
#include <memory>

#include "halfback/brdf/brdf.hpp"
#include "halfback/formats/rgl_writer.hpp"

namespace halfback::study {

struct DupuyJakobLayout {
  int theta_i = 8;      // incidence slices (Dupuy & Jakob's published files have 8)
  int resolution = 32;  // pairs per slice: resolution × resolution
  int ndf_nodes = 128;  // retro-reflection measurements, the NDF table's nodes
  std::size_t retro_measurements() const { return std::size_t(ndf_nodes); }
  std::size_t slice_measurements() const {
    return std::size_t(theta_i) * std::size_t(resolution) * std::size_t(resolution);
  }
  std::size_t measurements() const { return retro_measurements() + slice_measurements(); }
  // export-rgl's options for this layout (the VNDF tables at the NDF's resolution).
  RglExportOptions export_options(int threads = 0) const;
};

// The layout of at most `budget` measurements: 8 slices, budget / 16 retro-reflection nodes
// (between 16 and 128: the published files' 128 from a budget of 2048 up), and the largest
// resolution whose slices fit in the rest (at most export-rgl's 512). Throws
// std::invalid_argument for a budget below the smallest layout (16 nodes and 8 slices of 2 × 2:
// 48 measurements).
DupuyJakobLayout dupuy_jakob_layout(std::size_t budget);

// `brdf` measured in `layout` and reconstructed: the material export-rgl writes with the
// layout's options, read back (the same values as the file, to the bit). Throws as rgl_fields:
// an anisotropic BRDF, one whose values the format cannot hold.
std::shared_ptr<const Brdf> dupuy_jakob_acquisition(const Brdf& brdf,
                                                    const DupuyJakobLayout& layout,
                                                    int threads = 0);

}  // namespace halfback::study
