// The fitter: model parsing against the registry, the sample layout, the losses' residuals, the
// Ceres problem (one parameter block per term, bound-aware forward differences) and the starts.
#include "halfback/fit/fit.hpp"

#include <ceres/ceres.h>
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <set>

#include "halfback/brdf/albedo.hpp"
#include "halfback/core/batch.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/fit/sample_limit.hpp"
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
    case Loss::bbm_ngan:
      return "bbm-ngan";
    case Loss::bbm_low_e1:
      return "bbm-low-e1";
    case Loss::bbm_low_e2:
      return "bbm-low-e2";
    case Loss::bbm_bieron_l2:
      return "bbm-bieron-l2";
    case Loss::bbm_bieron_log:
      return "bbm-bieron-log";
    case Loss::bbm_standard_log:
      return "bbm-standard-log";
    case Loss::log:
      break;
  }
  return "log";
}

bool is_bbm(Loss loss) {
  switch (loss) {
    case Loss::bbm_ngan:
    case Loss::bbm_low_e1:
    case Loss::bbm_low_e2:
    case Loss::bbm_bieron_l2:
    case Loss::bbm_bieron_log:
    case Loss::bbm_standard_log:
      return true;
    default:
      return false;
  }
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

std::string_view layout_name(Azimuths azimuths) {
  return azimuths == Azimuths::turned ? kTurnedLayoutName : kLayoutName;
}

namespace {

// v turned about the normal (z) by the angle whose cosine and sine are c and s.
Vec3<double> turned(const Vec3<double>& v, double c, double s) {
  return {c * v.x - s * v.y, s * v.x + c * v.y, v.z};
}

}  // namespace

Samples halfdiff_samples(std::size_t n, Azimuths azimuths) {
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
    DirPair<double> pair{{d[0], d[1], d[2]}, {d[3], d[4], d[5]}};
    if (azimuths == Azimuths::turned) {
      const double phi = 2 * std::numbers::pi * radical_inverse(i, 7);
      pair = {turned(pair.wi, std::cos(phi), std::sin(phi)),
              turned(pair.wo, std::cos(phi), std::sin(phi))};
    }
    s.pairs.push_back(pair);
    s.weight.push_back(jac);
    s.cos_i.push_back(d[2]);
    total += jac;
  }
  const double scale = double(s.weight.size()) / total;
  for (double& w : s.weight) w *= scale;
  return s;
}

// ---- BBM's grid ----------------------------------------------------------------------------

namespace {

bool is_low(Loss loss) {
  return loss == Loss::bbm_low_e1 || loss == Loss::bbm_low_e2;
}

// A grid point (φ, θ) as BBM's spherical::convert makes it, with components of magnitude below
// the machine epsilon set to 0 (BBM's guard against round-off near zero).
Vec3<double> grid_direction(double phi, double theta) {
  const auto snap = [](double x) {
    return std::abs(x) < std::numeric_limits<double>::epsilon() ? 0.0 : x;
  };
  return {snap(std::cos(phi) * std::sin(theta)), snap(std::sin(phi) * std::sin(theta)),
          snap(std::cos(theta))};
}

// The elevations 0, step, ..., π/2 of `n` points (BBM divides by max(n − 1, 1)).
double grid_theta(std::size_t j, std::size_t n) {
  return double(j) * (std::numbers::pi / 2) / double(std::max<std::size_t>(n, 2) - 1);
}

double sin_of(const Vec3<double>& v) {
  return std::sqrt(std::max(1 - v.z * v.z, 0.0));
}

}  // namespace

BbmGrid default_grid(Loss loss) {
  if (is_low(loss)) return {36, 17, 1, 17};
  return {18, 10, 18, 10};
}

