#include "halfback/study/report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <sstream>

#include "halfback/figure/chart.hpp"
#include "halfback/figure/material.hpp"
#include "halfback/figure/plot.hpp"
#include "halfback/figure/render.hpp"
#include "halfback/util/atomic_file.hpp"
#include "halfback/util/csv.hpp"
#include "halfback/util/text_encoding.hpp"

namespace halfback::study {

namespace {

std::string md_cell(const std::string& s) {
  std::string out;
  for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

std::string table_header(const std::string& first) {
  std::string h = "| " + first + " |", rule = "|---|";
  for (Space s : kStudied) {
    h += fmt::format(" {} |", name_of(s));
    rule += "---|";
  }
  return h + "\n" + rule + "\n";
}

// The parameterization with the lowest value in each row, counted over the rows.
struct Wins {
  std::array<int, kStudied.size()> count{};
  // Ties (within 10^-9 relative) count for each of the tied parameterizations.
  void add(const std::array<double, kStudied.size()>& v) {
    const double best = *std::min_element(v.begin(), v.end());
    if (!std::isfinite(best)) return;
    for (std::size_t i = 0; i < v.size(); ++i)
      if (v[i] <= best + 1e-9 * std::abs(best) + 1e-15) ++count[i];
  }
  std::string text() const {
    std::string s;
    for (std::size_t i = 0; i < kStudied.size(); ++i)
      s += fmt::format("{}{} {}", i ? ", " : "", name_of(kStudied[i]), count[i]);
    return s;
  }
};

// Without a spacing: the own one (the tables of section 3 are those of the own design).
const GonioPoint* find_point(const std::vector<GonioPoint>& pts, Design d, std::size_t budget,
                             Spacing spacing = Spacing::own) {
  for (const GonioPoint& p : pts)
    if (p.spacing == spacing && p.design == d && p.budget == budget) return &p;
  return nullptr;
}

// " regular / stratified |": the two designs' errors at a budget ("–" where not measured).
std::string design_cells(const std::vector<GonioPoint>& pts, std::size_t budget) {
  std::string cell;
  for (Design d : kDesigns) {
    const GonioPoint* p = find_point(pts, d, budget);
    cell += (cell.empty() ? " " : " / ") + (p ? fmt::format("{:.4f}", p->error) : "–");
  }
  return cell + " |";
}

std::pair<std::vector<double>, std::vector<double>> curve(const std::vector<GonioPoint>& pts,
                                                          Design d,
                                                          Spacing spacing = Spacing::own) {
  std::vector<double> n, e;
  for (const GonioPoint& p : pts)
    if (p.spacing == spacing && p.design == d) {
      n.push_back(double(p.samples));
      e.push_back(p.error);
    }
  return {n, e};
}

std::string samples_text(double n, double smallest) {
  if (n == 0) return fmt::format("≤ {:.0f}", smallest);
  if (std::isinf(n)) return "not reached";
  return fmt::format("{:.3g}", n);
}

// The gonio curves as small multiples: one panel per BRDF, a colour per parameterization, the
// regular design solid and the stratified one dashed.
figure::Scene gonio_chart(const std::vector<BrdfResult>& results, bool four_d,
                          const StudyConfig& config) {
  figure::LogLogChart c;
  c.title = fmt::format("Virtual gonio-reflectometer{}: relative error ({} space) against samples",
                        four_d ? " (4D, full form)" : "", name_of(config.space));
  c.x_label = "measurements";
  c.y_label = "relative error";
  for (const BrdfResult& b : results) {
    if (four_d && b.isotropic) continue;
    figure::LogLogPanel panel{b.label, {}};
    for (std::size_t i = 0; i < b.params.size(); ++i)
      for (Design d : kDesigns) {
        auto [n, e] = curve(four_d ? b.params[i].gonio_4d : b.params[i].gonio, d);
        bool positive = !n.empty(), exact = true;
        for (double v : e) {
          positive &= v > 0 && std::isfinite(v);
          exact &= v < 1e-12;
        }
        if (!positive || exact) continue;  // an exact reconstruction has no place on a log axis
        panel.series.push_back({fmt::format("{} {}", name_of(b.params[i].space), name_of(d)),
                                int(i), d == Design::stratified, n, e});
      }
    if (!panel.series.empty()) c.panels.push_back(std::move(panel));
  }
  if (c.panels.empty()) return {};
  c.columns = int(std::min<std::size_t>(4, c.panels.size()));
  return figure::loglog_chart(c);
}

// The renderings of the BRDFs and of their regular-design reconstructions under the first
// environment, side by side (the same tone mapping for a row), for the eye.
figure::Scene examples_chart(const std::vector<BrdfResult>& results, const StudyConfig& config) {
  const double cell = 66, gap = 4, label_w = 250, top = 78;
  std::size_t rows = 0;
  for (const BrdfResult& b : results) rows += b.example_images.size() == kStudied.size() + 1;
  if (rows == 0 || config.environments.empty()) return {};
  figure::Scene sc;
  sc.title = "Renderings of the reconstructions";
  const std::string title = fmt::format(
      "The BRDF and its reconstructions from {} measurements (regular design), under {}",
      config.image_budget, config.environments.front().label);
  const std::string note = fmt::format(
      "{} environment samples per pixel, the same in every image: the noise is common to a row",
      config.image_spp);
  sc.width = figure::snap(std::max(label_w + double(kStudied.size() + 1) * (cell + gap) + 10,
                                   24 + 13 * 0.62 * double(title.size())));
  sc.height = figure::snap(top + 14 + double(rows) * (cell + gap) + 10);
  sc.text({12, 24}, figure::escape_markup(title), 13, figure::HAlign::left,
          figure::VAlign::baseline, figure::kBlack, 0, true);
  sc.text({12, 42}, figure::escape_markup(note), 9.5);
  const char* heads[] = {"BRDF", "halfdiff", "ortho", "hybrid", "spherical"};
  for (std::size_t k = 0; k < std::size(heads); ++k)
    sc.text({label_w + double(k) * (cell + gap) + cell / 2, top - 8}, heads[k], 9,
            figure::HAlign::centre);
  double y = top;
  for (const BrdfResult& b : results) {
    if (b.example_images.size() != kStudied.size() + 1) continue;
    sc.text({label_w - 8, y + cell / 2}, figure::escape_markup(b.label), 8.5, figure::HAlign::right,
            figure::VAlign::middle);
    for (std::size_t k = 0; k < b.example_images.size(); ++k)
      sc.add(
          figure::rendering_item(b.example_images[k], label_w + double(k) * (cell + gap), y, cell));
    y += cell + gap;
  }
  return sc;
}

void save_plot(const figure::Scene& sc, const std::filesystem::path& dir, const std::string& stem,
               std::vector<std::string>& files) {
  if (sc.items.empty()) return;
  for (const char* ext : {".png", ".svg"}) {
    figure::save(sc, dir / (stem + ext));
    files.push_back(stem + ext);
  }
}

// What the results hold beyond the isotropic metrics 1-2, which decides the optional sections,
// files and plots.
struct Contents {
  bool anisotropic = false, gonio = false, images = false;
};

Contents contents_of(const std::vector<BrdfResult>& results) {
  Contents has;
  for (const BrdfResult& b : results) {
    has.anisotropic |= !b.isotropic;
    for (const ParamResult& p : b.params) {
      has.gonio |= !p.gonio.empty() || !p.gonio_4d.empty();
      has.images |= !p.images.empty();
    }
  }
  return has;
}

// The CSV files' text: the columns of the issue first, then what tells rows apart (dims,
// budget, ...).
struct CsvTables {
  std::string azimuthal = "brdf,parameterization,error,dims\n";
  std::string separability = "brdf,parameterization,rank,error,dims\n";
  std::string gonio = "brdf,parameterization,design,samples,error,dims,budget,spacing\n";
  std::string budget = "brdf,parameterization,design,dims,target_error,samples,note,spacing\n";
  std::string image =
      "brdf,parameterization,design,samples,environment,relative_rmse,mean_delta_e2000,"
      "p95_delta_e2000,mae,rmse,ssim\n";
};

void add_separability_rows(std::string& csv, const std::string& brdf, std::string_view pn,
                           const std::vector<double>& errors, int dims,
                           const std::vector<int>& ranks) {
  for (std::size_t i = 0; i < errors.size() && i < ranks.size(); ++i)
    csv += fmt::format("{},{},{},{:.6g},{}\n", brdf, pn, ranks[i], errors[i], dims);
}

// The gonio points, and for each design the samples needed to reach each target error.
void add_gonio_rows(CsvTables& t, const std::string& brdf, std::string_view pn,
                    const std::vector<GonioPoint>& pts, int dims) {
  for (const GonioPoint& g : pts)
    t.gonio += fmt::format("{},{},{},{},{:.6g},{},{},{}\n", brdf, pn, name_of(g.design), g.samples,
                           g.error, dims, g.budget, name_of(g.spacing));
  for (Spacing spacing : kSpacings)
    for (Design d : kDesigns) {
      const auto [n, e] = curve(pts, d, spacing);
      if (n.empty()) continue;
      for (double target : kTargetErrors) {
        const double s = samples_to_reach(n, e, target);
        t.budget += fmt::format("{},{},{},{},{},{},{},{}\n", brdf, pn, name_of(d), dims, target,
                                s == 0 || std::isinf(s) ? std::string() : fmt::format("{:.0f}", s),
                                s == 0          ? "below_range"
                                : std::isinf(s) ? "not_reached"
                                                : "reached",
                                name_of(spacing));
      }
    }
}

CsvTables csv_tables(const std::vector<BrdfResult>& results, const StudyConfig& config) {
  CsvTables t;
  for (const BrdfResult& b : results) {
    const std::string brdf = csv_text_field(b.label);
    for (const ParamResult& p : b.params) {
      const std::string_view pn = name_of(p.space);
      t.azimuthal += fmt::format("{},{},{:.6g},3\n", brdf, pn, p.azimuthal);
      if (!b.isotropic) t.azimuthal += fmt::format("{},{},{:.6g},4\n", brdf, pn, p.azimuthal_4d);
      add_separability_rows(t.separability, brdf, pn, p.separability_2d, 2, config.ranks);
      add_separability_rows(t.separability, brdf, pn, p.separability_3d, 3, config.ranks);
      if (!b.isotropic)
        add_separability_rows(t.separability, brdf, pn, p.separability_4d, 4, config.ranks);
      add_gonio_rows(t, brdf, pn, p.gonio, 3);
      add_gonio_rows(t, brdf, pn, p.gonio_4d, 4);
      for (const ImagePoint& i : p.images)
        t.image +=
            fmt::format("{},{},{},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n", brdf, pn,
                        name_of(i.design), i.samples, csv_text_field(i.environment),
                        i.relative_rmse, i.mean_delta_e, i.p95_delta_e, i.mae, i.rmse, i.ssim);
    }
  }
  return t;
}

void write_csv_files(const std::filesystem::path& dir, const CsvTables& t, const Contents& has,
                     std::vector<std::string>& files) {
  auto csv = [&](const char* name, const std::string& text) {
    write_file_atomically(dir / name, text);
    files.push_back(name);
  };
  csv("azimuthal.csv", t.azimuthal);
  csv("separability.csv", t.separability);
  if (has.gonio) {
    csv("gonio.csv", t.gonio);
    csv("budget.csv", t.budget);
  }
  if (has.images) csv("image.csv", t.image);
}

// The mean image-space error of one parameterization's renderings of a design, over the
// environments (INFINITY when there is none).
struct MeanImageError {
  double relative_rmse = INFINITY, delta_e = INFINITY;
  int count = 0;
  double mae = INFINITY, rmse = INFINITY, ssim = 0;  // Sztrajman et al. 2021's protocol
};

MeanImageError mean_image_error(const std::vector<ImagePoint>& images, Design d) {
  double r = 0, e = 0, mae = 0, rmse = 0, ssim = 0;
  int n = 0;
  for (const ImagePoint& p : images)
    if (p.design == d) {
      r += p.relative_rmse;
      e += p.mean_delta_e;
      mae += p.mae;
      rmse += p.rmse;
      ssim += p.ssim;
      ++n;
    }
  if (n == 0) return {};
  return {r / n, e / n, n, mae / n, rmse / n, ssim / n};
}

bool has_images(const BrdfResult& b) {
  for (const ParamResult& p : b.params)
    if (!p.images.empty()) return true;
  return false;
}

figure::BarChart azimuthal_chart(const std::vector<BrdfResult>& results, const std::string& es) {
  figure::BarChart c;
  for (Space s : kStudied) c.series.emplace_back(name_of(s));
  c.title = fmt::format("Azimuthal dependence ({} error space)", es);
  c.x_label = "relative error of dropping the relative azimuth";
  for (const BrdfResult& b : results) {
    c.rows.push_back(b.label);
    c.values.emplace_back();
    for (const ParamResult& p : b.params) c.values.back().push_back(p.azimuthal);
  }
  return c;
}

figure::BarChart separability_chart(const std::vector<BrdfResult>& results, const std::string& es) {
  figure::BarChart c;
  for (Space s : kStudied) c.series.emplace_back(name_of(s));
  c.title = fmt::format("Separability of the 2D projection, rank 1 ({} error space)", es);
  c.x_label = "relative error of the best rank-1 approximation";
  for (const BrdfResult& b : results) {
    c.rows.push_back(b.label);
    c.values.emplace_back();
    for (const ParamResult& p : b.params)
      c.values.back().push_back(p.separability_2d.empty() ? 0.0 : p.separability_2d[0]);
  }
  return c;
}

// The regular design's relative RMSE of the BRDFs that were rendered (0 where not finite).
figure::BarChart image_chart(const std::vector<BrdfResult>& results, const StudyConfig& config) {
  figure::BarChart c;
  for (Space s : kStudied) c.series.emplace_back(name_of(s));
  c.title = fmt::format("Image-space error of the reconstructions from {} measurements",
                        config.image_budget);
  c.x_label = "relative RMSE of the sphere renderings (regular design, mean over maps)";
  for (const BrdfResult& b : results) {
    if (!has_images(b)) continue;
    c.rows.push_back(b.label);
    c.values.emplace_back();
    for (const ParamResult& p : b.params) {
      const MeanImageError m = mean_image_error(p.images, Design::regular);
      c.values.back().push_back(m.count && std::isfinite(m.relative_rmse) ? m.relative_rmse : 0.0);
    }
  }
  return c;
}

// The plots, in the order they are written. Some may have nothing to draw (every curve exact, no
// rendering): the report links only those that are written.
struct ReportPlots {
  figure::Scene summary, azimuthal, separability, gonio, gonio4d, designs, image, renderings;
};

figure::Scene designs_plot(const std::vector<BrdfResult>& results, const StudyConfig& config);

ReportPlots report_plots(const std::vector<BrdfResult>& results, const StudyConfig& config,
                         const Contents& has) {
  const std::string es(name_of(config.space));
  ReportPlots p;
  p.azimuthal = figure::bar_chart(azimuthal_chart(results, es));
  p.separability = figure::bar_chart(separability_chart(results, es));
  if (has.gonio) p.gonio = gonio_chart(results, false, config);
  if (has.gonio && has.anisotropic) p.gonio4d = gonio_chart(results, true, config);
  if (has.gonio) p.designs = designs_plot(results, config);
  if (has.images) {
    p.image = figure::bar_chart(image_chart(results, config));
    p.renderings = examples_chart(results, config);
  }
  return p;
}

void save_plots(const ReportPlots& p, const std::filesystem::path& dir,
                std::vector<std::string>& files) {
  save_plot(p.summary, dir, "summary", files);
  save_plot(p.azimuthal, dir, "azimuthal", files);
  save_plot(p.separability, dir, "separability", files);
  save_plot(p.gonio, dir, "gonio", files);
  save_plot(p.gonio4d, dir, "gonio4d", files);
  save_plot(p.designs, dir, "designs", files);
  save_plot(p.image, dir, "image", files);
  save_plot(p.renderings, dir, "renderings", files);
}

std::string plot_link(const figure::Scene& sc, const char* alt, const char* stem) {
  return sc.items.empty() ? std::string() : fmt::format("![{}]({}.png)\n\n", alt, stem);
}

std::string report_header(const std::vector<BrdfResult>& results, const StudyConfig& config,
                          bool any_aniso, double seconds) {
  return fmt::format(
      "# halfback study\n\n"
      "Measure: cos θi cos θo dωi dωo, through each parameterization's Jacobian. Values: the "
      "luminance of ρ in the **{}** error space. Metrics 1–2 on a {} × {} × {} grid of cell "
      "centres of each isotropic form (midpoint rule){}. Definitions: docs/study.md. {} BRDFs "
      "in {:.1f} s.\n\n",
      name_of(config.space), config.grid.a, config.grid.b, config.grid.phi,
      any_aniso ? fmt::format(", and {} × {} × {} × {} cells of the full form for the anisotropic "
                              "ones",
                              config.full_grid[0], config.full_grid[1], config.full_grid[2],
                              config.full_grid[3])
                : "",
      results.size(), seconds);
}

// 1. Azimuthal dependence.
std::string azimuthal_section(const std::vector<BrdfResult>& results, bool any_aniso) {
  std::string md =
      "## 1. Azimuthal dependence\n\nThe relative error of replacing the BRDF by its mean over "
      "the relative azimuth of each parameterization (lower: the BRDF is more nearly 2D "
      "there).\n\n" +
      table_header("BRDF");
  Wins wins;
  for (const BrdfResult& b : results) {
    md += "| " + md_cell(b.label) + " |";
    std::array<double, kStudied.size()> v{};
    for (std::size_t i = 0; i < b.params.size(); ++i) {
      v[i] = b.params[i].azimuthal;
      md += fmt::format(" {:.4f} |", v[i]);
    }
    wins.add(v);
    md += "\n";
  }
  md += fmt::format(
      "\nLowest error (BRDFs; ties count for each): {}.\n\n![Azimuthal "
      "dependence](azimuthal.png)\n\n",
      wins.text());
  if (!any_aniso) return md;
  md +=
      "Anisotropic BRDFs, 4D: the error of dropping the second azimuth (φd, φk or φo) at "
      "fixed (a, φa, b).\n\n" +
      table_header("BRDF");
  for (const BrdfResult& b : results) {
    if (b.isotropic) continue;
    md += "| " + md_cell(b.label) + " |";
    for (const ParamResult& p : b.params) md += fmt::format(" {:.4f} |", p.azimuthal_4d);
    md += "\n";
  }
  return md + "\n";
}

// One table of separability errors ("r1 / r2 / ..." per cell), and which parameterization has
// the lowest rank-1 error.
std::string separability_table(const std::vector<BrdfResult>& results, const StudyConfig& config,
                               const char* heading, std::vector<double> ParamResult::*member,
                               bool aniso_only) {
  std::string t = std::string(heading) + "\n\n" + table_header("BRDF");
  Wins w;
  for (const BrdfResult& b : results) {
    if (aniso_only && b.isotropic) continue;
    t += "| " + md_cell(b.label) + " |";
    std::array<double, kStudied.size()> first{};
    for (std::size_t i = 0; i < b.params.size(); ++i) {
      const std::vector<double>& v = b.params[i].*member;
      std::string cell;
      for (std::size_t k = 0; k < v.size(); ++k)
        cell += fmt::format("{}{:.3f}", k ? " / " : "", v[k]);
      t += " " + cell + " |";
      first[i] = v.empty() ? INFINITY : v[0];
    }
    w.add(first);
    t += "\n";
  }
  return t + fmt::format("\nLowest rank-{} error (BRDFs): {}.\n\n",
                         config.ranks.empty() ? 0 : config.ranks[0], w.text());
}

// 2. Separability.
std::string separability_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                                 bool any_aniso) {
  std::string ranks;
  for (std::size_t i = 0; i < config.ranks.size(); ++i)
    ranks += fmt::format("{}{}", i ? ", " : "", config.ranks[i]);
  std::string md = fmt::format(
      "## 2. Separability\n\nRelative errors of the best rank-r approximations, "
      "r = {}.\n\n",
      ranks);
  md += separability_table(results, config, "2D projection ρ̄(a, b):", &ParamResult::separability_2d,
                           false);
  md += "![Separability, rank 1](separability.png)\n\n";
  md += separability_table(results, config, "3D table unfolded along its azimuth, (a, b) × φ:",
                           &ParamResult::separability_3d, false);
  if (any_aniso)
    md += separability_table(results, config,
                             "Anisotropic BRDFs, 4D table unfolded as (a, φa) × (b, φb):",
                             &ParamResult::separability_4d, true);
  return md;
}

// The errors of both designs at one budget, and which parameterization is best (regular design).
std::string gonio_budget_table(const std::vector<BrdfResult>& results, std::size_t budget) {
  std::string md =
      fmt::format("Budget {} (regular / stratified):\n\n", budget) + table_header("BRDF");
  Wins w;
  for (const BrdfResult& b : results) {
    md += "| " + md_cell(b.label) + " |";
    std::array<double, kStudied.size()> v{};
    for (std::size_t i = 0; i < b.params.size(); ++i) {
      md += design_cells(b.params[i].gonio, budget);
      const GonioPoint* r = find_point(b.params[i].gonio, Design::regular, budget);
      v[i] = r ? r->error : INFINITY;
    }
    w.add(v);
    md += "\n";
  }
  return md + fmt::format("\nLowest error, regular design (BRDFs): {}.\n\n", w.text());
}

// The samples each design needs to reach `target`, interpolated between the budgets.
std::string samples_to_target_table(const std::vector<BrdfResult>& results, double target) {
  std::string md = fmt::format(
                       "Measurements needed to reach a relative error of {} (regular / "
                       "stratified; interpolated log-log between budgets):\n\n",
                       target) +
                   table_header("BRDF");
  for (const BrdfResult& b : results) {
    md += "| " + md_cell(b.label) + " |";
    for (const ParamResult& p : b.params) {
      std::string cell;
      for (Design d : kDesigns) {
        const auto [n, e] = curve(p.gonio, d);
        cell += (cell.empty() ? "" : " / ") +
                (n.empty() ? std::string("–")
                           : samples_text(samples_to_reach(n, e, target), n.front()));
      }
      md += " " + cell + " |";
    }
    md += "\n";
  }
  return md;
}

// The reference budget of the matching table: the image budget when it is one of the budgets,
// else the middle one.
std::size_t reference_budget(const StudyConfig& config) {
  return std::find(config.budgets.begin(), config.budgets.end(), config.image_budget) !=
                 config.budgets.end()
             ? config.image_budget
             : config.budgets[config.budgets.size() / 2];
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// The lowest regular-design error at budget `ref` over the parameterizations, with its samples
// (INFINITY when not measured).
std::pair<double, double> best_regular_error(const BrdfResult& b, std::size_t ref) {
  double best = INFINITY, best_samples = 0;
  for (const ParamResult& p : b.params)
    if (const GonioPoint* g = find_point(p.gonio, Design::regular, ref); g && g->error < best) {
      best = g->error;
      best_samples = double(g->samples);
    }
  return {best, best_samples};
}

// The budget each parameterization needs to match the best one at a reference budget, its
// median over the BRDFs, and the BRDFs left out because some parameterization is exact.
std::string matching_budget_table(const std::vector<BrdfResult>& results, std::size_t ref) {
  std::string md =
      fmt::format(
          "\nMeasurements each parameterization needs to reach E*, the lowest error of the "
          "regular design at N = {} (as a multiple of the best one's samples; log-log "
          "interpolation; “> ×k” when even the largest budget does not reach E*):\n\n",
          ref) +
      table_header("BRDF (E*)");
  std::array<std::vector<double>, kStudied.size()> ratios;
  std::string exact;
  for (const BrdfResult& b : results) {
    const auto [best, best_samples] = best_regular_error(b, ref);
    if (!std::isfinite(best)) continue;  // not measured
    if (best <= 1e-12) {                 // reconstructed exactly by some parameterization
      exact += (exact.empty() ? "" : ", ") + b.label;
      continue;
    }
    md += fmt::format("| {} ({:.3g}) |", md_cell(b.label), best);
    for (std::size_t i = 0; i < b.params.size(); ++i) {
      const auto [n, e] = curve(b.params[i].gonio, Design::regular);
      const double need = samples_to_reach(n, e, best * (1 + 1e-9));
      const double ratio = need == 0 ? n.front() / best_samples : need / best_samples;
      ratios[i].push_back(ratio);
      md += std::isinf(ratio) ? fmt::format(" > ×{:.3g} |", n.back() / best_samples)
                              : fmt::format(" ×{:.2f} |", ratio);
    }
    md += "\n";
  }
  std::string medians;
  for (std::size_t i = 0; i < kStudied.size(); ++i)
    if (!ratios[i].empty())
      medians += fmt::format("{}{} ×{:.3g}", medians.empty() ? "" : ", ", name_of(kStudied[i]),
                             median(ratios[i]));
  if (!medians.empty()) md += "\nMedian over the BRDFs: " + medians + ".\n";
  if (!exact.empty())
    md += "\nLeft out, reconstructed exactly (E* = 0) by at least one parameterization: " + exact +
          ".\n";
  return md;
}

// The anisotropic BRDFs' 4D gonio-reflectometer, one row per BRDF and 4D budget.
std::string gonio_4d_table(const std::vector<BrdfResult>& results, const StudyConfig& config) {
  std::string md = "Anisotropic BRDFs, 4D (measured in the full form; regular / stratified):\n\n";
  md += "| BRDF | budget |";
  for (Space s : kStudied) md += fmt::format(" {} |", name_of(s));
  md += "\n|---|---|---|---|---|---|\n";
  for (const BrdfResult& b : results) {
    if (b.isotropic) continue;
    for (std::size_t budget : config.budgets_4d) {
      md += "| " + md_cell(b.label) + fmt::format(" | {} |", budget);
      for (const ParamResult& p : b.params) md += design_cells(p.gonio_4d, budget);
      md += "\n";
    }
  }
  return md;
}

// Section 3b. A design: a spacing in a layout (the own spacing in both layouts, the others in
// the regular one; study.hpp).
struct DesignKey {
  Spacing spacing = Spacing::own;
  Design layout = Design::regular;
};

std::string design_name(const DesignKey& k) {
  return k.spacing == Spacing::own ? fmt::format("own {}", name_of(k.layout))
                                   : std::string(name_of(k.spacing));
}

// The designs measured at budget `ref` for some isotropic BRDF, in the order of kSpacings.
std::vector<DesignKey> designs_measured(const std::vector<BrdfResult>& results, std::size_t ref) {
  std::vector<DesignKey> keys;
  for (Spacing spacing : kSpacings)
    for (Design d : kDesigns) {
      bool any = false;
      for (const BrdfResult& b : results)
        for (const ParamResult& p : b.params)
          any |= find_point(p.gonio, d, ref, spacing) != nullptr;
      if (any) keys.push_back({spacing, d});
    }
  return keys;
}

double design_error(const ParamResult& p, const DesignKey& k, std::size_t ref) {
  const GonioPoint* g = find_point(p.gonio, k.layout, ref, k.spacing);
  return g ? g->error : INFINITY;
}

// The BRDFs measured in every design by every parameterization at `ref` (compared like with
// like), each parameterization's median error per design over them, and its best design.
struct DesignComparison {
  std::vector<DesignKey> keys;
  std::vector<const BrdfResult*> brdfs;
  std::string exact;  // BRDFs left out: some design reconstructs them exactly (no winner)
  std::array<std::vector<double>, kStudied.size()> median;  // per design
  std::array<std::size_t, kStudied.size()> best{};          // index into keys
};

DesignComparison compare_designs(const std::vector<BrdfResult>& results, std::size_t ref) {
  DesignComparison c;
  c.keys = designs_measured(results, ref);
  for (const BrdfResult& b : results) {
    bool complete = b.params.size() == kStudied.size();
    double lowest = INFINITY;
    for (const ParamResult& p : b.params)
      for (const DesignKey& k : c.keys) {
        complete &= std::isfinite(design_error(p, k, ref));
        lowest = std::min(lowest, design_error(p, k, ref));
      }
    if (complete && lowest <= 1e-12) c.exact += (c.exact.empty() ? "" : ", ") + b.label;
    if (complete && lowest > 1e-12) c.brdfs.push_back(&b);
  }
  for (std::size_t i = 0; i < kStudied.size() && !c.brdfs.empty(); ++i) {
    for (const DesignKey& k : c.keys) {
      std::vector<double> e;
      for (const BrdfResult* b : c.brdfs) e.push_back(design_error(b->params[i], k, ref));
      c.median[i].push_back(median(e));
    }
    c.best[i] =
        std::size_t(std::min_element(c.median[i].begin(), c.median[i].end()) - c.median[i].begin());
  }
  return c;
}

figure::Scene designs_chart(const DesignComparison& c, std::size_t ref, ErrorSpace es) {
  if (c.brdfs.empty() || c.keys.size() < 2) return {};
  figure::BarChart chart;
  chart.title =
      fmt::format("Designs: median relative error ({} space) at N = {}", name_of(es), ref);
  chart.x_label =
      fmt::format("median over {} BRDFs of the reconstruction's relative error", c.brdfs.size());
  for (const DesignKey& k : c.keys) chart.series.push_back(design_name(k));
  for (std::size_t i = 0; i < kStudied.size(); ++i) {
    chart.rows.emplace_back(name_of(kStudied[i]));
    chart.values.push_back(c.median[i]);
  }
  figure::BarChartLayout layout;
  layout.label_width = 110;  // the rows are parameterization names
  return figure::bar_chart(chart, layout);
}

figure::Scene designs_plot(const std::vector<BrdfResult>& results, const StudyConfig& config) {
  const std::size_t ref = reference_budget(config);
  return designs_chart(compare_designs(results, ref), ref, config.space);
}

// Which parameterization has the lowest error for each BRDF, with each parameterization in
// `design[i]` (an index into c.keys).
std::vector<std::size_t> winners(const DesignComparison& c, std::size_t ref,
                                 const std::array<std::size_t, kStudied.size()>& design) {
  std::vector<std::size_t> w;
  for (const BrdfResult* b : c.brdfs) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < kStudied.size(); ++i)
      if (design_error(b->params[i], c.keys[design[i]], ref) <
          design_error(b->params[best], c.keys[design[best]], ref))
        best = i;
    w.push_back(best);
  }
  return w;
}

std::string win_counts(const std::vector<std::size_t>& w) {
  std::array<int, kStudied.size()> n{};
  for (std::size_t i : w) ++n[i];
  std::string s;
  for (std::size_t i = 0; i < kStudied.size(); ++i)
    s += fmt::format("{}{} {}", i ? ", " : "", name_of(kStudied[i]), n[i]);
  return s;
}

std::size_t most_wins(const std::vector<std::size_t>& w) {
  std::array<int, kStudied.size()> n{};
  for (std::size_t i : w) ++n[i];
  return std::size_t(std::max_element(n.begin(), n.end()) - n.begin());
}

// The table of each parameterization's median error per design, with its best design.
std::string design_median_table(const DesignComparison& c) {
  std::string md = "| parameterization |", rule = "|---|";
  for (const DesignKey& k : c.keys) {
    md += " " + design_name(k) + " |";
    rule += "---|";
  }
  md += " best |\n" + rule + "---|\n";
  for (std::size_t i = 0; i < kStudied.size(); ++i) {
    md += fmt::format("| {} |", name_of(kStudied[i]));
    for (std::size_t k = 0; k < c.keys.size(); ++k)
      md += k == c.best[i] ? fmt::format(" **{:.4f}** |", c.median[i][k])
                           : fmt::format(" {:.4f} |", c.median[i][k]);
    md += " " + design_name(c.keys[c.best[i]]) + " |\n";
  }
  return md;
}

// What changes between the comparison in the own regular design and best against best.
// The index in c.keys of a design, or c.keys.size() when it was not measured.
std::size_t key_index(const DesignComparison& c, Spacing spacing, Design layout) {
  for (std::size_t k = 0; k < c.keys.size(); ++k)
    if (c.keys[k].spacing == spacing && c.keys[k].layout == layout) return k;
  return c.keys.size();
}

// The paper's question in one line per parameterization whose angle design differs from its own
// (ortho, hybrid): the same iso-surfaces with halfdiff's spacing of the magnitudes.
std::string angle_line(const DesignComparison& c) {
  const std::size_t own = key_index(c, Spacing::own, Design::regular);
  const std::size_t angle = key_index(c, Spacing::angle, Design::regular);
  if (own == c.keys.size() || angle == c.keys.size()) return {};
  std::string md;
  for (std::size_t i = 0; i < kStudied.size(); ++i)
    if (!same_as_own(kStudied[i], true, Spacing::angle))
      md += fmt::format("{}{} {:.4f} → {:.4f} (×{:.2f})", md.empty() ? "" : "; ",
                        name_of(kStudied[i]), c.median[i][own], c.median[i][angle],
                        c.median[i][angle] / c.median[i][own]);
  return md.empty() ? md
                    : "Uniform in angle instead of their own coordinates (median error, own "
                      "regular → angle): " +
                          md + ".\n\n";
}

// What changes between the comparison in the own regular design and best against best.
std::string design_conclusions(const DesignComparison& c, std::size_t ref) {
  const std::vector<std::size_t> after = winners(c, ref, c.best);
  const std::size_t own_key = key_index(c, Spacing::own, Design::regular);
  if (own_key == c.keys.size())  // nothing to compare with
    return fmt::format("\nLowest error, best against best (BRDFs): {}.\n\n", win_counts(after));
  std::array<std::size_t, kStudied.size()> own{};
  own.fill(own_key);
  const std::vector<std::size_t> before = winners(c, ref, own);
  std::string changed;
  int n_changed = 0;
  for (std::size_t j = 0; j < c.brdfs.size(); ++j)
    if (before[j] != after[j]) {
      changed += fmt::format("{}{} ({} → {})", changed.empty() ? "" : ", ", c.brdfs[j]->label,
                             name_of(kStudied[before[j]]), name_of(kStudied[after[j]]));
      ++n_changed;
    }
  const std::size_t top_before = most_wins(before), top_after = most_wins(after);
  std::string md = fmt::format(
      "\nLowest error, each parameterization in the own regular design (BRDFs): {}.\n"
      "Lowest error, best against best (each in its best design above): {}.\n\n",
      win_counts(before), win_counts(after));
  md += top_before == top_after
            ? fmt::format("**The parameterization with the most wins does not change: {}.** ",
                          name_of(kStudied[top_after]))
            : fmt::format("**The parameterization with the most wins changes, from {} to {}.** ",
                          name_of(kStudied[top_before]), name_of(kStudied[top_after]));
  md += n_changed == 0 ? std::string("No BRDF changes its best parameterization.\n\n")
                       : fmt::format("{} of {} BRDFs change their best parameterization: {}.\n\n",
                                     n_changed, c.brdfs.size(), changed);
  return md + angle_line(c);
}

// 3b. Designs: the coordinates against the spacing of the samples.
std::string designs_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                            const ReportPlots& plots) {
  const std::size_t ref = reference_budget(config);
  const DesignComparison c = compare_designs(results, ref);
  if (c.keys.size() < 2 || c.brdfs.empty()) return {};
  std::string md = fmt::format(
      "## 3b. Designs: coordinates against spacing\n\nThe same gonio-reflectometer at N = {} in "
      "each design (docs/study.md, “Designs”): the cells uniform in the parameterization's own "
      "coordinates (regular or stratified), in angle (the sine-like magnitudes through their "
      "arcsine), in MERL's spacing (angle, and √ of the half-vector angle), or in warps learned "
      "from the other BRDFs (leave-one-out). Median relative error over the {} isotropic BRDFs "
      "measured in every design; the lowest of each parameterization in bold, its best "
      "design:\n\n",
      ref, c.brdfs.size());
  md += design_median_table(c);
  md += "\nBest against best, per BRDF (each parameterization in its best design):\n\n" +
        table_header("BRDF");
  for (const BrdfResult* b : c.brdfs) {
    md += "| " + md_cell(b->label) + " |";
    for (std::size_t i = 0; i < kStudied.size(); ++i)
      md += fmt::format(" {:.4f} |", design_error(b->params[i], c.keys[c.best[i]], ref));
    md += "\n";
  }
  md += design_conclusions(c, ref);
  if (!c.exact.empty())
    md += "Left out, reconstructed exactly by some design: " + c.exact + ".\n\n";
  return md + plot_link(plots.designs, "Designs", "designs");
}

