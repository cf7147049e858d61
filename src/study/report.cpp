// The files of a study (report.hpp): the CSV files of the metrics' tables, the figures,
// report.md (a section per metric of study_metrics()) and report.html. The report's pieces are in
// report_*.cpp (report_internal.hpp), the HTML step in markdown_html.cpp.
#include "halfback/study/report.hpp"

#include "halfback/study/metric.hpp"
#include "halfback/util/atomic_file.hpp"
#include "report_internal.hpp"

namespace halfback::study {

namespace {

// NAME.csv of every table of study_tables() that has rows: the rows of every BRDF, in the order
// of the results, numbers to 6 significant digits.
void write_csv_files(const std::filesystem::path& dir, const std::vector<BrdfResult>& results,
                     std::vector<std::string>& files) {
  for (const TableDef& def : study_tables()) {
    const MetricTable columns = def.columns();
    std::string rows;
    for (const BrdfResult& b : results) {
      MetricTable derived = columns;
      if (def.derive) def.derive(b, derived);
      rows += csv_rows(def.derive ? derived : b.table(columns.name), b.label, NumberText::rounded);
    }
    if (rows.empty()) continue;  // not measured (no gonio-reflectometer, no images)
    const std::string name = columns.name + ".csv";
    write_file_atomically(dir / name, csv_header(columns) + rows);
    files.push_back(name);
  }
}

}  // namespace

StudyOutput write_study(const std::filesystem::path& dir, const std::vector<BrdfResult>& results,
                        const StudyConfig& config, double seconds) {
  using namespace report;
  params_of(results);  // the same parameterizations for every BRDF, or an error before any file
  StudyOutput out;
  const Contents has = contents_of(results);
  write_csv_files(dir, results, out.files);

  const std::vector<SummaryMetric> summary = summary_metrics(results, config, has);
  const ReportPlots plots = report_plots(results, config, has, summary);
  std::string md = report_header(results, config, has.anisotropic, seconds) +
                   answers_section(results, summary) + summary_section(results, summary, plots);
  for (const Metric* m : study_metrics()) md += m->report_section(results, config, plots);
  md += files_and_networks_section(results, config);
  md += files_paragraph(out.files);

  // The plots before report.html, which embeds them.
  save_plots(plots, dir, out.files);
  write_file_atomically(dir / "report.md", md);
  write_file_atomically(dir / "report.html", markdown_to_html(md, dir, "halfback study"));
  out.files.push_back("report.md");
  out.files.push_back("report.html");
  out.markdown = md;
  return out;
}

}  // namespace halfback::study
