// The pieces of the study's report (report.hpp), by kind: what the results are read into
// (report_analysis.cpp), the Markdown tables (report_tables.cpp), the figures
// (report_charts.cpp) and the prose of each section around them (report_sections.cpp);
// report.cpp writes the files, markdown_html.cpp turns the Markdown into HTML.
//
// The report's columns are the parameterizations of its results (params_of()): every BRDF of a
// report has the same ones, in the same order, and every per-parameterization array below is in
// that order.
#pragma once

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "halfback/figure/scene.hpp"
#include "halfback/study/metric_tables.hpp"
#include "halfback/study/study.hpp"

namespace halfback::study::report {

// ---------------------------------------------------------------------------------------------
// Reading the results (report_analysis.cpp)
// ---------------------------------------------------------------------------------------------

// The parameterizations of every BRDF of `results` (not empty). Throws std::invalid_argument
// naming two BRDFs studied with different parameterizations.
const std::vector<Space>& params_of(const std::vector<BrdfResult>& results);

// What the results hold beyond the isotropic metrics 1-2, which decides the optional sections,
// files and plots.
struct Contents {
  bool anisotropic = false, gonio = false, images = false, sampling = false;
};
Contents contents_of(const std::vector<BrdfResult>& results);

// The point of a design at a budget; without a spacing, the own one (the tables of section 3 are
// those of the own design). Null when not measured.
const GonioPoint* find_point(const std::vector<GonioPoint>& points, acquire::Design layout,
                             std::size_t budget, acquire::Spacing spacing = acquire::Spacing::own);
// The result points into `points`: never into a temporary (gonio_points() returns one).
const GonioPoint* find_point(std::vector<GonioPoint>&& points, acquire::Design layout,
                             std::size_t budget,
                             acquire::Spacing spacing = acquire::Spacing::own) = delete;

// The reference budget of the comparisons: the image budget when it is one of the budgets,
// else the middle one.
std::size_t reference_budget(const StudyConfig& config);

double median(std::vector<double> v);

// "1 BRDF", "2 BRDFs".
std::string brdf_count(std::size_t n);

// The mean image-space error of one parameterization's renderings of a design, over the
// environments (INFINITY when there is none).
struct MeanImageError {
  double relative_rmse = INFINITY, delta_e = INFINITY;
  int count = 0;
  double mae = INFINITY, rmse = INFINITY, ssim = 0;  // Sztrajman et al. 2021's protocol
};
MeanImageError mean_image_error(const std::vector<ImagePoint>& images, acquire::Design layout);
bool has_images(const BrdfResult& b);

// Section 3b. A design: a spacing in a layout (the own spacing in both layouts, the others in
// the regular one; study.hpp).
struct DesignKey {
  acquire::Spacing spacing = acquire::Spacing::own;
  acquire::Design layout = acquire::Design::regular;
};
std::string design_name(const DesignKey& k);
// The error of one parameterization of a BRDF in a design at budget `ref` (INFINITY: not measured).
double design_error(const BrdfResult& b, Space space, const DesignKey& k, std::size_t ref);

// The BRDFs measured in every design by every parameterization at `ref` (compared like with
// like), each parameterization's median error per design over them, and its best design.
struct DesignComparison {
  std::vector<Space> params;
  std::vector<DesignKey> keys;
  std::vector<const BrdfResult*> brdfs;
  std::string exact;  // BRDFs left out: some design reconstructs them exactly (no winner)
  std::vector<std::vector<double>> median;  // per parameterization, per design
  std::vector<std::size_t> best;            // per parameterization: an index into keys
};
DesignComparison compare_designs(const std::vector<BrdfResult>& results, std::size_t ref);
// The index in c.keys of a design, or c.keys.size() when it was not measured.
std::size_t key_index(const DesignComparison& c, acquire::Spacing spacing, acquire::Design layout);
// Which parameterization has the lowest error for each BRDF of c, each parameterization i in
// design c.keys[design[i]].
std::vector<std::size_t> winners(const DesignComparison& c, std::size_t ref,
                                 const std::vector<std::size_t>& design);
// "halfdiff 3, ortho 0, ...": how many of `winners` each parameterization is.
std::string win_counts(const std::vector<Space>& params, const std::vector<std::size_t>& winners);
// The parameterization with the most of `winners` (the first of those tied).
std::size_t most_wins(const std::vector<Space>& params, const std::vector<std::size_t>& winners);

// Measured files beside the neural BRDFs fitted to them: "rgl:NAME" or "merl:NAME" with
// "nbrdf:NAME" (the same material), as (file, network) indices into the results.
std::vector<std::pair<std::size_t, std::size_t>> file_network_pairs(
    const std::vector<BrdfResult>& results);
// Per metric of section 5 (azimuthal, separability, gonio, image), the values of the
// parameterizations for one BRDF (INFINITY where not measured).
inline constexpr const char* kPairedMetrics[] = {"azimuthal", "separability", "gonio", "image"};
std::vector<std::vector<double>> paired_metric_values(const BrdfResult& b, std::size_t ref);

// The summary: the metrics per kind of BRDF (neural, measured files, models), for whole
// databases whose per-BRDF tables are too long to read. One metric: its value for each BRDF (in
// the order of the results) and parameterization, INFINITY where it was not measured.
struct SummaryMetric {
  std::string name;
  std::string chart_row;  // the metric's rows in the summary plot ("own", "best"); empty: none
  std::vector<std::vector<double>> values;
  std::string use;  // the use it answers for, in the report's Answers ("importance sampling")
};
std::vector<SummaryMetric> summary_metrics(const std::vector<BrdfResult>& results,
                                           const StudyConfig& config, const Contents& has);
// The kinds in the order they first appear, each with the indices of its BRDFs; "all" last when
// there is more than one kind.
using Kinds = std::vector<std::pair<std::string, std::vector<std::size_t>>>;
Kinds kinds_of(const std::vector<BrdfResult>& results);
// Each parameterization's median over the BRDFs of `rows` measured in all of them (NaN: none),
// and the number of those BRDFs.
std::pair<std::vector<double>, std::size_t> medians(const SummaryMetric& m,
                                                    const std::vector<std::size_t>& rows);

// ---------------------------------------------------------------------------------------------
// Figures (report_charts.cpp)
// ---------------------------------------------------------------------------------------------

// The plots, in the order they are written. Some may have nothing to draw (every curve exact, no
// rendering): the report links only those that are written.
struct ReportPlots {
  figure::Scene summary, azimuthal, separability, gonio, gonio4d, designs, image, renderings,
      sampling, strategies;
};
ReportPlots report_plots(const std::vector<BrdfResult>& results, const StudyConfig& config,
                         const Contents& has, const std::vector<SummaryMetric>& summary);
// The most BRDFs the renderings figure shows: a whole-data study renders 176, whose rows would
// make a figure 51 000 pixels tall (above what an image can have).
inline constexpr std::size_t kMaxExampleRows = 24;
// The renderings of the BRDFs and of their regular-design reconstructions under the first
// environment, a column per parameterization (empty when there are none).
figure::Scene examples_chart(const std::vector<BrdfResult>& results, const StudyConfig& config);
// Writes the plots that have something to draw as PNG and SVG, adding their names to `files`.
void save_plots(const ReportPlots& plots, const std::filesystem::path& dir,
                std::vector<std::string>& files);
// "![alt](stem.png)\n\n", or nothing when the plot has nothing to draw (it is not written).
std::string plot_link(const figure::Scene& plot, const char* alt, const char* stem);

// ---------------------------------------------------------------------------------------------
// Markdown tables (report_tables.cpp): each a table and the line that counts its winners
// ---------------------------------------------------------------------------------------------

// The parameterization with the lowest value in each row, counted over the rows.
class Wins {
 public:
  explicit Wins(const std::vector<Space>& params) : params_(params), count_(params.size()) {}
  // Ties (within 10^-9 relative) count for each of the tied parameterizations; a row without a
  // finite value counts for none.
  void add(const std::vector<double>& v);
  int count(std::size_t i) const { return count_[i]; }
  // "halfdiff 2, ortho 0, ..."
  std::string text() const;