// 3. Gonio-reflectometer.
std::string gonio_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                          bool any_aniso, const ReportPlots& plots) {
  std::string md = fmt::format(
      "## 3. Virtual gonio-reflectometer\n\nRelative error of the reconstruction from N "
      "measurements placed in each parameterization's isotropic form (regular grid / "
      "stratified random), against the BRDF at {} test pairs drawn from the measure.\n\n",
      config.test_pairs);
  for (std::size_t budget : config.budgets) md += gonio_budget_table(results, budget);
  md += samples_to_target_table(results, kTargetErrors[1]);
  md += matching_budget_table(results, reference_budget(config));
  md += "\n" + plot_link(plots.gonio, "Virtual gonio-reflectometer", "gonio");
  if (any_aniso)
    md += gonio_4d_table(results, config) + "\n" +
          plot_link(plots.gonio4d, "Virtual gonio-reflectometer, 4D", "gonio4d");
  return md;
}

// One rendered BRDF's rows of the image-space tables (regular, stratified): "rmse / ΔE" cells,
// and the values the lowest errors are counted on.
struct ImageRows {
  std::array<std::string, 2> text;
  std::array<std::array<double, kStudied.size()>, 2> rmse{}, delta_e{};
};

ImageRows image_rows(const BrdfResult& b) {
  ImageRows rows;
  for (std::string& t : rows.text) t = "| " + md_cell(b.label) + " |";
  for (std::size_t i = 0; i < b.params.size(); ++i)
    for (std::size_t d = 0; d < 2; ++d) {
      const MeanImageError m = mean_image_error(b.params[i].images, kDesigns[d]);
      rows.rmse[d][i] = m.relative_rmse;
      rows.delta_e[d][i] = m.delta_e;
      rows.text[d] +=
          m.count ? fmt::format(" {:.4f} / {:.2f} |", m.relative_rmse, m.delta_e) : " – |";
    }
  return rows;
}

