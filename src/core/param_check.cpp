#include "halfback/core/param_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string_view>
#include <type_traits>

namespace halfback {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

// Messages without fmt (core links no formatting library): "{}" takes the next argument, and
// "{:.Ng}" or "{:.Nf}" a number in printf's form.
std::string text_of(const std::string& s, const std::string&) {
  return s;
}
std::string text_of(const char* s, const std::string&) {
  return s;
}
std::string text_of(std::string_view s, const std::string&) {
  return std::string(s);
}
template <class N>
requires std::is_arithmetic_v<N> std::string text_of(N v, const std::string& spec) {
  char buf[48];
  if (spec.empty()) {
    if constexpr (std::is_integral_v<N>)
      return std::to_string(v);
    else
      std::snprintf(buf, sizeof buf, "%.6g", double(v));
  } else {
    std::string format(1, '%');
    format.append(spec, 1, std::string::npos);  // ":.3g" -> "%.3g"
    std::snprintf(buf, sizeof buf, format.c_str(), double(v));
  }
  return buf;
}

std::string say(std::string_view pattern) {
  return std::string(pattern);
}
template <class A, class... Rest>
std::string say(std::string_view pattern, const A& a, const Rest&... rest) {
  const std::size_t open = pattern.find('{'), close = pattern.find('}', open);
  if (open == std::string_view::npos || close == std::string_view::npos)
    return std::string(pattern);
  const std::string spec(pattern.substr(open + 1, close - open - 1));
  return std::string(pattern.substr(0, open)) + text_of(a, spec) +
         say(pattern.substr(close + 1), rest...);
}

using Pairs = std::vector<DirPair<double>>;
using Rows = std::vector<double>;  // row-major tuples

double angle_gap(double a, double b) {
  const double d = std::fmod(std::abs(a - b), kTwoPi);
  return std::min(d, kTwoPi - d);
}

double pair_gap(const DirPair<double>& a, const DirPair<double>& b) {
  const double d[6] = {a.wi.x - b.wi.x, a.wi.y - b.wi.y, a.wi.z - b.wi.z,
                       a.wo.x - b.wo.x, a.wo.y - b.wo.y, a.wo.z - b.wo.z};
  double m = 0;
  for (double v : d) m = std::isnan(v) ? INFINITY : std::max(m, std::abs(v));
  return m;
}

std::string pair_text(const DirPair<double>& p) {
  return say("wi = ({:.6g}, {:.6g}, {:.6g}), wo = ({:.6g}, {:.6g}, {:.6g})", p.wi.x, p.wi.y, p.wi.z,
             p.wo.x, p.wo.y, p.wo.z);
}

std::string tuple_text(const double* q, std::size_t d) {
  std::string s = "(";
  for (std::size_t i = 0; i < d; ++i) s += say("{}{:.6g}", i ? ", " : "", q[i]);
  return s + ")";
}

// Uniform pairs in solid angle with both elevations at least z_min (away from grazing, where some
// maps are degenerate by construction).
Pairs random_pairs(std::size_t n, std::uint64_t seed, double z_min) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  auto w = [&] {
    const double z = z_min + (1 - z_min) * u(rng), phi = kTwoPi * u(rng);
    const double r = std::sqrt((1 - z) * (1 + z));
    return Vec3<double>{r * std::cos(phi), r * std::sin(phi), z};
  };
  Pairs p(n);
  for (auto& x : p) x = {w(), w()};
  return p;
}

DirPair<double> rotated(const DirPair<double>& p, double a) {
  const double c = std::cos(a), s = std::sin(a);
  return {detail::rotate_z(p.wi, c, s), detail::rotate_z(p.wo, c, s)};
}

// The checks share the descriptor and the options.
class Checker {
 public:
  Checker(const ParamDescriptor& d, const ParamCheckOptions& o)
      : d_(d), o_(o), pairs_(random_pairs(o.pairs, o.seed, 0.05)) {}

