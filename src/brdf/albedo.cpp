#include "halfback/brdf/albedo.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

namespace halfback {

AlbedoEstimate directional_albedo(const Brdf& brdf, const Vec3<double>& wi, int n,
                                  std::uint64_t seed) {
  // A NaN direction would give NaN-free zeros (every pair invalid), i.e. a plausible wrong answer.
  const double norm2 = wi.x * wi.x + wi.y * wi.y + wi.z * wi.z;
  if (!(std::abs(norm2 - 1) <= 1e-6))
    throw std::invalid_argument(fmt::format(
        "directional albedo: the incident direction ({:g}, {:g}, {:g}) is not a finite unit vector",
        wi.x, wi.y, wi.z));
  if (n < 1)
    throw std::invalid_argument(fmt::format("directional albedo: n = {} samples per axis", n));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> jitter(0, 1);
  std::vector<DirPair<double>> pairs;
  pairs.reserve(std::size_t(n) * std::size_t(n));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      // Uniform on the unit disk (r = √u, φ = 2πv), lifted to the hemisphere: pdf = cos θo / π.
      const double u = (i + jitter(rng)) / n, v = (j + jitter(rng)) / n;
      const double r = std::sqrt(u), phi = 2 * std::numbers::pi * v;
      const Vec3<double> wo{r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1 - u))};
      pairs.push_back({wi, wo});
    }
  std::vector<Rgb> values(pairs.size());
  brdf.eval_batch(pairs, values);
  // Strata are equal-weight; the spread of the per-stratum values bounds the error from above.
  double s[3] = {0, 0, 0}, s2[3] = {0, 0, 0};
  std::size_t measured = 0;
  for (const Rgb& v : values) {
    if (!std::isfinite(v.r + v.g + v.b)) continue;  // missing: not part of the average
    ++measured;
    const double c[3] = {v.r, v.g, v.b};
    for (int k = 0; k < 3; ++k) {
      s[k] += c[k];
      s2[k] += c[k] * c[k];
    }
  }
  if (measured == 0) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {{nan, nan, nan}, {nan, nan, nan}, 0.0};
  }
  const double m = double(measured), pi = std::numbers::pi;
  double mean[3], se[3];
  for (int k = 0; k < 3; ++k) {
    mean[k] = pi * s[k] / m;
    const double var = std::max(0.0, s2[k] / m - (s[k] / m) * (s[k] / m));
    se[k] = pi * std::sqrt(var / m);
  }
  return {{mean[0], mean[1], mean[2]}, {se[0], se[1], se[2]}, m / double(values.size())};
}

}  // namespace halfback
