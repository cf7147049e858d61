// The Markdown tables of the report (report_internal.hpp): one column per parameterization of
// the results, and under most tables the line that says which parameterization wins how often.
#include <fmt/format.h>

#include <algorithm>
#include <array>

#include "halfback/study/metric.hpp"
#include "report_internal.hpp"

namespace halfback::study::report {

using acquire::Design;
using acquire::kDesigns;
using acquire::samples_to_reach;
using acquire::Spacing;

void Wins::add(const std::vector<double>& v) {
  const double best = *std::min_element(v.begin(), v.end());
  if (!std::isfinite(best)) return;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (v[i] <= best + 1e-9 * std::abs(best) + 1e-15) ++count_[i];
}

std::string Wins::text() const {
  std::string s;
  for (std::size_t i = 0; i < params_.size(); ++i)
    s += fmt::format("{}{} {}", i ? ", " : "", name_of(params_[i]), count_[i]);
  return s;
}

std::string row_start(const std::string& label) {
  return "| " + md_cell(label) + " |";
}

namespace {

// " regular / stratified |": the own design's errors in both layouts at a budget ("–" where
// not measured).
std::string design_cells(const std::vector<GonioPoint>& points, std::size_t budget) {
  std::string cell;
  for (Design d : kDesigns) {
    const GonioPoint* p = find_point(points, d, budget);
    cell += (cell.empty() ? " " : " / ") + (p ? fmt::format("{:.4f}", p->error) : "–");
  }
  return cell + " |";
}

std::string samples_text(double n, double smallest) {
  if (n == 0) return fmt::format("≤ {:.0f}", smallest);
  if (std::isinf(n)) return "not reached";
  return fmt::format("{:.3g}", n);
}

// The lowest regular-design error at budget `ref` over the parameterizations, with its samples
// (INFINITY when not measured).
std::pair<double, double> best_regular_error(const BrdfResult& b, std::size_t ref) {
  double best = INFINITY, best_samples = 0;
  for (Space s : b.params) {
    const std::vector<GonioPoint> points = gonio_points(b, s, 3);
    if (const GonioPoint* g = find_point(points, Design::regular, ref); g && g->error < best) {
      best = g->error;
      best_samples = double(g->samples);
    }
  }
  return {best, best_samples};
}

// The parameterization with the lowest value ("–" when none is finite).
std::string lowest_of(const std::vector<double>& v, const std::vector<Space>& params) {
  std::size_t best = v.size();
  for (std::size_t i = 0; i < v.size(); ++i)
    if (std::isfinite(v[i]) && (best == v.size() || v[i] < v[best])) best = i;
  return best == v.size() ? "–" : std::string(name_of(params[best]));
}

}  // namespace

std::string md_cell(const std::string& s) {
  std::string out;
  for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

std::string table_header(const std::string& first, const std::vector<Space>& params) {
  std::string h = "| " + first + " |", rule = "|---|";
  for (char c : first)
    if (c == '|') rule += "---|";  // `first` is several cells
  for (Space s : params) {
    h += fmt::format(" {} |", name_of(s));
    rule += "---|";
  }
  return h + "\n" + rule + "\n";
}

// ---------------------------------------------------------------------------------------------
// Metrics 1-2
// ---------------------------------------------------------------------------------------------

std::string azimuthal_table_md(const std::vector<BrdfResult>& results) {
  const std::vector<Space>& params = params_of(results);
  std::string md = table_header("BRDF", params);
  Wins wins(params);
  for (const BrdfResult& b : results) {
    md += row_start(b.label);
    std::vector<double> v;
    for (Space s : params) {
      v.push_back(azimuthal_error(b, s, 3));
      md += fmt::format(" {:.4f} |", v.back());
    }
    wins.add(v);
    md += "\n";
  }
  return md + fmt::format("\nLowest error (BRDFs; ties count for each): {}.\n\n", wins.text());
}

std::string azimuthal_4d_table_md(const std::vector<BrdfResult>& results) {
  const std::vector<Space>& params = params_of(results);
  std::string md = table_header("BRDF", params);
  for (const BrdfResult& b : results) {
    if (b.isotropic) continue;
    md += row_start(b.label);
    for (Space s : params) md += fmt::format(" {:.4f} |", azimuthal_error(b, s, 4));
    md += "\n";
  }
  return md;
}

std::string separability_table_md(const std::vector<BrdfResult>& results, const StudyConfig& config,
                                  const char* heading, int dims) {
  const std::vector<Space>& params = params_of(results);
  std::string t = std::string(heading) + "\n\n" + table_header("BRDF", params);
  Wins w(params);
  for (const BrdfResult& b : results) {
    if (dims == 4 && b.isotropic) continue;
    t += row_start(b.label);
    std::vector<double> first;
    for (Space s : params) {
      const std::vector<double> v = separability_errors(b, s, dims);
      std::string cell;
      for (std::size_t k = 0; k < v.size(); ++k)
        cell += fmt::format("{}{:.3f}", k ? " / " : "", v[k]);
      t += " " + cell + " |";
      first.push_back(v.empty() ? INFINITY : v[0]);
    }
    w.add(first);
    t += "\n";
  }
  return t + fmt::format("\nLowest rank-{} error (BRDFs): {}.\n\n",
                         config.ranks.empty() ? 0 : config.ranks[0], w.text());
}

// ---------------------------------------------------------------------------------------------
// Metric 3: the gonio-reflectometer
// ---------------------------------------------------------------------------------------------

std::string gonio_budget_table(const std::vector<BrdfResult>& results, std::size_t budget) {
  const std::vector<Space>& params = params_of(results);
  std::string md =
      fmt::format("Budget {} (regular / stratified):\n\n", budget) + table_header("BRDF", params);
  Wins w(params);
  for (const BrdfResult& b : results) {
    md += row_start(b.label);
    std::vector<double> v;
    for (Space s : params) {
      const std::vector<GonioPoint> points = gonio_points(b, s, 3);
      md += design_cells(points, budget);
      const GonioPoint* r = find_point(points, Design::regular, budget);
      v.push_back(r ? r->error : INFINITY);
    }
    w.add(v);
    md += "\n";
  }
  return md + fmt::format("\nLowest error, regular design (BRDFs): {}.\n\n", w.text());
}

std::string samples_to_target_table(const std::vector<BrdfResult>& results, double target) {
  const std::vector<Space>& params = params_of(results);
  std::string md = fmt::format(
                       "Measurements needed to reach a relative error of {} (regular / "
                       "stratified; interpolated log-log between budgets):\n\n",
                       target) +
                   table_header("BRDF", params);
  for (const BrdfResult& b : results) {
    md += row_start(b.label);
    for (Space s : params) {
      const std::vector<GonioPoint> points = gonio_points(b, s, 3);
      std::string cell;
      for (Design d : kDesigns) {
        const GonioCurve c = gonio_curve(points, d);
        cell += (cell.empty() ? "" : " / ") +
                (c.samples.empty() ? std::string("–")
                                   : samples_text(samples_to_reach(c.samples, c.errors, target),
                                                  c.samples.front()));
      }
      md += " " + cell + " |";
    }
    md += "\n";
  }
  return md;
}

std::string matching_budget_table(const std::vector<BrdfResult>& results, std::size_t ref) {
  const std::vector<Space>& params = params_of(results);
  std::string md =
      fmt::format(
          "\nMeasurements each parameterization needs to reach E*, the lowest error of the "
          "regular design at N = {} (as a multiple of the best one's samples; log-log "
          "interpolation; “> ×k” when even the largest budget does not reach E*):\n\n",
          ref) +
      table_header("BRDF (E*)", params);
  std::vector<std::vector<double>> ratios(params.size());
  std::string exact;
  for (const BrdfResult& b : results) {
    const auto [best, best_samples] = best_regular_error(b, ref);
    if (!std::isfinite(best)) continue;  // not measured
    if (best <= 1e-12) {                 // reconstructed exactly by some parameterization
      exact += (exact.empty() ? "" : ", ") + b.label;
      continue;
    }
    md += fmt::format("| {} ({:.3g}) |", md_cell(b.label), best);
    for (std::size_t i = 0; i < params.size(); ++i) {
      const GonioCurve c = gonio_curve(gonio_points(b, params[i], 3), Design::regular);
      const double need = samples_to_reach(c.samples, c.errors, best * (1 + 1e-9));
      const double ratio = need == 0 ? c.samples.front() / best_samples : need / best_samples;
      ratios[i].push_back(ratio);
      md += std::isinf(ratio) ? fmt::format(" > ×{:.3g} |", c.samples.back() / best_samples)
                              : fmt::format(" ×{:.2f} |", ratio);
    }
    md += "\n";
  }
  // A BRDF on which the largest budget does not reach E* counts as above every multiple; when
  // it is half of them or more, the median is not a multiple.
  std::string medians;
  for (std::size_t i = 0; i < params.size(); ++i) {
    if (ratios[i].empty()) continue;
    const auto unreached = std::size_t(
        std::count_if(ratios[i].begin(), ratios[i].end(), [](double r) { return std::isinf(r); }));
    const double m = median(ratios[i]);
    const std::string tail =
        unreached == 0 ? "" : fmt::format(" ({} of {} not reached)", unreached, ratios[i].size());
    medians +=
        fmt::format("{}{} {}{}", medians.empty() ? "" : ", ", name_of(params[i]),
                    std::isinf(m) ? std::string("not reached") : fmt::format("×{:.3g}", m), tail);
  }
  if (!medians.empty()) md += "\nMedian over the BRDFs: " + medians + ".\n";
  if (!exact.empty())
    md += "\nLeft out, reconstructed exactly (E* = 0) by at least one parameterization: " + exact +
          ".\n";
  return md;
}

std::string gonio_4d_table(const std::vector<BrdfResult>& results, const StudyConfig& config) {
  const std::vector<Space>& params = params_of(results);
  std::string md = "Anisotropic BRDFs, 4D (measured in the full form; regular / stratified):\n\n";
  md += table_header("BRDF | budget", params);
  for (const BrdfResult& b : results) {
    if (b.isotropic) continue;
    for (std::size_t budget : config.budgets_4d) {
      md += row_start(b.label) + fmt::format(" {} |", budget);
      for (Space s : params) md += design_cells(gonio_points(b, s, 4), budget);
      md += "\n";
    }
  }
  return md;
}

// ---------------------------------------------------------------------------------------------
// Designs (section 3b)
// ---------------------------------------------------------------------------------------------

std::string design_median_table(const DesignComparison& c) {
  std::string md = "| parameterization |", rule = "|---|";
  for (const DesignKey& k : c.keys) {
    md += ' ';  // pieces appended apart: GCC 12 bug 105329 (src/study/CMakeLists.txt)
    md += design_name(k);
    md += " |";
    rule += "---|";
  }
  md += " best |\n" + rule + "---|\n";
  for (std::size_t i = 0; i < c.params.size(); ++i) {
    md += fmt::format("| {} |", name_of(c.params[i]));
    for (std::size_t k = 0; k < c.keys.size(); ++k)
      md += k == c.best[i] ? fmt::format(" **{:.4f}** |", c.median[i][k])
                           : fmt::format(" {:.4f} |", c.median[i][k]);
    md += ' ';
    md += design_name(c.keys[c.best[i]]);
    md += " |\n";
  }
  return md;
}

std::string best_design_table(const DesignComparison& c, std::size_t ref) {
  std::string md = table_header("BRDF", c.params);
  for (const BrdfResult* b : c.brdfs) {
    md += row_start(b->label);
    for (std::size_t i = 0; i < c.params.size(); ++i)
      md += fmt::format(" {:.4f} |", design_error(*b, c.params[i], c.keys[c.best[i]], ref));
    md += "\n";
  }
  return md;
}

// ---------------------------------------------------------------------------------------------
// Metric 4: images
// ---------------------------------------------------------------------------------------------

std::string image_tables(const std::vector<BrdfResult>& results) {
  const std::vector<Space>& params = params_of(results);
  // Per layout (regular, stratified): the rows, and the wins by relative RMSE and by ΔE00.
  std::array<std::string, 2> rows;
  std::array<Wins, 2> rmse_wins{Wins(params), Wins(params)}, de_wins{Wins(params), Wins(params)};
  for (const BrdfResult& b : results) {
    if (!has_images(b)) continue;  // no finite ground truth to compare with (an ALTA file's gaps)
    for (std::size_t d = 0; d < 2; ++d) {
      std::vector<double> rmse, delta_e;
      rows[d] += row_start(b.label);
      for (Space s : params) {
        const MeanImageError m = mean_image_error(image_points(b, s), kDesigns[d]);
        rmse.push_back(m.relative_rmse);
        delta_e.push_back(m.delta_e);
        rows[d] += m.count ? fmt::format(" {:.4f} / {:.2f} |", m.relative_rmse, m.delta_e) : " – |";
      }
      rows[d] += "\n";
      rmse_wins[d].add(rmse);
      de_wins[d].add(delta_e);
    }
  }
  auto wins_line = [&](std::size_t d) {
    return fmt::format("\nLowest relative RMSE (BRDFs): {}; lowest ΔE00: {}.\n\n",
                       rmse_wins[d].text(), de_wins[d].text());
  };
  return table_header("BRDF", params) + rows[0] + wins_line(0) + "Stratified design:\n\n" +
         table_header("BRDF", params) + rows[1] + wins_line(1);
}

std::string published_image_table(const std::vector<BrdfResult>& results) {
  const std::vector<Space>& params = params_of(results);
  std::string md =
      "The protocol of Sztrajman et al. 2021 on the same renderings (regular design, mean over "
      "the environments): MAE / RMSE / SSIM of the tone-mapped images (values in [0, 1]; SSIM "
      "of their luminance with the constants of Wang et al. 2004; docs/study.md):\n\n" +
      table_header("BRDF", params);
  Wins mae(params), ssim(params);
  for (const BrdfResult& b : results) {
    if (!has_images(b)) continue;
    md += row_start(b.label);
    std::vector<double> m, one_minus_ssim;
    for (Space s : params) {
      const MeanImageError e = mean_image_error(image_points(b, s), Design::regular);
      m.push_back(e.mae);
      one_minus_ssim.push_back(e.count ? 1 - e.ssim : INFINITY);
      md += e.count ? fmt::format(" {:.4f} / {:.4f} / {:.4f} |", e.mae, e.rmse, e.ssim) : " – |";
    }
    mae.add(m);
    ssim.add(one_minus_ssim);
    md += "\n";
  }
  return md +
         fmt::format("\nLowest MAE (BRDFs): {}; highest SSIM: {}.\n\n", mae.text(), ssim.text());
}

// ---------------------------------------------------------------------------------------------
// Files and their networks (section 5)
// ---------------------------------------------------------------------------------------------

std::string file_network_winner_table(const std::vector<BrdfResult>& results, std::size_t ref) {
  const std::vector<Space>& params = params_of(results);
  constexpr std::size_t n = std::size(kPairedMetrics);
  std::string md = "| material |", rule = "|---|";
  for (const char* metric : kPairedMetrics) {
    md += fmt::format(" {} |", metric);
    rule += "---|";
  }
  md += "\n" + rule + "\n";
  std::array<int, n> agree{}, compared{};
  for (const auto& [f, nw] : file_network_pairs(results)) {
    const auto vf = paired_metric_values(results[f], ref),
               vn = paired_metric_values(results[nw], ref);
    md += row_start(results[nw].label.substr(6));
    for (std::size_t m = 0; m < n; ++m) {
      const std::string a = lowest_of(vf[m], params), b = lowest_of(vn[m], params);
      md += fmt::format(" {} / {} |", a, b);
      if (a != "–" && b != "–") {
        ++compared[m];
        agree[m] += a == b;
      }
    }
    md += "\n";
  }
  md += "\nThe same winner for file and network: ";
  for (std::size_t m = 0; m < n; ++m)
    md += fmt::format("{}{} {} of {}", m ? ", " : "", kPairedMetrics[m], agree[m], compared[m]);
  return md + ".\n\n";
}

std::string file_network_gonio_table(const std::vector<BrdfResult>& results, std::size_t ref) {
  std::string md = table_header("material", params_of(results));
  for (const auto& [f, nw] : file_network_pairs(results))
    for (const std::size_t k : {f, nw}) {
      md += row_start(results[k].label);
      for (Space s : results[k].params) {
        const std::vector<GonioPoint> points = gonio_points(results[k], s, 3);
        const GonioPoint* g = find_point(points, Design::regular, ref);
        md += g ? fmt::format(" {:.4f} |", g->error) : " – |";
      }
      md += "\n";
    }
  return md;
}

// ---------------------------------------------------------------------------------------------
// The summary
// ---------------------------------------------------------------------------------------------

std::string summary_table(const SummaryMetric& m, const std::vector<Space>& params,
                          const Kinds& kinds) {
  std::string md = "**" + m.name + "**\n\n" + table_header("kind | BRDFs", params);
  for (const auto& [kind, rows] : kinds) {
    const auto [med, n] = medians(m, rows);
    if (n == 0) continue;
    Wins wins(params);
    for (std::size_t j : rows) wins.add(m.values[j]);
    const double lowest = *std::min_element(med.begin(), med.end());
    md += fmt::format("| {} | {} |", kind, n);
    for (std::size_t i = 0; i < params.size(); ++i)
      md += med[i] == lowest ? fmt::format(" **{:.4f}** ({}) |", med[i], wins.count(i))
                             : fmt::format(" {:.4f} ({}) |", med[i], wins.count(i));
    md += "\n";
  }
  return md + "\n";
}

// Dupuy & Jakob's acquisition (the dupuy-jakob rows of the per-material parameterization) against
// each parameterization's own regular grid, per budget: the medians over the BRDFs measured in all
// of them and, per BRDF, which is lowest. Empty when no BRDF has such rows.
std::string dupuy_jakob_table(const std::vector<BrdfResult>& results, const StudyConfig& config) {
  const std::vector<Space>& params = params_of(results);
  std::string rows;
  for (const std::size_t budget : config.budgets) {
    std::vector<std::vector<double>> errors(params.size() + 1);
    std::vector<int> wins(params.size() + 1, 0);
    std::size_t measured = 0, brdfs = 0;
    for (const BrdfResult& b : results) {
      std::vector<double> row(params.size() + 1, NAN);
      for (Space s : params) {
        const std::vector<GonioPoint> points = gonio_points(b, s, 3);
        if (const GonioPoint* p = find_point(points, Design::dupuy_jakob, budget, Spacing::own)) {
          row[0] = p->error;
          measured = p->samples;
        }
      }
      for (std::size_t k = 0; k < params.size(); ++k) {
        const std::vector<GonioPoint> points = gonio_points(b, params[k], 3);
        if (const GonioPoint* p = find_point(points, Design::regular, budget, Spacing::own))
          row[k + 1] = p->error;
      }
      if (std::any_of(row.begin(), row.end(), [](double v) { return !std::isfinite(v); })) continue;
      ++brdfs;
      const double best = *std::min_element(row.begin(), row.end());
      for (std::size_t k = 0; k < row.size(); ++k) {
        errors[k].push_back(row[k]);
        wins[k] += row[k] <= best;
      }
    }
    if (brdfs == 0) continue;
    rows += fmt::format("| {} | {} | {} |", budget, brdfs, measured);
    for (std::size_t k = 0; k < errors.size(); ++k)
      rows += fmt::format(" {:.4f} ({}) |", median(errors[k]), wins[k]);
    rows += "\n";
  }
  if (rows.empty()) return {};
  return "Dupuy & Jakob's acquisition (`dupuy-jakob`: the retro-reflection, then 8 incidence "
         "slices through the VNDF warp, as `export-rgl` writes it; docs/acquisition.md) against "
         "each parameterization's own regular grid at the same budget: median relative error "
         "over the BRDFs measured in all (in parentheses: on how many each is the lowest), and "
         "the measurements Dupuy & Jakob's layout takes, the retro-reflection included.\n\n" +
         table_header("budget | BRDFs | its measurements | Dupuy & Jakob", params) + rows + "\n";
}

// Per kind of BRDF and measurement count: the median error of Nielsen's reconstructions, the
// measurements halfdiff's regular grid needs for the same error (its curve over the study's
// budgets, samples_to_reach; "< smallest" and "> largest" outside it), and on how many BRDFs
// Nielsen's n measurements beat the grid's smallest budget.
std::string nielsen_table(const std::vector<BrdfResult>& results, const StudyConfig& config) {
  const Space halfdiff = space_of<HalfDiff>;
  std::string rows;
  // Each BRDF's halfdiff rows, read once.
  std::vector<std::vector<GonioPoint>> points(results.size());
  for (std::size_t j = 0; j < results.size(); ++j) {
    const BrdfResult& b = results[j];
    if (std::find(b.params.begin(), b.params.end(), halfdiff) != b.params.end())
      points[j] = gonio_points(b, halfdiff, 3);
  }
  for (const auto& [kind, members] : kinds_of(results))
    for (const std::size_t n : config.nielsen_counts) {
      std::vector<double> errors, needs;
      int wins = 0;
      for (const std::size_t j : members) {
        const GonioPoint* p = find_point(points[j], Design::nielsen, n);
        const GonioCurve grid = gonio_curve(points[j], Design::regular);
        if (!p || grid.samples.empty()) continue;
        errors.push_back(p->error);
        needs.push_back(samples_to_reach(grid.samples, grid.errors, p->error));
        wins += p->error < grid.errors.front();
      }
      if (errors.empty()) continue;
      const double need = median(needs);
      const std::string need_text = need == 0          ? "< smallest"
                                    : std::isinf(need) ? "> largest"
                                                       : fmt::format("{:.0f}", need);
      rows += fmt::format("| {} | {} | {} | {:.4f} | {} | {} |\n", kind, n, errors.size(),
                          median(errors), need_text, wins);
    }
  if (rows.empty()) return {};
  return fmt::format(
             "Nielsen et al. 2015's minimal sampling (`nielsen`: n measurements at the directions "
             "that "
             "condition a database's principal components best, the BRDF left out of its own "
             "basis; "
             "docs/acquisition.md): median error per kind of BRDF, the measurements halfdiff's "
             "regular "
             "grid needs for the same error (median over the BRDFs, interpolated on its curve over "
             "the budgets {}), and on how many BRDFs the n measurements beat the grid's smallest "
             "budget.\n\n| kind | n | BRDFs | Nielsen's error | the grid needs | better than the "
             "grid "
             "at {} |\n|---|---|---|---|---|---|\n",
             fmt::join(config.budgets, ", "), config.budgets.empty() ? 0 : config.budgets.front()) +
         rows + "\n";
}

}  // namespace halfback::study::report
