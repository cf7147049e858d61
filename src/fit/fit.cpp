// The fitter: model parsing against the registry, the sample layout, the losses' residuals, the
// Ceres problem (one parameter block per term, bound-aware forward differences) and the starts.
#include "halfback/fit/fit.hpp"

#include <ceres/ceres.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <set>

#include "halfback/core/batch.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::fit {

std::string_view name_of(Loss loss) {
  switch (loss) {
    case Loss::ngan:
      return "ngan";
    case Loss::low_e1:
      return "low-e1";
    case Loss::low_e2:
      return "low-e2";
    case Loss::cube_root:
      return "cube-root";
    case Loss::bieron_l2:
      return "bieron-l2";
    case Loss::bieron_log:
      return "bieron-log";
    case Loss::nielsen:
      return "nielsen";
    case Loss::log:
      break;
  }
  return "log";
}

std::optional<Loss> parse_loss(std::string_view name) {
  for (Loss l : kLosses)
    if (name_of(l) == name) return l;
  return std::nullopt;
}

std::string loss_names() {
  std::string s;
  for (Loss l : kLosses) {
    if (!s.empty()) s += ", ";  // appended piece by piece: GCC 12's false -Wrestrict (bug 105329)
    s += name_of(l);
  }
  return s;
}

// ---- Sample layout -------------------------------------------------------------------------

namespace {

double radical_inverse(std::size_t i, std::size_t base) {
  double inv = 1.0 / double(base), f = inv, r = 0;
  for (; i > 0; i /= base, f *= inv) r += f * double(i % base);
  return r;
}

}  // namespace

Samples halfdiff_samples(std::size_t n) {
  if (n == 0) throw std::invalid_argument("the number of samples must be positive");
  const Form iso{*space_from_name("halfdiff"), true}, dirs{Space::dirs, false};
  Samples s;
  s.pairs.reserve(n);
  double total = 0;
  // At most a few times n points: about 60 % of the box lies in the hemisphere.
  for (std::size_t i = 1; s.pairs.size() < n && i < 16 * n + 64; ++i) {
    const double q[3] = {radical_inverse(i, 2) * std::numbers::pi / 2,
                         radical_inverse(i, 3) * std::numbers::pi / 2,
                         radical_inverse(i, 5) * std::numbers::pi};
    double d[6], jac = 0;
    if (!convert_one<double>(iso, dirs, q, d, &jac)) continue;
    if (!(d[2] > 0 && d[5] > 0 && std::isfinite(jac) && jac > 0)) continue;
    s.pairs.push_back({{d[0], d[1], d[2]}, {d[3], d[4], d[5]}});
    s.weight.push_back(jac);
    s.cos_i.push_back(d[2]);
    total += jac;
  }
  const double scale = double(s.weight.size()) / total;
  for (double& w : s.weight) w *= scale;
  return s;
}

// ---- Models --------------------------------------------------------------------------------

