// The virtual gonio-reflectometer of the study (metric 3; docs/study.md): a BRDF measured
// at N points laid out in one parameterization, reconstructed everywhere by interpolation in that
// parameterization, and compared with the ground truth over the whole space of direction pairs.
//
// Layouts (the `Design` of the code). Both divide the bounding box of the parameterization's
// isotropic form (a, b, φ) — or of its full form (a, φa, b, φb) for anisotropic BRDFs — into cells,
// n per magnitude axis and 2n per azimuth (which spans [0, 2π)), n chosen so that the number of
// cells inside the domain is nearest the budget N (in ratio):
//   regular     one measurement at the centre of every cell inside the domain;
//   stratified  one at a uniformly random point of every cell (redrawn up to 8 times until it
//               falls inside the domain; a cell that never does has no measurement).
// The cells are uniform in the warped coordinates of the setup's spacing (design.hpp): own, the
// default, leaves the coordinates as they are. Measurements, reconstruction and the count of
// cells inside the domain all work in the warped coordinates u = F(x).
// Pairs beyond the instrument's reach (max_theta_deg) are not measured.
// No symmetry is assumed (neither reciprocity nor the mirror symmetry φ → −φ): every
// parameterization measures the same space, so budgets compare like with like.
//
// Reconstruction, at the coordinates x of a pair in the same form: from the 2^d cells around x
// (those whose centres bracket x on every axis; azimuths wrap around; beyond the outermost
// centres of another axis, the two outermost cells),
//   regular     multilinear interpolation of their values (extrapolation beyond the outermost
//               centres, clamped to >= 0);
//   stratified  the value at x of the affine least-squares fit to their measurements, limited
//               to the range of those measurements (no overshoot around a narrow peak); like
//               multilinear interpolation, exact for affine functions (where x is inside the
//               measurements' range) and second-order accurate for smooth ones.
// Cells without a measurement (outside the domain or the reach, or whose value was not finite)
// are first filled by dilation: in rounds, each empty cell next to filled ones takes the mean of
// the linear extrapolations from them, at its centre. Values are RGB ρ, reconstructed channel by
// channel in linear space, as a renderer would use a measured table.
//
// Error: ( Σ (T(Ŷ) − T(Y))² / Σ T(Y)² )^½ over test pairs drawn from the measure
// dμ = cos θi cos θo dωi dωo (normalized: independent cosine-weighted directions, uniform
// azimuths), T the error space of samples.hpp: a Monte-Carlo estimate of the same μ-weighted
// relative L² error as the other metrics, over the whole pair space or over the pairs within
// the instrument's reach (the study's default: docs/study.md says why).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/acquire/design.hpp"
#include "halfback/acquire/samples.hpp"
#include "halfback/brdf/brdf.hpp"
#include "halfback/brdf/resample.hpp"
#include "halfback/core/space.hpp"

namespace halfback::acquire {

// The grid layouts above (kDesigns), and two of the literature's acquisitions, reconstructed their
// own way, not by GonioReconstruction (which refuses them; their instrument plans are
// acquisition.hpp's dupuy_jakob_pilot_plan and nielsen_plan):
// Dupuy & Jakob 2018's (`dupuy_jakob`, dupuy_jakob_design.hpp), a design of the study's
// "dupuy-jakob:per-material" parameterization only (its rows are that parameterization's), and
// Nielsen et al. 2015's minimal sampling (`nielsen`, nielsen.hpp), rows of halfdiff (their
// candidate configurations are MERL's bins) whose budget is the number of measurements.
// Between them, the sequential design (sequential_design.hpp): a pilot grid, then a grid in the
// warps its values ask for; of every parameterization, isotropic form only.
enum class Design { regular, stratified, sequential, dupuy_jakob, nielsen };
inline constexpr std::array<Design, 2> kDesigns{Design::regular, Design::stratified};
// The designs of every parameterization (the grids and the sequential design).
inline constexpr std::array<Design, 3> kGridDesigns{Design::regular, Design::stratified,
                                                    Design::sequential};
inline constexpr std::array<Design, 5> kAllDesigns{
    Design::regular, Design::stratified, Design::sequential, Design::dupuy_jakob, Design::nielsen};
std::string_view name_of(Design d);
// "regular", "stratified" or "dupuy-jakob"; nullopt for anything else.
std::optional<Design> parse_design(std::string_view name);

struct GonioSetup {
  Space space = space_of<Hybrid>;  // a parameterization, not dirs
  bool isotropic = true;           // measure in the isotropic (3D) form, else in the full (4D) one
  Design design = Design::regular;
  std::size_t budget = 10000;  // measurements wanted (>= 1)
  std::uint64_t seed = 1;      // the stratified design's random points
  // The instrument's reach: no measurement where ωi or ωo is farther than this from the normal
  // (those cells are filled by dilation). Real gonio-reflectometers stop short of grazing, and
  // measured data are least reliable there (RGL's ρ grows like 1/cos θo past ~87°).
  double max_theta_deg = 90;
  // The spacing of the cells along each axis (design.hpp); `learned` holds the warps of the
  // learned spacing for this space (required by it, ignored by the others).
  Spacing spacing = Spacing::own;
  std::optional<LearnedWarps> learned{};
};

// The cells of a setup: default_grid()'s ranges with n cells per magnitude axis and 2n per
// azimuth, n such that the cells inside the domain are nearest the budget in ratio.
GridSpec gonio_cells(const GonioSetup& setup);

// Where a setup measures, known before anything is measured: its cells (in the warped
// coordinates), their warps, and one point per cell that the instrument reaches — the cell's
// centre, or the stratified design's random point, drawn again up to 8 times while it falls
// outside the domain or the reach — in cell order. A cell no point reaches has none: it is
// filled by dilation. `halfback plan` writes it; GonioReconstruction measures it.
struct PlannedPoint {
  std::size_t cell = 0;
  std::array<float, 4> offset{};  // where in the cell, in cell units from its lower corner
  DirPair<double> pair{};
};
struct GonioPlan {
  GonioSetup setup;
  GridSpec cells;
  std::vector<AxisWarp> warps;  // one per axis of `cells`
  std::vector<PlannedPoint> points;
};
// Throws what gonio_cells() throws.
GonioPlan gonio_plan(const GonioSetup& setup);

// A BRDF measured by the virtual gonio-reflectometer and reconstructed (a Brdf, so that it can be
// evaluated, resampled and rendered like any other).
class GonioReconstruction final : public Brdf {
 public:
  // Measures `truth` (which need not outlive this) at the points of gonio_plan(setup). Throws
  // std::invalid_argument for dirs or a budget of 0, std::runtime_error when no measurement has
  // a finite value.
  GonioReconstruction(const Brdf& truth, const GonioSetup& setup);
  // The values measured at a plan's points (values[k] at plan.points[k]; NaN: not measured,
  // filled by dilation like a cell out of reach), of a BRDF called `measured`. Throws
  // std::invalid_argument when the counts differ, std::runtime_error when no value is finite.
  GonioReconstruction(GonioPlan plan, std::span<const Rgb> values, std::string measured);

