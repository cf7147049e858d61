// The study's tables, one per metric (docs/study.md, "Output"; table.hpp): their columns, the
// typed records of their rows, and the one list of them (study_tables()) that the generic code
// follows: part files, Python's dicts, the CSV files and merges. Every table's first column is
// "parameterization"; a BRDF's table holds the rows of each parameterization together.
//
// The tables come from the list of metrics (metric.hpp): each metric says which tables it has.
// The tables below are those of the first metrics; a metric's table may as well be in its file.
#pragma once

#include <span>
#include <vector>

#include "halfback/core/space.hpp"
#include "halfback/study/study.hpp"
#include "halfback/study/table.hpp"

namespace halfback::study {

// One entry of the list: a table's name and columns, and for a table derived from the stored
// ones (written as a CSV file, never stored: a part or a Python dict does not carry it), how.
struct TableDef {
  MetricTable (*columns)();  // the table with its name and columns, without rows
  void (*derive)(const BrdfResult& result, MetricTable& into) = nullptr;
};

// Every table of every metric of study_metrics(), in the order of the CSV files: azimuthal,
// separability, gonio, budget, image, sampling, fit, then those of metrics registered later.
std::vector<TableDef> study_tables();
// The stored tables (those of study_tables() that are not derived), without rows, in order.
std::vector<MetricTable> stored_tables();

// The rows of one parameterization.
std::vector<const Row*> rows_of(const MetricTable& table, Space space);

// azimuthal: the relative error of dropping the relative azimuth (dims 3) or, for anisotropic
// BRDFs, the second azimuth of the full form (dims 4). NaN where not measured.
MetricTable azimuthal_table();
void add_azimuthal(MetricTable& table, Space space, double error, int dims);
double azimuthal_error(const BrdfResult& result, Space space, int dims);

// separability: the relative errors of the best rank-r approximations, one row per rank, of the
// 2D projection (dims 2), the 3D table unfolded along its azimuth (3), the 4D table (4).
MetricTable separability_table();
void add_separability(MetricTable& table, Space space, const std::vector<int>& ranks,
                      const std::vector<double>& errors, int dims);
std::vector<double> separability_errors(const BrdfResult& result, Space space, int dims);

// gonio: the virtual gonio-reflectometer's reconstructions, in the isotropic form (dims 3) or
// the full form of an anisotropic BRDF (dims 4).
MetricTable gonio_table();
void add_gonio(MetricTable& table, Space space, const GonioPoint& point, int dims);
std::vector<GonioPoint> gonio_points(const BrdfResult& result, Space space, int dims);
// The samples and errors of the points of one design, in the order of the points.
struct GonioCurve {
  std::vector<double> samples, errors;
};
GonioCurve gonio_curve(const std::vector<GonioPoint>& points, acquire::Design layout,
                       acquire::Spacing spacing = acquire::Spacing::own);

// budget (derived from gonio): the measurements each design needs to reach the target errors.
inline constexpr double kTargetErrors[] = {0.05, 0.02, 0.01};
MetricTable budget_table();
void derive_budget(const BrdfResult& result, MetricTable& into);

// image: the image-space error of the reconstructions at the image budget, per environment.
MetricTable image_table();
void add_image(MetricTable& table, Space space, const ImagePoint& point);
std::vector<ImagePoint> image_points(const BrdfResult& result, Space space);

// sampling: the importance samplers in the parameterization's chart, per table size and sampler
// ("tabulated", "factored"); sampling_points gives one sampler's rows, in the order of the sizes.
MetricTable sampling_table();
void add_sampling(MetricTable& table, Space space, const SamplingPoint& point);
std::vector<SamplingPoint> sampling_points(const BrdfResult& result, Space space,
                                           std::string_view sampler = "tabulated");

}  // namespace halfback::study
