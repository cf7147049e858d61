// The files of `halfback study` (docs/study.md, "Output"): one CSV per metric, plots (PNG and
// SVG), report.md and report.html (the same report with the plots embedded).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/study/metric_tables.hpp"
#include "halfback/study/study.hpp"

namespace halfback::study {

struct StudyOutput {
  std::string markdown;            // report.md
  std::vector<std::string> files;  // the names written in the directory
};

// Writes the study of `results` into `dir` (which must exist); its columns are the
// parameterizations of the results. Every file is written to a temporary file and renamed into
// place. Throws std::invalid_argument when the BRDFs were studied with different
// parameterizations, std::runtime_error naming a file that cannot be written.
StudyOutput write_study(const std::filesystem::path& dir, const std::vector<BrdfResult>& results,
                        const StudyConfig& config, double seconds);

// The subset of Markdown that the report uses — ATX headings, paragraphs, "* " lists, pipe
// tables, `code`, **bold** and images on a line of their own — as a standalone HTML page. Images
// are embedded as base64 data: URIs of the PNG files read from `image_dir`; one that
// cannot be read is left as a link. Everything else is escaped.
std::string markdown_to_html(std::string_view markdown, const std::filesystem::path& image_dir,
                             std::string_view title);

}  // namespace halfback::study
