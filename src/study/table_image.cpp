// The table of metric 4, the image-space error (metric_tables.hpp).
#include "halfback/study/metric_tables.hpp"
#include "table_columns.hpp"

namespace halfback::study {

MetricTable image_table() {
  return {"image",
          {columns::parameterization(), columns::design(), columns::integer("samples"),
           columns::text("environment"), columns::real("relative_rmse"),
           columns::real("mean_delta_e2000"), columns::real("p95_delta_e2000"),
           columns::real("mae"), columns::real("rmse"), columns::real("ssim")},
          {}};
}

void add_image(MetricTable& table, Space space, const ImagePoint& p) {
  table.add({std::string(name_of(space)), std::string(name_of(p.design)), std::int64_t(p.samples),
             p.environment, p.relative_rmse, p.mean_delta_e, p.p95_delta_e, p.mae, p.rmse, p.ssim});
}

std::vector<ImagePoint> image_points(const BrdfResult& result, Space space) {
  const MetricTable& t = result.table("image");
  std::vector<ImagePoint> points;
  for (const Row* row : rows_of(t, space))
    points.push_back({columns::design_of(t, *row), std::size_t(t.integer(*row, "samples")),
                      t.text(*row, "environment"), t.real(*row, "relative_rmse"),
                      t.real(*row, "mean_delta_e2000"), t.real(*row, "p95_delta_e2000"),
                      t.real(*row, "mae"), t.real(*row, "rmse"), t.real(*row, "ssim")});
  return points;
}

}  // namespace halfback::study