namespace {

// Parameters that switch a model's form rather than tune it: held at their default (Schlick
// Fresnel on the microfacet models) unless the model spec gives them (docs/fit.md).
bool held_by_rule(std::string_view model, std::string_view param) {
  return (model == "ggx" || model == "beckmann") && (param == "eta" || param == "k");
}

// Whether `p` is a grey value whose channels (p_r, p_g, p_b, defaulting to it) the model has.
bool has_channels(const ModelInfo& info, const ModelParam& p) {
  int n = 0;
  for (const ModelParam& q : info.params)
    if (q.default_from == p.name &&
        (q.name == p.name + "_r" || q.name == p.name + "_g" || q.name == p.name + "_b"))
      ++n;
  return n == 3;
}

const ModelParam* find_param(const ModelInfo& info, std::string_view name) {
  for (const ModelParam& p : info.params)
    if (p.name == name) return &p;
  return nullptr;
}

double default_of(const ModelInfo& info, const ModelParam& p) {
  const ModelParam* src = p.default_from.empty() ? &p : find_param(info, p.default_from);
  return src ? src->default_value : p.default_value;
}

// The terms of "a+b:k=v" ('+' followed by a lowercase letter separates terms, as load_sum).
std::vector<std::string_view> split_terms(std::string_view spec) {
  std::vector<std::string_view> terms;
  std::size_t start = 0;
  for (std::size_t i = 0; i + 1 < spec.size(); ++i)
    if (spec[i] == '+' && spec[i + 1] >= 'a' && spec[i + 1] <= 'z') {
      terms.push_back(spec.substr(start, i - start));
      start = i + 1;
    }
  terms.push_back(spec.substr(start));
  return terms;
}

struct TermSpec {
  std::string name;
  std::vector<std::pair<std::string, double>> given;
};

TermSpec parse_term(std::string_view text, const ModelRegistry& registry) {
  if (text.empty()) throw std::invalid_argument("empty model term");
  // The registry validates names, keys and ranges, with its own messages.
  (void)registry.create(text);
  TermSpec t;
  const std::size_t colon = text.find(':');
  t.name = std::string(text.substr(0, colon));
  const ModelInfo* info = registry.find(t.name);
  if (colon == std::string_view::npos) return t;
  std::string_view rest = text.substr(colon + 1);
  while (!rest.empty()) {
    const std::size_t comma = rest.find(',');
    const std::string_view item = rest.substr(0, comma);
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    const std::size_t eq = item.find('=');
    const std::string key =
        eq == std::string_view::npos ? info->params.at(0).name : std::string(item.substr(0, eq));
    const std::string value(eq == std::string_view::npos ? item : item.substr(eq + 1));
    const ModelParam* p = find_param(*info, key);
    if (!p->choices.empty()) {
      const auto it = std::find(p->choices.begin(), p->choices.end(), value);
      t.given.emplace_back(key, double(it - p->choices.begin()));
    } else {
      t.given.emplace_back(key, std::stod(value));  // the registry has checked it
    }
  }
  return t;
}

}  // namespace

Model parse_model(std::string_view text) {
  const ModelRegistry& registry = model_registry();
  Model m;
  for (std::string_view term_text : split_terms(text)) {
    const TermSpec t = parse_term(term_text, registry);
    const ModelInfo& info = *registry.find(t.name);
    const std::size_t term = m.terms.size();
    m.terms.push_back(t.name);
    for (const ModelParam& p : info.params) {
      const auto given = std::find_if(t.given.begin(), t.given.end(),
                                      [&](const auto& g) { return g.first == p.name; });
      Param out{term, p.name, default_of(info, p), p.min, p.max, false};
      if (given != t.given.end()) {
        out.value = given->second;
        m.params.push_back(out);
        continue;
      }
      // Fitted: numeric parameters that are neither a grey value with channels, nor one that
      // follows another (alpha_x after alpha: the fitted models are isotropic), nor held by rule.
      // A channel whose grey value is given follows it (held, not written).
      const ModelParam* source =
          p.default_from.empty() ? nullptr : find_param(info, p.default_from);
      const bool channel = source && has_channels(info, *source);
      const bool source_given =
          source && std::any_of(t.given.begin(), t.given.end(),
                                [&](const auto& g) { return g.first == source->name; });
      if (source_given) continue;
      if (!p.choices.empty() || has_channels(info, p) || (!p.default_from.empty() && !channel) ||
          held_by_rule(t.name, p.name))
        continue;
      out.fitted = true;
      m.params.push_back(out);
    }
  }
  return m;
}

namespace {

std::string term_spec(const Model& m, std::size_t term) {
  std::string s = m.terms[term];
  char sep = ':';
  for (const Param& p : m.params)
    if (p.term == term) {
      s += fmt::format("{}{}={}", sep, p.name, p.value);  // shortest form that reads back exactly
      sep = ',';
    }
  return s;
}

}  // namespace

std::string spec_of(const Model& m) {
  std::string s;
  for (std::size_t t = 0; t < m.terms.size(); ++t) {
    if (t) s += '+';
    s += term_spec(m, t);
  }
  return s;
}

// ---- Losses --------------------------------------------------------------------------------