// The image-space protocol of Sztrajman et al. 2021 on the same renderings (regular design).
std::string published_image_table(const std::vector<BrdfResult>& results) {
  std::string md =
      "The protocol of Sztrajman et al. 2021 on the same renderings (regular design, mean over "
      "the environments): MAE / RMSE / SSIM of the tone-mapped images (values in [0, 1]; SSIM "
      "of their luminance with the constants of Wang et al. 2004; docs/study.md):\n\n" +
      table_header("BRDF");
  Wins mae, ssim;
  for (const BrdfResult& b : results) {
    if (!has_images(b)) continue;
    md += "| " + md_cell(b.label) + " |";
    std::array<double, kStudied.size()> m{}, one_minus_ssim{};
    for (std::size_t i = 0; i < b.params.size(); ++i) {
      const MeanImageError e = mean_image_error(b.params[i].images, Design::regular);
      m[i] = e.mae;
      one_minus_ssim[i] = e.count ? 1 - e.ssim : INFINITY;
      md += e.count ? fmt::format(" {:.4f} / {:.4f} / {:.4f} |", e.mae, e.rmse, e.ssim) : " – |";
    }
    mae.add(m);
    ssim.add(one_minus_ssim);
    md += "\n";
  }
  return md +
         fmt::format("\nLowest MAE (BRDFs): {}; highest SSIM: {}.\n\n", mae.text(), ssim.text());
}