Samples bbm_grid_samples(Loss loss, const BbmGrid& g) {
  if (!is_bbm(loss))
    throw std::invalid_argument(
        fmt::format("loss '{}' is not measured on BBM's grid", name_of(loss)));
  if (g.in_phi == 0 || g.in_theta == 0 || g.out_phi == 0 || g.out_theta == 0)
    throw std::invalid_argument("every count of BBM's grid must be positive");
  if (is_low(loss) && g.out_phi != 1)
    throw std::invalid_argument(fmt::format(
        "loss '{}' does not sample the outgoing azimuth: out_phi must be 1", name_of(loss)));
  // The product in floating point first: counts from outside must not wrap around.
  const double pairs =
      double(g.in_phi) * double(g.in_theta) * double(g.out_phi) * double(g.out_theta);
  check_fit_samples(pairs > double(kMaxFitSamples) ? kMaxFitSamples + 1 : std::size_t(pairs),
                    "BBM grid pairs");
  const std::size_t n = std::size_t(pairs);
  Samples s;
  s.pairs.reserve(n);
  s.weight.reserve(n);
  s.cos_i.reserve(n);
  const double two_pi = 2 * std::numbers::pi;
  for (std::size_t a = 0; a < g.in_phi; ++a)
    for (std::size_t b = 0; b < g.in_theta; ++b) {
      const Vec3<double> wi =
          grid_direction(double(a) * two_pi / double(g.in_phi), grid_theta(b, g.in_theta));
      for (std::size_t c = 0; c < g.out_phi; ++c)
        for (std::size_t d = 0; d < g.out_theta; ++d) {
          const Vec3<double> wo =
              grid_direction(double(c) * two_pi / double(g.out_phi), grid_theta(d, g.out_theta));
          s.pairs.push_back({wi, wo});
          s.weight.push_back(is_low(loss) ? sin_of(wi) : sin_of(wi) * sin_of(wo));
          s.cos_i.push_back(std::max(wi.z, 0.0));
        }
    }
  return s;
}

// ---- Models --------------------------------------------------------------------------------