namespace {

// The residual of one channel of one sample (docs/fit.md, "Losses"): model value m, target t,
// cos θi ci, cos θo co, sqrt of the sample's solid-angle weight sw.
double residual(Loss loss, double m, double t, double ci, double co, double sw) {
  switch (loss) {
    case Loss::ngan:
      return sw * ci * (m - t);
    case Loss::low_e1:
      return ci * (m - t);
    case Loss::low_e2:
      return std::log1p(ci * std::max(m, 0.0)) - std::log1p(ci * t);
    case Loss::cube_root:
      return sw * (std::cbrt(ci * m) - std::cbrt(ci * t));
    case Loss::bieron_l2:
      return sw * std::sqrt(co) * ci * (m - t);
    case Loss::bieron_log:
      return sw * std::sqrt(co) * (std::log1p(ci * std::max(m, 0.0)) - std::log1p(ci * t));
    case Loss::nielsen: {
      // The study's error space (study/metrics.hpp): ln(1 + ρ c / ε), c = max(cos θi cos θo, 0.01).
      constexpr double kEps = 1e-3;
      const double c = std::max(ci * co, 0.01);
      return sw * std::sqrt(ci * co) *
             (std::log1p(c * std::max(m, 0.0) / kEps) - std::log1p(c * t / kEps));
    }
    case Loss::log:
      break;
  }
  return sw * std::sqrt(ci * co) * (std::log1p(std::max(m, 0.0)) - std::log1p(t));
}

constexpr std::size_t kGrain = 2048;

// ρ of `brdf` at every sample pair, over the project's parallel loop.
void eval_all(const Brdf& brdf, const Samples& s, std::span<Rgb> out, int threads) {
  parallel_for(
      s.pairs.size(), kGrain,
      [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) out[i] = brdf.eval(s.pairs[i]);
      },
      threads);
}

void residuals(Loss loss, const Samples& s, std::span<const Rgb> target, std::span<const Rgb> model,
               double* r, int threads) {
  parallel_for(
      s.pairs.size(), kGrain,
      [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
          const double c = s.cos_i[i], co = s.pairs[i].wo.z, sw = std::sqrt(s.weight[i]);
          r[3 * i] = residual(loss, model[i].r, target[i].r, c, co, sw);
          r[3 * i + 1] = residual(loss, model[i].g, target[i].g, c, co, sw);
          r[3 * i + 2] = residual(loss, model[i].b, target[i].b, c, co, sw);
        }
      },
      threads);
}

double mean_square(std::span<const double> r) {
  double sum = 0;
  for (double x : r) sum += x * x;
  return sum / double(r.size());
}

}  // namespace

double loss_value(std::span<const Rgb> target_rgb, const Brdf& model, Loss loss,
                  const Samples& samples, int threads) {
  std::vector<Rgb> m(samples.pairs.size());
  eval_all(model, samples, m, threads);
  std::vector<double> r(3 * m.size());
  residuals(loss, samples, target_rgb, m, r.data(), threads);
  return mean_square(r);
}

int channel_of(const Param& p) {
  const std::size_t n = p.name.size();
  if (n < 3 || p.name[n - 2] != '_') return -1;
  switch (p.name[n - 1]) {
    case 'r':
      return 0;
    case 'g':
      return 1;
    case 'b':
      return 2;
    default:
      return -1;
  }
}

// ---- The least-squares problem -------------------------------------------------------------