// 4. Image-space error.
std::string image_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                          const ReportPlots& plots) {
  std::string envs;
  for (std::size_t i = 0; i < config.environments.size(); ++i)
    envs += (i ? ", " : "") + config.environments[i].label;
  std::string md =
      fmt::format(
          "## 4. Image-space error\n\nThe reconstructions from {} measurements rendered on a "
          "sphere ({}², {} environment samples per pixel, the same for every image) under "
          "{}, against the rendering of the BRDF itself: relative RMSE / mean CIEDE2000 of "
          "the tone-mapped images, averaged over the environments; regular design, then "
          "stratified.\n\n",
          config.image_budget, config.image_size, config.image_spp, envs) +
      table_header("BRDF");
  std::array<Wins, 2> rmse_wins, de_wins;
  std::string strat_rows, no_images;
  for (const BrdfResult& b : results) {
    if (!has_images(b)) {  // no finite ground truth to compare with (an ALTA file's gaps)
      no_images += (no_images.empty() ? "" : ", ") + b.label;
      continue;
    }
    const ImageRows rows = image_rows(b);
    for (std::size_t d = 0; d < 2; ++d) {
      rmse_wins[d].add(rows.rmse[d]);
      de_wins[d].add(rows.delta_e[d]);
    }
    md += rows.text[0] + "\n";
    strat_rows += rows.text[1] + "\n";
  }
  md += fmt::format(
            "\nLowest relative RMSE (BRDFs): {}; lowest ΔE00: {}.\n\nStratified "
            "design:\n\n",
            rmse_wins[0].text(), de_wins[0].text()) +
        table_header("BRDF") + strat_rows +
        fmt::format(
            "\nLowest relative RMSE (BRDFs): {}; lowest ΔE00: {}.\n\n"
            "![Image-space error](image.png)\n\n",
            rmse_wins[1].text(), de_wins[1].text()) +
        plot_link(plots.renderings, "Renderings of the reconstructions", "renderings");
  md += published_image_table(results);
  if (!no_images.empty())
    md += "Not rendered (the BRDF has no value somewhere, so there is no ground-truth image): " +
          no_images + ".\n\n";
  return md;
}

