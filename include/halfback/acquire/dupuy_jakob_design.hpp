// Dupuy & Jakob 2018's acquisition ("An Adaptive Parameterization for Efficient Material
// Acquisition and Representation") as a design of the virtual gonio-reflectometer, sized to a
// measurement budget (docs/acquisition.md, "Dupuy & Jakob's layout"). It is what
// `halfback export-rgl` writes: the retro-reflection ρ(ω, ω) measured at the NDF table's nodes
// (the microfacet distribution is recovered from it by power iteration), then resolution²
// pairs in each of the incidence slices, evenly spaced in σ, laid out through the visible-normal
// warp of that distribution; the reconstruction is the RGL file's own interpolation. Every
// measurement counts against the budget, the retro-reflection ones included.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/formats/rgl_writer.hpp"

namespace halfback::acquire {

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

// The layout as an instrument measures it, in two stages (docs/acquisition.md, "Planning Dupuy &
// Jakob's layout"): what dupuy_jakob_acquisition evaluates, split where it must wait for values.
//   1. the retro-reflection pairs (ω, ω) at the NDF table's nodes, known beforehand;
//   2. the pairs the incidence slices' tables are read at: their elevations and the VNDF warp
//      follow from the distribution recovered from stage 1's values (retro[k] at pair k of
//      stage 1), so they are known only once those are measured. Pairs below the horizon are not
//      measured (the tables hold 0 there); a pair repeated is listed once.
// Both in the order dupuy_jakob_acquisition evaluates them. Throws std::invalid_argument as
// dupuy_jakob_acquisition does (the retro-reflection not finite, or zero everywhere) or when the
// values are not one per pair of stage 1.
std::vector<DirPair<double>> dupuy_jakob_retro_pairs(const DupuyJakobLayout& layout);
std::vector<DirPair<double>> dupuy_jakob_slice_pairs(const DupuyJakobLayout& layout,
                                                     std::span<const Rgb> retro);

// The RGL file's fields from the values measured at both stages' pairs (slices[k] at pair k of
// stage 2): the fields export-rgl writes of a BRDF with these values, so that read back they are
// dupuy_jakob_acquisition's material when the values are the BRDF's. Throws std::invalid_argument
// for counts that differ or a value that is not finite (naming the pair), or as rgl_fields.
std::vector<TensorFieldData> dupuy_jakob_fields(const DupuyJakobLayout& layout,
                                                std::span<const Rgb> retro,
                                                std::span<const Rgb> slices, int threads = 0);
// The material of those fields, as dupuy_jakob_acquisition reads it back.
std::shared_ptr<const Brdf> dupuy_jakob_material(const std::vector<TensorFieldData>& fields,
                                                 const std::string& name);

}  // namespace halfback::acquire