namespace {

// The fitted parameters of each term (indices into Model::params), one Ceres block per term
// that has any.
struct Blocks {
  std::vector<std::size_t> term;                 // the term of each block
  std::vector<std::vector<std::size_t>> params;  // its fitted parameters
};

Blocks blocks_of(const Model& m) {
  Blocks b;
  for (std::size_t t = 0; t < m.terms.size(); ++t) {
    std::vector<std::size_t> ps;
    for (std::size_t i = 0; i < m.params.size(); ++i)
      if (m.params[i].term == t && m.params[i].fitted) ps.push_back(i);
    if (!ps.empty()) b.term.push_back(t), b.params.push_back(std::move(ps));
  }
  return b;
}

// A block's fitted parameters in groups that one difference serves: the three channels of a colour
// parameter change disjoint residuals, so one evaluation with all three shifted gives three
// columns of the Jacobian.
std::vector<std::vector<std::size_t>> difference_groups(const Model& m,
                                                        const std::vector<std::size_t>& params) {
  std::vector<std::vector<std::size_t>> groups;
  std::vector<std::string> stems;  // of each group; empty for a parameter alone
  const auto joins = [&](std::size_t g, const Param& p) {
    return !stems[g].empty() && p.name.starts_with(stems[g]) &&
           p.name.size() == stems[g].size() + 2 &&
           std::none_of(groups[g].begin(), groups[g].end(), [&](std::size_t k) {
             return channel_of(m.params[params[k]]) == channel_of(p);
           });
  };
  for (std::size_t j = 0; j < params.size(); ++j) {
    const Param& p = m.params[params[j]];
    std::size_t g = 0;
    while (g < groups.size() && !(channel_of(p) >= 0 && joins(g, p))) ++g;
    if (g == groups.size()) {
      groups.emplace_back();
      stems.push_back(channel_of(p) >= 0 ? p.name.substr(0, p.name.size() - 2) : std::string());
    }
    groups[g].push_back(j);
  }
  return groups;
}

// Residuals of the loss at the block values, and their Jacobian by forward differences (backward
// at the upper bound), each difference re-evaluating only the term its parameters belong to, the
// channels of a colour parameter in one difference. Derivatives are numeric because the models
// are not templated (docs/fit.md). Evaluate() is called by one thread at a time (the solver runs
// single-threaded; the evaluations use the project's parallel loop), so scratch is shared.
class FitCost final : public ceres::CostFunction {
 public:
  FitCost(const Model& model, const Blocks& blocks, const Samples& samples,
          std::span<const Rgb> target, Loss loss, int threads)
      : model_(model),
        blocks_(blocks),
        s_(samples),
        target_(target),
        loss_(loss),
        threads_(threads),
        fixed_(samples.pairs.size(), Rgb{0, 0, 0}),
        terms_(blocks.term.size(), std::vector<Rgb>(samples.pairs.size())),
        sum_(samples.pairs.size()),
        shifted_(samples.pairs.size()),
        shifted_sum_(samples.pairs.size()),
        shifted_r_(3 * samples.pairs.size()) {
    set_num_residuals(int(3 * samples.pairs.size()));
    for (const auto& ps : blocks.params) {
      mutable_parameter_block_sizes()->push_back(int(ps.size()));
      groups_.push_back(difference_groups(model, ps));
    }
    // Terms without a fitted parameter are constant: their sum once.
    std::vector<Rgb> v(s_.pairs.size());
    for (std::size_t t = 0; t < model.terms.size(); ++t) {
      if (std::find(blocks.term.begin(), blocks.term.end(), t) != blocks.term.end()) continue;
      eval_all(*load_brdf(term_spec(model, t)), s_, v, threads_);
      for (std::size_t i = 0; i < v.size(); ++i) fixed_[i] = fixed_[i] + v[i];
    }
  }

  bool Evaluate(double const* const* values, double* r, double** jacobians) const override {
    try {
      return evaluate(values, r, jacobians);
    } catch (const std::exception&) {
      return false;  // a value the model refuses: Ceres shrinks the step
    }
  }

 private:
  // The term of block b at block values v (others' parameters as in model_), into `out`.
  void term_values(std::size_t b, const double* v, std::vector<Rgb>& out) const {
    Model m = model_;
    for (std::size_t j = 0; j < blocks_.params[b].size(); ++j)
      m.params[blocks_.params[b][j]].value = v[j];
    eval_all(*load_brdf(term_spec(m, blocks_.term[b])), s_, out, threads_);
  }

  bool evaluate(double const* const* values, double* r, double** jacobians) const {
    const std::size_t n = s_.pairs.size(), nb = blocks_.term.size();
    sum_ = fixed_;
    for (std::size_t b = 0; b < nb; ++b) {
      term_values(b, values[b], terms_[b]);
      for (std::size_t i = 0; i < n; ++i) sum_[i] = sum_[i] + terms_[b][i];
    }
    residuals(loss_, s_, target_, sum_, r, threads_);
    if (!jacobians) return true;
    for (std::size_t b = 0; b < nb; ++b)
      if (jacobians[b])
        for (const auto& group : groups_[b])
          difference_columns(b, values[b], group, r, jacobians[b]);
    return true;
  }

  // The Jacobian's columns of the parameters `group` of block b (indices into the block), from
  // one shifted evaluation of the term. A colour channel's column is zero off its channel.
  void difference_columns(std::size_t b, const double* x, const std::vector<std::size_t>& group,
                          const double* r, double* jac) const {
    const std::size_t np = blocks_.params[b].size(), n = s_.pairs.size();
    std::vector<double> v(x, x + np), h(np, 0.0);
    for (std::size_t j : group) {
      const Param& p = model_.params[blocks_.params[b][j]];
      // Forward (backward at the upper bound); about sqrt(machine epsilon) relative, or of the
      // range where x is near 0.
      h[j] = 1e-7 * std::max(std::abs(x[j]), 1e-3 * std::max(1.0, p.max - p.min));
      if (x[j] + h[j] > p.max) h[j] = -h[j];
      v[j] = x[j] + h[j];
    }
    term_values(b, v.data(), shifted_);
    for (std::size_t i = 0; i < n; ++i) shifted_sum_[i] = sum_[i] - terms_[b][i] + shifted_[i];
    residuals(loss_, s_, target_, shifted_sum_, shifted_r_.data(), threads_);
    for (std::size_t j : group) {
      const int channel = group.size() > 1 ? channel_of(model_.params[blocks_.params[b][j]]) : -1;
      for (std::size_t k = 0; k < 3 * n; ++k)
        jac[k * np + j] =
            channel < 0 || int(k % 3) == channel ? (shifted_r_[k] - r[k]) / h[j] : 0.0;
    }
  }