// Measured files beside the neural BRDFs fitted to them: "rgl:NAME" or "merl:NAME" with
// "nbrdf:NAME" (the same material), as (file, network) indices into the results.
std::vector<std::pair<std::size_t, std::size_t>> file_network_pairs(
    const std::vector<BrdfResult>& results) {
  std::map<std::string, std::size_t> networks;
  for (std::size_t i = 0; i < results.size(); ++i)
    if (results[i].label.rfind("nbrdf:", 0) == 0) networks[results[i].label.substr(6)] = i;
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t i = 0; i < results.size(); ++i) {
    const std::string& l = results[i].label;
    for (const char* prefix : {"rgl:", "merl:"})
      if (l.rfind(prefix, 0) == 0)
        if (const auto it = networks.find(l.substr(std::string_view(prefix).size()));
            it != networks.end())
          pairs.emplace_back(i, it->second);
  }
  return pairs;
}

// The parameterization with the lowest value ("–" when none is finite).
std::string lowest_of(const std::array<double, kStudied.size()>& v) {
  std::size_t best = v.size();
  for (std::size_t i = 0; i < v.size(); ++i)
    if (std::isfinite(v[i]) && (best == v.size() || v[i] < v[best])) best = i;
  return best == v.size() ? "–" : std::string(name_of(kStudied[best]));
}

