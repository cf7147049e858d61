// Reading the results for the report (report_internal.hpp): what they hold, the comparisons of
// designs, the pairs of files and networks, and the summary's metrics per kind of BRDF.
#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <stdexcept>

#include "halfback/study/metric.hpp"
#include "report_internal.hpp"

namespace halfback::study::report {

using acquire::Design;
using acquire::kGridDesigns;
using acquire::kSpacings;
using acquire::Spacing;

namespace {

std::string names(const std::vector<Space>& params) {
  std::string s;
  for (Space p : params) s += (s.empty() ? "" : ",") + std::string(name_of(p));
  return s;
}

}  // namespace

const std::vector<Space>& params_of(const std::vector<BrdfResult>& results) {
  static const std::vector<Space> kNone;
  if (results.empty()) return kNone;
  const BrdfResult& first = results.front();
  for (const BrdfResult& b : results)
    if (b.params != first.params)
      throw std::invalid_argument(fmt::format(
          "study report: '{}' was studied in {} but '{}' in {}: a report compares the same "
          "parameterizations for every BRDF",
          first.label, names(first.params), b.label, names(b.params)));
  return first.params;
}

Contents contents_of(const std::vector<BrdfResult>& results) {
  Contents has;
  for (const BrdfResult& b : results) {
    has.anisotropic |= !b.isotropic;
    has.gonio |= !b.table("gonio").rows.empty();
    has.images |= has_images(b);
    has.sampling |= !b.table("sampling").rows.empty();
  }
  return has;
}

const GonioPoint* find_point(const std::vector<GonioPoint>& points, Design layout,
                             std::size_t budget, Spacing spacing) {
  for (const GonioPoint& p : points)
    if (p.spacing == spacing && p.design == layout && p.budget == budget) return &p;
  return nullptr;
}

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

MeanImageError mean_image_error(const std::vector<ImagePoint>& images, Design layout) {
  double r = 0, e = 0, mae = 0, rmse = 0, ssim = 0;
  int n = 0;
  for (const ImagePoint& p : images)
    if (p.design == layout) {
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
  return !b.table("image").rows.empty();
}

// ---------------------------------------------------------------------------------------------
// Designs (section 3b)
// ---------------------------------------------------------------------------------------------

std::string design_name(const DesignKey& k) {
  return k.spacing == Spacing::own ? fmt::format("own {}", name_of(k.layout))
                                   : std::string(name_of(k.spacing));
}

double design_error(const BrdfResult& b, Space space, const DesignKey& k, std::size_t ref) {
  const std::vector<GonioPoint> points = gonio_points(b, space, 3);
  const GonioPoint* g = find_point(points, k.layout, ref, k.spacing);
  return g ? g->error : INFINITY;
}

namespace {

// The designs measured at budget `ref` for some isotropic BRDF, in the order of kSpacings.
std::vector<DesignKey> designs_measured(const std::vector<BrdfResult>& results, std::size_t ref) {
  std::vector<DesignKey> keys;
  for (Spacing spacing : kSpacings)
    for (Design d : kGridDesigns) {
      bool any = false;
      for (const BrdfResult& b : results)
        for (Space s : b.params) {
          const std::vector<GonioPoint> points = gonio_points(b, s, 3);
          any |= find_point(points, d, ref, spacing) != nullptr;
        }
      if (any) keys.push_back({spacing, d});
    }
  return keys;
}

}  // namespace

DesignComparison compare_designs(const std::vector<BrdfResult>& results, std::size_t ref) {
  DesignComparison c;
  c.params = params_of(results);
  c.keys = designs_measured(results, ref);
  c.median.resize(c.params.size());
  c.best.resize(c.params.size());
  for (const BrdfResult& b : results) {
    bool complete = true;
    double lowest = INFINITY;
    for (Space s : c.params)
      for (const DesignKey& k : c.keys) {
        complete &= std::isfinite(design_error(b, s, k, ref));
        lowest = std::min(lowest, design_error(b, s, k, ref));
      }
    if (complete && lowest <= 1e-12) c.exact += (c.exact.empty() ? "" : ", ") + b.label;
    if (complete && lowest > 1e-12) c.brdfs.push_back(&b);
  }
  for (std::size_t i = 0; i < c.params.size() && !c.brdfs.empty(); ++i) {
    for (const DesignKey& k : c.keys) {
      std::vector<double> e;
      for (const BrdfResult* b : c.brdfs) e.push_back(design_error(*b, c.params[i], k, ref));
      c.median[i].push_back(median(e));
    }
    c.best[i] =
        std::size_t(std::min_element(c.median[i].begin(), c.median[i].end()) - c.median[i].begin());
  }
  return c;
}

std::size_t key_index(const DesignComparison& c, Spacing spacing, Design layout) {
  for (std::size_t k = 0; k < c.keys.size(); ++k)
    if (c.keys[k].spacing == spacing && c.keys[k].layout == layout) return k;
  return c.keys.size();
}

std::vector<std::size_t> winners(const DesignComparison& c, std::size_t ref,
                                 const std::vector<std::size_t>& design) {
  auto error = [&](const BrdfResult& b, std::size_t i) {
    return design_error(b, c.params[i], c.keys[design[i]], ref);
  };
  std::vector<std::size_t> w;
  for (const BrdfResult* b : c.brdfs) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < c.params.size(); ++i)
      if (error(*b, i) < error(*b, best)) best = i;
    w.push_back(best);
  }
  return w;
}