 private:
  std::vector<Space> params_;
  std::vector<int> count_;
};

std::string md_cell(const std::string& s);
// "| label |", the first cell of a BRDF's row.
std::string row_start(const std::string& label);
// "| first | halfdiff | ... |" and its rule; `first` may be several cells ("kind | BRDFs").
std::string table_header(const std::string& first, const std::vector<Space>& params);

std::string azimuthal_table_md(const std::vector<BrdfResult>& results);
std::string azimuthal_4d_table_md(const std::vector<BrdfResult>& results);
// One table of separability errors of the tables of `dims` ("r1 / r2 / ..." per cell), and which
// parameterization has the lowest rank-1 error.
std::string separability_table_md(const std::vector<BrdfResult>& results, const StudyConfig& config,
                                  const char* heading, int dims);
std::string gonio_budget_table(const std::vector<BrdfResult>& results, std::size_t budget);
std::string samples_to_target_table(const std::vector<BrdfResult>& results, double target);
std::string matching_budget_table(const std::vector<BrdfResult>& results, std::size_t ref);
std::string gonio_4d_table(const std::vector<BrdfResult>& results, const StudyConfig& config);
std::string design_median_table(const DesignComparison& c);
std::string best_design_table(const DesignComparison& c, std::size_t ref);
// The image-space tables of section 4: the regular design's, then the stratified one's.
std::string image_tables(const std::vector<BrdfResult>& results);
std::string published_image_table(const std::vector<BrdfResult>& results);
std::string dupuy_jakob_table(const std::vector<BrdfResult>& results, const StudyConfig& config);
// Nielsen et al.'s minimal sampling (halfdiff's nielsen rows) per kind of BRDF and count, against
// halfdiff's regular grid; empty when no BRDF has such rows.
std::string nielsen_table(const std::vector<BrdfResult>& results, const StudyConfig& config);
std::string file_network_winner_table(const std::vector<BrdfResult>& results, std::size_t ref);
std::string file_network_gonio_table(const std::vector<BrdfResult>& results, std::size_t ref);
std::string summary_table(const SummaryMetric& m, const std::vector<Space>& params,
                          const Kinds& kinds);

// ---------------------------------------------------------------------------------------------
// Sections (report_sections.cpp): the prose around the tables and figures
// ---------------------------------------------------------------------------------------------

std::string report_header(const std::vector<BrdfResult>& results, const StudyConfig& config,
                          bool any_aniso, double seconds);
// The report's first section: per use (a summary metric), the parameterization with the lowest
// median over all BRDFs, by how much, and which wins on each kind of BRDF.
std::string answers_section(const std::vector<BrdfResult>& results,
                            const std::vector<SummaryMetric>& metrics);
std::string summary_section(const std::vector<BrdfResult>& results,
                            const std::vector<SummaryMetric>& metrics, const ReportPlots& plots);
std::string azimuthal_section(const std::vector<BrdfResult>& results, bool any_aniso);
std::string separability_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                                 bool any_aniso);
std::string gonio_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                          bool any_aniso, const ReportPlots& plots);
std::string designs_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                            const ReportPlots& plots);
std::string image_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                          const ReportPlots& plots);
std::string files_and_networks_section(const std::vector<BrdfResult>& results,
                                       const StudyConfig& config);
// The closing line: the CSV files written, then what always follows them.
std::string files_paragraph(const std::vector<std::string>& csv_files);

}  // namespace halfback::study::report
