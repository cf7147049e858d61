#include "halfback/acquire/sequential_design.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "halfback/acquire/design.hpp"

namespace halfback::acquire {

GonioSetup sequential_pilot(const GonioSetup& setup, const SequentialOptions& options) {
  const double pilot_share = options.pilot_share;
  if (!setup.isotropic)
    throw std::invalid_argument("the sequential design measures the isotropic form only");
  if (setup.design != Design::sequential)
    throw std::invalid_argument("sequential_pilot: the setup is not of the sequential design");
  if (!(pilot_share > 0 && pilot_share < 1))
    throw std::invalid_argument("the sequential design's pilot share must be in (0, 1)");
  GonioSetup pilot = setup;
  pilot.design = Design::regular;
  pilot.spacing = Spacing::own;
  pilot.learned.reset();
  pilot.budget =
      std::max<std::size_t>(1, std::size_t(std::lround(double(setup.budget) * pilot_share)));
  return pilot;
}

IsoSamples pilot_samples(const GonioPlan& pilot, std::span<const Rgb> values, ErrorSpace es) {
  if (pilot.setup.design != Design::regular || pilot.setup.spacing != Spacing::own ||
      !pilot.setup.isotropic)
    throw std::invalid_argument("a sequential pilot is a regular isotropic grid, own spacing");
  if (values.size() != pilot.points.size())
    throw std::invalid_argument("the pilot: one value per point");
  const auto& axes = pilot.cells.axes;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Rgb> per_cell(pilot.cells.points(), Rgb{nan, nan, nan});
  for (std::size_t k = 0; k < values.size(); ++k) per_cell[pilot.points[k].cell] = values[k];
  return isotropic_samples_of(per_cell, pilot.setup.space,
                              {axes[0].count, axes[1].count, axes[2].count}, es);
}

GonioSetup sequential_main(const GonioSetup& setup, const IsoSamples& pilot, std::size_t measured,
                           const SequentialOptions& options) {
  GonioSetup main = setup;
  main.design = Design::regular;
  main.spacing = Spacing::learned;
  main.learned = warps_for_demand(axis_demand(pilot), options.uniform_share);
  main.budget = setup.budget > measured ? setup.budget - measured : 1;
  return main;
}

std::size_t finite_values(std::span<const Rgb> values) {
  return std::size_t(std::count_if(values.begin(), values.end(), [](const Rgb& v) {
    return std::isfinite(v.r) && std::isfinite(v.g) && std::isfinite(v.b);
  }));
}

GonioSetup sequential_main(const GonioSetup& setup, const GonioPlan& pilot,
                           std::span<const Rgb> values, ErrorSpace es,
                           const SequentialOptions& options) {
  return sequential_main(setup, pilot_samples(pilot, values, es), finite_values(values), options);
}

SequentialAcquisition sequential_acquisition(const Brdf& truth, const GonioSetup& setup,
                                             ErrorSpace es, const SequentialOptions& options) {
  const GonioPlan pilot = gonio_plan(sequential_pilot(setup, options));
  std::vector<DirPair<double>> pairs;
  for (const PlannedPoint& p : pilot.points) pairs.push_back(p.pair);
  std::vector<Rgb> values(pairs.size());
  truth.eval_batch(pairs, values);
  const GonioSetup main = sequential_main(setup, pilot, values, es, options);
  SequentialAcquisition a;
  a.reconstruction = std::make_unique<GonioReconstruction>(truth, main);
  a.samples = finite_values(values) + a.reconstruction->samples();
  a.warps = *main.learned;
  return a;
}

}  // namespace halfback::acquire
