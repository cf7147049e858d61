// The sections of the report (report_internal.hpp): headings, what each metric means and what
// its tables say, around the tables of report_tables.cpp and the figures of report_charts.cpp.
#include <fmt/format.h>

#include <algorithm>

#include "halfback/study/metric.hpp"
#include "report_internal.hpp"

namespace halfback::study::report {

using acquire::Design;
using acquire::same_as_own;
using acquire::Spacing;

namespace {
// The parameterizations that exist but were not compared, and how to compare them.
std::string left_out(const StudyConfig& config) {
  std::string names;
  for (Space s : parameterizations())
    if (std::find(config.params.begin(), config.params.end(), s) == config.params.end())
      names += (names.empty() ? "" : ", ") + std::string(name_of(s));
  if (names.empty()) return {};
  return " Not compared here: " + names + " (`--params` names the parameterizations compared).";
}
}  // namespace

std::string report_header(const std::vector<BrdfResult>& results, const StudyConfig& config,
                          bool any_aniso, double seconds) {
  return fmt::format(
      "# halfback study\n\n"
      "Measure: cos θi cos θo dωi dωo, through each parameterization's Jacobian. Values: the "
      "luminance of ρ in the **{}** error space. Metrics 1–2 on a {} × {} × {} grid of cell "
      "centres of each isotropic form (midpoint rule){}. Definitions: docs/study.md. {} "
      "in {:.1f} s.{}{}\n\n",
      name_of(config.space), config.grid.a, config.grid.b, config.grid.phi,
      any_aniso ? fmt::format(", and {} × {} × {} × {} cells of the full form for the anisotropic "
                              "ones",
                              config.full_grid[0], config.full_grid[1], config.full_grid[2],
                              config.full_grid[3])
                : "",
      brdf_count(results.size()), seconds, left_out(config),
      config.quick
          ? "\n\n**A quick run** (`--quick`: smaller grids, fewer budgets and test pairs): "
            "its headline can differ from a full run's; do not quote it as the study's "
            "result."
          : "");
}

namespace {

// "four" for 4: small counts in words, as in prose.
std::string count_in_words(std::size_t n) {
  static constexpr const char* kWords[] = {"no",  "one",   "two",   "three", "four", "five",
                                           "six", "seven", "eight", "nine",  "ten"};
  return n < std::size(kWords) ? kWords[n] : fmt::format("{}", n);
}

}  // namespace

namespace {

// The lowest median of `med` (NaN: not measured) and the lowest of those that differ from it,
// as indices (med.size(): none). Parameterizations with the very same median (those that share a
// sampler chart share its numbers) are tied with the first, not runners-up.
std::pair<std::size_t, std::size_t> two_lowest(const std::vector<double>& med) {
  std::size_t first = med.size(), second = med.size();
  for (std::size_t i = 0; i < med.size(); ++i)
    if (std::isfinite(med[i]) && (first == med.size() || med[i] < med[first])) first = i;
  for (std::size_t i = 0; i < med.size(); ++i)
    if (first != med.size() && std::isfinite(med[i]) && med[i] != med[first] &&
        (second == med.size() || med[i] < med[second]))
      second = i;
  return {first, second};
}

// "halfdiff", or "halfdiff = stereo-halfdiff" for the parameterizations tied at med[first].
std::string tied_names(const std::vector<Space>& params, const std::vector<double>& med,
                       std::size_t first) {
  std::string names;
  for (std::size_t i = 0; i < med.size(); ++i)
    if (med[i] == med[first])
      names += (names.empty() ? "" : " = ") + std::string(name_of(params[i]));
  return names;
}

// "×1.90" (how many times the winner's median the runner-up's is), "tie" when equal to 3 digits.
std::string margin(double winner, double runner_up) {
  if (!(winner > 0)) return runner_up > 0 ? std::string("exact") : std::string("tie");
  const double r = runner_up / winner;
  return r < 1.0005 ? std::string("tie")
         : r < 10   ? fmt::format("×{:.2f}", r)
                    : fmt::format("×{:.3g}", r);
}

}  // namespace

std::string answers_section(const std::vector<BrdfResult>& results,
                            const std::vector<SummaryMetric>& metrics) {
  const std::vector<Space>& params = params_of(results);
  if (params.size() < 2) return {};
  const Kinds kinds = kinds_of(results);
  std::string rows;
  for (const SummaryMetric& m : metrics) {
    if (m.use.empty()) continue;
    std::vector<std::size_t> all(results.size());
    for (std::size_t j = 0; j < all.size(); ++j) all[j] = j;
    const auto [med, n] = medians(m, all);
    const auto [first, second] = two_lowest(med);
    if (n == 0 || second == med.size()) continue;
    Wins wins(params);
    for (std::size_t j : all)
      if (std::all_of(m.values[j].begin(), m.values[j].end(),
                      [](double v) { return std::isfinite(v); }))
        wins.add(m.values[j]);
    std::string by_kind;
    if (kinds.size() > 1)
      for (const auto& [kind, rows_of_kind] : kinds) {
        if (kind == "all") continue;
        const auto [kmed, kn] = medians(m, rows_of_kind);
        const auto [kfirst, ksecond] = two_lowest(kmed);
        if (kn == 0 || ksecond == kmed.size()) continue;
        by_kind +=
            fmt::format("{}{} ({}): {} {}", by_kind.empty() ? "" : "; ", kind, kn,
                        tied_names(params, kmed, kfirst), margin(kmed[kfirst], kmed[ksecond]));
      }
    rows += fmt::format("| {} | **{}** {:.4g} | {} {:.4g} | {} | {} of {} | {} |\n", m.use,
                        tied_names(params, med, first), med[first], tied_names(params, med, second),
                        med[second], margin(med[first], med[second]), wins.count(first), n,
                        by_kind.empty() ? "–" : by_kind);
  }
  if (rows.empty()) return {};
  return fmt::format(
             "## Answers\n\nWhich parameterization for what, on the {} of this run: per use, "
             "the parameterization with the lowest median (over the BRDFs measured in all of "
             "them; the metrics and kinds of the Summary below, lower is better), the "
             "runner-up, the margin (runner-up's median over the winner's), on how many BRDFs "
             "the winner is the lowest, and the winner of each kind of BRDF with its margin. "
             "docs/answers.md answers the same on the whole shared data.\n\n"
             "| use | winner (median) | runner-up | margin | winner lowest on | by kind |\n"
             "|---|---|---|---|---|---|\n",
             brdf_count(results.size())) +
         rows + "\n";
}

std::string summary_section(const std::vector<BrdfResult>& results,
                            const std::vector<SummaryMetric>& metrics, const ReportPlots& plots) {
  const std::vector<Space>& params = params_of(results);
  std::string md = fmt::format(
      "## Summary\n\nFor each kind of BRDF and each metric below: the median relative error "
      "(for importance sampling, relative variance; lower is better) of each parameterization "
      "over the BRDFs of that kind measured in all {}, and in parentheses the number of BRDFs "
      "on which it has the lowest value (ties count for each). "
      "The lowest median is in bold. The kind comes from the label (the reader's prefix for a "
      "file; a model's spec is a model).\n\n",
      params.size() == 1 ? "of them" : count_in_words(params.size()));
  const Kinds kinds = kinds_of(results);
  for (const SummaryMetric& m : metrics) md += summary_table(m, params, kinds);
  return md + plot_link(plots.summary, "Summary", "summary");
}

// 1. Azimuthal dependence.
std::string azimuthal_section(const std::vector<BrdfResult>& results, bool any_aniso) {
  std::string md =
      "## 1. Azimuthal dependence\n\nThe relative error of replacing the BRDF by its mean over "
      "the relative azimuth of each parameterization (lower: the BRDF is more nearly 2D "
      "there).\n\n" +
      azimuthal_table_md(results) + "![Azimuthal dependence](azimuthal.png)\n\n";
  if (!any_aniso) return md;
  return md +
         "Anisotropic BRDFs, 4D: the error of dropping the second azimuth (φd, φk or φo) at "
         "fixed (a, φa, b).\n\n" +
         azimuthal_4d_table_md(results) + "\n";
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
  md += separability_table_md(results, config, "2D projection ρ̄(a, b):", 2);
  md += "![Separability, rank 1](separability.png)\n\n";
  md +=
      separability_table_md(results, config, "3D table unfolded along its azimuth, (a, b) × φ:", 3);
  if (any_aniso)
    md += separability_table_md(results, config,
                                "Anisotropic BRDFs, 4D table unfolded as (a, φa) × (b, φb):", 4);
  return md;
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
  md += dupuy_jakob_table(results, config);
  md += nielsen_table(results, config);
  md += "\n" + plot_link(plots.gonio, "Virtual gonio-reflectometer", "gonio");
  md += plot_link(plots.strategies, "Acquisition strategies by kind", "strategies");
  if (any_aniso)
    md += gonio_4d_table(results, config) + "\n" +
          plot_link(plots.gonio4d, "Virtual gonio-reflectometer, 4D", "gonio4d");
  return md;
}

namespace {

// The paper's question in one line per parameterization whose angle design differs from its own
// (ortho, hybrid): the same iso-surfaces with halfdiff's spacing of the magnitudes.
std::string angle_line(const DesignComparison& c) {
  const std::size_t own = key_index(c, Spacing::own, Design::regular);
  const std::size_t angle = key_index(c, Spacing::angle, Design::regular);
  if (own == c.keys.size() || angle == c.keys.size()) return {};
  std::string md;
  for (std::size_t i = 0; i < c.params.size(); ++i)
    if (!same_as_own(c.params[i], true, Spacing::angle))
      md += fmt::format("{}{} {:.4f} → {:.4f} (×{:.2f})", md.empty() ? "" : "; ",
                        name_of(c.params[i]), c.median[i][own], c.median[i][angle],
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
    return fmt::format("\nLowest error, best against best (BRDFs): {}.\n\n",
                       win_counts(c.params, after));
  const std::vector<std::size_t> before =
      winners(c, ref, std::vector<std::size_t>(c.params.size(), own_key));
  std::string changed;
  int n_changed = 0;
  for (std::size_t j = 0; j < c.brdfs.size(); ++j)
    if (before[j] != after[j]) {
      changed += fmt::format("{}{} ({} → {})", changed.empty() ? "" : ", ", c.brdfs[j]->label,
                             name_of(c.params[before[j]]), name_of(c.params[after[j]]));
      ++n_changed;
    }
  const std::size_t top_before = most_wins(c.params, before),
                    top_after = most_wins(c.params, after);
  std::string md = fmt::format(
      "\nLowest error, each parameterization in the own regular design (BRDFs): {}.\n"
      "Lowest error, best against best (each in its best design above): {}.\n\n",
      win_counts(c.params, before), win_counts(c.params, after));
  md += top_before == top_after
            ? fmt::format("**The parameterization with the most wins does not change: {}.** ",
                          name_of(c.params[top_after]))
            : fmt::format("**The parameterization with the most wins changes, from {} to {}.** ",
                          name_of(c.params[top_before]), name_of(c.params[top_after]));
  md += n_changed == 0 ? std::string("No BRDF changes its best parameterization.\n\n")
                       : fmt::format("{} of {} {} their best parameterization: {}.\n\n", n_changed,
                                     brdf_count(c.brdfs.size()),
                                     n_changed == 1 ? "changes" : "change", changed);
  return md + angle_line(c);
}

}  // namespace

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
      "from the other BRDFs (leave-one-out). Median relative error over the {} "
      "measured in every design (isotropic); the lowest of each parameterization in bold, its best "
      "design:\n\n",
      ref, brdf_count(c.brdfs.size()));
  md += design_median_table(c);
  md += "\nBest against best, per BRDF (each parameterization in its best design):\n\n" +
        best_design_table(c, ref);
  md += design_conclusions(c, ref);
  if (!c.exact.empty())
    md += "Left out, reconstructed exactly by some design: " + c.exact + ".\n\n";
  return md + plot_link(plots.designs, "Designs", "designs");
}

