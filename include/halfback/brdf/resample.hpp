// Resampling: a BRDF tabulated on a regular grid of any parameterization, with a validity mask.
//
// Three kinds of grid over a parameterization P (docs/formats.md, "Resampled tables"):
//   full       the 4D coordinates of P                   (e.g. hbar, phi_h, k, phi_k)
//   isotropic  the 3D isotropic form of P                (e.g. hbar, k, dphi), canonical pose
//   slice      the isotropic form at a fixed relative azimuth: the two non-azimuthal coordinates
//              (e.g. hbar, k at dphi = 90°), the slices of the paper's Figures 2-5
// Each axis is a range [lo, hi] with `count` samples, either at the centres of `count` equal cells
// (the default, as MERL does: no sample on a singular boundary such as θ = π/2) or at `count`
// equally spaced nodes including both ends. A grid point outside the parameterization's domain
// (no pair of directions in the upper hemisphere has those coordinates) is invalid: its values are
// NaN and its mask 0. The table is row-major, the last axis fastest.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/core/space.hpp"

namespace halfback {

enum class GridKind { full, isotropic, slice };
enum class GridSampling { centres, nodes };

std::string_view name_of(GridKind kind);
std::string_view name_of(GridSampling sampling);

struct GridAxis {
  std::string name;  // the coordinate's column name (space.hpp), e.g. "theta_h"
  double lo = 0, hi = 1;
  std::size_t count = 1;
  // The i-th sample position.
  double position(std::size_t i, GridSampling sampling) const;
};

struct GridSpec {
  Space space = space_of<Hybrid>;  // a parameterization, not dirs
  GridKind kind = GridKind::isotropic;
  GridSampling sampling = GridSampling::centres;
  double slice_azimuth = 0;    // kind == slice: the relative azimuth, radians (wrapped by point)
  std::vector<GridAxis> axes;  // 4, 3 or 2 axes (full, isotropic, slice)

  std::size_t points() const;
  // The form whose coordinates a grid point is evaluated at (the slice's is the isotropic one).
  Form form() const { return {space, kind != GridKind::full}; }
  // The coordinates in form() of point `flat` (row-major, last axis fastest): the axes'
  // positions, then, for a slice, its azimuth; dimension(form()) values are meaningful.
  std::array<double, 4> point(std::size_t flat) const;
  // The axis called `name`; throws std::invalid_argument naming the grid's axes otherwise.
  GridAxis& axis(std::string_view name);
};

// The one rule for relative azimuths given by users (the CLI, Python, the figures): any finite
// azimuth is wrapped into [0°, 360°) (−90 → 270, 360 → 0, 400 → 40); NaN and infinities are an
// error (std::invalid_argument "WHAT: 'nan' is not a finite azimuth in degrees").
double wrap_azimuth_degrees(double degrees, std::string_view what);
// The same in radians, into [0, 2π), for the azimuth a slice is evaluated at (GridSpec::point).
double wrap_azimuth_radians(double radians);

// The grid of a kind over `space`, each axis on the range that bounds the domain (angles θ in
// [0, π/2], azimuths in [0, 2π), ‖h̄‖, ‖k̄‖, ‖k‖ in [0, 1]), with counts[i] samples on axis i (a
// single count applies to every axis), a slice at slice_azimuth wrapped into [0, 2π). Throws
// std::invalid_argument for dirs, a wrong number of counts, a count of 0 or a non-finite azimuth.
GridSpec default_grid(Space space, GridKind kind, std::vector<std::size_t> counts,
                      double slice_azimuth = 0);

// The most points a grid may have: a table keeps 25 bytes a point (RGB doubles and the mask), so
// 1.7 GB at this limit, which an ordinary machine holds (2^31 points would take 54 GB).
inline constexpr std::size_t kMaxGridPoints = std::size_t{1} << 26;

// Checks a grid (the right axes for its kind, finite ranges with lo < hi, counts >= 1, nodes
// need counts >= 2 only when lo != hi, at most kMaxGridPoints); throws std::invalid_argument.
void validate(const GridSpec& grid);

// The direction pairs of points [begin, begin + pairs.size()) of a grid, by the core's checked
// batch inverse of its form: valid[j] is 1 where point begin + j is a pair of directions of the
// upper hemisphere, 0 elsewhere (pairs[j] is NaN there). With `jacobian` (pairs.size() values),
// also the measure of the form at each point (batch.hpp). On the calling thread.
void grid_pairs(const GridSpec& grid, std::size_t begin, std::span<DirPair<double>> pairs,
                std::span<std::uint8_t> valid, std::span<double> jacobian = {});

// The direction pairs at coordinates of a form, given as dimension(form) columns of
// pairs.size() values each, by the core's checked batch inverse; `valid` and `jacobian` as in
// grid_pairs(). On the calling thread.
void coordinates_to_pairs(Form form, std::span<const std::span<const double>> columns,
                          std::span<DirPair<double>> pairs, std::span<std::uint8_t> valid,
                          std::span<double> jacobian = {});

struct ResampledTable {
  GridSpec grid;
  std::string brdf_name, brdf_description;
  std::vector<double> rgb;          // points() × 3; NaN where invalid
  std::vector<std::uint8_t> valid;  // points(); 1 inside the domain, 0 outside
  std::size_t valid_count() const;
};

struct ResampleOptions {
  int threads = 0;  // as in core/parallel.hpp: 0 all cores, 1 the calling thread, n at most n
};

// Tabulates `brdf` on `grid` (validated first). A valid point whose ρ is not finite keeps that
// value; the mask only says whether the coordinates are those of a pair of directions.
ResampledTable resample(const Brdf& brdf, const GridSpec& grid,
                        const ResampleOptions& options = {});

}  // namespace halfback