namespace {

// Parameters that switch a model's form rather than tune it: held at their default (Schlick
// Fresnel on the microfacet models) unless the model spec gives them (docs/fit.md).
// Bagher et al.'s normalisation and shadowing constants are held too (BBM marks them dependent:
// the paper derives them from α and p by its own fitted approximations, not restated here).
bool held_by_rule(std::string_view model, std::string_view param) {
  if (model == "bagher-sgd")
    for (std::string_view dependent : {"kscale", "lambda", "c", "k", "theta0"})
      if (param == dependent || (param.size() == dependent.size() + 2 &&
                                 param.starts_with(dependent) && param[dependent.size()] == '_'))
        return true;
  return (model == "ggx" || model == "beckmann") && (param == "eta" || param == "k");
}

// Whether `p` is a grey value whose channels (p_r, p_g, p_b, defaulting to it) the model has;
// or p_red, p_green, p_blue: channels that may drive every channel of ρ (disney's base colour,
// through its tints), which channel_of() does not count as colour channels.
bool has_channels(const ModelInfo& info, const ModelParam& p) {
  int n = 0, long_names = 0;
  for (const ModelParam& q : info.params) {
    if (q.default_from != p.name) continue;
    n += q.name == p.name + "_r" || q.name == p.name + "_g" || q.name == p.name + "_b";
    long_names +=
        q.name == p.name + "_red" || q.name == p.name + "_green" || q.name == p.name + "_blue";
  }
  return n == 3 || long_names == 3;
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

}  // namespace

FitEnergy fitted_energy(std::string_view spec) {
  const BrdfPtr model = load_brdf(spec);
  FitEnergy e;
  for (const double theta_deg : kEnergyAngles) {
    const double t = theta_deg * std::numbers::pi / 180;
    const AlbedoEstimate a =
        directional_albedo(*model, Vec3<double>{std::sin(t), 0, std::cos(t)}, 256);
    const double mean[3] = {a.mean.r, a.mean.g, a.mean.b};
    const double error[3] = {a.standard_error.r, a.standard_error.g, a.standard_error.b};
    for (int c = 0; c < 3; ++c)
      if (mean[c] > e.max_albedo) e = {mean[c], theta_deg, error[c]};
  }
  return e;
}

Model parse_model(std::string_view text) {
  const ModelRegistry& registry = model_registry();
  Model m;
  for (std::string_view term_text : split_terms(text)) {
    if (term_text.empty()) throw std::invalid_argument("empty model term");
    const ParsedModelSpec t = registry.parse(term_text);
    const ModelInfo& info = *t.info;
    const std::size_t term = m.terms.size();
    m.terms.push_back(info.name);
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
      // follows another (alpha_x after alpha: a lobe is isotropic unless alpha_x or alpha_y is
      // given), nor held by rule. A channel whose grey value is given follows it (held, not
      // written). Parameters without effect are held later, on the fit's samples.
      const ModelParam* source =
          p.default_from.empty() ? nullptr : find_param(info, p.default_from);
      const bool channel = source && has_channels(info, *source);
      const bool source_given =
          source && std::any_of(t.given.begin(), t.given.end(),
                                [&](const auto& g) { return g.first == source->name; });
      if (source_given) continue;
      if (!p.choices.empty() || has_channels(info, p) || (!p.default_from.empty() && !channel) ||
          held_by_rule(info.name, p.name))
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

// Term t of `m` as a BRDF; null when the model refuses the values.
BrdfPtr term_brdf(const Model& m, std::size_t t) {
  try {
    return load_brdf(term_spec(m, t));
  } catch (const std::exception&) {
    return nullptr;
  }
}

// `m` with parameter i at `value`.
Model moved(const Model& m, std::size_t i, double value) {
  Model out = m;
  out.params[i].value = value;
  return out;
}

// The values of term t of `m` at `pairs`; empty when the model refuses the values.
std::vector<Rgb> term_values_at(const Model& m, std::size_t t,
                                std::span<const DirPair<double>> pairs) {
  const BrdfPtr b = term_brdf(m, t);
  std::vector<Rgb> v;
  if (!b) return v;
  v.reserve(pairs.size());
  for (const DirPair<double>& p : pairs) v.push_back(b->eval(p));
  return v;
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

// BBM sums its error over the channels and averages over the samples; halfback's loss value is
// the mean over samples and channels: √3 in a bbm_* residual makes the two the same number.
const double kSqrt3 = std::sqrt(3.0);

// The residual of one channel of one sample (docs/fit.md, "Losses"): model value m, target t,
// cos θi ci, cos θo co, sqrt of the sample's weight sw (solid-angle weight on halfback's layout,
// the loss's sine factors on BBM's grid). BBM's log losses do not clamp m at 0: neither do they.
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
    case Loss::bbm_ngan:
    case Loss::bbm_low_e1:
      return kSqrt3 * sw * ci * (m - t);
    case Loss::bbm_low_e2:
    case Loss::bbm_standard_log:
      return kSqrt3 * sw * (std::log1p(ci * m) - std::log1p(ci * t));
    case Loss::bbm_bieron_l2:
      return kSqrt3 * sw * std::sqrt(std::max(co, 0.0)) * ci * (m - t);
    case Loss::bbm_bieron_log:
      return kSqrt3 * sw * std::sqrt(std::max(co, 0.0)) * (std::log1p(ci * m) - std::log1p(ci * t));
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

bool is_missing(const Rgb& v) {
  return std::isnan(v.r) || std::isnan(v.g) || std::isnan(v.b);
}

// loss_value() of the target's measured samples only (defined with usable_samples()).
double measured_loss_value(std::span<const Rgb> target_rgb, const Brdf& model, Loss loss,
                           const Samples& samples, int threads);

}  // namespace

double loss_value(std::span<const Rgb> target_rgb, const Brdf& model, Loss loss,
                  const Samples& samples, int threads) {
  if (std::any_of(target_rgb.begin(), target_rgb.end(), is_missing))
    return measured_loss_value(target_rgb, model, loss, samples, threads);
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

namespace detail {
namespace {
std::atomic<bool> shortcuts_on{true};
}  // namespace
void set_fit_shortcuts(bool on) {
  shortcuts_on = on;
}
bool fit_shortcuts() {
  return shortcuts_on;
}
}  // namespace detail

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
          std::span<const Rgb> target, Loss loss, int threads,
          const std::function<bool()>& cancelled)
      : model_(model),
        blocks_(blocks),
        s_(samples),
        target_(target),
        loss_(loss),
        threads_(threads),
        cancelled_(cancelled),
        fixed_(samples.pairs.size(), Rgb{0, 0, 0}),
        terms_(blocks.term.size(), std::vector<Rgb>(samples.pairs.size())),
        sum_(samples.pairs.size()),
        shifted_(samples.pairs.size()),
        shifted_sum_(samples.pairs.size()),
        shifted_r_(3 * samples.pairs.size()),
        shortcuts_(detail::fit_shortcuts()),
        valid_(blocks.term.size(), false),
        at_(blocks.term.size()) {
    set_num_residuals(int(3 * samples.pairs.size()));
    for (std::size_t b = 0; b < blocks.params.size(); ++b) {
      mutable_parameter_block_sizes()->push_back(int(blocks.params[b].size()));
      groups_.push_back(difference_groups(model, blocks.params[b]));
      scales_.emplace_back();
      for (const auto& group : groups_.back())
        scales_.back().push_back(shortcuts_ && scales_term(b, group));
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

  bool stop() const { return cancelled_ && cancelled_(); }

  // Whether `group` (indices into block b) is the three channels of a parameter to which ρ of the
  // term is proportional, channel by channel (an albedo: ρ_c = a_c X, X not depending on a):
  // checked at up to 256 of the samples, the block's other values at the start, with the channels
  // at two sets of values of different ratios. A model that refuses the values: not a scale.
  bool scales_term(std::size_t b, const std::vector<std::size_t>& group) const {
    if (group.size() != 3) return false;
    const std::vector<std::size_t>& ps = blocks_.params[b];
    Model base = model_, other = model_;
    double ratio[3] = {0, 0, 0};
    for (std::size_t j : group) {
      const Param& p = model_.params[ps[j]];
      const int c = channel_of(p);
      if (c < 0) return false;
      static constexpr double kOther[3] = {0.2, 0.7, 0.1};
      const double u = p.min + 0.4 * (p.max - p.min), w = p.min + kOther[c] * (p.max - p.min);
      if (!(u != 0 && std::isfinite(u) && std::isfinite(w))) return false;
      base.params[ps[j]].value = u;
      other.params[ps[j]].value = w;
      ratio[c] = w / u;
    }
    const std::size_t stride = std::max<std::size_t>(s_.pairs.size() / 256, 1);
    std::vector<DirPair<double>> probe;
    for (std::size_t i = 0; i < s_.pairs.size(); i += stride) probe.push_back(s_.pairs[i]);
    const std::vector<Rgb> u = term_values_at(base, blocks_.term[b], probe),
                           w = term_values_at(other, blocks_.term[b], probe);
    if (u.empty() || w.empty()) return false;
    bool any = false;
    const auto same = [](double a, double b) {
      return std::isfinite(a) && std::abs(a - b) <= 1e-12 * std::max(std::abs(a), std::abs(b));
    };
    for (std::size_t i = 0; i < u.size(); ++i) {
      const double uv[3] = {u[i].r, u[i].g, u[i].b}, wv[3] = {w[i].r, w[i].g, w[i].b};
      for (int c = 0; c < 3; ++c) {
        if (!same(wv[c], uv[c] * ratio[c])) return false;
        any = any || uv[c] != 0;
      }
    }
    return any;
  }

  // Whether the columns of group g of block b at block values x come from the term's values by
  // scaling (scales_term, and no channel at or near 0, where the term is 0 and tells nothing).
  bool scaled(std::size_t b, std::size_t g, const double* x, const double* h) const {
    if (!scales_[b][g]) return false;
    for (std::size_t j : groups_[b][g])
      if (!(std::abs(x[j]) >= std::abs(h[j]))) return false;
    return true;
  }

  // False (a failed evaluation, which ends the solve with the callback below) once cancelled.
  bool evaluate(double const* const* values, double* r, double** jacobians) const {
    const std::size_t n = s_.pairs.size(), nb = blocks_.term.size();
    sum_ = fixed_;
    for (std::size_t b = 0; b < nb; ++b) {
      if (stop()) return false;
      // Ceres evaluates an accepted step twice (its cost, then its Jacobian): a term whose block
      // values are those of its last evaluation is reused, bit for bit.
      const std::size_t np = blocks_.params[b].size();
      if (!(shortcuts_ && valid_[b] && std::equal(values[b], values[b] + np, at_[b].begin()))) {
        valid_[b] = false;
        term_values(b, values[b], terms_[b]);
        at_[b].assign(values[b], values[b] + np);
        valid_[b] = true;
      }
      for (std::size_t i = 0; i < n; ++i) sum_[i] = sum_[i] + terms_[b][i];
    }
    residuals(loss_, s_, target_, sum_, r, threads_);
    // Residuals that are not finite: a failed evaluation (Ceres shrinks its step).
    if (!std::all_of(r, r + 3 * n, [](double x) { return std::isfinite(x); })) return false;
    if (!jacobians) return true;
    for (std::size_t b = 0; b < nb; ++b)
      if (jacobians[b])
        for (std::size_t g = 0; g < groups_[b].size(); ++g) {
          if (stop()) return false;
          difference_columns(b, values[b], g, r, jacobians[b]);
        }
    return true;
  }

  // The Jacobian's columns of the parameters `group` of block b (indices into the block), from
  // one shifted evaluation of the term. A colour channel's column is zero off its channel.
  void difference_columns(std::size_t b, const double* x, std::size_t g, const double* r,
                          double* jac) const {
    const std::vector<std::size_t>& group = groups_[b][g];
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
    if (scaled(b, g, x, h.data())) {
      // ρ of the term is proportional to each channel of the group: shifting channel c by h_c
      // scales the term's channel c by 1 + h_c / x_c, no evaluation needed.
      double f[3] = {0, 0, 0};
      for (std::size_t j : group) f[channel_of(model_.params[blocks_.params[b][j]])] = h[j] / x[j];
      for (std::size_t i = 0; i < n; ++i) {
        const Rgb& t = terms_[b][i];
        shifted_sum_[i] = sum_[i] + Rgb{t.r * f[0], t.g * f[1], t.b * f[2]};
      }
    } else {
      term_values(b, v.data(), shifted_);
      for (std::size_t i = 0; i < n; ++i) shifted_sum_[i] = sum_[i] - terms_[b][i] + shifted_[i];
    }
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
  const std::function<bool()>& cancelled_;  // FitOptions::cancelled: no more evaluations
  std::vector<Rgb> fixed_;
  std::vector<std::vector<std::vector<std::size_t>>> groups_;  // per block
  mutable std::vector<std::vector<Rgb>> terms_;                // scratch, per block
  mutable std::vector<Rgb> sum_, shifted_, shifted_sum_;
  mutable std::vector<double> shifted_r_;
  bool shortcuts_;                         // detail::fit_shortcuts() when made
  std::vector<std::vector<bool>> scales_;  // per block and group: scales_term()
  mutable std::vector<bool> valid_;        // per block: terms_[b] is the term at at_[b]
  mutable std::vector<std::vector<double>> at_;
};

void throw_if_cancelled(const FitOptions& o) {
  if (o.cancelled && o.cancelled()) throw FitCancelled("the fit was cancelled");
}

// Ends a solve at the end of an iteration once FitOptions::cancelled says so.
class CancelCallback final : public ceres::IterationCallback {
 public:
  explicit CancelCallback(const std::function<bool()>& cancelled) : cancelled_(cancelled) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return cancelled_ && cancelled_() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }

 private:
  const std::function<bool()>& cancelled_;
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
  const bool shortcuts = detail::fit_shortcuts();
  ceres::Problem problem;
  std::vector<double*> ptrs;
  for (auto& v : x) ptrs.push_back(v.data());
  throw_if_cancelled(o);
  problem.AddResidualBlock(new FitCost(start, blocks, s, target, o.loss, o.threads, o.cancelled),
                           nullptr, ptrs);
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
  // With bounds, Ceres projects each step and checks it by an Armijo line search; its default cubic
  // interpolation asks for the gradient, a whole Jacobian, at every point it tries. Quadratic
  // interpolation needs values only (detail::set_fit_shortcuts, docs/fit.md).
  if (shortcuts) options.line_search_interpolation_type = ceres::QUADRATIC;
  CancelCallback cancel(o.cancelled);
  options.callbacks.push_back(&cancel);
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  throw_if_cancelled(o);
  Solved out{start, 0, int(summary.iterations.size())};
  for (std::size_t b = 0; b < x.size(); ++b)
    for (std::size_t j = 0; j < x[b].size(); ++j)
      out.model.params[blocks.params[b][j]].value = x[b][j];
  out.loss = loss_value(target, *load_brdf(spec_of(out.model)), o.loss, s, o.threads);
  // A solution whose loss is not a number (a log loss of a model below −1/cos θi, an overflow)
  // loses to every other.
  if (std::isnan(out.loss)) out.loss = std::numeric_limits<double>::infinity();
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

// The samples a fit uses: within reach (θi and θo ≤ max_theta) and measured (no NaN channel),
// their weights scaled back to mean 1; and how many were left out of each kind. Infinite and
// negative values stay, for check_target() to refuse: they are not a missing measurement.
struct Usable {
  Samples samples;
  std::vector<Rgb> target;
  std::size_t missing = 0, out_of_reach = 0;
};

Usable usable_samples(const Samples& s, std::span<const Rgb> t, double max_theta) {
  if (!(max_theta > 0 && max_theta <= std::numbers::pi / 2))
    throw std::invalid_argument(
        fmt::format("max_theta = {} rad: the reach must be in (0, pi/2]", max_theta));
  // cos θ ≥ cos(max_theta), with π/2 keeping every pair (cos(π/2) is 6e-17, not 0).
  const double min_cos = max_theta >= std::numbers::pi / 2 ? 0.0 : std::cos(max_theta);
  Usable u;
  double total = 0;
  for (std::size_t i = 0; i < s.pairs.size(); ++i) {
    const DirPair<double>& p = s.pairs[i];
    if (p.wi.z < min_cos || p.wo.z < min_cos) {
      ++u.out_of_reach;
      continue;
    }
    if (is_missing(t[i])) {
      ++u.missing;
      continue;
    }
    u.samples.pairs.push_back(p);
    u.samples.weight.push_back(s.weight[i]);
    u.samples.cos_i.push_back(s.cos_i[i]);
    u.target.push_back(t[i]);
    total += s.weight[i];
  }
  if (u.target.empty())
    throw FitDataError(fmt::format(
        "no sample left to fit: of {}, {} are out of reach (max_theta = {:.4g} deg) and {} "
        "missing (NaN)",
        s.pairs.size(), u.out_of_reach, max_theta * 180 / std::numbers::pi, u.missing));
  if (u.missing || u.out_of_reach) {
    const double scale = double(u.target.size()) / total;
    for (double& w : u.samples.weight) w *= scale;
  }
  return u;
}

double measured_loss_value(std::span<const Rgb> target_rgb, const Brdf& model, Loss loss,
                           const Samples& samples, int threads) {
  const Usable u = usable_samples(samples, target_rgb, std::numbers::pi / 2);
  return loss_value(u.target, model, loss, u.samples, threads);
}

}  // namespace

double loss_of(const Brdf& target, const Brdf& model, Loss loss, std::size_t samples, int threads,
               std::optional<BbmGrid> grid) {
  const Samples s = is_bbm(loss) ? bbm_grid_samples(loss, grid.value_or(default_grid(loss)))
                                 : halfdiff_samples(samples, model.isotropic() ? Azimuths::canonical
                                                                               : Azimuths::turned);
  std::vector<Rgb> t(s.pairs.size());
  eval_all(target, s, t, threads);
  check_target(t, s);
  return loss_value(t, model, loss, s, threads);
}

// ---- What the model can do: anisotropy, parameters without effect, dead lobes ---------------

namespace {

// Whether moving parameter i to 25 % or 75 % of its range changes its term at `probe` (a value
// the model refuses counts as a change: the parameter matters).
bool has_effect(const Model& m, std::size_t i, std::span<const DirPair<double>> probe) {
  const Param& p = m.params[i];
  const std::vector<Rgb> base = term_values_at(m, p.term, probe);
  for (double q : {0.25, 0.75}) {
    const std::vector<Rgb> v =
        term_values_at(moved(m, i, p.min + q * (p.max - p.min)), p.term, probe);
    if (base.empty() || v != base) return true;
  }
  return false;
}

}  // namespace

bool can_be_anisotropic(const Model& model) {
  const auto anisotropic = [](const Model& m, std::size_t t) {
    const BrdfPtr b = term_brdf(m, t);
    return b && !b->isotropic();
  };
  for (std::size_t t = 0; t < model.terms.size(); ++t)
    if (anisotropic(model, t)) return true;
  for (std::size_t i = 0; i < model.params.size(); ++i) {
    const Param& p = model.params[i];
    if (p.fitted && (anisotropic(moved(model, i, at_quantile(p, 0.1)), p.term) ||
                     anisotropic(moved(model, i, at_quantile(p, 0.9)), p.term)))
      return true;
  }
  return false;
}

Model hold_parameters_without_effect(Model model, const Samples& samples) {
  // 512 pairs spread over the samples (every k-th): a prefix of BBM's grid, ordered by ωi's
  // azimuth, holds no mirror pair, where a sharp lobe is all it is.
  const std::size_t stride = std::max<std::size_t>(samples.pairs.size() / 512, 1);
  std::vector<DirPair<double>> probe;
  for (std::size_t i = 0; i < samples.pairs.size() && probe.size() < 512; i += stride)
    probe.push_back(samples.pairs[i]);
  for (std::size_t i = 0; i < model.params.size(); ++i)
    if (model.params[i].fitted && !has_effect(model, i, probe)) model.params[i].fitted = false;
  return model;
}

namespace {

// Each term's share of the sum's albedo (Σ w cos θi ρ̄ over `s`, ρ̄ the mean of the channels; a
// sum that is 0 everywhere: every share 0), the loss of the sum without it, and whether it is a
// dead lobe (FitResult::dead). Each term is evaluated twice: nothing per term is kept.
void report_terms(FitResult& r, const Samples& s, std::span<const Rgb> target, int threads) {
  const std::size_t n = s.pairs.size(), terms = r.model.terms.size();
  std::vector<double> integral(terms, 0.0);
  std::vector<Rgb> v(n), sum(n, Rgb{0, 0, 0}), others(n);
  for (std::size_t t = 0; t < terms; ++t) {
    eval_all(*load_brdf(term_spec(r.model, t)), s, v, threads);
    for (std::size_t i = 0; i < n; ++i) {
      integral[t] += s.weight[i] * s.cos_i[i] * (v[i].r + v[i].g + v[i].b) / 3;
      sum[i] = sum[i] + v[i];
    }
  }
  const double total = std::accumulate(integral.begin(), integral.end(), 0.0);
  std::vector<double> res(3 * n);
  for (std::size_t t = 0; t < terms; ++t) {
    eval_all(*load_brdf(term_spec(r.model, t)), s, v, threads);
    for (std::size_t i = 0; i < n; ++i) others[i] = sum[i] - v[i];
    residuals(r.loss, s, target, others, res.data(), threads);
    r.albedo_share.push_back(total > 0 ? integral[t] / total : 0.0);
    r.loss_without.push_back(mean_square(res));
    r.dead.push_back(r.albedo_share.back() < kDeadLobeShare ||
                     r.loss_without.back() <= (1 + kDeadLobeLoss) * r.loss_value);
  }
}

bool any_fitted(const Model& model) {
  return std::any_of(model.params.begin(), model.params.end(),
                     [](const Param& p) { return p.fitted; });
}

Model fittable_model(std::string_view model_spec) {
  Model model = parse_model(model_spec);
  if (!any_fitted(model))
    throw std::invalid_argument(
        fmt::format("model '{}': every parameter is given, nothing to fit", model_spec));
  return model;
}

// `model` with its parameters without effect at `s` held; std::invalid_argument when none is left.
Model effective_model(const Model& model, const Samples& s, std::string_view model_spec) {
  Model out = hold_parameters_without_effect(model, s);
  if (!any_fitted(out))
    throw std::invalid_argument(fmt::format(
        "model '{}': no parameter left to fit (the others are given, held by rule or have no "
        "effect, docs/fit.md)",
        model_spec));
  return out;
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
  check_fit_samples(o.samples, "samples");  // every caller's bound, not only the CLI's
  const Model parsed = fittable_model(model_spec);
  const Azimuths azimuths = can_be_anisotropic(parsed) ? Azimuths::turned : Azimuths::canonical;
  const Samples s = is_bbm(o.loss) ? bbm_grid_samples(o.loss, o.grid.value_or(default_grid(o.loss)))
                                   : halfdiff_samples(o.samples, azimuths);
  const Model model = effective_model(parsed, s, model_spec);
  std::vector<Model> starts;
  for (const std::string& spec : o.starts) starts.push_back(start_from_spec(model, spec));
  if (!target.isotropic())
    throw FitDataError(
        "the target BRDF is anisotropic: the fit samples the isotropic coordinates and fits "
        "models whose roughness is isotropic unless given, so it refuses anisotropic targets");
  std::vector<Rgb> all(s.pairs.size());
  eval_all(target, s, all, o.threads);
  const Usable u = usable_samples(s, all, o.max_theta);
  check_target(u.target, u.samples);
  throw_if_cancelled(o);
  if (starts.empty()) starts = automatic_starts(model, &target);
  // The kept samples in the layout's order: a prefix of them is still spread as the layout's.
  // BBM's grid is ordered by ωi's azimuth: its prefix is not a layout, a random subset is.
  FitResult r = best_of(solve_starts(starts, u.samples, u.target, !is_bbm(o.loss), o),
                        u.target.size(), starts.size(), o.loss, t0);
  r.layout = is_bbm(o.loss) ? kBbmGridLayoutName : layout_name(azimuths);
  r.missing = u.missing;
  r.out_of_reach = u.out_of_reach;
  report_terms(r, u.samples, u.target, o.threads);
  return r;
}

FitResult fit_at(const Samples& samples, std::span<const Rgb> values, std::string_view model_spec,
                 const FitOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t n = samples.pairs.size();
  if (n == 0 || values.size() != n || samples.weight.size() != n || samples.cos_i.size() != n)
    throw std::invalid_argument(fmt::format(
        "fit_at: {} pairs, {} weights, {} cosines and {} values: not one of each per pair", n,
        samples.weight.size(), samples.cos_i.size(), values.size()));
  const Model model = effective_model(fittable_model(model_spec), samples, model_spec);
  std::vector<Model> starts;
  for (const std::string& spec : o.starts) starts.push_back(start_from_spec(model, spec));
  const Usable u = usable_samples(samples, values, o.max_theta);
  check_target(u.target, u.samples);
  if (starts.empty()) starts = automatic_starts(model, nullptr);
  FitResult r = best_of(solve_starts(starts, u.samples, u.target, false, o), u.target.size(),
                        starts.size(), o.loss, t0);
  r.layout = "given";
  r.missing = u.missing;
  r.out_of_reach = u.out_of_reach;
  report_terms(r, u.samples, u.target, o.threads);
  return r;
}

}  // namespace halfback::fit