  std::string name() const override;
  std::string description() const override;
  bool isotropic() const override { return setup_.isotropic; }
  bool reciprocal() const override { return false; }  // not enforced by the reconstruction
  Rgb eval(const DirPair<double>& pair) const override;
  void eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const override;

  const GonioSetup& setup() const { return setup_; }
  const GridSpec& cells() const { return cells_; }  // in the warped coordinates
  const std::vector<AxisWarp>& warps() const { return warps_; }
  std::size_t samples() const { return samples_; }  // measurements taken (finite values)

 private:
  // The constructors' work: the measured values into their cells (filled[c] = 1 where a finite
  // value was taken), then the others filled by dilation.
  void init(GonioPlan plan, std::span<const Rgb> values);
  void fill_unmeasured(std::vector<std::uint8_t>& filled);
  // An empty cell's value from its filled neighbours (none when it has no filled neighbour).
  std::optional<Rgb> dilated_value(std::size_t cell, const std::vector<std::uint8_t>& filled) const;
  // The regular design's corners beyond the outermost centres: extrapolation slopes limited.
  void limit_edge_slopes(const double* t, const std::size_t* cell, Rgb* corner) const;
  // The next cell along `axis` in direction `step` (±1), wrapping around an azimuth.
  std::optional<std::size_t> neighbour(std::size_t cell, std::size_t axis, int step) const;

  Rgb reconstruct(const double* x) const;        // at coordinates x of the form
  static Rgb outside(const DirPair<double>& p);  // at a pair the form does not take

  GonioSetup setup_;
  GridSpec cells_;
  std::vector<AxisWarp> warps_;  // one per axis of cells_
  std::string truth_name_;
  std::size_t dim_ = 3;
  std::size_t samples_ = 0;
  std::array<bool, 4> periodic_{};
  std::array<std::size_t, 4> stride_{};
  // Per cell: the point of its measurement (or, for a filled cell, its centre) in cell units,
  // each coordinate in [0, 1) from the cell's lower corner, and the value there.
  std::vector<std::array<float, 4>> offset_;
  std::vector<Rgb> value_;
};

// Test pairs for reconstruction_error(): `count` pairs drawn from the measure
// cos θi cos θo dωi dωo normalized on the pairs whose directions are both within `max_theta_deg`
// of the normal (90: the whole pair space), those where the truth is finite kept, with the
// truth's value in the error space.
struct TestPairs {
  std::vector<DirPair<double>> pairs;
  std::vector<double> truth;
  ErrorSpace space = ErrorSpace::log;
};
TestPairs draw_test_pairs(const Brdf& truth, std::size_t count, std::uint64_t seed, ErrorSpace es,
                          double max_theta_deg = 90);
// The pairs draw_test_pairs() draws, all of them (before the truth's non-finite ones are left
// out). Throws std::invalid_argument for a largest angle outside (0, 90].
std::vector<DirPair<double>> test_pair_directions(std::size_t count, std::uint64_t seed,
                                                  double max_theta_deg = 90);

// The relative error of a reconstruction over the test pairs (header comment).
double reconstruction_error(const Brdf& reconstruction, const TestPairs& test);

// The budget at which an error curve (samples ascending, errors) reaches `target`, by linear
// interpolation of log error against log samples between the two budgets that bracket it;
// 0 when the smallest budget already reaches it, and +∞ when the largest does not.
double samples_to_reach(std::span<const double> samples, std::span<const double> errors,
                        double target);

}  // namespace halfback::acquire