// 4. Image-space error.
std::string image_section(const std::vector<BrdfResult>& results, const StudyConfig& config,
                          const ReportPlots& plots) {
  std::string envs;
  for (std::size_t i = 0; i < config.environments.size(); ++i)
    envs += (i ? ", " : "") + config.environments[i].label;
  std::string md = fmt::format(
      "## 4. Image-space error\n\nThe reconstructions from {} measurements rendered on a "
      "sphere ({}², {} environment samples per pixel, the same for every image) under "
      "{}, against the rendering of the BRDF itself: relative RMSE / mean CIEDE2000 of "
      "the tone-mapped images, averaged over the environments; regular design, then "
      "stratified.\n\n",
      config.image_budget, config.image_size, config.image_spp, envs);
  md += image_tables(results) + "![Image-space error](image.png)\n\n" +
        plot_link(plots.renderings, "Renderings of the reconstructions", "renderings");
  md += published_image_table(results);
  std::string no_images;  // no finite ground truth to compare with (an ALTA file's gaps)
  for (const BrdfResult& b : results)
    if (!has_images(b)) no_images += (no_images.empty() ? "" : ", ") + b.label;
  if (!no_images.empty())
    md += "Not rendered (the BRDF has no value somewhere, so there is no ground-truth image): " +
          no_images + ".\n\n";
  return md;
}

