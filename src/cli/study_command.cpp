// `halfback study`: the quantitative comparison of the parameterizations on a set of BRDFs
// (include/halfback/study/metrics.hpp, docs/study.md). Writes CSV files and a Markdown report.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <future>
#include <iterator>
#include <string>
#include <vector>

#include "command.hpp"
#include "halfback/brdf/load.hpp"
#include "halfback/figure/chart.hpp"
#include "halfback/figure/render.hpp"
#include "halfback/study/metrics.hpp"

namespace halfback::cli {

namespace {

struct StudyOptions {
  std::vector<std::string> specs;
  std::string out = "study";
  std::string space = "log";
  bool quick = false;
};

const std::vector<int> kRanks{1, 2, 4, 8};

// The BRDFs of the specs: files, every BRDF file of a directory (by content), or models.
std::vector<std::pair<std::string, BrdfPtr>> load_all(const std::vector<std::string>& specs) {
  std::vector<std::pair<std::string, BrdfPtr>> brdfs;
  for (const std::string& spec : specs) {
    std::error_code ec;
    if (std::filesystem::is_directory(spec, ec)) {
      const auto files = brdf_files_in(spec);
      if (files.empty())
        throw UsageError(fmt::format("'{}': no MERL, RGL or ALTA file in this directory", spec));
      for (const auto& f : files) brdfs.emplace_back(f.string(), load_brdf(f.string()));
    } else {
      brdfs.emplace_back(spec, load_brdf(spec));
    }
  }
  return brdfs;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

int run_study(const StudyOptions& o) {
  if (o.specs.empty()) throw UsageError("no BRDF given (files, directories or model specs)");
  study::ErrorSpace es;
  if (o.space == "linear")
    es = study::ErrorSpace::linear;
  else if (o.space == "log")
    es = study::ErrorSpace::log;
  else if (o.space == "cbrt")
    es = study::ErrorSpace::cbrt;
  else
    throw UsageError(fmt::format("--space '{}': expected linear, log or cbrt", o.space));
  const auto brdfs = load_all(o.specs);
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  if (ec || !std::filesystem::is_directory(o.out))
    throw std::runtime_error(fmt::format("cannot create the output directory '{}': {}", o.out,
                                         ec ? ec.message() : "a file of that name exists"));
  const study::IsoGrid grid = o.quick ? study::IsoGrid{24, 24, 32} : study::IsoGrid{64, 64, 64};
  const Space params[] = {Space::halfdiff, Space::ortho, Space::hybrid, Space::spherical};

  std::string azimuthal = "brdf,parameterization,error\n";
  std::string separability = "brdf,parameterization,rank,error\n";
  std::string report = fmt::format(
      "# halfback study\n\n"
      "Measure: cos θi cos θo dωi dωo, through each parameterization's Jacobian. Values: "
      "luminance of ρ in the {} error space. Grid: {} × {} × {} cells of each isotropic form "
      "(midpoint rule). Metrics: docs/study.md.\n\n"
      "## Azimuthal dependence (relative error of dropping the relative azimuth)\n\n"
      "| BRDF | halfdiff | ortho | hybrid | spherical |\n|---|---|---|---|---|\n",
      study::name_of(es), grid.a, grid.b, grid.phi);
  std::string sep_table =
      "\n## Separability of the 2D projection (relative error of the best rank-r "
      "approximation, r = 1, 2, 4, 8)\n\n| BRDF | halfdiff | ortho | hybrid | spherical |\n"
      "|---|---|---|---|---|\n";
  figure::BarChart az_chart, sep_chart;
  for (Space s : params) {
    az_chart.series.emplace_back(name_of(s));
    sep_chart.series.emplace_back(name_of(s));
  }
  az_chart.title = fmt::format("Azimuthal dependence ({} error space)", study::name_of(es));
  az_chart.x_label = "relative error of dropping the relative azimuth";
  sep_chart.title =
      fmt::format("Separability of the 2D projection, rank 1 ({} error space)", study::name_of(es));
  sep_chart.x_label = "relative error of the best rank-1 approximation";
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < brdfs.size(); ++k) {
    const auto& [spec, brdf] = brdfs[k];
    // Files by their BRDF's name (merl:..., rgl:...), models by their spec, which holds their
    // parameters (two GGX of different roughness are both named "ggx").
    std::error_code ec;
    const std::string label = std::filesystem::exists(spec, ec) ? brdf->name() : spec;
    fmt::print(stderr, "halfback study: [{}/{}] {}\n", k + 1, brdfs.size(), label);
    if (!brdf->isotropic())
      warn("study", label + " is anisotropic: the isotropic metrics see its canonical pose");
    std::string az_row = "| " + label + " |", sep_row = az_row;
    az_chart.rows.push_back(label);
    sep_chart.rows.push_back(label);
    az_chart.values.emplace_back();
    sep_chart.values.emplace_back();
    // The parameterizations are independent: one task each (the low-rank fits are serial).
    struct Result {
      double azimuthal;
      std::vector<double> r2, r3;
    };
    std::vector<std::future<Result>> tasks;
    for (Space s : params)
      tasks.push_back(std::async(std::launch::async, [&, s] {
        const study::IsoSamples x = study::sample_isotropic(*brdf, s, grid, es);
        return Result{study::azimuthal_error(x), study::separability_2d(x, kRanks),
                      study::separability_unfolded(x, kRanks)};
      }));
    for (std::size_t pi = 0; pi < std::size(params); ++pi) {
      const Space s = params[pi];
      const Result res = tasks[pi].get();
      const double e = res.azimuthal;
      const auto& r2 = res.r2;
      const auto& r3 = res.r3;
      azimuthal += fmt::format("{},{},{:.6g}\n", csv_field(label), name_of(s), e);
      for (std::size_t i = 0; i < kRanks.size(); ++i) {
        separability += fmt::format("{},{},{},{:.6g}\n", csv_field(label),
                                    std::string(name_of(s)) + "-2d", kRanks[i], r2[i]);
        separability += fmt::format("{},{},{},{:.6g}\n", csv_field(label),
                                    std::string(name_of(s)) + "-3d", kRanks[i], r3[i]);
      }
      az_chart.values.back().push_back(e);
      sep_chart.values.back().push_back(r2[0]);
      az_row += fmt::format(" {:.4f} |", e);
      sep_row += fmt::format(" {:.3f} / {:.3f} / {:.3f} / {:.3f} |", r2[0], r2[1], r2[2], r2[3]);
    }
    report += az_row + "\n";
    sep_table += sep_row + "\n";
  }
  report += sep_table;
  report += fmt::format(
      "\nIn separability.csv, `P-2d` is the 2D projection over (a, b) and `P-3d` the 3D table "
      "unfolded along its azimuth, (a, b) × φ.\n\n{} BRDFs in {:.1f} s.\n",
      brdfs.size(), std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  const std::filesystem::path dir(o.out);
  write_file_atomically(dir / "azimuthal.csv", azimuthal);
  write_file_atomically(dir / "separability.csv", separability);
  report +=
      "\n![Azimuthal dependence](azimuthal.png)\n\n![Separability, rank 1](separability.png)\n";
  for (const char* ext : {".png", ".svg"}) {
    figure::save(figure::bar_chart(az_chart), dir / (std::string("azimuthal") + ext));
    figure::save(figure::bar_chart(sep_chart), dir / (std::string("separability") + ext));
  }
  write_file_atomically(dir / "report.md", report);
  fmt::print(
      "{}\nwritten in {}: report.md, azimuthal.csv, separability.csv, "
      "azimuthal.{{png,svg}}, separability.{{png,svg}}\n",
      report, dir.string());
  return kExitOk;
}

}  // namespace

Command register_study(CLI::App& parent) {
  auto o = std::make_shared<StudyOptions>();
  CLI::App* app = parent.add_subcommand(
      "study",
      "Compare the parameterizations on BRDFs: azimuthal dependence and separability (CSV and "
      "a Markdown report)");
  app->add_option("specs", o->specs, "BRDFs: files, directories of files, or model specs")
      ->required();
  app->add_option("-o,--out", o->out, "Output directory (created if missing)")
      ->capture_default_str();
  app->add_option("--space", o->space, "Error space: linear, log (log(1 + Y)) or cbrt (Y^(1/3))")
      ->capture_default_str();
  app->add_flag("--quick", o->quick, "A coarse grid (24 x 24 x 32 instead of 64^3)");
  app->footer(
      "Metrics (docs/study.md), under the measure cos(theta_i) cos(theta_o) dwi dwo:\n"
      "  azimuthal.csv     brdf,parameterization,error: the error of dropping the relative\n"
      "                    azimuth (the BRDF replaced by its average over it)\n"
      "  separability.csv  brdf,parameterization,rank,error: best rank-r approximations of the\n"
      "                    2D projection (P-2d) and of the 3D table unfolded along the azimuth\n"
      "                    (P-3d), r = 1, 2, 4, 8\n"
      "Example:\n"
      "  halfback study --out study ggx:alpha=0.2 ../shared/data/rgl");
  return {app, [o] { return run_study(*o); }};
}

}  // namespace halfback::cli
