// The guide-table sampling of Distribution1D against the binary search it replaced: the same cell
// and remapped number for every u (edges of buckets and cells included), the same χ² test of the
// drawn cells against the weights, and the batch 2D sampling equal to one sample at a time.
#include "halfback/render/distribution.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "support/test_stats.hpp"

namespace halfback::render {
namespace {

// Weight lists that stress a guide table: zeros (runs of them, at both ends), one cell with
// almost all of the mass, smooth and random ones, a single cell.
std::vector<std::vector<double>> weight_lists() {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::vector<double>> lists{{1}, {0, 0, 3, 0}, {1, 0, 3, 0, 4}};
  std::vector<double> spike(1000, 1e-6);
  spike[613] = 1e6;
  lists.push_back(spike);
  std::vector<double> runs(512);
  for (std::size_t i = 0; i < runs.size(); ++i) runs[i] = (i / 37) % 2 ? u(rng) : 0;
  lists.push_back(runs);
  std::vector<double> random(777);
  for (double& w : random) w = u(rng) < 0.2 ? 50 * u(rng) : u(rng);
  lists.push_back(random);
  return lists;
}

// The numbers where a guide table can go wrong: bucket edges k / n (and the doubles next to them),
// the CDF's own values, 0 and the largest double below 1, and random ones.
std::vector<double> probe_numbers(const Distribution1D& d) {
  std::vector<double> us{0.0, 0x1.fffffffffffffp-1, 0.5};
  const std::size_t n = d.size();
  for (std::size_t k = 0; k <= n; ++k) {
    const double e = double(k) / double(n);
    for (double v : {e, std::nextafter(e, 0.0), std::nextafter(e, 1.0)})
      if (v >= 0 && v < 1) us.push_back(v);
  }
  double cdf = 0;
  for (std::size_t i = 0; i < n; ++i) {
    cdf += d.probability(i);
    if (cdf < 1) us.push_back(cdf);
  }
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 20000; ++i) us.push_back(u(rng));
  return us;
}

TEST(Distribution, GuideTableEqualsBinarySearch) {
  for (const auto& w : weight_lists()) {
    const Distribution1D d(w);
    for (double u : probe_numbers(d)) {
      const auto a = d.sample(u), b = d.sample_by_search(u);
      ASSERT_EQ(a.index, b.index) << "u = " << u << ", " << w.size() << " cells";
      ASSERT_EQ(a.probability, b.probability);
      ASSERT_EQ(a.remapped, b.remapped);
      ASSERT_GT(a.probability, 0) << "a cell of weight 0 was drawn";
    }
  }
}

// χ² of the cells drawn with n random numbers against n × probability, for a sampling function.
template <class Sample>
double chi2_z_of(const Distribution1D& d, Sample sample, int n) {
  std::vector<double> count(d.size(), 0.0);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < n; ++i) ++count[sample(u(rng)).index];
  double chi2 = 0, pooled = 0, pooled_count = 0;
  int dof = -1;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const double e = n * d.probability(i);
    if (e == 0) {
      EXPECT_EQ(count[i], 0) << "cell " << i << " has weight 0";
      continue;
    }
    if (e < 5) {  // small cells pooled into one bin
      pooled += e;
      pooled_count += count[i];
      continue;
    }
    chi2 += (count[i] - e) * (count[i] - e) / e;
    ++dof;
  }
  if (pooled > 0) {
    chi2 += (pooled_count - pooled) * (pooled_count - pooled) / pooled;
    ++dof;
  }
  return dof > 0 ? testing::chi2_z(chi2, dof) : 0;
}

TEST(Distribution, GuideTableChiSquareLikeBinarySearch) {
  for (const auto& w : weight_lists()) {
    const Distribution1D d(w);
    const double z_guide = chi2_z_of(
        d, [&](double u) { return d.sample(u); }, 200000);
    const double z_search = chi2_z_of(
        d, [&](double u) { return d.sample_by_search(u); }, 200000);
    EXPECT_LT(z_guide, 4.5) << w.size() << " cells";
    EXPECT_LT(z_search, 4.5) << w.size() << " cells";
    EXPECT_EQ(z_guide, z_search);  // the same cells from the same numbers
  }
}

TEST(Distribution, BatchSampleEqualsOneAtATime) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> w(24 * 40);
  for (double& x : w) x = u(rng) < 0.3 ? 0 : u(rng);
  for (std::size_t c = 0; c < 40; ++c) w[5 * 40 + c] = 0;  // a black row
  const Distribution2D d(24, 40, w);
  std::vector<double> u1(1000), u2(1000);
  for (std::size_t i = 0; i < u1.size(); ++i) {
    u1[i] = u(rng);
    u2[i] = u(rng);
  }
  std::vector<Distribution2D::Sample> out(u1.size());
  d.sample(u1, u2, out);
  for (std::size_t i = 0; i < u1.size(); ++i) {
    const auto s = d.sample(u1[i], u2[i]);
    ASSERT_EQ(out[i].row, s.row);
    ASSERT_EQ(out[i].col, s.col);
    ASSERT_EQ(out[i].probability, s.probability);
    ASSERT_EQ(out[i].remapped_row, s.remapped_row);
    ASSERT_EQ(out[i].remapped_col, s.remapped_col);
  }
}

}  // namespace
}  // namespace halfback::render
