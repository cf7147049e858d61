// Fitting analytic models (one lobe or a sum of lobes of the model registry) to any BRDF, by
// bounded nonlinear least squares (Ceres) under one of the literature's losses, from several
// starts. Definitions of the sample layout and of the losses: docs/fit.md.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/brdf/brdf.hpp"

namespace halfback::fit {

// A target the fit cannot use (not finite, negative or zero everywhere it is sampled;
// anisotropic): a data error, not a usage error.
class FitDataError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The first eight are halfback's: residuals on halfback's sample layout (below). The bbm_* ones are
// the published losses exactly as BBM (bsdfbenchmark/bbm, include/loss/) defines them: BBM's
// per-sample error on BBM's regular grid of directions (bbm_grid_samples), summed over the
// channels and averaged over the grid (docs/fit.md, "Published losses").
enum class Loss {
  ngan,
  low_e1,
  low_e2,
  cube_root,
  bieron_l2,
  bieron_log,
  log,
  nielsen,
  bbm_ngan,          // nganL2: ((m − t) cos θi)² sin θi sin θo, both directions on the grid
  bbm_low_e1,        // lowL2: ((m − t) cos θi)² sin θi, ωo in the plane φo = 0
  bbm_low_e2,        // lowLog: (log(1 + m cos θi) − log(1 + t cos θi))² sin θi, φo = 0
  bbm_bieron_l2,     // bieronL2: nganL2 · max(cos θo, 0)
  bbm_bieron_log,    // bieronLog: the log error · max(cos θo, 0) sin θi sin θo
  bbm_standard_log,  // standardLog: the log error · sin θi sin θo
};
inline constexpr Loss kLosses[] = {
    Loss::ngan,           Loss::low_e1,          Loss::low_e2,     Loss::cube_root,
    Loss::bieron_l2,      Loss::bieron_log,      Loss::log,        Loss::nielsen,
    Loss::bbm_ngan,       Loss::bbm_low_e1,      Loss::bbm_low_e2, Loss::bbm_bieron_l2,
    Loss::bbm_bieron_log, Loss::bbm_standard_log};
// Whether `loss` is one of BBM's (measured on BBM's grid, not on halfback's layout).
bool is_bbm(Loss loss);
std::string_view name_of(Loss loss);                    // "ngan", "low-e1", ...
std::optional<Loss> parse_loss(std::string_view name);  // nullopt when unknown
std::string loss_names();                               // "ngan, low-e1, ..."

// The sample layout: n pairs from a Halton sequence (bases 2, 3, 5) in the isotropic halfdiff
// coordinates θh ∈ [0, π/2), θd ∈ [0, π/2), φd ∈ [0, π) at the canonical pose (φh = 0); points
// whose pair leaves the upper hemisphere are skipped. weight: the solid-angle measure
// dωi dωo / (dθh dθd dφd) of each point, scaled to mean 1.
struct Samples {
  std::vector<DirPair<double>> pairs;
  std::vector<double> weight;
  std::vector<double> cos_i;
};
// How the layout's pairs sit about the normal. canonical: every pair at φh = 0. turned: the
// same pairs, each turned about the normal by 2π times the Halton sequence's fourth coordinate
// (base 7) of its point, so that the layout covers the azimuths; an isotropic BRDF has the same
// values at both, weights and cos θi are unchanged (docs/fit.md, "Sample layout").
enum class Azimuths { canonical, turned };
Samples halfdiff_samples(std::size_t n, Azimuths azimuths = Azimuths::canonical);
inline constexpr std::string_view kLayoutName = "halfdiff-halton";
inline constexpr std::string_view kTurnedLayoutName = "halfdiff-halton-turned";
std::string_view layout_name(Azimuths azimuths);

// BBM's grid of direction pairs (its spherical_linearizer): for each direction a regular grid of
// `phi` azimuths 2πk/phi (k < phi) by `theta` elevations (π/2)·j/(theta − 1) (j < theta, both
// 0 and π/2 included; 0 alone when theta = 1), every incident point with every outgoing point.
// The Löw losses have out_phi = 1 (ωo at φo = 0).
struct BbmGrid {
  std::size_t in_phi = 0, in_theta = 0, out_phi = 0, out_theta = 0;
};
// The grid halfback measures `loss` (a bbm_* one) on unless told otherwise: BBM fixes no size
// (its loss constructors take it). Löw's losses: 36 × 17 incident by 17 outgoing elevations
// (10°, 5.625°, 5.625° steps; 10 404 pairs); the others 18 × 10 by 18 × 10 (20°, 10°; 32 400
// pairs). Counts whose last elevation is not exactly on the horizon are avoided (docs/fit.md).
BbmGrid default_grid(Loss loss);
// The grid's pairs, BBM's incident direction as ωi, in BBM's order; weight: the loss's sine
// factors (sin θi sin θo, or sin θi for Löw's), sin θ as BBM computes it, √max(1 − z², 0);
// cos_i: cos θi. Components below the machine epsilon in magnitude are 0, as in BBM. Throws
// std::invalid_argument for a loss that is not a bbm_* one or a grid with a zero count, or out_phi
// ≠ 1 for Löw's losses.
Samples bbm_grid_samples(Loss loss, const BbmGrid& grid);
inline constexpr std::string_view kBbmGridLayoutName = "bbm-grid";

// One parameter of one term of a model.
struct Param {
  std::size_t term = 0;
  std::string name;
  double value = 0;
  double min = 0, max = 0;  // the registry's range (the fit's bounds)
  bool fitted = false;      // false: held (given in the model spec, or held by rule, docs/fit.md)
};

// A model to fit: "ggx", "lambert+ggx", "ggx:f0=0.9" (values given are held), parsed against
// the loader's model registry. Throws std::invalid_argument naming an unknown model or parameter,
// or a value out of range.
struct Model {
  std::vector<std::string> terms;  // model names
  std::vector<Param> params;       // every fitted or given parameter, by term
};
Model parse_model(std::string_view model);

// Whether some term of `model` is anisotropic at its values or with one fitted parameter moved
// to 10 % or 90 % of its range (Brdf::isotropic() of the term): "ggx:alpha_x=0.1" can be (α
// fitted drives alpha_y), "ggx" cannot. fit() samples such a model on the turned layout.
bool can_be_anisotropic(const Model& model);

// `model` with each fitted parameter that has no effect held (fitted = false): one whose move to
// 25 % and to 75 % of its range, the others at their values, leaves the term's values unchanged
// at 512 of `samples` spread over them (every (n/512)-th) ("ggx:eta=1.5": f0 has no effect under
// the exact Fresnel factor). fit() and fit_at() neither vary nor report as fitted such parameters.
Model hold_parameters_without_effect(Model model, const Samples& samples);

// The channel a parameter drives alone (0, 1, 2 for NAME_r/_g/_b), or -1 for one that may drive
// every channel (a shape parameter such as alpha). Contract of the registry's colour parameters
// (models/colour_params.hpp), checked for every registered model by
// FitModel.ColourChannelsDriveTheirChannelOnly.
int channel_of(const Param& p);

// The spec of the model at its parameters' values ("lambert:albedo_r=...+ggx:alpha=..."),
// readable by load_brdf(), exact to the last bit (the shortest decimal that reads back as the same
// double).
std::string spec_of(const Model& model);

struct FitOptions {
  Loss loss = Loss::ngan;
  std::size_t samples = 20000;
  int threads = 0;  // core/parallel.hpp
  // When not empty: the only starts, each a model spec of the same terms ("ggx:alpha=3") whose
  // values replace the defaults of the fitted parameters. Empty: the automatic starts
  // (docs/fit.md).
  std::vector<std::string> starts = {};
  int max_iterations = 200;
  // An instrument's reach, in radians in (0, π/2]: a sample whose θi or θo exceeds it is out of
  // reach and left out of the fit (counted in FitResult::out_of_reach).
  double max_theta = 1.5707963267948966;
  // When set, polled while the fit runs (before each evaluation of a term, at the end of each
  // iteration, before each start); once it returns true, fit() and fit_at() stop within one
  // evaluation of a term and throw FitCancelled. For a caller with a deadline, or whose client
  // may leave (the explorer's server). Called from the fitting thread only.
  std::function<bool()> cancelled = {};
  // The grid of a bbm_* loss (`samples` is then not used); nullopt: default_grid(loss).
  std::optional<BbmGrid> grid = std::nullopt;
};

// A fit stopped because FitOptions::cancelled returned true.
class FitCancelled : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A term of a fitted model is a dead lobe (docs/fit.md, "Dead lobes") when
// - its share of the sum's albedo is below kDeadLobeShare: Σ w cos θi ρ̄ over the fit's samples
//   (ρ̄ the mean of the channels; on fit()'s layout an estimate of the albedo averaged over the
//   hemisphere), the term's over the sum's; or
// - the fit's loss without the term is at most (1 + kDeadLobeLoss) times the fit's loss: it does
//   nothing the fit needs (a GGX lobe pushed to α = 10, f0 = 0, whose Schlick grazing term
//   cannot vanish, keeps 0.1 % of the albedo).
inline constexpr double kDeadLobeShare = 1e-4;
inline constexpr double kDeadLobeLoss = 1e-3;

// The incidence angles (degrees) at which a fitted model's directional albedo is reported.
inline constexpr double kEnergyAngles[] = {0, 30, 60, 80, 85};

struct FitResult {
  Model model;       // parameters at the best start's solution
  std::string spec;  // spec_of(model)
  Loss loss = Loss::ngan;
  // Mean over samples and channels of the squared residuals (docs/fit.md); for a bbm_* loss
  // BBM's value (the mean over the grid of the sum over channels).
  double loss_value = 0;
  // kLayoutName, kTurnedLayoutName, kBbmGridLayoutName, or "given" (fit_at: the caller's)
  std::string layout;
  std::vector<double> albedo_share;  // per term: its share of the sum's albedo, in [0, 1]
  std::vector<double> loss_without;  // per term: the loss of the other terms alone
  std::vector<bool> dead;            // per term: a dead lobe (the rule above)
  std::size_t samples = 0;           // the samples fitted: within reach and measured
  // Samples left out (docs/fit.md, "Missing and out-of-reach samples"): a target value that is
  // NaN in some channel is missing (an unmeasured bin, a row a lab did not measure); a pair with
  // θi or θo above FitOptions::max_theta is out of reach. The weights of the others are scaled
  // back to mean 1.
  std::size_t missing = 0, out_of_reach = 0;
  std::size_t starts = 0;
  int iterations = 0;  // of all starts
  double seconds = 0;
};

// A fitted model's energy: its largest directional albedo, over the channels and θi of
// kEnergyAngles, with that θi and the estimate's standard error. A model above 1 reflects more
// light than it receives (a renderer gains energy); nothing in a loss forbids it (docs/fit.md,
// "Energy"). Computed by those who report a fit (the CLI, the explorer, Python), not by fit():
// the study fits thousands of times and never reports it.
struct FitEnergy {
  double max_albedo = 0, theta_deg = 0, standard_error = 0;
  // True when max_albedo exceeds 1 by more than three standard errors.
  bool creates_energy() const { return max_albedo > 1 + 3 * standard_error; }
};

// The energy of the model `spec` (a fit's FitResult::spec): 256² stratified samples a direction,
// deterministic.
FitEnergy fitted_energy(std::string_view spec);

// Fits `model` to `target` on the layout of options.samples pairs: turned when the model can be
// anisotropic (can_be_anisotropic), canonical otherwise; missing and out-of-reach samples left
// out (FitResult). Throws std::invalid_argument for a bad
// model or start spec, or a model with nothing to fit (every parameter given, held by rule or
// without effect); FitDataError for a target the fit cannot use.
FitResult fit(const Brdf& target, std::string_view model, const FitOptions& options = {});

// Fits `model` to values measured at the caller's pairs (e.g. a gonio-reflectometer's plan:
// values[k] at samples.pairs[k], weighted by samples.weight[k], whose mean should be 1 for the
// loss's value to compare with fit()'s), from the registry's defaults and the grid of starts (no
// start from a peak: there is no BRDF to look at); NaN values (rows not measured) and pairs out
// of reach left out, as fit() does. Throws std::invalid_argument for mismatched
// sizes, no pairs, or as fit() for the model; FitDataError for values the fit cannot use.
FitResult fit_at(const Samples& samples, std::span<const Rgb> values, std::string_view model,
                 const FitOptions& options = {});

// The loss of `model` against target values `target_rgb` at `samples` (one per pair). Missing
// values (NaN in a channel) are left out as fit() leaves them out, the other weights scaled back
// to mean 1, so that the loss of a fit's spec on its own target is its FitResult::loss_value;
// throws FitDataError when every value is missing.
double loss_value(std::span<const Rgb> target_rgb, const Brdf& model, Loss loss,
                  const Samples& samples, int threads = 0);

// The loss of `model` against `target` on the layout of `samples` pairs, as fit() measures it
// (FitResult::loss_value is loss_of(target, the fitted spec's BRDF, ...) for the same samples):
// the turned layout when `model` is anisotropic, the canonical one otherwise (an isotropic model
// has the same loss on both, to rounding).
// Throws FitDataError for a target the fit cannot use.
// For a bbm_* loss: on `grid` (default_grid(loss) when nullopt), `samples` not used.
double loss_of(const Brdf& target, const Brdf& model, Loss loss, std::size_t samples,
               int threads = 0, std::optional<BbmGrid> grid = std::nullopt);

namespace detail {
// The fitter's shortcuts (docs/fit.md, "What a fit costs"), on by default: Ceres's bounded line
// search interpolates quadratically (values only, no Jacobian at its trial points); a term whose
// values are those of its last evaluation is not evaluated again; a parameter to which the term
// is proportional channel by channel (an albedo) gets its Jacobian columns from the term's
// values. Off: the fitter as before them (the benchmarks' and tests' baseline). Read when a
// solve starts; set it between fits, not during one.
void set_fit_shortcuts(bool on);
bool fit_shortcuts();
}  // namespace detail

}  // namespace halfback::fit
