#include "chart_cells.hpp"

namespace halfback::render::detail {

Vec3<double> SliceGrid::view(int index) const {
  const int k = index / n_phi, l = index % n_phi;
  const double theta = (k + 0.5) / n_theta * kPi / 2;
  const double phi = n_phi == 1 ? 0.0 : (l + 0.5) / n_phi * 2 * kPi;
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

SliceGrid::Blend SliceGrid::blend(const Vec3<double>& wo) const {
  Blend b{};
  const double theta = std::atan2(std::sqrt(wo.x * wo.x + wo.y * wo.y), wo.z);
  const double x = theta / (kPi / 2) * n_theta - 0.5;
  int k0 = int(std::floor(x));
  double tk = x - k0;
  if (k0 < 0) {
    k0 = 0;
    tk = 0;
  } else if (k0 >= n_theta - 1) {
    k0 = n_theta - 1;
    tk = 0;
  }
  const int k1 = std::min(k0 + 1, n_theta - 1);
  if (n_phi == 1) {
    b.index[0] = k0;
    b.weight[0] = 1 - tk;
    b.index[1] = k1;
    b.weight[1] = tk;
    b.count = 2;
    return b;
  }
  const double y = azimuth(wo.y, wo.x) / (2 * kPi) * n_phi - 0.5;
  int l0 = int(std::floor(y));
  const double tl = y - l0;
  l0 = (l0 % n_phi + n_phi) % n_phi;
  const int l1 = (l0 + 1) % n_phi;
  const int ks[2] = {k0, k1}, ls[2] = {l0, l1};
  const double wk[2] = {1 - tk, tk}, wl[2] = {1 - tl, tl};
  b.count = 4;
  for (int a = 0; a < 2; ++a)
    for (int c = 0; c < 2; ++c) {
      b.index[2 * a + c] = ks[a] * n_phi + ls[c];
      b.weight[2 * a + c] = wk[a] * wl[c];
    }
  return b;
}

std::vector<double> tabulate_cells(const Brdf& brdf, const ParamMap& map, const Vec3<double>& wo,
                                   int radial, int azimuthal, int supersample) {
  const int ss = supersample;
  const std::size_t cells = std::size_t(radial) * std::size_t(azimuthal);
  std::vector<DirPair<double>> pairs;
  std::vector<double> factor;  // cos θi |J| of each point in the hemisphere
  std::vector<std::size_t> cell_of;
  pairs.reserve(cells * std::size_t(ss * ss));
  for (int i = 0; i < radial; ++i)
    for (int j = 0; j < azimuthal; ++j)
      for (int a = 0; a < ss; ++a)
        for (int b = 0; b < ss; ++b) {
          const double s = (i + (a + 0.5) / ss) / radial;
          const double t = (j + (b + 0.5) / ss) / azimuthal;
          Vec3<double> wi{0, 0, 0};
          double jac = 0;
          if (!map.forward(wo, s, t, wi, jac)) continue;
          pairs.push_back({wi, wo});
          factor.push_back(wi.z * jac);
          cell_of.push_back(std::size_t(i) * std::size_t(azimuthal) + std::size_t(j));
        }
  std::vector<Rgb> values(pairs.size());
  brdf.eval_batch(pairs, values);
  std::vector<double> weights(cells, 0.0);
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    const double v = values[p].luminance() * factor[p];
    if (std::isfinite(v) && v > 0) weights[cell_of[p]] += v;
  }
  return weights;
}

}  // namespace halfback::render::detail