std::string win_counts(const std::vector<Space>& params, const std::vector<std::size_t>& winners) {
  std::vector<int> n(params.size());
  for (std::size_t i : winners) ++n[i];
  std::string s;
  for (std::size_t i = 0; i < params.size(); ++i)
    s += fmt::format("{}{} {}", i ? ", " : "", name_of(params[i]), n[i]);
  return s;
}

std::size_t most_wins(const std::vector<Space>& params, const std::vector<std::size_t>& winners) {
  std::vector<int> n(params.size());
  for (std::size_t i : winners) ++n[i];
  return std::size_t(std::max_element(n.begin(), n.end()) - n.begin());
}

// ---------------------------------------------------------------------------------------------
// Files and their networks (section 5)
// ---------------------------------------------------------------------------------------------

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

std::vector<std::vector<double>> paired_metric_values(const BrdfResult& b, std::size_t ref) {
  std::vector<std::vector<double>> v(std::size(kPairedMetrics),
                                     std::vector<double>(b.params.size(), INFINITY));
  for (std::size_t i = 0; i < b.params.size(); ++i) {
    const Space s = b.params[i];
    v[0][i] = azimuthal_error(b, s, 3);
    if (const auto sep = separability_errors(b, s, 2); !sep.empty()) v[1][i] = sep[0];
    const std::vector<GonioPoint> points = gonio_points(b, s, 3);
    if (const GonioPoint* g = find_point(points, Design::regular, ref)) v[2][i] = g->error;
    v[3][i] = mean_image_error(image_points(b, s), Design::regular).relative_rmse;
  }
  return v;
}

// ---------------------------------------------------------------------------------------------
// The summary
// ---------------------------------------------------------------------------------------------

