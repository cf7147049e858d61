// Statistics helpers for the sampling tests: a χ² goodness-of-fit test of sampled directions
// against a pdf integrated by quadrature over cells of (cos θ, φ), and sampler checks shared by
// the model and renderer tests.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "halfback/brdf/brdf.hpp"

namespace halfback::render::testing {

struct DirSample {
  Vec3<double> dir;
  double pdf;  // 0: no sample
};

// Wilson–Hilferty: the standard normal deviate of a χ² statistic with k degrees of freedom.
inline double chi2_z(double chi2, double k) {
  const double a = 2 / (9 * k);
  return (std::cbrt(chi2 / k) - (1 - a)) / std::sqrt(a);
}

struct Chi2Result {
  double chi2 = 0, dof = 0, z = 0;
  double integral = 0;        // ∫ pdf over the domain (quadrature)
  double valid_fraction = 0;  // of the samples
};

// Samples `n` directions, bins them into theta_bins × phi_bins cells of (cos θ, φ) over the upper
// hemisphere (or the sphere when `sphere`), and compares with N ∫_cell pdf (sub-quadrature of
// sub² points per cell). Cells expected to get fewer than 5 are pooled; failed samples form a
// bin of their own, expected N (1 − ∫ pdf).
//
// A pdf with an integrable singularity (a piecewise-constant density in polar coordinates has one
// at their pole) defeats the quadrature near it: the cells within `cap_deg` of `singular` (when
// cap_deg > 0) are pooled with the failed samples, and that bin's expectation is the rest of the
// mass, N (1 − Σ other cells).
inline Chi2Result chi2_test(const std::function<DirSample(double, double)>& sample,
                            const std::function<double(const Vec3<double>&)>& pdf, int n,
                            bool sphere = false, int theta_bins = 16, int phi_bins = 32,
                            int sub = 12, std::uint64_t seed = 7, Vec3<double> singular = {0, 0, 1},
                            double cap_deg = 0) {
  const double pi = std::numbers::pi;
  const double z_lo = sphere ? -1 : 0;
  auto cell_of = [&](const Vec3<double>& d) {
    const double phi = std::atan2(d.y, d.x) + pi;
    int i = int((d.z - z_lo) / (1 - z_lo) * theta_bins);
    int j = int(phi / (2 * pi) * phi_bins);
    i = std::clamp(i, 0, theta_bins - 1);
    j = std::clamp(j, 0, phi_bins - 1);
    return i * phi_bins + j;
  };
  const int cells = theta_bins * phi_bins;
  std::vector<double> expected(std::size_t(cells) + 1, 0), observed(std::size_t(cells) + 1, 0);
  const double dz = (1 - z_lo) / theta_bins, dphi = 2 * pi / phi_bins;
  double integral = 0;
  const double cos_cap = std::cos(cap_deg * pi / 180);
  std::vector<char> in_cap(std::size_t(cells) + 1, 0);
  in_cap[std::size_t(cells)] = 1;
  for (int i = 0; i < theta_bins; ++i)
    for (int j = 0; j < phi_bins; ++j) {
      double sum = 0;
      for (int a = 0; a < sub; ++a)
        for (int b = 0; b < sub; ++b) {
          const double z = z_lo + (i + (a + 0.5) / sub) * dz;
          const double phi = (j + (b + 0.5) / sub) * dphi - pi;
          const double s = std::sqrt(std::max(0.0, 1 - z * z));
          const Vec3<double> d{s * std::cos(phi), s * std::sin(phi), z};
          sum += pdf(d);
          if (cap_deg > 0 && d.x * singular.x + d.y * singular.y + d.z * singular.z > cos_cap)
            in_cap[std::size_t(i * phi_bins + j)] = 1;
        }
      const double p = sum / (sub * sub) * dz * dphi;
      expected[std::size_t(i * phi_bins + j)] = p;
      integral += p;
    }
  // The failed samples and the cells of the cap: the rest of the mass.
  double rest = 1;
  for (int c = 0; c < cells; ++c)
    if (!in_cap[std::size_t(c)]) rest -= expected[std::size_t(c)];
  for (int c = 0; c < cells; ++c)
    if (in_cap[std::size_t(c)]) expected[std::size_t(c)] = 0;
  expected[std::size_t(cells)] = std::max(0.0, rest);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  int valid = 0;
  for (int k = 0; k < n; ++k) {
    const DirSample s = sample(u(rng), u(rng));
    if (s.pdf > 0) {
      ++valid;
      const int c = cell_of(s.dir);
      observed[in_cap[std::size_t(c)] ? std::size_t(cells) : std::size_t(c)] += 1;
    } else {
      observed[std::size_t(cells)] += 1;
    }
  }
  Chi2Result r;
  r.integral = integral;  // includes the cap, where it is least accurate
  r.valid_fraction = double(valid) / n;
  double pooled_e = 0, pooled_o = 0;
  int bins = 0;
  for (std::size_t c = 0; c < expected.size(); ++c) {
    const double e = expected[c] * n;
    if (e < 5) {
      pooled_e += e;
      pooled_o += observed[c];
      continue;
    }
    r.chi2 += (observed[c] - e) * (observed[c] - e) / e;
    ++bins;
  }
  if (pooled_e >= 5) {
    r.chi2 += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
    ++bins;
  } else {
    // Too little expected mass to test as a bin: it must not hold many samples either.
    EXPECT_LE(pooled_o, 5 + 5 * std::sqrt(5.0)) << "samples in cells the pdf gives ~no mass";
  }
  r.dof = std::max(1, bins - 1);
  r.z = chi2_z(r.chi2, r.dof);
  return r;
}

}  // namespace halfback::render::testing
