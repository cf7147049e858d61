#include "fit_metric.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "halfback/core/batch.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/fit/fit.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::study {

namespace {

// The largest relative change of a fitted shape parameter (not a colour channel) from `whole`.
double shape_change(const fit::Model& layout, const fit::Model& whole) {
  double worst = 0;
  for (std::size_t i = 0; i < whole.params.size(); ++i) {
    const fit::Param& p = whole.params[i];
    if (!p.fitted || fit::channel_of(p) >= 0) continue;
    const double scale = std::max(std::abs(p.value), 1e-6 * (p.max - p.min));
    worst = std::max(worst, std::abs(layout.params[i].value - p.value) / scale);
  }
  return worst;
}

// The solid angle dωi dωo per unit volume of the isotropic coordinates of `space` at a pair:
// the weight of a measurement whose cell has the volume of every other (the own spacing's cells).
double solid_angle_density(Space space, const DirPair<double>& pair) {
  const Form iso{space, true}, dirs{Space::dirs, false};
  const double d[6] = {pair.wi.x, pair.wi.y, pair.wi.z, pair.wo.x, pair.wo.y, pair.wo.z};
  double q[3], back[6], jac = 0;
  if (!convert_one<double>(dirs, iso, d, q) || !convert_one<double>(iso, dirs, q, back, &jac))
    return 0;
  return std::isfinite(jac) && jac > 0 ? jac : 0;
}

// The measurements of a plan where the BRDF is finite, each weighted 1 or by its cell's solid
// angle, the weights' mean 1.
std::pair<fit::Samples, std::vector<Rgb>> measured(const Brdf& brdf, const GonioPlan& plan,
                                                   FitWeights weights) {
  fit::Samples s;
  std::vector<Rgb> values;
  double total = 0;
  for (const PlannedPoint& p : plan.points) {
    const Rgb v = brdf.eval(p.pair);
    if (!(std::isfinite(v.r) && std::isfinite(v.g) && std::isfinite(v.b))) continue;
    const double w =
        weights == FitWeights::uniform ? 1.0 : solid_angle_density(plan.setup.space, p.pair);
    if (!(w > 0)) continue;
    s.pairs.push_back(p.pair);
    s.weight.push_back(w);
    s.cos_i.push_back(p.pair.wi.z);
    values.push_back(v);
    total += w;
  }
  for (double& w : s.weight) w *= double(s.weight.size()) / total;
  return {std::move(s), std::move(values)};
}

struct Job {
  std::size_t param = 0;
  Design design = Design::regular;
  std::size_t budget = 0;
  FitWeights weights = FitWeights::uniform;
};

}  // namespace

std::optional<fit::FitResult> whole_fit(const Brdf& brdf, const StudyConfig& config,
                                        const std::function<void(std::string)>& say) {
  if (config.fit_model.empty() || !brdf.isotropic()) return std::nullopt;
  const fit::FitOptions o{.loss = fit::parse_loss(config.fit_loss).value(),  // validate() checked
                          .samples = config.fit_samples};
  try {
    return fit::fit(brdf, config.fit_model, o);
  } catch (const fit::FitDataError& e) {
    say(fmt::format("fit: skipped, {}", e.what()));
    return std::nullopt;
  }
}

std::vector<std::pair<Space, FitPoint>> fit_metric(const Brdf& brdf, const StudyConfig& config,
                                                   std::span<const Space> work,
                                                   const std::optional<fit::FitResult>& whole_fit) {
  if (!whole_fit || config.fit_budgets.empty()) return {};
  const fit::FitResult& whole = *whole_fit;
  const fit::Loss loss = fit::parse_loss(config.fit_loss).value();
  fit::FitOptions o{.loss = loss, .samples = config.fit_samples};
  const fit::Samples layout = fit::halfdiff_samples(config.fit_samples);
  std::vector<Rgb> truth(layout.pairs.size());
  for (std::size_t i = 0; i < truth.size(); ++i) truth[i] = brdf.eval(layout.pairs[i]);

  std::vector<Job> jobs;
  for (std::size_t k = 0; k < work.size(); ++k)
    for (Design d : kDesigns)
      for (std::size_t budget : config.fit_budgets)
        for (FitWeights w : kFitWeights) jobs.push_back({k, d, budget, w});
  std::vector<std::optional<FitPoint>> rows(jobs.size());
  o.threads = 1;  // one fit per job, the jobs on all cores
  parallel_for(jobs.size(), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      GonioSetup setup{.space = work[jobs[j].param],
                       .design = jobs[j].design,
                       .budget = jobs[j].budget,
                       .seed = config.seed,
                       .max_theta_deg = config.max_theta_deg};
      const auto [samples, values] = measured(brdf, gonio_plan(setup), jobs[j].weights);
      if (samples.pairs.empty()) continue;
      try {
        const fit::FitResult r = fit::fit_at(samples, values, config.fit_model, o);
        const double on_whole = fit::loss_value(truth, *load_brdf(r.spec), loss, layout, 1);
        rows[j] = FitPoint{jobs[j].design,
                           jobs[j].budget,
                           samples.pairs.size(),
                           jobs[j].weights,
                           config.fit_model,
                           config.fit_loss,
                           whole.loss_value,
                           on_whole,
                           shape_change(r.model, whole.model),
                           r.spec};
      } catch (const fit::FitDataError&) {  // e.g. zero at every measurement: no row
      }
    }
  });
  std::vector<std::pair<Space, FitPoint>> out;
  for (std::size_t j = 0; j < jobs.size(); ++j)
    if (rows[j]) out.emplace_back(config.params[jobs[j].param], *rows[j]);
  return out;
}

}  // namespace halfback::study
