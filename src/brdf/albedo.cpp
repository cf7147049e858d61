#include "halfback/brdf/albedo.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

namespace halfback {

namespace {

constexpr std::size_t kBlock = 4096;  // strata drawn and evaluated at once

// The running sums of the stratum estimates.
struct Sums {
  double s[3] = {0, 0, 0}, s2[3] = {0, 0, 0};
  std::size_t measured = 0, total = 0;
  void add(const Rgb& v) {
    ++total;
    if (!std::isfinite(v.r + v.g + v.b)) return;  // missing: not part of the average
    ++measured;
    const double c[3] = {v.r, v.g, v.b};
    for (int k = 0; k < 3; ++k) {
      s[k] += c[k];
      s2[k] += c[k] * c[k];
    }
  }
  AlbedoEstimate estimate(double scale) const {
    if (measured == 0) {
      const double nan = std::numeric_limits<double>::quiet_NaN();
      return {{nan, nan, nan}, {nan, nan, nan}, 0.0};
    }
    const double m = double(measured);
    double mean[3], se[3];
    for (int k = 0; k < 3; ++k) {
      mean[k] = scale * s[k] / m;
      const double var = std::max(0.0, s2[k] / m - (s[k] / m) * (s[k] / m));
      se[k] = scale * std::sqrt(var / m);
    }
    return {{mean[0], mean[1], mean[2]}, {se[0], se[1], se[2]}, m / double(total)};
  }
};

// Uniform on the unit disk (r = √u, φ = 2πv), lifted to the hemisphere: pdf = cos θo / π.
Vec3<double> cosine_direction(double u, double v) {
  const double r = std::sqrt(u), phi = 2 * std::numbers::pi * v;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1 - u))};
}

// The strata [first, first + count) of the n × n grid, in row order: their jittered points.
void jittered(int n, std::size_t first, std::size_t count, std::mt19937_64& rng,
              std::vector<double>& u, std::vector<double>& v) {
  std::uniform_real_distribution<double> jitter(0, 1);
  u.resize(count);
  v.resize(count);
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t s = first + k;
    u[k] = (double(s / std::size_t(n)) + jitter(rng)) / n;
    v[k] = (double(s % std::size_t(n)) + jitter(rng)) / n;
  }
}

AlbedoEstimate by_cosine(const Brdf& brdf, const Vec3<double>& wi, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const std::size_t strata = std::size_t(n) * std::size_t(n);
  std::vector<double> u, v;
  std::vector<DirPair<double>> pairs;
  std::vector<Rgb> values;
  Sums sums;
  for (std::size_t first = 0; first < strata; first += kBlock) {
    const std::size_t m = std::min(kBlock, strata - first);
    jittered(n, first, m, rng, u, v);
    pairs.resize(m);
    for (std::size_t k = 0; k < m; ++k) pairs[k] = {wi, cosine_direction(u[k], v[k])};
    values.resize(m);
    brdf.eval_batch(pairs, values);
    for (const Rgb& x : values) sums.add(x);
  }
  return sums.estimate(std::numbers::pi);
}

// The balance heuristic's estimate of one stratum from one cosine sample and one BRDF sample:
// Σ ρ cos θo / (p_cos + p_brdf) over the two (0 for a sample with no density or below the
// horizon).
AlbedoEstimate by_mis(const Brdf& brdf, const Vec3<double>& wi, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const std::size_t strata = std::size_t(n) * std::size_t(n);
  std::vector<double> u, v, bu, bv;
  std::vector<Vec3<double>> from(kBlock, wi);
  std::vector<BrdfSample> drawn(kBlock);
  std::vector<DirPair<double>> pairs, back;
  std::vector<Rgb> values;
  std::vector<double> p_brdf;
  Sums sums;
  for (std::size_t first = 0; first < strata; first += kBlock) {
    const std::size_t m = std::min(kBlock, strata - first);
    jittered(n, first, m, rng, u, v);
    jittered(n, first, m, rng, bu, bv);
    // By reciprocity, the sampler of ωi given ωo draws ωo given ωi when the roles are swapped.
    brdf.sample_batch(std::span(from).first(m), bu, bv, std::span(drawn).first(m));
    pairs.resize(2 * m);
    for (std::size_t k = 0; k < m; ++k) {
      pairs[k] = {wi, cosine_direction(u[k], v[k])};
      const bool ok = drawn[k].pdf > 0 && drawn[k].wi.z > 0;
      pairs[m + k] = {wi, ok ? drawn[k].wi : Vec3<double>{0, 0, 1}};
    }
    values.resize(2 * m);
    brdf.eval_batch(pairs, values);
    back.resize(2 * m);  // the BRDF sampler's density at each ωo: pdf(ωo ← ωi)
    for (std::size_t k = 0; k < 2 * m; ++k) back[k] = {pairs[k].wo, wi};
    p_brdf.resize(2 * m);
    brdf.pdf_batch(back, p_brdf);
    for (std::size_t k = 0; k < m; ++k) {
      Rgb f{0, 0, 0};
      for (const std::size_t i : {k, m + k}) {
        const Vec3<double>& wo = pairs[i].wo;
        if (i == m + k && !(drawn[k].pdf > 0 && drawn[k].wi.z > 0)) continue;
        const double denom = wo.z / std::numbers::pi + p_brdf[i];
        if (!(denom > 0)) continue;
        f = f + values[i] * (wo.z / denom);
      }
      sums.add(f);
    }
  }
  return sums.estimate(1.0);
}

}  // namespace

AlbedoEstimate directional_albedo(const Brdf& brdf, const Vec3<double>& wi, int n,
                                  std::uint64_t seed, AlbedoSampling sampling) {
  // A NaN direction would give NaN-free zeros (every pair invalid), i.e. a plausible wrong answer.
  const double norm2 = wi.x * wi.x + wi.y * wi.y + wi.z * wi.z;
  if (!(std::abs(norm2 - 1) <= 1e-6))
    throw std::invalid_argument(fmt::format(
        "directional albedo: the incident direction ({:g}, {:g}, {:g}) is not a finite unit vector",
        wi.x, wi.y, wi.z));
  if (n < 1 || n > kMaxAlbedoSide)
    throw std::invalid_argument(
        fmt::format("directional albedo: n = {} samples per axis (1 to {})", n, kMaxAlbedoSide));
  if (sampling == AlbedoSampling::automatic)
    sampling = brdf.has_importance_sampling() && brdf.reciprocal() ? AlbedoSampling::mis
                                                                   : AlbedoSampling::cosine;
  if (sampling == AlbedoSampling::mis && !brdf.reciprocal())
    throw std::invalid_argument(
        "directional albedo: MIS draws ωo with the BRDF's sampler of ωi, which needs reciprocity");
  return sampling == AlbedoSampling::mis ? by_mis(brdf, wi, n, seed) : by_cosine(brdf, wi, n, seed);
}

}  // namespace halfback