  ParamCheckReport run() {
    ParamCheckReport r;
    r.parameterization = std::string(d_.name());
    r.checks.push_back(vectorized());
    if (!r.checks.back().passed) return r;  // nothing else can be measured
    for (auto check : {&Checker::range, &Checker::round_trip, &Checker::domain, &Checker::jacobian,
                       &Checker::isotropic, &Checker::reciprocity})
      r.checks.push_back((this->*check)());
    return r;
  }

 private:
  Rows forward(const Pairs& p, bool iso) const {
    Rows q(p.size() * (iso ? 3 : 4));
    d_.forward_rows(iso, p.data(), p.size(), q.data());
    return q;
  }
  Pairs inverse(const Rows& q, bool iso, std::vector<std::uint8_t>& ok) const {
    const std::size_t n = q.size() / (iso ? 3 : 4);
    Pairs p(n);
    ok.assign(n, 0);
    d_.inverse_rows(iso, q.data(), n, p.data(), ok.data());
    return p;
  }

  ParamCheck vectorized() const {
    const Pairs few(pairs_.begin(),
                    pairs_.begin() + std::ptrdiff_t(std::min<std::size_t>(97, pairs_.size())));
    for (const bool iso : {false, true}) {
      const Rows q = forward(few, iso);
      for (std::size_t i = 0; i < q.size(); ++i)
        if (!std::isfinite(q[i]))
          return {"vectorized", false,
                  say("the {} forward map gives {} at row {} of {} ({})", iso ? "isotropic" : "4D",
                      q[i], i / (iso ? 3 : 4), few.size(), pair_text(few[i / (iso ? 3 : 4)]))};
    }
    return {"vectorized", true, say("{} rows at once, finite", few.size())};
  }

  ParamCheck round_trip() const {
    std::vector<std::uint8_t> ok;
    const Pairs back = inverse(forward(pairs_, false), false, ok);
    double worst = 0, worst_swapped = INFINITY;
    std::size_t at = 0, refused = 0;
    for (std::size_t i = 0; i < pairs_.size(); ++i) {
      if (!ok[i]) {
        ++refused;
        continue;
      }
      const double e = pair_gap(back[i], pairs_[i]);
      if (e > worst) worst = e, at = i;
      worst_swapped = std::min(worst_swapped, pair_gap(back[i], {pairs_[i].wo, pairs_[i].wi}));
    }
    if (refused > 0)
      return {"round trip", false,
              say("the inverse refuses the forward image of {} of {} valid pairs", refused,
                  pairs_.size())};
    if (worst <= o_.tolerance)
      return {"round trip", true,
              say("pair -> q -> pair within {:.3g} on {} pairs", worst, pairs_.size())};
    const bool swapped = worst_swapped <= o_.tolerance;
    return {"round trip", false,
            swapped
                ? std::string("the inverse returns the pair swapped, (wo, wi) instead of (wi, wo)")
                : say("pair -> q -> pair is off by {:.3g} (tolerance {:.3g}) at {}", worst,
                      o_.tolerance, pair_text(pairs_[at]))};
  }

  ParamCheck range() const {
    const Rows q = forward(pairs_, false);
    const auto axes = d_.axes(false);
    for (std::size_t i = 0; i < q.size(); ++i) {
      const Axis& a = axes[i % 4];
      const double v = q[i], slack = 1e-9 * (a.hi - a.lo);
      const bool in = a.kind == AxisKind::azimuth ? v >= a.lo && v < a.hi
                                                  : v >= a.lo - slack && v <= a.hi + slack;
      if (!in)
        return {"range", false,
                say("coordinate {} ('{}') is {:.9g}, outside its declared range [{:.6g}, "
                    "{:.6g}{}, at {}",
                    i % 4, a.column, v, a.lo, a.hi, a.kind == AxisKind::azimuth ? ")" : "]",
                    pair_text(pairs_[i / 4]))};
    }
    return {"range", true, "every coordinate of the forward images in its declared range"};
  }

