// Metric 6 of the study (fit_metric.cpp, docs/study.md, "Fitting from measurements"): its table's
// records, and the fit of the whole BRDF that the sampling metric's fitted-mixture sampler uses.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/fit/fit.hpp"
#include "halfback/study/metric.hpp"

namespace halfback::study {

// config.option("fit_model") fitted under fit_loss to the whole BRDF on fit()'s layout of
// fit_samples pairs (made once per BRDF): the reference of metric 6 and the fitted-mixture sampler
// of metric 5. Nullopt for an anisotropic BRDF, the fit metric off, or a BRDF the fit cannot use
// (not finite or negative where sampled: study.say tells why).
const std::optional<fit::FitResult>& whole_fit(BrdfStudy& study);

// A row of the fit table: `model` fitted under `loss` to the `samples` measurements of a design
// at `budget`, and to the whole BRDF (fit()'s layout): both fits' losses on the whole BRDF's
// layout, and the largest relative change of a shape parameter (not a colour channel) between
// them.
// How the fit weights a design's measurements: each 1 (as a laboratory fits its data; the design's
// density then weights the loss), or by the solid angle dωi dωo of its cell (so that the loss
// estimates the same integral as the whole fit's).
enum class FitWeights { uniform, solid_angle };
inline constexpr std::array<FitWeights, 2> kFitWeights{FitWeights::uniform,
                                                       FitWeights::solid_angle};
std::string_view name_of(FitWeights w);  // "uniform", "solid-angle"
std::optional<FitWeights> parse_fit_weights(std::string_view name);

// A fit's loss below this is round-off: the model reproduces the BRDF exactly (the losses of a
// real fit are many orders of magnitude above it), and a ratio of two such losses is noise.
inline constexpr double kRoundOffLoss = 1e-20;

struct FitPoint {
  acquire::Design design = acquire::Design::regular;
  std::size_t budget = 0, samples = 0;
  FitWeights weights = FitWeights::uniform;
  std::string model, loss;
  double whole_loss = 0, layout_loss = 0, shape_change = 0;
  std::string spec;  // the layout's fit
};

// fit: a model fitted to the measurements of each design (isotropic form, own spacing) against
// the same model fitted to the whole BRDF; excess = layout_loss / whole_loss − 1 (derived when
// the row is added).
MetricTable fit_table();
void add_fit(MetricTable& table, Space space, const FitPoint& point);
std::vector<FitPoint> fit_points(const BrdfResult& result, Space space);

}  // namespace halfback::study
