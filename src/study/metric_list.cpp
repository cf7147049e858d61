// The study's built-in metrics (metric.hpp), in the order of the tables, CSV files, settings and
// report sections. A metric: its file (NAME_metric.cpp, defining NAME_metric()) and its line here.
#include "halfback/study/metric.hpp"

namespace halfback::study {

const Metric& azimuthal_metric();
const Metric& separability_metric();
const Metric& gonio_metric();
const Metric& image_metric();
const Metric& sampling_metric();
const Metric& fit_metric();
const Metric& neural_metric();

std::span<const Metric* const> builtin_metrics() {
  static const Metric* const kMetrics[] = {
      &azimuthal_metric(), &separability_metric(), &gonio_metric(),  &image_metric(),
      &sampling_metric(),  &fit_metric(),          &neural_metric(),
  };
  return kMetrics;
}

}  // namespace halfback::study