  // Uniform tuples of the box of the declared ranges.
  Rows box_tuples(std::size_t n, bool iso, std::uint64_t seed, double& volume) const {
    const auto axes = d_.axes(iso);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    Rows q(n * axes.size());
    volume = 1;
    for (const Axis& a : axes) volume *= a.hi - a.lo;
    for (std::size_t i = 0; i < q.size(); ++i) {
      const Axis& a = axes[i % axes.size()];
      q[i] = a.lo + u(rng) * (a.hi - a.lo);
    }
    return q;
  }

  ParamCheck domain() const {
    double volume = 0;
    const Rows q = box_tuples(o_.box_samples / 4, false, o_.seed + 1, volume);
    std::vector<std::uint8_t> ok, ok2;
    const Pairs p = inverse(q, false, ok);
    Pairs valid;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (!ok[i]) continue;
      for (const Vec3<double>& w : {p[i].wi, p[i].wo})
        if (!(std::abs(detail::dot(w, w) - 1) <= 1e-9 && w.z >= 0))
          return {"domain", false,
                  say("the inverse accepts {} but gives {}", tuple_text(&q[4 * i], 4),
                      pair_text(p[i]))};
      valid.push_back(p[i]);
    }
    if (valid.empty())
      return {"domain", false, "the inverse accepts no tuple of the box of the declared ranges"};
    const Pairs again = inverse(forward(valid, false), false, ok2);
    std::size_t off = 0;
    for (std::size_t i = 0; i < valid.size(); ++i)
      off += !ok2[i] || pair_gap(again[i], valid[i]) > 1e-6;
    const bool passed = double(off) <= 1e-3 * double(valid.size());
    return {"domain", passed,
            say("{:.1f} % of the box valid; q -> pair -> q -> pair moved {} of {} pairs by "
                "more than 1e-6",
                100.0 * double(valid.size()) / double(p.size()), off, valid.size())};
  }

  // sqrt(det(AᵀA)) of the 6×4 central differences of the inverse at q: the volume element.
  double fd_volume(const double* q, double step) const {
    Rows qs;
    for (int d = 0; d < 4; ++d)
      for (const double s : {step, -step}) {
        qs.insert(qs.end(), q, q + 4);
        qs[qs.size() - 4 + std::size_t(d)] += s;
      }
    std::vector<std::uint8_t> ok;
    const Pairs p = inverse(qs, false, ok);
    double a[4][6];  // the columns of the derivative
    for (int d = 0; d < 4; ++d) {
      if (!ok[2 * std::size_t(d)] || !ok[2 * std::size_t(d) + 1]) return NAN;
      const DirPair<double>&u = p[2 * std::size_t(d)], &v = p[2 * std::size_t(d) + 1];
      const double diff[6] = {u.wi.x - v.wi.x, u.wi.y - v.wi.y, u.wi.z - v.wi.z,
                              u.wo.x - v.wo.x, u.wo.y - v.wo.y, u.wo.z - v.wo.z};
      for (int r = 0; r < 6; ++r) a[d][r] = diff[r] / (2 * step);
    }
    return gram_volume(a);
  }

  // Points of the forward images well inside their ranges, where differences do not straddle.
  Rows interior_points() const {
    const Pairs p = random_pairs(o_.jacobian_points * 4, o_.seed + 2, 0.1);
    const Rows q = forward(p, false);
    const auto axes = d_.axes(false);
    Rows inside;
    for (std::size_t i = 0; i < p.size() && inside.size() < 4 * o_.jacobian_points; ++i) {
      bool ok = true;
      for (std::size_t c = 0; c < 4; ++c) {
        const Axis& a = axes[c];
        const double margin = 0.03 * (a.hi - a.lo), v = q[4 * i + c];
        ok = ok && v > a.lo + margin && v < a.hi - margin &&
             (a.kind == AxisKind::azimuth || std::abs(v) > margin);
      }
      if (ok) inside.insert(inside.end(), &q[4 * i], &q[4 * i] + 4);
    }
    return inside;
  }

  ParamCheck jacobian() const {
    const Rows q = interior_points();
    const std::size_t n = q.size() / 4;
    std::vector<double> j(n);
    d_.jacobian_rows(false, q.data(), n, j.data());
    std::size_t off = 0, compared = 0;
    double worst = 0;
    std::size_t at = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double fd = fd_volume(&q[4 * i], 1e-6);
      if (!std::isfinite(fd)) continue;
      ++compared;
      const double rel = std::abs(j[i] - fd) / std::max(std::abs(fd), 1e-3);
      if (rel > worst) worst = rel, at = i;
      off += !(rel <= 1e-4);
    }
    if (compared < n / 2 || compared == 0)
      return {"jacobian", false, "too few interior points to compare J with finite differences"};
    if (double(off) > 0.01 * double(compared))
      return {"jacobian", false,
              say("J differs from the finite-difference volume by {:.3g} (relative) at "
                  "{} ({} of {} points beyond 1e-4)",
                  worst, tuple_text(&q[4 * at], 4), off, compared)};
    return integrals(say("finite differences within {:.2g} at {} points", worst, compared));
  }

  // ∫ J 1[valid] dq = (2π)², ∫ J zi zo 1[valid] dq = π², over the box of the ranges.
  ParamCheck integrals(const std::string& fd) const {
    double volume = 0;
    const Rows q = box_tuples(o_.box_samples, false, o_.seed + 3, volume);
    const std::size_t n = q.size() / 4;
    std::vector<std::uint8_t> ok;
    const Pairs p = inverse(q, false, ok);
    std::vector<double> j(n);
    d_.jacobian_rows(false, q.data(), n, j.data());
    double s[2] = {}, s2[2] = {};
    for (std::size_t i = 0; i < n; ++i) {
      if (!ok[i]) continue;
      const double v[2] = {j[i] * volume, j[i] * volume * p[i].wi.z * p[i].wo.z};
      for (int k = 0; k < 2; ++k) s[k] += v[k], s2[k] += v[k] * v[k];
    }
    const double target[2] = {kTwoPi * kTwoPi, std::numbers::pi * std::numbers::pi};
    std::string text = fd;
    bool passed = true;
    for (int k = 0; k < 2; ++k) {
      const double mean = s[k] / double(n);
      const double se = std::sqrt(std::max(0.0, s2[k] / double(n) - mean * mean) / double(n));
      const bool ok_k = std::abs(mean - target[k]) <= 4 * se + 0.005 * target[k];
      passed = passed && ok_k;
      text += say("; ∫ J{} = {:.4g} ± {:.2g} ({} {:.4g})", k ? " cos θi cos θo" : "", mean, se,
                  ok_k ? "expected" : "NOT the expected", target[k]);
    }
    return {"jacobian", passed, text};
  }

  ParamCheck isotropic() const {
    std::mt19937_64 rng(o_.seed + 4);
    std::uniform_real_distribution<double> u(0, kTwoPi);
    Pairs turned(pairs_.size());
    for (std::size_t i = 0; i < pairs_.size(); ++i) turned[i] = rotated(pairs_[i], u(rng));
    const Rows a = forward(pairs_, true), b = forward(turned, true);
    const auto axes = d_.axes(true);
    for (std::size_t i = 0; i < a.size(); ++i) {
      const bool az = axes[i % 3].kind == AxisKind::azimuth;
      const double gap = az ? angle_gap(a[i], b[i]) : std::abs(a[i] - b[i]);
      if (!(gap <= 1e-7))
        return {"isotropic", false,
                say("the isotropic coordinate {} changes by {:.3g} when {} is rotated "
                    "about n",
                    i % 3, gap, pair_text(pairs_[i / 3]))};
    }
    std::vector<std::uint8_t> ok;
    const Pairs back = inverse(a, true, ok);
    for (std::size_t i = 0; i < back.size(); ++i) {
      const DirPair<double>&p = pairs_[i], &r = back[i];
      const double inv_p[3] = {p.wi.z, p.wo.z, detail::dot(p.wi, p.wo)};
      const double inv_r[3] = {r.wi.z, r.wo.z, detail::dot(r.wi, r.wo)};
      const double cross_p = p.wi.x * p.wo.y - p.wi.y * p.wo.x;
      const double cross_r = r.wi.x * r.wo.y - r.wi.y * r.wo.x;
      double gap = std::abs(cross_p - cross_r);
      for (int k = 0; k < 3; ++k) gap = std::max(gap, std::abs(inv_p[k] - inv_r[k]));
      if (!ok[i] || !(gap <= 1e-6))
        return {"isotropic", false,
                say("the isotropic inverse is not a rotation of the pair (off by {:.3g}) "
                    "at {}",
                    gap, pair_text(p))};
    }
    return {"isotropic", true, "rotation invariant; the inverse is a rotation of the pair"};
  }

  ParamCheck reciprocity() const {
    const Rows q = forward(pairs_, false);
    Rows r(q.size());
    for (std::size_t i = 0; i < pairs_.size(); ++i) {
      const Tuple4<double> t = d_.reciprocal({q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]});
      std::copy(t.begin(), t.end(), r.begin() + std::ptrdiff_t(4 * i));
    }
    std::vector<std::uint8_t> ok;
    const Pairs p = inverse(r, false, ok);
    for (std::size_t i = 0; i < p.size(); ++i)
      if (!ok[i] || !(pair_gap(p[i], {pairs_[i].wo, pairs_[i].wi}) <= 1e-7))
        return {
            "reciprocity", false,
            say("the reciprocity map does not give the swapped pair at {}", pair_text(pairs_[i]))};
    return {"reciprocity", true, "the reciprocity map gives the swapped pair"};
  }

  const ParamDescriptor& d_;
  const ParamCheckOptions& o_;
  Pairs pairs_;
};

}  // namespace

