// Fitting analytic models (one lobe or a sum of lobes of the model registry) to any BRDF, by
// bounded nonlinear least squares (Ceres) under one of the literature's losses, from several
// starts. Definitions of the sample layout and of the losses: docs/fit.md.
#pragma once

#include <cstddef>
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

enum class Loss { ngan, low_e1, low_e2, cube_root, bieron_l2, bieron_log, log, nielsen };
inline constexpr Loss kLosses[] = {Loss::ngan,      Loss::low_e1,     Loss::low_e2, Loss::cube_root,
                                   Loss::bieron_l2, Loss::bieron_log, Loss::log,    Loss::nielsen};
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
Samples halfdiff_samples(std::size_t n);
inline constexpr std::string_view kLayoutName = "halfdiff-halton";

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
};

struct FitResult {
  Model model;       // parameters at the best start's solution
  std::string spec;  // spec_of(model)
  Loss loss = Loss::ngan;
  double loss_value = 0;  // mean over samples and channels of the squared residuals (docs/fit.md)
  std::size_t samples = 0;
  std::size_t starts = 0;
  int iterations = 0;  // of all starts
  double seconds = 0;
};

// Fits `model` to `target`. Throws std::invalid_argument for a bad model or start spec, or a
// model with nothing to fit;
// FitDataError for a target the fit cannot use.
FitResult fit(const Brdf& target, std::string_view model, const FitOptions& options = {});

// Fits `model` to values measured at the caller's pairs (e.g. a gonio-reflectometer's plan:
// values[k] at samples.pairs[k], weighted by samples.weight[k], whose mean should be 1 for the
// loss's value to compare with fit()'s), from the registry's defaults and the grid of starts (no
// start from a peak: there is no BRDF to look at). Throws std::invalid_argument for mismatched
// sizes, no pairs, or as fit() for the model; FitDataError for values the fit cannot use.
FitResult fit_at(const Samples& samples, std::span<const Rgb> values, std::string_view model,
                 const FitOptions& options = {});

// The loss of `model` against target values `target_rgb` at `samples` (one per pair).
double loss_value(std::span<const Rgb> target_rgb, const Brdf& model, Loss loss,
                  const Samples& samples, int threads = 0);

// The loss of `model` against `target` on the layout of `samples` pairs, as fit() measures it
// (FitResult::loss_value is loss_of(target, the fitted spec's BRDF, ...) for the same samples).
// Throws FitDataError for a target the fit cannot use.
double loss_of(const Brdf& target, const Brdf& model, Loss loss, std::size_t samples,
               int threads = 0);

}  // namespace halfback::fit