// 5. The same materials as measured files and as their neural fits, side by side: does the
// network representation change which parameterization wins?
std::string files_and_networks_section(const std::vector<BrdfResult>& results,
                                       const StudyConfig& config) {
  if (file_network_pairs(results).empty()) return {};
  const std::size_t ref = config.budgets.empty() ? 0 : reference_budget(config);
  std::string md = fmt::format(
      "## 5. Measured files and their neural BRDFs\n\nThe same materials as measured files and "
      "as the neural BRDFs fitted to them (Sztrajman et al. 2021): the parameterization with the "
      "lowest error under each metric (azimuthal dependence; rank-1 separability of the 2D "
      "projection; gonio-reflectometer error of the regular design at N = {}; image-space "
      "relative RMSE), file / network.\n\n",
      ref);
  md += file_network_winner_table(results, ref);
  if (ref == 0) return md;
  return md +
         fmt::format("Gonio-reflectometer error at N = {} (regular design), file then network:\n\n",
                     ref) +
         file_network_gonio_table(results, ref) + "\n";
}

std::string files_paragraph(const std::vector<std::string>& csv_files) {
  std::string md = "Files: ";
  for (std::size_t i = 0; i < csv_files.size(); ++i) md += (i ? ", " : "") + csv_files[i];
  return md +
         ", the plots as PNG and SVG, and report.html (this report with the plots embedded).\n";
}

}  // namespace halfback::study::report