  const Model& model_;
  const Blocks& blocks_;
  const Samples& s_;
  std::span<const Rgb> target_;
  Loss loss_;
  int threads_;
  std::vector<Rgb> fixed_;
  std::vector<std::vector<std::vector<std::size_t>>> groups_;  // per block
  mutable std::vector<std::vector<Rgb>> terms_;                // scratch, per block
  mutable std::vector<Rgb> sum_, shifted_, shifted_sum_;
  mutable std::vector<double> shifted_r_;
};

struct Solved {
  Model model;
  double loss = std::numeric_limits<double>::infinity();
  int iterations = 0;
};

// One Levenberg–Marquardt run from `start` (its fitted values), within the registry's bounds.
Solved solve_from(const Model& start, const Samples& s, std::span<const Rgb> target,
                  const FitOptions& o, double function_tolerance = 1e-9) {
  const Blocks blocks = blocks_of(start);
  std::vector<std::vector<double>> x(blocks.term.size());
  for (std::size_t b = 0; b < x.size(); ++b)
    for (std::size_t i : blocks.params[b])
      x[b].push_back(std::clamp(start.params[i].value, start.params[i].min, start.params[i].max));
  ceres::Problem problem;
  std::vector<double*> ptrs;
  for (auto& v : x) ptrs.push_back(v.data());
  problem.AddResidualBlock(new FitCost(start, blocks, s, target, o.loss, o.threads), nullptr, ptrs);
  for (std::size_t b = 0; b < x.size(); ++b)
    for (std::size_t j = 0; j < x[b].size(); ++j) {
      const Param& p = start.params[blocks.params[b][j]];
      problem.SetParameterLowerBound(x[b].data(), int(j), p.min);
      problem.SetParameterUpperBound(x[b].data(), int(j), p.max);
    }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  options.max_num_iterations = o.max_iterations;
  options.function_tolerance = function_tolerance;
  options.gradient_tolerance = 1e-12;
  options.parameter_tolerance = 1e-10;
  options.logging_type = ceres::SILENT;
  options.num_threads = 1;  // the residuals run on the project's parallel loop
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  Solved out{start, 0, int(summary.iterations.size())};
  for (std::size_t b = 0; b < x.size(); ++b)
    for (std::size_t j = 0; j < x[b].size(); ++j)
      out.model.params[blocks.params[b][j]].value = x[b][j];
  out.loss = loss_value(target, *load_brdf(spec_of(out.model)), o.loss, s, o.threads);
  return out;
}

// ---- Starts --------------------------------------------------------------------------------

// The roughness that gives a GGX peak of the target's half-width: ρ along θh (θd = 0) falls to
// half its height above the floor at tan θh = α sqrt(√2 − 1). Nullopt without a peak at θh = 0.
std::optional<double> roughness_from_peak(const Brdf& target) {
  const Form iso{*space_from_name("halfdiff"), true}, dirs{Space::dirs, false};
  std::vector<double> lum;
  for (int deg = 0; deg <= 85; ++deg) {
    const double q[3] = {deg * std::numbers::pi / 180, 0, 0};
    double d[6];
    if (!convert_one<double>(iso, dirs, q, d)) return std::nullopt;
    const Rgb v = target.eval({{d[0], d[1], d[2]}, {d[3], d[4], d[5]}});
    lum.push_back((v.r + v.g + v.b) / 3);
  }
  const double floor = *std::min_element(lum.begin(), lum.end());
  const double height = lum[0] - floor;
  if (!(height > 0) || *std::max_element(lum.begin(), lum.end()) > lum[0]) return std::nullopt;
  for (std::size_t deg = 1; deg < lum.size(); ++deg)
    if (lum[deg] - floor <= height / 2)
      return std::tan(double(deg) * std::numbers::pi / 180) / std::sqrt(std::sqrt(2.0) - 1);
  return std::nullopt;
}

// Whether a fitted parameter shapes the lobe (not a colour channel): the grid varies those.
bool is_shape(const Param& p) {
  return channel_of(p) < 0;
}

// The value at fraction q of [min, max], geometric when the range spans decades.
double at_quantile(const Param& p, double q) {
  const double lo = p.min > 0 ? p.min : p.max * 1e-6;
  if (p.max > 100 * lo) return std::exp(std::log(lo) + q * (std::log(p.max) - std::log(lo)));
  return p.min + q * (p.max - p.min);
}

// The registry's defaults, α from the target's peak (when there is a target BRDF to look at),
// and the grid.
std::vector<Model> automatic_starts(const Model& m, const Brdf* target) {
  std::vector<Model> starts{m};  // the registry's defaults
  if (const auto alpha = target ? roughness_from_peak(*target) : std::nullopt) {
    Model guess = m;
    for (Param& p : guess.params)
      if (p.fitted && p.name == "alpha") p.value = std::clamp(*alpha, p.min, p.max);
    starts.push_back(guess);
  }
  for (double q : {0.1, 0.3, 0.5, 0.7, 0.9}) {
    Model g = m;
    for (Param& p : g.params)
      if (p.fitted && is_shape(p)) p.value = at_quantile(p, q);
    starts.push_back(g);
  }
  // A start equal to an earlier one (the peak's guess of a model without α is its defaults) would
  // only repeat that run.
  std::vector<Model> distinct;
  for (const Model& s : starts)
    if (std::none_of(distinct.begin(), distinct.end(), [&](const Model& d) {
          return std::equal(d.params.begin(), d.params.end(), s.params.begin(),
                            [](const Param& a, const Param& b) { return a.value == b.value; });
        }))
      distinct.push_back(s);
  return distinct;
}

Model start_from_spec(const Model& m, std::string_view spec) {
  const Model given = parse_model(spec);
  if (given.terms != m.terms)
    throw std::invalid_argument(fmt::format("start '{}': not the terms of the model", spec));
  Model out = m;
  for (const Param& g : given.params) {
    if (g.fitted) continue;  // not given in the start
    auto it = std::find_if(out.params.begin(), out.params.end(),
                           [&](const Param& p) { return p.term == g.term && p.name == g.name; });
    if (it == out.params.end() || !it->fitted)
      throw std::invalid_argument(
          fmt::format("start '{}': '{}' is not a fitted parameter", spec, g.name));
    it->value = g.value;
  }
  return out;
}

// Many starts on many samples: each start runs on a subset of kCoarseSamples (for the Halton
// layout its prefix, itself a layout; for a caller's samples a seeded random subset), then the
// distinct coarse solutions within 5 % of the best loss run again on all samples (docs/fit.md,
// "Starts"). Returns every run.
constexpr std::size_t kCoarseSamples = 4096;
// At most this many basins are refined: on a valley (He's η against its albedo) the starts stop
// in several "basins" a fraction of a percent apart, and each full run costs more than all the
// coarse ones.
constexpr std::size_t kMaxRefined = 2;
// The coarse runs only pick the basins: they stop at a relative change of the loss of 1e-6 (the
// fine run's is 1e-9).
constexpr double kCoarseTolerance = 1e-6;

struct Subset {
  Samples samples;
  std::vector<Rgb> target;
};

// The samples `keep` of `s` with their targets, weights renormalised to mean 1.
Subset subset_of(const Samples& s, std::span<const Rgb> target, std::span<const std::size_t> keep) {
  Subset out;
  double total = 0;
  for (std::size_t i : keep) {
    out.samples.pairs.push_back(s.pairs[i]);
    out.samples.weight.push_back(s.weight[i]);
    out.samples.cos_i.push_back(s.cos_i[i]);
    out.target.push_back(target[i]);
    total += s.weight[i];
  }
  for (double& w : out.samples.weight) w *= double(keep.size()) / total;
  return out;
}

Subset coarse_subset(const Samples& s, std::span<const Rgb> target, bool halton_prefix) {
  std::vector<std::size_t> keep(s.pairs.size());
  std::iota(keep.begin(), keep.end(), std::size_t{0});
  if (!halton_prefix) {  // a partial Fisher–Yates shuffle, seeded: the same subset every run
    std::mt19937_64 rng(20261205);
    for (std::size_t i = 0; i < kCoarseSamples; ++i)
      std::swap(keep[i], keep[i + std::size_t(rng() % (keep.size() - i))]);
    std::sort(keep.begin(), keep.begin() + std::ptrdiff_t(kCoarseSamples));
  }
  keep.resize(kCoarseSamples);
  return subset_of(s, target, keep);
}

// Whether two solutions lie in one basin: every fitted parameter within 5 % (of its value, or of
// 1e-3 of its range near zero). Coarse solutions of one basin differ by about 1 % where the loss
// is flat; one of them is refined.
bool same_basin(const Model& a, const Model& b) {
  for (std::size_t i = 0; i < a.params.size(); ++i) {
    const Param& p = a.params[i];
    const double scale =
        std::max({std::abs(p.value), std::abs(b.params[i].value), 1e-3 * (p.max - p.min)});
    if (p.fitted && std::abs(p.value - b.params[i].value) > 0.05 * scale) return false;
  }
  return true;
}

bool at_bound(const Param& p) {
  const double tol = 1e-12 * (p.max - p.min);
  return p.value <= p.min + tol || p.value >= p.max - tol;
}

// The full solve from a coarse solution. Parameters the coarse solve left at a bound are held
// there (Ceres's steps truncated at a bound shrink its trust region: dozens of iterations of
// creeping otherwise); one whose inward move lowers the loss afterwards is freed and the solve
// resumed (the bound's KKT condition, checked by a difference).
Solved refine(const Model& coarse, const Samples& s, std::span<const Rgb> target,
              const FitOptions& o) {
  Model held = coarse;
  std::vector<std::size_t> pinned;
  for (std::size_t i = 0; i < held.params.size(); ++i)
    if (held.params[i].fitted && at_bound(held.params[i]))
      held.params[i].fitted = false, pinned.push_back(i);
  const bool any_free =
      std::any_of(held.params.begin(), held.params.end(), [](auto& p) { return p.fitted; });
  Solved r = any_free ? solve_from(held, s, target, o) : Solved{held, 0, 0};
  if (!any_free) r.loss = loss_value(target, *load_brdf(spec_of(held)), o.loss, s, o.threads);
  bool freed = false;
  for (std::size_t i : pinned) {
    Param& p = r.model.params[i];
    Model trial = r.model;
    const double step = 1e-6 * (p.max - p.min);
    trial.params[i].value = p.value <= p.min + step ? p.min + step : p.max - step;
    if (loss_value(target, *load_brdf(spec_of(trial)), o.loss, s, o.threads) < r.loss)
      p.fitted = true, freed = true;
  }
  if (freed) {
    const Solved again = solve_from(r.model, s, target, o);
    r = {again.model, again.loss, r.iterations + again.iterations};
  }
  for (std::size_t i : pinned) r.model.params[i].fitted = true;
  return r;
}

std::vector<Solved> solve_starts(const std::vector<Model>& starts, const Samples& s,
                                 std::span<const Rgb> target, bool halton_prefix,
                                 const FitOptions& o) {
  std::vector<Solved> out;
  if (s.pairs.size() <= 2 * kCoarseSamples) {
    for (const Model& start : starts) out.push_back(solve_from(start, s, target, o));
    return out;
  }
  const Subset coarse = coarse_subset(s, target, halton_prefix);
  std::vector<Solved> rough;
  for (const Model& start : starts)
    rough.push_back(solve_from(start, coarse.samples, coarse.target, o, kCoarseTolerance));
  std::sort(rough.begin(), rough.end(), [](auto& a, auto& b) { return a.loss < b.loss; });
  std::vector<const Model*> refined;
  for (const Solved& r : rough) {
    if (refined.size() == kMaxRefined) break;
    if (!(r.loss <= 1.05 * rough.front().loss) && !refined.empty()) break;
    if (std::any_of(refined.begin(), refined.end(),
                    [&](const Model* m) { return same_basin(*m, r.model); }))
      continue;
    refined.push_back(&r.model);
    out.push_back(refine(r.model, s, target, o));
  }
  for (Solved& r : rough)
    out.push_back({r.model, std::numeric_limits<double>::infinity(), r.iterations});
  return out;
}

// ---- The target ----------------------------------------------------------------------------

std::string where(const DirPair<double>& p) {
  return fmt::format("wi = ({:.4f}, {:.4f}, {:.4f}), wo = ({:.4f}, {:.4f}, {:.4f})", p.wi.x, p.wi.y,
                     p.wi.z, p.wo.x, p.wo.y, p.wo.z);
}

// Throws FitDataError unless every sampled value is finite and ≥ 0 and some is > 0.
void check_target(std::span<const Rgb> v, const Samples& s) {
  std::size_t bad = 0, first = 0;
  bool any_positive = false;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const bool ok = std::isfinite(v[i].r) && std::isfinite(v[i].g) && std::isfinite(v[i].b) &&
                    v[i].r >= 0 && v[i].g >= 0 && v[i].b >= 0;
    if (!ok && bad++ == 0) first = i;
    any_positive = any_positive || (ok && (v[i].r > 0 || v[i].g > 0 || v[i].b > 0));
  }
  if (bad)
    throw FitDataError(
        fmt::format("the target BRDF is not finite or negative at {} of {} samples, first at {} "
                    "(rho = {}, {}, {})",
                    bad, v.size(), where(s.pairs[first]), v[first].r, v[first].g, v[first].b));
  if (!any_positive)
    throw FitDataError(fmt::format("the target BRDF is zero at all {} samples", v.size()));
}

}  // namespace

