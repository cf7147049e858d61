// The table of metric 5, importance sampling (metric_tables.hpp).
#include "halfback/study/metric_tables.hpp"
#include "table_columns.hpp"

namespace halfback::study {

MetricTable sampling_table() {
  return {
      "sampling",
      {columns::parameterization(), columns::integer("table_kib"), columns::text("sampler"),
       columns::real("sampler_kib"), columns::text("chart"), columns::real("relative_variance"),
       columns::real("relative_variance_error"), columns::real("ns_per_sample"),
       columns::real("efficiency_vs_cosine"), columns::text("own_sampler"),
       columns::real("efficiency_vs_own"), columns::real("vndf_warp_kib"),
       columns::real("efficiency_vs_vndf_warp"), columns::real("efficiency_vs_fitted_mixture"),
       columns::real("pixel_relative_variance_brdf"), columns::real("pixel_relative_variance_mis"),
       columns::real("pixel_efficiency_vs_cosine_brdf"),
       columns::real("pixel_efficiency_vs_cosine_mis")},
      {}};
}

void add_sampling(MetricTable& table, Space space, const SamplingPoint& p) {
  table.add({std::string(name_of(space)), std::int64_t(p.kib), p.sampler, p.sampler_kib, p.chart,
             p.relative_variance, p.relative_variance_error, p.ns_per_sample,
             p.efficiency_vs_cosine, p.own_sampler, p.efficiency_vs_own, p.vndf_warp_kib,
             p.efficiency_vs_vndf_warp, p.efficiency_vs_fitted_mixture,
             p.pixel_relative_variance_brdf, p.pixel_relative_variance_mis,
             p.pixel_efficiency_vs_cosine_brdf, p.pixel_efficiency_vs_cosine_mis});
}

std::vector<SamplingPoint> sampling_points(const BrdfResult& result, Space space,
                                           std::string_view sampler) {
  const MetricTable& t = result.table("sampling");
  std::vector<SamplingPoint> points;
  for (const Row* row : rows_of(t, space))
    if (t.text(*row, "sampler") == sampler)
      points.push_back({std::size_t(t.integer(*row, "table_kib")), t.text(*row, "sampler"),
                        t.real(*row, "sampler_kib"), t.text(*row, "chart"),
                        t.real(*row, "relative_variance"), t.real(*row, "relative_variance_error"),
                        t.real(*row, "ns_per_sample"), t.real(*row, "efficiency_vs_cosine"),
                        t.text(*row, "own_sampler"), t.real(*row, "efficiency_vs_own"),
                        t.real(*row, "vndf_warp_kib"), t.real(*row, "efficiency_vs_vndf_warp"),
                        t.real(*row, "efficiency_vs_fitted_mixture"),
                        t.real(*row, "pixel_relative_variance_brdf"),
                        t.real(*row, "pixel_relative_variance_mis"),
                        t.real(*row, "pixel_efficiency_vs_cosine_brdf"),
                        t.real(*row, "pixel_efficiency_vs_cosine_mis")});
  return points;
}

}  // namespace halfback::study
