#include "halfback/brdf/rho_bound.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "halfback/core/param.hpp"

namespace halfback {

namespace {

constexpr double kDeg = std::numbers::pi / 180;
constexpr int kProbeSide = 32;

std::vector<DirPair<double>> probe_pairs(bool isotropic) {
  const double min_z = std::cos(89 * kDeg);
  std::vector<DirPair<double>> pairs;
  const int n_phi_h = isotropic ? 1 : 4;
  pairs.reserve(std::size_t(n_phi_h) * kProbeSide * kProbeSide * kProbeSide);
  for (int a = 0; a < n_phi_h; ++a)
    for (int i = 0; i < kProbeSide; ++i)
      for (int j = 0; j < kProbeSide; ++j)
        for (int k = 0; k < kProbeSide; ++k) {
          const double u = double(i) / (kProbeSide - 1);
          const Tuple4<double> q{u * u * 89 * kDeg, a * std::numbers::pi / 4,
                                 double(j) / (kProbeSide - 1) * 89 * kDeg,
                                 double(k) / kProbeSide * 2 * std::numbers::pi};
          const Solved<double> s = inverse<HalfDiff>(q);
          if (s.in_domain && s.pair.wi.z >= min_z && s.pair.wo.z >= min_z) pairs.push_back(s.pair);
        }
  return pairs;
}

}  // namespace

std::string rho_above_bound(double rho, std::string_view where, std::string_view quantity) {
  const std::string value = std::isinf(rho) ? fmt::format("{} overflows to infinity", quantity)
                                            : fmt::format("{} = {:g} sr⁻¹", quantity, rho);
  return fmt::format("{}{}{}, above the bound of {:g} sr⁻¹ on a BRDF's value", value,
                     where.empty() ? "" : " at ", where, kMaxRho);
}

std::string describe_halfdiff(const DirPair<double>& pair) {
  const Tuple4<double> q = HalfDiff::forward(pair);
  std::string s = fmt::format("θh = {:.4g}°, θd = {:.4g}°, φd = {:.4g}°", q[0] / kDeg, q[2] / kDeg,
                              q[3] / kDeg);
  if (q[1] != 0) s += fmt::format(", φh = {:.4g}°", q[1] / kDeg);
  return s;
}

RhoProbe probe_rho(const Brdf& brdf) {
  const std::vector<DirPair<double>> pairs = probe_pairs(brdf.isotropic());
  std::vector<Rgb> rho(pairs.size());
  brdf.eval_batch(pairs, rho);
  RhoProbe r;
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    r.largest = std::max(r.largest, rho[p].max_channel());
    if (!r.excess && !rho_within_bound(rho[p])) r.excess = RhoExcess{pairs[p], rho[p]};
  }
  return r;
}

std::optional<RhoExcess> find_rho_above_bound(const Brdf& brdf) {
  return probe_rho(brdf).excess;
}

void require_rho_bound(const Brdf& brdf, const std::string& why) {
  if (const auto excess = find_rho_above_bound(brdf))
    throw std::invalid_argument(fmt::format(
        "{}: {} ({})", brdf.name(),
        rho_above_bound(excess->rho.max_channel(), describe_halfdiff(excess->pair)), why));
}

}  // namespace halfback