double loss_of(const Brdf& target, const Brdf& model, Loss loss, std::size_t samples, int threads) {
  const Samples s = halfdiff_samples(samples);
  std::vector<Rgb> t(s.pairs.size());
  eval_all(target, s, t, threads);
  check_target(t, s);
  return loss_value(t, model, loss, s, threads);
}

namespace {

Model fittable_model(std::string_view model_spec) {
  Model model = parse_model(model_spec);
  if (std::none_of(model.params.begin(), model.params.end(),
                   [](const Param& p) { return p.fitted; }))
    throw std::invalid_argument(
        fmt::format("model '{}': every parameter is given, nothing to fit", model_spec));
  return model;
}

FitResult best_of(const std::vector<Solved>& solved, std::size_t samples, std::size_t starts,
                  Loss loss, std::chrono::steady_clock::time_point t0) {
  FitResult result;
  for (const Solved& x : solved) result.iterations += x.iterations;
  const Solved& best = *std::min_element(solved.begin(), solved.end(),
                                         [](auto& a, auto& b) { return a.loss < b.loss; });
  result.model = best.model;
  result.spec = spec_of(result.model);
  result.loss = loss;
  result.loss_value = best.loss;
  result.samples = samples;
  result.starts = starts;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace

FitResult fit(const Brdf& target, std::string_view model_spec, const FitOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const Model model = fittable_model(model_spec);
  std::vector<Model> starts;
  for (const std::string& spec : o.starts) starts.push_back(start_from_spec(model, spec));
  if (!target.isotropic())
    throw FitDataError(
        "the target BRDF is anisotropic: the fit samples the isotropic coordinates at one pose "
        "and fits isotropic models (alpha_x = alpha_y), so it refuses anisotropic targets");
  const Samples s = halfdiff_samples(o.samples);
  std::vector<Rgb> t(s.pairs.size());
  eval_all(target, s, t, o.threads);
  check_target(t, s);
  if (starts.empty()) starts = automatic_starts(model, &target);
  return best_of(solve_starts(starts, s, t, true, o), s.pairs.size(), starts.size(), o.loss, t0);
}

FitResult fit_at(const Samples& samples, std::span<const Rgb> values, std::string_view model_spec,
                 const FitOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t n = samples.pairs.size();
  if (n == 0 || values.size() != n || samples.weight.size() != n || samples.cos_i.size() != n)
    throw std::invalid_argument(fmt::format(
        "fit_at: {} pairs, {} weights, {} cosines and {} values: not one of each per pair", n,
        samples.weight.size(), samples.cos_i.size(), values.size()));
  const Model model = fittable_model(model_spec);
  std::vector<Model> starts;
  for (const std::string& spec : o.starts) starts.push_back(start_from_spec(model, spec));
  check_target(values, samples);
  if (starts.empty()) starts = automatic_starts(model, nullptr);
  return best_of(solve_starts(starts, samples, values, false, o), n, starts.size(), o.loss, t0);
}

}  // namespace halfback::fit
