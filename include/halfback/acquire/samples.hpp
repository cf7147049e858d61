// A BRDF's values under the measure every comparison of parameterizations uses (study/metrics.hpp,
// the designs, the virtual gonio-reflectometer; docs/study.md):
//
// Measure: dμ = cos θi cos θo dωi dωo (the projected solid angles: the weight of a pair in
// rendering), written in each parameterization's isotropic coordinates (a, b, φ) with the core's
// Jacobian, dωi dωo = J₃(a, b, φ) da db dφ (batch.hpp, jacobian of an isotropic form).
// Values: the luminance Y = 0.2126 r + 0.7152 g + 0.0722 b of ρ, in an error space T
// (docs/study.md, "Error spaces"): linear (Y), log (ln(1 + Y)), cube root (Y^⅓), or two published
// ones that also see the pair's cosines:
//   nielsen  ln(1 + Y c / ε), c = max(cos θi cos θo, 0.01), ε = 0.001: a difference of two values
//            is Nielsen et al. 2015's log-relative mapping ln((Y c + ε)/(Y_ref c + ε)) (the clamp
//            of c and ε are those of their code release);
//   low      ln(1 + Y cos θi): the cosine-weighted log of Löw et al. 2012.
// Quadrature: the midpoint rule on a regular grid of cell centres of (a, b, φ) over the ranges of
// resample.hpp's default grids; cells outside the domain have weight 0.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/core/space.hpp"

namespace halfback::acquire {

// The largest sample budget a plan, a design or a study takes: a budget's tables and test pairs
// take tens of bytes per sample, so this keeps one study within a few GB (10x the default largest,
// 4D).
inline constexpr std::size_t kMaxSampleBudget = 10'000'000;

enum class ErrorSpace { linear, log, cbrt, nielsen, low };
inline constexpr std::array<ErrorSpace, 5> kErrorSpaces{
    ErrorSpace::linear, ErrorSpace::log, ErrorSpace::cbrt, ErrorSpace::nielsen, ErrorSpace::low};
std::string_view name_of(ErrorSpace s);
std::optional<ErrorSpace> parse_error_space(std::string_view name);

// The value every metric compares: the luminance of ρ (Rgb::luminance) at a pair whose
// directions have the cosines cos_i = cos θi and cos_o = cos θo, mapped to the error space.
double to_error_space(double luminance, ErrorSpace es, double cos_i, double cos_o);

struct IsoGrid {
  std::size_t a = 64, b = 64, phi = 64;  // cells of the two magnitudes and of the azimuth
};

// An isotropic BRDF sampled on the isotropic grid of one parameterization.
struct IsoSamples {
  Space space = space_of<Hybrid>;
  IsoGrid grid;
  std::vector<double> value;  // a.b.phi values (φ fastest) in the error space; 0 where invalid
  std::vector<double> weight;  // dμ of each cell: J₃ cos θi cos θo Δa Δb Δφ; 0 where invalid
  double total_weight() const;
};

// Throws std::invalid_argument for Space::dirs or an empty grid.
IsoSamples sample_isotropic(const Brdf& brdf, Space space, const IsoGrid& grid, ErrorSpace es);
// The same from values measured at the cells' centres (values[p] at cell p, in the grid's order, φ
// fastest): a value that is not finite is no measurement (weight 0). Throws std::invalid_argument
// for an empty grid or a count of values other than its cells'.
IsoSamples isotropic_samples_of(std::span<const Rgb> values, Space space, const IsoGrid& grid,
                                ErrorSpace es);

// The 4D version, for anisotropic BRDFs: the BRDF on a grid of cell centres of the full form
// (a, φa, b, φb) of a parameterization — (θh, φh, θd, φd), (‖h̄‖, φh, ‖k̄‖, φk), (‖h̄‖, φh, ‖k‖, φk)
// or (θi, φi, θo, φo) — with dμ = J₄ cos θi cos θo da dφa db dφb (the core's 4D Jacobian).
struct FullSamples {
  Space space = space_of<Hybrid>;
  std::array<std::size_t, 4> counts{16, 32, 16, 32};  // cells of a, φa, b, φb
  std::vector<double> value;   // row-major (φb fastest), in the error space; 0 where invalid
  std::vector<double> weight;  // dμ of each cell; 0 where invalid
  double total_weight() const;
};
FullSamples sample_full(const Brdf& brdf, Space space, const std::array<std::size_t, 4>& counts,
                        ErrorSpace es);

}  // namespace halfback::acquire