// Per metric, the values of the parameterizations for one BRDF (INFINITY where not measured).
std::array<std::array<double, kStudied.size()>, 4> metric_values(const BrdfResult& b,
                                                                 std::size_t ref) {
  std::array<std::array<double, kStudied.size()>, 4> v{};
  for (auto& row : v) row.fill(INFINITY);
  for (std::size_t i = 0; i < b.params.size() && i < kStudied.size(); ++i) {
    const ParamResult& p = b.params[i];
    v[0][i] = p.azimuthal;
    if (!p.separability_2d.empty()) v[1][i] = p.separability_2d[0];
    if (const GonioPoint* g = find_point(p.gonio, Design::regular, ref)) v[2][i] = g->error;
    v[3][i] = mean_image_error(p.images, Design::regular).relative_rmse;
  }
  return v;
}

// 5. The same materials as measured files and as their neural fits, side by side: does the
// network representation change which parameterization wins?
std::string files_and_networks_section(const std::vector<BrdfResult>& results,
                                       const StudyConfig& config) {
  const auto pairs = file_network_pairs(results);
  if (pairs.empty()) return {};
  const std::size_t ref = config.budgets.empty() ? 0 : reference_budget(config);
  const char* metrics[] = {"azimuthal", "separability", "gonio", "image"};
  std::string md = fmt::format(
      "## 5. Measured files and their neural BRDFs\n\nThe same materials as measured files and "
      "as the neural BRDFs fitted to them (Sztrajman et al. 2021): the parameterization with the "
      "lowest error under each metric (azimuthal dependence; rank-1 separability of the 2D "
      "projection; gonio-reflectometer error of the regular design at N = {}; image-space "
      "relative RMSE), file / network.\n\n| material | azimuthal | separability | gonio | "
      "image |\n|---|---|---|---|---|\n",
      ref);
  std::array<int, 4> agree{}, compared{};
  for (const auto& [f, n] : pairs) {
    const auto vf = metric_values(results[f], ref), vn = metric_values(results[n], ref);
    md += "| " + md_cell(results[n].label.substr(6)) + " |";
    for (std::size_t m = 0; m < 4; ++m) {
      const std::string a = lowest_of(vf[m]), b = lowest_of(vn[m]);
      md += fmt::format(" {} / {} |", a, b);
      if (a != "–" && b != "–") {
        ++compared[m];
        agree[m] += a == b;
      }
    }
    md += "\n";
  }
  md += "\nThe same winner for file and network: ";
  for (std::size_t m = 0; m < 4; ++m)
    md += fmt::format("{}{} {} of {}", m ? ", " : "", metrics[m], agree[m], compared[m]);
  md += ".\n\n";
  if (ref == 0) return md;
  md += fmt::format("Gonio-reflectometer error at N = {} (regular design), file then network:\n\n",
                    ref) +
        table_header("material");
  for (const auto& [f, n] : pairs)
    for (const std::size_t k : {f, n}) {
      md += "| " + md_cell(results[k].label) + " |";
      for (const ParamResult& p : results[k].params) {
        const GonioPoint* g = find_point(p.gonio, Design::regular, ref);
        md += g ? fmt::format(" {:.4f} |", g->error) : " – |";
      }
      md += "\n";
    }
  return md + "\n";
}