double gram_volume(const double (&a)[4][6]) {
  double g[4][4] = {};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int r = 0; r < 6; ++r) g[i][j] += a[i][r] * a[j][r];
  double det = 1;  // Gaussian elimination with partial pivoting
  for (int c = 0; c < 4; ++c) {
    int piv = c;
    for (int r = c + 1; r < 4; ++r)
      if (std::abs(g[r][c]) > std::abs(g[piv][c])) piv = r;
    if (piv != c) std::swap(g[piv], g[c]), det = -det;
    det *= g[c][c];
    if (g[c][c] == 0) return 0;
    for (int r = c + 1; r < 4; ++r) {
      const double f = g[r][c] / g[c][c];
      for (int k = c; k < 4; ++k) g[r][k] -= f * g[c][k];
    }
  }
  return std::sqrt(std::abs(det));
}

bool ParamCheckReport::passed() const {
  return std::all_of(checks.begin(), checks.end(), [](const ParamCheck& c) { return c.passed; });
}

std::string ParamCheckReport::first_failure() const {
  for (const ParamCheck& c : checks)
    if (!c.passed) return parameterization + ": " + c.name + ": " + c.detail;
  return {};
}

std::string ParamCheckReport::text() const {
  std::string s;
  for (const ParamCheck& c : checks)
    s += say("{} {}: {}\n", c.passed ? "ok    " : "FAILED", c.name, c.detail);
  return s;
}

ParamCheckReport check_parameterization(const ParamDescriptor& param,
                                        const ParamCheckOptions& options) {
  return Checker(param, options).run();
}

}  // namespace halfback