namespace {

// The kind of a BRDF, from its label: a file's label starts with its reader's prefix, a material
// compiled into the library with "embedded:", a model's is its spec.
std::string kind_of(const std::string& label) {
  static constexpr std::pair<std::string_view, std::string_view> kKinds[] = {
      {"nbrdf:", "neural BRDFs"},
      {"merl:", "MERL files"},
      {"rgl:", "RGL files"},
      {"alta:", "ALTA files"},
      {"embedded:", "embedded materials"}};
  for (const auto& [prefix, kind] : kKinds)
    if (label.starts_with(prefix)) return std::string(kind);
  return "models";
}

// The gonio-reflectometer at `ref`, each parameterization in its best design, for the BRDFs
// that c compares (INFINITY for the others).
SummaryMetric best_design_metric(const std::vector<BrdfResult>& results, const DesignComparison& c,
                                 std::size_t ref) {
  SummaryMetric best{fmt::format("gonio-reflectometer, N = {}, each in its best design", ref),
                     "best",
                     {},
                     "acquisition: each in its best design"};
  for (const BrdfResult& b : results) {
    best.values.emplace_back(c.params.size(), INFINITY);
    if (std::find(c.brdfs.begin(), c.brdfs.end(), &b) != c.brdfs.end())
      for (std::size_t i = 0; i < c.params.size(); ++i)
        best.values.back()[i] = design_error(b, c.params[i], c.keys[c.best[i]], ref);
  }
  return best;
}

// Importance sampling at the smallest table size: the relative variance of the albedo estimate
// of each parameterization's tabulated sampler (INFINITY where not measured).
SummaryMetric sampling_summary_metric(const std::vector<BrdfResult>& results,
                                      const StudyConfig& config) {
  const std::vector<std::size_t> sizes = option_counts(config, "sampler_kib");
  const std::size_t kib = sizes.empty() ? 0 : *std::min_element(sizes.begin(), sizes.end());
  SummaryMetric m{fmt::format("importance sampling, relative variance of the albedo estimate, "
                              "tables of {} KiB",
                              kib),
                  "",
                  {},
                  "importance sampling (a table of equal memory)"};
  const std::vector<Space>& params = params_of(results);
  for (const BrdfResult& b : results) {
    m.values.emplace_back(params.size(), INFINITY);
    for (std::size_t i = 0; i < params.size(); ++i)
      for (const SamplingPoint& p : sampling_points(b, params[i], "tabulated"))
        if (p.kib == kib && std::isfinite(p.relative_variance))
          m.values.back()[i] = p.relative_variance;
  }
  return m;
}

}  // namespace

std::string brdf_count(std::size_t n) {
  return fmt::format("{} BRDF{}", n, n == 1 ? "" : "s");
}

std::vector<SummaryMetric> summary_metrics(const std::vector<BrdfResult>& results,
                                           const StudyConfig& config, const Contents& has) {
  const std::size_t ref = has.gonio ? reference_budget(config) : 0;
  SummaryMetric azimuthal{"azimuthal dependence", "", {}, "compactness: dropping the azimuth"},
      separability{
          "separability (rank 1, 2D projection)", "", {}, "compactness: one separable term"},
      own{fmt::format("gonio-reflectometer, N = {}, own regular design", ref),
          "own",
          {},
          "interpolation from a gonio-reflectometer (regular grid)"},
      image{"image-space relative RMSE (regular design)",
            "",
            {},
            "renderings of the interpolated measurements"};
  for (const BrdfResult& b : results) {
    auto v = paired_metric_values(b, ref);
    azimuthal.values.push_back(std::move(v[0]));
    separability.values.push_back(std::move(v[1]));
    own.values.push_back(std::move(v[2]));
    image.values.push_back(std::move(v[3]));
  }
  std::vector<SummaryMetric> m{std::move(azimuthal), std::move(separability)};
  if (has.gonio) m.push_back(std::move(own));
  const DesignComparison c = has.gonio ? compare_designs(results, ref) : DesignComparison{};
  if (c.keys.size() >= 2 && !c.brdfs.empty()) m.push_back(best_design_metric(results, c, ref));
  if (has.images) m.push_back(std::move(image));
  if (has.sampling) m.push_back(sampling_summary_metric(results, config));
  return m;
}

Kinds kinds_of(const std::vector<BrdfResult>& results) {
  Kinds kinds;
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

std::pair<std::vector<double>, std::size_t> medians(const SummaryMetric& m,
                                                    const std::vector<std::size_t>& rows) {
  const std::size_t n_params = m.values.empty() ? 0 : m.values.front().size();
  std::vector<std::vector<double>> v(n_params);
  std::size_t complete = 0;
  for (std::size_t j : rows) {
    const auto& x = m.values[j];
    if (std::all_of(x.begin(), x.end(), [](double e) { return std::isfinite(e); })) {
      for (std::size_t i = 0; i < n_params; ++i) v[i].push_back(x[i]);
      ++complete;
    }
  }
  std::vector<double> med(n_params);
  for (std::size_t i = 0; i < n_params; ++i) med[i] = v[i].empty() ? NAN : median(v[i]);
  return {med, complete};
}

}  // namespace halfback::study::report