// ---------------------------------------------------------------------------------------------
// Summary: the metrics per kind of BRDF (neural, measured files, models), for whole databases
// whose per-BRDF tables are too long to read.
// ---------------------------------------------------------------------------------------------

// The kind of a BRDF, from its label: a file's label starts with its reader's prefix, a model's
// is its spec.
std::string kind_of(const std::string& label) {
  static constexpr std::pair<std::string_view, std::string_view> kKinds[] = {
      {"nbrdf:", "neural BRDFs"},
      {"merl:", "MERL files"},
      {"rgl:", "RGL files"},
      {"alta:", "ALTA files"}};
  for (const auto& [prefix, kind] : kKinds)
    if (label.starts_with(prefix)) return std::string(kind);
  return "models";
}

// One metric: its value for each BRDF (in the order of the results) and parameterization,
// INFINITY where it was not measured.
struct SummaryMetric {
  std::string name;
  std::string chart_row;  // the metric's rows in the summary plot ("own", "best"); empty: none
  std::vector<std::array<double, kStudied.size()>> values;
};

std::vector<SummaryMetric> summary_metrics(const std::vector<BrdfResult>& results,
                                           const StudyConfig& config, const Contents& has) {
  const std::size_t ref = has.gonio ? reference_budget(config) : 0;
  SummaryMetric azimuthal{"azimuthal dependence", "", {}},
      separability{"separability (rank 1, 2D projection)", "", {}},
      own{fmt::format("gonio-reflectometer, N = {}, own regular design", ref), "own", {}},
      image{"image-space relative RMSE (regular design)", "", {}};
  for (const BrdfResult& b : results) {
    const auto v = metric_values(b, ref);
    azimuthal.values.push_back(v[0]);
    separability.values.push_back(v[1]);
    own.values.push_back(v[2]);
    image.values.push_back(v[3]);
  }
  std::vector<SummaryMetric> m{std::move(azimuthal), std::move(separability)};
  if (has.gonio) m.push_back(std::move(own));
  const DesignComparison c = has.gonio ? compare_designs(results, ref) : DesignComparison{};
  if (c.keys.size() >= 2 && !c.brdfs.empty()) {
    SummaryMetric best{
        fmt::format("gonio-reflectometer, N = {}, each in its best design", ref), "best", {}};
    for (const BrdfResult& b : results) {
      best.values.emplace_back();
      best.values.back().fill(INFINITY);
      if (std::find(c.brdfs.begin(), c.brdfs.end(), &b) != c.brdfs.end())
        for (std::size_t i = 0; i < kStudied.size(); ++i)
          best.values.back()[i] = design_error(b.params[i], c.keys[c.best[i]], ref);
    }
    m.push_back(std::move(best));
  }
  if (has.images) m.push_back(std::move(image));
  return m;
}

// The kinds in the order they first appear, each with the indices of its BRDFs; "all" last when
// there is more than one kind.
std::vector<std::pair<std::string, std::vector<std::size_t>>> kinds_of(
    const std::vector<BrdfResult>& results) {
  std::vector<std::pair<std::string, std::vector<std::size_t>>> kinds;
  for (std::size_t j = 0; j < results.size(); ++j) {
    const std::string kind = kind_of(results[j].label);
    auto it =
        std::find_if(kinds.begin(), kinds.end(), [&](const auto& k) { return k.first == kind; });
    if (it == kinds.end()) it = kinds.insert(kinds.end(), {kind, {}});
    it->second.push_back(j);
  }
  if (kinds.size() > 1) {
    std::vector<std::size_t> all(results.size());
    for (std::size_t j = 0; j < all.size(); ++j) all[j] = j;
    kinds.emplace_back("all", std::move(all));
  }
  return kinds;
}

// Each parameterization's median over the BRDFs of `rows` measured in all four (NaN: none), and
// the number of those BRDFs.
std::pair<std::array<double, kStudied.size()>, std::size_t> medians(
    const SummaryMetric& m, const std::vector<std::size_t>& rows) {
  std::array<std::vector<double>, kStudied.size()> v;
  for (std::size_t j : rows) {
    const auto& x = m.values[j];
    if (std::all_of(x.begin(), x.end(), [](double e) { return std::isfinite(e); }))
      for (std::size_t i = 0; i < kStudied.size(); ++i) v[i].push_back(x[i]);
  }
  std::array<double, kStudied.size()> med;
  for (std::size_t i = 0; i < kStudied.size(); ++i) med[i] = v[i].empty() ? NAN : median(v[i]);
  return {med, v[0].size()};
}

std::string summary_table(
    const SummaryMetric& m,
    const std::vector<std::pair<std::string, std::vector<std::size_t>>>& kinds) {
  std::string md = "**" + m.name + "**\n\n| kind | BRDFs |", rule = "|---|---|";
  for (Space s : kStudied) {
    md += fmt::format(" {} |", name_of(s));
    rule += "---|";
  }
  md += "\n" + rule + "\n";
  for (const auto& [kind, rows] : kinds) {
    const auto [med, n] = medians(m, rows);
    if (n == 0) continue;
    Wins wins;
    for (std::size_t j : rows) wins.add(m.values[j]);
    const double lowest = *std::min_element(med.begin(), med.end());
    md += fmt::format("| {} | {} |", kind, n);
    for (std::size_t i = 0; i < kStudied.size(); ++i)
      md += med[i] == lowest ? fmt::format(" **{:.4f}** ({}) |", med[i], wins.count[i])
                             : fmt::format(" {:.4f} ({}) |", med[i], wins.count[i]);
    md += "\n";
  }
  return md + "\n";
}

