// The grids of metrics 1-2 (azimuthal, separability): a BRDF sampled in one parameterization's
// isotropic form and, for an anisotropic BRDF, its full form, made once per parameterization for
// both metrics (BrdfStudy::task: dropped when the parameterization's task ends).
#pragma once

#include <memory>
#include <optional>

#include "halfback/acquire/samples.hpp"
#include "halfback/study/metric.hpp"

namespace halfback::study {

struct GridSamples {
  acquire::IsoSamples iso;
  std::optional<acquire::FullSamples> full;  // anisotropic BRDFs only
};

// The grids of parameterization k (study.work[k]), sampled on first use. Called from k's task
// only.
inline const GridSamples& grid_samples(BrdfStudy& study, std::size_t k) {
  std::any& slot = study.task[k]["grid_samples"];
  if (!slot.has_value()) {
    auto g = std::make_shared<GridSamples>();
    g->iso =
        acquire::sample_isotropic(study.brdf, study.work[k], study.config.grid, study.config.space);
    if (!study.brdf.isotropic())
      g->full = acquire::sample_full(study.brdf, study.work[k], study.config.full_grid,
                                     study.config.space);
    slot = std::shared_ptr<const GridSamples>(std::move(g));
  }
  return *std::any_cast<std::shared_ptr<const GridSamples>>(slot);
}

}  // namespace halfback::study
