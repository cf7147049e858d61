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

const GonioPoint* find_point(const std::vector<GonioPoint>& pts, Design d, std::size_t budget) {
  for (const GonioPoint& p : pts)
    if (p.design == d && p.budget == budget) return &p;
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
                                                          Design d) {
  std::vector<double> n, e;
  for (const GonioPoint& p : pts)
    if (p.design == d) {
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

}  // namespace

StudyOutput write_study(const std::filesystem::path& dir, const std::vector<BrdfResult>& results,
                        const StudyConfig& config, double seconds) {
  StudyOutput out;
  const std::string es(name_of(config.space));
  bool any_aniso = false, any_gonio = false, any_images = false;
  for (const BrdfResult& b : results) {
    any_aniso |= !b.isotropic;
    for (const ParamResult& p : b.params) {
      any_gonio |= !p.gonio.empty() || !p.gonio_4d.empty();
      any_images |= !p.images.empty();
    }
  }

  // CSV files: the columns of the issue first, then what tells rows apart (dims, budget, ...).
  std::string az = "brdf,parameterization,error,dims\n";
  std::string sep = "brdf,parameterization,rank,error,dims\n";
  std::string gon = "brdf,parameterization,design,samples,error,dims,budget\n";
  std::string bud = "brdf,parameterization,design,dims,target_error,samples,note\n";
  std::string img =
      "brdf,parameterization,design,samples,environment,relative_rmse,mean_delta_e2000,"
      "p95_delta_e2000\n";
  for (const BrdfResult& b : results) {
    const std::string brdf = csv_text_field(b.label);
    for (const ParamResult& p : b.params) {
      const std::string_view pn = name_of(p.space);
      az += fmt::format("{},{},{:.6g},3\n", brdf, pn, p.azimuthal);
      if (!b.isotropic) az += fmt::format("{},{},{:.6g},4\n", brdf, pn, p.azimuthal_4d);
      auto ranks = [&](const std::vector<double>& v, int dims) {
        for (std::size_t i = 0; i < v.size() && i < config.ranks.size(); ++i)
          sep += fmt::format("{},{},{},{:.6g},{}\n", brdf, pn, config.ranks[i], v[i], dims);
      };
      ranks(p.separability_2d, 2);
      ranks(p.separability_3d, 3);
      if (!b.isotropic) ranks(p.separability_4d, 4);
      auto gonio_rows = [&](const std::vector<GonioPoint>& pts, int dims) {
        for (const GonioPoint& g : pts)
          gon += fmt::format("{},{},{},{},{:.6g},{},{}\n", brdf, pn, name_of(g.design), g.samples,
                             g.error, dims, g.budget);
        for (Design d : kDesigns) {
          const auto [n, e] = curve(pts, d);
          if (n.empty()) continue;
          for (double target : kTargetErrors) {
            const double s = samples_to_reach(n, e, target);
            bud += fmt::format("{},{},{},{},{},{},{}\n", brdf, pn, name_of(d), dims, target,
                               s == 0 || std::isinf(s) ? std::string() : fmt::format("{:.0f}", s),
                               s == 0          ? "below_range"
                               : std::isinf(s) ? "not_reached"
                                               : "reached");
          }
        }
      };
      gonio_rows(p.gonio, 3);
      gonio_rows(p.gonio_4d, 4);
      for (const ImagePoint& i : p.images)
        img += fmt::format("{},{},{},{},{},{:.6g},{:.6g},{:.6g}\n", brdf, pn, name_of(i.design),
                           i.samples, csv_text_field(i.environment), i.relative_rmse,
                           i.mean_delta_e, i.p95_delta_e);
    }
  }
  auto csv = [&](const char* name, const std::string& text) {
    write_file_atomically(dir / name, text);
    out.files.push_back(name);
  };
  csv("azimuthal.csv", az);
  csv("separability.csv", sep);
  if (any_gonio) {
    csv("gonio.csv", gon);
    csv("budget.csv", bud);
  }
  if (any_images) csv("image.csv", img);

  // The plots that may have nothing to draw (every curve exact, no rendering): the report links
  // only those that are written.
  const figure::Scene gonio_scene =
      any_gonio ? gonio_chart(results, false, config) : figure::Scene{};
  const figure::Scene gonio4d_scene =
      any_gonio && any_aniso ? gonio_chart(results, true, config) : figure::Scene{};
  const figure::Scene renderings_scene =
      any_images ? examples_chart(results, config) : figure::Scene{};
  auto link = [](const figure::Scene& sc, const char* alt, const char* stem) {
    return sc.items.empty() ? std::string() : fmt::format("![{}]({}.png)\n\n", alt, stem);
  };

  // The report.
  std::string md = fmt::format(
      "# halfback study\n\n"
      "Measure: cos θi cos θo dωi dωo, through each parameterization's Jacobian. Values: the "
      "luminance of ρ in the **{}** error space. Metrics 1–2 on a {} × {} × {} grid of cell "
      "centres of each isotropic form (midpoint rule){}. Definitions: docs/study.md. {} BRDFs "
      "in {:.1f} s.\n\n",
      es, config.grid.a, config.grid.b, config.grid.phi,
      any_aniso ? fmt::format(", and {} × {} × {} × {} cells of the full form for the anisotropic "
                              "ones",
                              config.full_grid[0], config.full_grid[1], config.full_grid[2],
                              config.full_grid[3])
                : "",
      results.size(), seconds);

  // 1. Azimuthal dependence.
  Wins az_wins;
  md +=
      "## 1. Azimuthal dependence\n\nThe relative error of replacing the BRDF by its mean over "
      "the relative azimuth of each parameterization (lower: the BRDF is more nearly 2D "
      "there).\n\n" +
      table_header("BRDF");
  figure::BarChart az_chart, sep_chart;
  for (Space s : kStudied) {
    az_chart.series.emplace_back(name_of(s));
    sep_chart.series.emplace_back(name_of(s));
  }
  az_chart.title = fmt::format("Azimuthal dependence ({} error space)", es);
  az_chart.x_label = "relative error of dropping the relative azimuth";
  sep_chart.title = fmt::format("Separability of the 2D projection, rank 1 ({} error space)", es);
  sep_chart.x_label = "relative error of the best rank-1 approximation";
  for (const BrdfResult& b : results) {
    std::string row = "| " + md_cell(b.label) + " |";
    std::array<double, kStudied.size()> v{};
    az_chart.rows.push_back(b.label);
    sep_chart.rows.push_back(b.label);
    az_chart.values.emplace_back();
    sep_chart.values.emplace_back();
    for (std::size_t i = 0; i < b.params.size(); ++i) {
      v[i] = b.params[i].azimuthal;
      row += fmt::format(" {:.4f} |", v[i]);
      az_chart.values.back().push_back(v[i]);
      sep_chart.values.back().push_back(
          b.params[i].separability_2d.empty() ? 0.0 : b.params[i].separability_2d[0]);
    }
    az_wins.add(v);
    md += row + "\n";
  }
  md += fmt::format(
      "\nLowest error (BRDFs; ties count for each): {}.\n\n![Azimuthal "
      "dependence](azimuthal.png)\n\n",
      az_wins.text());
  if (any_aniso) {
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
    md += "\n";
  }

  // 2. Separability.
  auto sep_table = [&](const char* heading, auto member, bool aniso_only) {
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
  };
  std::string ranks;
  for (std::size_t i = 0; i < config.ranks.size(); ++i)
    ranks += fmt::format("{}{}", i ? ", " : "", config.ranks[i]);
  md += fmt::format(
      "## 2. Separability\n\nRelative errors of the best rank-r approximations, "
      "r = {}.\n\n",
      ranks);
  md += sep_table("2D projection ρ̄(a, b):", &ParamResult::separability_2d, false);
  md += "![Separability, rank 1](separability.png)\n\n";
  md += sep_table("3D table unfolded along its azimuth, (a, b) × φ:", &ParamResult::separability_3d,
                  false);
  if (any_aniso)
    md += sep_table("Anisotropic BRDFs, 4D table unfolded as (a, φa) × (b, φb):",
                    &ParamResult::separability_4d, true);

  // 3. Gonio-reflectometer.
  if (any_gonio) {
    md += fmt::format(
        "## 3. Virtual gonio-reflectometer\n\nRelative error of the reconstruction from N "
        "measurements placed in each parameterization's isotropic form (regular grid / "
        "stratified random), against the BRDF at {} test pairs drawn from the measure.\n\n",
        config.test_pairs);
    for (std::size_t budget : config.budgets) {
      md += fmt::format("Budget {} (regular / stratified):\n\n", budget) + table_header("BRDF");
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
      md += fmt::format("\nLowest error, regular design (BRDFs): {}.\n\n", w.text());
    }
    const double target = kTargetErrors[1];
    md += fmt::format(
              "Measurements needed to reach a relative error of {} (regular / stratified; "
              "interpolated log-log between budgets):\n\n",
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
    // The budget each parameterization needs to match the best one at a reference budget.
    const std::size_t ref = std::find(config.budgets.begin(), config.budgets.end(),
                                      config.image_budget) != config.budgets.end()
                                ? config.image_budget
                                : config.budgets[config.budgets.size() / 2];
    md += fmt::format(
              "\nMeasurements each parameterization needs to reach E*, the lowest error of the "
              "regular design at N = {} (as a multiple of the best one's samples; log-log "
              "interpolation; “> ×k” when even the largest budget does not reach E*):\n\n",
              ref) +
          table_header("BRDF (E*)");
    std::array<std::vector<double>, kStudied.size()> ratios;
    std::string exact;
    for (const BrdfResult& b : results) {
      double best = INFINITY, best_samples = 0;
      for (const ParamResult& p : b.params)
        if (const GonioPoint* g = find_point(p.gonio, Design::regular, ref); g && g->error < best) {
          best = g->error;
          best_samples = double(g->samples);
        }
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
    for (std::size_t i = 0; i < kStudied.size(); ++i) {
      std::vector<double> r = ratios[i];
      if (r.empty()) continue;
      std::sort(r.begin(), r.end());
      const double m =
          r.size() % 2 ? r[r.size() / 2] : 0.5 * (r[r.size() / 2 - 1] + r[r.size() / 2]);
      medians += fmt::format("{}{} ×{:.3g}", medians.empty() ? "" : ", ", name_of(kStudied[i]), m);
    }
    if (!medians.empty()) md += "\nMedian over the BRDFs: " + medians + ".\n";
    if (!exact.empty())
      md +=
          "\nLeft out, reconstructed exactly (E* = 0) by at least one parameterization: " + exact +
          ".\n";
    md += "\n" + link(gonio_scene, "Virtual gonio-reflectometer", "gonio");
    if (any_aniso) {
      md += "Anisotropic BRDFs, 4D (measured in the full form; regular / stratified):\n\n";
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
      md += "\n" + link(gonio4d_scene, "Virtual gonio-reflectometer, 4D", "gonio4d");
    }
  }

  // 4. Image-space error.
  figure::BarChart im_chart;
  if (any_images) {
    std::string envs;
    for (std::size_t i = 0; i < config.environments.size(); ++i)
      envs += (i ? ", " : "") + config.environments[i].label;
    md += fmt::format(
              "## 4. Image-space error\n\nThe reconstructions from {} measurements rendered on a "
              "sphere ({}², {} environment samples per pixel, the same for every image) under "
              "{}, against the rendering of the BRDF itself: relative RMSE / mean CIEDE2000 of "
              "the tone-mapped images, averaged over the environments; regular design, then "
              "stratified.\n\n",
              config.image_budget, config.image_size, config.image_spp, envs) +
          table_header("BRDF");
    for (Space s : kStudied) im_chart.series.emplace_back(name_of(s));
    im_chart.title = fmt::format("Image-space error of the reconstructions from {} measurements",
                                 config.image_budget);
    im_chart.x_label = "relative RMSE of the sphere renderings (regular design, mean over maps)";
    std::array<Wins, 2> rmse_wins, de_wins;
    std::string strat_rows;
    std::string no_images;
    for (const BrdfResult& b : results) {
      bool has_images = false;
      for (const ParamResult& p : b.params) has_images |= !p.images.empty();
      if (!has_images) {  // no finite ground truth to compare with (an ALTA file's gaps)
        no_images += (no_images.empty() ? "" : ", ") + b.label;
        continue;
      }
      im_chart.rows.push_back(b.label);
      im_chart.values.emplace_back();
      std::array<std::string, 2> row{"| " + md_cell(b.label) + " |",
                                     "| " + md_cell(b.label) + " |"};
      std::array<std::array<double, kStudied.size()>, 2> rm{}, de{};
      for (std::size_t i = 0; i < b.params.size(); ++i)
        for (std::size_t d = 0; d < 2; ++d) {
          double r = 0, e = 0;
          int n = 0;
          for (const ImagePoint& p : b.params[i].images)
            if (p.design == kDesigns[d]) {
              r += p.relative_rmse;
              e += p.mean_delta_e;
              ++n;
            }
          rm[d][i] = n ? r / n : INFINITY;
          de[d][i] = n ? e / n : INFINITY;
          row[d] += n ? fmt::format(" {:.4f} / {:.2f} |", r / n, e / n) : " – |";
          if (d == 0) im_chart.values.back().push_back(n && std::isfinite(r) ? r / n : 0.0);
        }
      for (std::size_t d = 0; d < 2; ++d) {
        rmse_wins[d].add(rm[d]);
        de_wins[d].add(de[d]);
      }
      md += row[0] + "\n";
      strat_rows += row[1] + "\n";
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
          link(renderings_scene, "Renderings of the reconstructions", "renderings");
    if (!no_images.empty())
      md += "Not rendered (the BRDF has no value somewhere, so there is no ground-truth image): " +
            no_images + ".\n\n";
  }
  md += "Files: ";
  for (std::size_t i = 0; i < out.files.size(); ++i) md += (i ? ", " : "") + out.files[i];
  md += ", the plots as PNG and SVG, and report.html (this report with the plots embedded).\n";

  save_plot(figure::bar_chart(az_chart), dir, "azimuthal", out.files);
  save_plot(figure::bar_chart(sep_chart), dir, "separability", out.files);
  save_plot(gonio_scene, dir, "gonio", out.files);
  save_plot(gonio4d_scene, dir, "gonio4d", out.files);
  if (any_images) save_plot(figure::bar_chart(im_chart), dir, "image", out.files);
  save_plot(renderings_scene, dir, "renderings", out.files);
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