// The gonio-reflectometer's median per kind, in the own regular design and in the best ones.
figure::Scene summary_plot(const std::vector<BrdfResult>& results,
                           const std::vector<SummaryMetric>& metrics, const StudyConfig& config,
                           const Contents& has) {
  if (!has.gonio) return {};
  figure::BarChart chart;
  chart.title = fmt::format("Gonio-reflectometer at N = {}: median relative error per kind",
                            reference_budget(config));
  chart.x_label = "median over the BRDFs of the kind (own regular design; each in its best design)";
  for (Space s : kStudied) chart.series.emplace_back(name_of(s));
  for (const auto& [kind, rows] : kinds_of(results))
    for (const SummaryMetric& m : metrics) {
      if (m.chart_row.empty()) continue;
      const auto [med, n] = medians(m, rows);
      if (n == 0) continue;
      chart.rows.push_back(fmt::format("{} ({}), {}", kind, n, m.chart_row));
      chart.values.emplace_back(med.begin(), med.end());
    }
  if (chart.rows.empty()) return {};
  figure::BarChartLayout layout;
  layout.label_width = 200;
  return figure::bar_chart(chart, layout);
}

// The summary section: per metric, each kind's median error and wins per parameterization.
std::string summary_section(const std::vector<BrdfResult>& results,
                            const std::vector<SummaryMetric>& metrics, const ReportPlots& plots) {
  const auto kinds = kinds_of(results);
  std::string md =
      "## Summary\n\nFor each kind of BRDF and each metric below: the median relative error of "
      "each parameterization over the BRDFs of that kind measured in all four, and in "
      "parentheses the number of BRDFs on which it has the lowest error (ties count for each). "
      "The lowest median is in bold. The kind comes from the label (the reader's prefix for a "
      "file; a model's spec is a model).\n\n";
  for (const SummaryMetric& m : metrics) md += summary_table(m, kinds);
  return md + plot_link(plots.summary, "Summary", "summary");
}

// The closing line: the CSV files written so far, then what always follows them.
std::string files_paragraph(const std::vector<std::string>& csv_files) {
  std::string md = "Files: ";
  for (std::size_t i = 0; i < csv_files.size(); ++i) md += (i ? ", " : "") + csv_files[i];
  return md +
         ", the plots as PNG and SVG, and report.html (this report with the plots embedded).\n";
}

}  // namespace

StudyOutput write_study(const std::filesystem::path& dir, const std::vector<BrdfResult>& results,
                        const StudyConfig& config, double seconds) {
  StudyOutput out;
  const Contents has = contents_of(results);
  write_csv_files(dir, csv_tables(results, config), has, out.files);

  const std::vector<SummaryMetric> summary = summary_metrics(results, config, has);
  ReportPlots plots = report_plots(results, config, has);
  plots.summary = summary_plot(results, summary, config, has);
  std::string md = report_header(results, config, has.anisotropic, seconds) +
                   summary_section(results, summary, plots) +
                   azimuthal_section(results, has.anisotropic) +
                   separability_section(results, config, has.anisotropic);
  if (has.gonio)
    md += gonio_section(results, config, has.anisotropic, plots) +
          designs_section(results, config, plots);
  if (has.images) md += image_section(results, config, plots);
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

namespace {

// `code` and **bold**, the rest escaped.
std::string inline_html(std::string_view s) {
  std::string out;
  bool code = false, bold = false;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '`') {
      out += code ? "</code>" : "<code>";
      code = !code;
    } else if (!code && s.substr(i, 2) == "**") {
      out += bold ? "</strong>" : "<strong>";
      bold = !bold;
      ++i;
    } else if (!code && s[i] == '\\' && i + 1 < s.size() && s[i + 1] == '|') {
      out += '|';
      ++i;
    } else {
      out += escape_xml(s.substr(i, 1));
    }
  }
  if (code) out += "</code>";
  if (bold) out += "</strong>";
  return out;
}

std::vector<std::string> table_cells(std::string_view line) {
  std::vector<std::string> cells;
  std::string cur;
  for (std::size_t i = 1; i < line.size(); ++i) {
    if (line[i] == '\\' && i + 1 < line.size() && line[i + 1] == '|') {
      cur += "\\|";
      ++i;
    } else if (line[i] == '|') {
      cells.push_back(cur);
      cur.clear();
    } else {
      cur += line[i];
    }
  }
  for (std::string& c : cells) {
    const auto a = c.find_first_not_of(' '), b = c.find_last_not_of(' ');
    c = a == std::string::npos ? "" : c.substr(a, b - a + 1);
  }
  return cells;
}

}  // namespace

std::string markdown_to_html(std::string_view markdown, const std::filesystem::path& image_dir,
                             std::string_view title) {
  std::vector<std::string> lines;
  {
    std::istringstream in{std::string(markdown)};
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  std::string html = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n"
      "<style>body{{font-family:sans-serif;max-width:72em;margin:2em auto;padding:0 1em;"
      "line-height:1.4}}table{{border-collapse:collapse;font-size:90%;margin:1em 0}}"
      "td,th{{border:1px solid #ccc;padding:2px 6px;text-align:right}}td:first-child{{text-align:"
      "left}}img{{max-width:100%}}code{{background:#f4f4f4}}</style>\n</head>\n<body>\n",
      escape_xml(title));
  std::string paragraph;
  auto flush = [&] {
    if (!paragraph.empty()) html += "<p>" + inline_html(paragraph) + "</p>\n";
    paragraph.clear();
  };
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& l = lines[i];
    if (l.empty()) {
      flush();
    } else if (l[0] == '#') {
      flush();
      const std::size_t level = std::min<std::size_t>(l.find_first_not_of('#'), 6);
      html += fmt::format("<h{0}>{1}</h{0}>\n", level,
                          inline_html(l.substr(std::min(l.size(), level + 1))));
    } else if (l.rfind("![", 0) == 0 && l.find("](") != std::string::npos && l.back() == ')') {
      flush();
      const std::size_t mid = l.find("](");
      const std::string alt = l.substr(2, mid - 2), src = l.substr(mid + 2, l.size() - mid - 3);
      std::ifstream f(image_dir / src, std::ios::binary);
      const std::string data((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
      if (!f.good() && data.empty())
        html += fmt::format("<p><a href=\"{}\">{}</a></p>\n", escape_xml(src), escape_xml(alt));
      else
        html += fmt::format("<p><img alt=\"{}\" src=\"data:image/png;base64,{}\"></p>\n",
                            escape_xml(alt), base64_encode(data));
    } else if (l[0] == '|') {
      flush();
      html += "<table>\n";
      bool header = true;
      for (; i < lines.size() && !lines[i].empty() && lines[i][0] == '|'; ++i) {
        if (lines[i].rfind("|---", 0) == 0) continue;
        html += "<tr>";
        for (const std::string& c : table_cells(lines[i]))
          html += fmt::format("<{0}>{1}</{0}>", header ? "th" : "td", inline_html(c));
        html += "</tr>\n";
        header = false;
      }
      --i;
      html += "</table>\n";
    } else if (l.rfind("* ", 0) == 0) {
      flush();
      html += "<ul>\n";
      for (; i < lines.size() && lines[i].rfind("* ", 0) == 0; ++i)
        html += "<li>" + inline_html(lines[i].substr(2)) + "</li>\n";
      --i;
      html += "</ul>\n";
    } else {
      paragraph += (paragraph.empty() ? "" : " ") + l;
    }
  }
  flush();
  return html + "</body>\n</html>\n";
}

}  // namespace halfback::study
