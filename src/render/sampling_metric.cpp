#include "halfback/render/sampling_metric.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>
#include <numbers>
#include <random>

namespace halfback::render {

namespace {

std::vector<Vec3<double>> outgoing_directions(const Brdf& brdf, const SamplingMetricOptions& o) {
  std::vector<Vec3<double>> wo;
  const double lo = std::cos(89.0 * std::numbers::pi / 180);
  const int phis = brdf.isotropic() ? 1 : std::max(1, o.phi_count);
  for (int t = 0; t < o.theta_count; ++t) {
    const double c = 1 - (t + 0.5) / o.theta_count * (1 - lo), s = std::sqrt(1 - c * c);
    for (int p = 0; p < phis; ++p) {
      const double phi = 2 * std::numbers::pi * p / phis;
      wo.push_back({s * std::cos(phi), s * std::sin(phi), c});
    }
  }
  return wo;
}

// The estimates f of one ωo, in luminance.
std::vector<double> estimates(const Brdf& brdf, const Brdf& sampler, const Vec3<double>& wo,
                              std::size_t n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3<double>> wos(n, wo);
  std::vector<double> u1(n), u2(n);
  for (std::size_t k = 0; k < n; ++k) u1[k] = u(rng), u2[k] = u(rng);
  std::vector<BrdfSample> s(n);
  sampler.sample_batch(wos, u1, u2, s);
  std::vector<DirPair<double>> pairs(n);
  for (std::size_t k = 0; k < n; ++k)
    pairs[k] = {s[k].pdf > 0 ? s[k].wi : Vec3<double>{0, 0, 1}, wo};
  std::vector<Rgb> rho(n);
  brdf.eval_batch(pairs, rho);
  std::vector<double> f(n, 0.0);
  for (std::size_t k = 0; k < n; ++k)
    if (s[k].pdf > 0 && s[k].wi.z > 0) f[k] = rho[k].luminance() * s[k].wi.z / s[k].pdf;
  return f;
}

OutgoingEstimate moments(const Vec3<double>& wo, const std::vector<double>& f) {
  const auto n = double(f.size());
  double mean = 0;
  for (double x : f) mean += x;
  mean /= n;
  double m2 = 0, m4 = 0;
  for (double x : f) {
    const double d = (x - mean) * (x - mean);
    m2 += d;
    m4 += d * d;
  }
  m2 /= n;
  m4 /= n;
  const double variance = m2 * n / (n - 1);
  return {wo, mean, variance, std::sqrt(std::max(0.0, m4 - m2 * m2) / n)};
}

// The calling thread's CPU time: the measurement below runs on one thread, and the CPU time of a
// thread does not grow while other processes hold the cores (wall-clock time under load made the
// efficiencies, and the tests that compare them, vary by two orders of magnitude).
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace

SamplingMeasure measure_sampling(const Brdf& brdf, const Brdf& sampler,
                                 const SamplingMetricOptions& o) {
  SamplingMeasure m;
  std::mt19937_64 rng(o.seed);
  const double t0 = thread_cpu_seconds();
  for (const Vec3<double>& wo : outgoing_directions(brdf, o))
    m.per_wo.push_back(
        moments(wo, estimates(brdf, sampler, wo, std::max<std::size_t>(2, o.samples), rng)));
  const double seconds = thread_cpu_seconds() - t0;
  m.seconds_per_sample = seconds / double(m.per_wo.size() * std::max<std::size_t>(2, o.samples));
  double sum = 0, err2 = 0;
  std::size_t counted = 0;
  for (const OutgoingEstimate& e : m.per_wo) {
    if (!(e.mean > 0)) continue;  // nothing reflected toward this ωo: no relative variance
    sum += e.variance / (e.mean * e.mean);
    err2 += (e.variance_error / (e.mean * e.mean)) * (e.variance_error / (e.mean * e.mean));
    ++counted;
  }
  m.relative_variance = counted ? sum / double(counted) : 0;
  m.relative_variance_error = counted ? std::sqrt(err2) / double(counted) : 0;
  return m;
}

double relative_efficiency(const SamplingMeasure& a, const SamplingMeasure& b) {
  // A variance below the rounding of the estimates (Lambert by the cosine) counts as that floor,
  // so that two exact samplers are equally efficient rather than 0/0.
  constexpr double kFloor = 1e-20;
  const double cost_a = std::max(a.relative_variance, kFloor) * a.seconds_per_sample;
  const double cost_b = std::max(b.relative_variance, kFloor) * b.seconds_per_sample;
  if (!std::isfinite(cost_a)) return 0;
  return cost_b / cost_a;
}

TabulationOptions tabulation_for_memory(Space param, std::size_t bytes) {
  // slices × radial × azimuthal = r/2 × r × 2r = r³ cells of 20 bytes (the CDF and probability
  // of a cell, 16 bytes, and its guide entry, 4).
  const double r = std::cbrt(double(bytes) / 20.0);
  TabulationOptions t;
  t.param = param;
  t.radial = std::max(4, int(std::lround(r)));
  t.azimuthal = 2 * t.radial;
  t.theta_slices = std::max(2, t.radial / 2);
  t.aniso_theta_slices = t.aniso_phi_slices =
      std::max(2, int(std::lround(std::sqrt(t.theta_slices * 2.0))));
  return t;
}

}  // namespace halfback::render
