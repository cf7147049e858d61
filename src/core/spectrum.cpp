// Spectra ↔ RGB (halfback/core/spectrum.hpp; derivations in docs/formats.md, "Spectra").
#include "halfback/core/spectrum.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace halfback::spectral {

namespace {

// One lobe of Wyman, Sloan & Shirley's fit: a Gaussian with different widths left and right of μ.
double lobe(double lambda, double mu, double sigma_left, double sigma_right) {
  const double t = (lambda - mu) / (lambda < mu ? sigma_left : sigma_right);
  return std::exp(-0.5 * t * t);
}

Matrix3 inverse(const Matrix3& m) {
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  Matrix3 r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      // cofactor of m[j][i], divided by the determinant
      const int a = (j + 1) % 3, b = (j + 2) % 3, c = (i + 1) % 3, d = (i + 2) % 3;
      r[i][j] = (m[a][c] * m[b][d] - m[a][d] * m[b][c]) / det;
    }
  return r;
}

std::array<double, 3> apply(const Matrix3& m, const std::array<double, 3>& v) {
  std::array<double, 3> out{};
  for (int i = 0; i < 3; ++i) out[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
  return out;
}

double sigmoid(double x) {
  return 0.5 + x / (2 * std::sqrt(1 + x * x));
}
double sigmoid_derivative(double x) {
  const double q = 1 + x * x;
  return 0.5 / (q * std::sqrt(q));
}
double inverse_sigmoid(double v) {
  return (2 * v - 1) / (2 * std::sqrt(v * (1 - v)));
}

constexpr double kLambdaCentre = 595, kLambdaHalfWidth = 235;  // t = (λ − 595) / 235 ∈ [−1, 1]

double to_t(double lambda) {
  return (lambda - kLambdaCentre) / kLambdaHalfWidth;
}

}  // namespace

std::array<double, 3> cie_1931(double l) {
  return {1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) -
              0.065 * lobe(l, 501.1, 20.4, 26.2),
          0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1),
          1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8)};
}

double planck(double lambda_nm, double temperature_k) {
  constexpr double c2 = 1.438776877e7;  // second radiation constant hc/k, in nm·K
  auto shape = [&](double l) { return std::pow(l, -5.0) / std::expm1(c2 / (l * temperature_k)); };
  return shape(lambda_nm) / shape(560.0);
}

double illuminant(double lambda_nm) {
  return planck(lambda_nm, 6504.0);
}

Matrix3 rgb_from_xyz(const std::array<double, 3>& white) {
  // Rec. 709 primaries (x, y); the columns of P are their XYZ with Y = 1, scaled by S so that
  // P·S·(1, 1, 1) = white.
  constexpr double xy[3][2] = {{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}};
  Matrix3 p{};
  for (int c = 0; c < 3; ++c) {
    p[0][c] = xy[c][0] / xy[c][1];
    p[1][c] = 1;
    p[2][c] = (1 - xy[c][0] - xy[c][1]) / xy[c][1];
  }
  const std::array<double, 3> s = apply(inverse(p), white);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) p[r][c] *= s[c];
  return inverse(p);
}

std::vector<double> default_wavelengths() {
  std::vector<double> out;
  for (double l = kLambdaMin; l <= kLambdaMax + 1e-9; l += 5) out.push_back(l);
  return out;
}

SpectrumToRgb::SpectrumToRgb(std::vector<double> wavelengths)
    : wavelengths_(std::move(wavelengths)) {
  const std::size_t n = wavelengths_.size();
  if (n < 2) throw std::invalid_argument("spectrum: at least 2 wavelengths are needed");
  for (std::size_t k = 0; k < n; ++k)
    if (!std::isfinite(wavelengths_[k]) || (k > 0 && !(wavelengths_[k] > wavelengths_[k - 1])))
      throw std::invalid_argument("spectrum: the wavelengths must be finite and increasing (" +
                                  std::to_string(wavelengths_[k]) + " nm at index " +
                                  std::to_string(k) + ")");
  // Midpoint rule on 0.1 nm cells of [kLambdaMin, kLambdaMax]: each cell's I·x̄ȳz̄ split between
  // the two samples around it by linear interpolation (constant beyond the ends).
  std::vector<std::array<double, 3>> xyz(n, {0, 0, 0});
  constexpr double h = 0.1;
  const int cells = static_cast<int>(std::lround((kLambdaMax - kLambdaMin) / h));
  double norm = 0;
  for (int c = 0; c < cells; ++c) {
    const double l = kLambdaMin + (c + 0.5) * h;
    const std::array<double, 3> cmf = cie_1931(l);
    const double e = illuminant(l) * h;
    norm += e * cmf[1];
    const auto above = std::upper_bound(wavelengths_.begin(), wavelengths_.end(), l);
    std::size_t k1 = static_cast<std::size_t>(above - wavelengths_.begin()), k0 = k1 - 1;
    double t = 0;
    if (k1 == 0) {
      k0 = k1 = 0;
    } else if (k1 == n) {
      k0 = k1 = n - 1;
    } else {
      t = (l - wavelengths_[k0]) / (wavelengths_[k1] - wavelengths_[k0]);
    }
    for (int i = 0; i < 3; ++i) {
      xyz[k0][i] += (1 - t) * e * cmf[i];
      xyz[k1][i] += t * e * cmf[i];
    }
  }
  std::array<double, 3> white{0, 0, 0};
  for (auto& w : xyz)
    for (int i = 0; i < 3; ++i) white[i] += (w[i] /= norm);
  const Matrix3 m = rgb_from_xyz(white);
  weights_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::array<double, 3> rgb = apply(m, xyz[k]);
    weights_[k] = {rgb[0], rgb[1], rgb[2]};
  }
}

Rgb SpectrumToRgb::operator()(std::span<const double> values) const {
  Rgb sum;
  for (std::size_t k = 0; k < weights_.size(); ++k) sum += weights_[k] * values[k];
  return sum;
}

Rgb SpectrumToRgb::operator()(std::span<const float> values) const {
  Rgb sum;
  for (std::size_t k = 0; k < weights_.size(); ++k) sum += weights_[k] * double(values[k]);
  return sum;
}

double SigmoidSpectrum::operator()(double lambda_nm) const {
  const double t = to_t(lambda_nm);
  return scale * sigmoid((c[0] * t + c[1]) * t + c[2]);
}

namespace {

struct Attempt {
  std::array<double, 3> c;
  Rgb rgb;  // of S(c0 t² + c1 t + c2), before the scale
  double cost = 0;
};

double component(const Rgb& v, int i) {
  return i == 0 ? v.r : i == 1 ? v.g : v.b;
}

Attempt evaluate(const SpectrumToRgb& to_rgb, const std::array<double, 3>& c, const Rgb& target) {
  Attempt a{c, {}, 0};
  const auto& l = to_rgb.wavelengths();
  for (std::size_t k = 0; k < l.size(); ++k) {
    const double t = to_t(l[k]);
    a.rgb += to_rgb.weight(k) * sigmoid((c[0] * t + c[1]) * t + c[2]);
  }
  const Rgb r = a.rgb - target;
  a.cost = r.r * r.r + r.g * r.g + r.b * r.b;
  return a;
}

// Levenberg–Marquardt on the three coefficients: RGB(S(c0 t² + c1 t + c2)) = target.
Attempt levenberg_marquardt(const SpectrumToRgb& to_rgb, std::array<double, 3> c,
                            const Rgb& target) {
  const auto& l = to_rgb.wavelengths();
  Attempt best = evaluate(to_rgb, c, target);
  double mu = 1e-3;
  for (int it = 0; it < 200 && best.cost > 1e-22; ++it) {
    Matrix3 j{};  // ∂RGB_i/∂c_j
    for (std::size_t k = 0; k < l.size(); ++k) {
      const double t = to_t(l[k]);
      const double d = sigmoid_derivative((best.c[0] * t + best.c[1]) * t + best.c[2]);
      const double basis[3] = {t * t, t, 1};
      for (int i = 0; i < 3; ++i)
        for (int m = 0; m < 3; ++m) j[i][m] += component(to_rgb.weight(k), i) * d * basis[m];
    }
    const Rgb r = best.rgb - target;
    Matrix3 a{};
    std::array<double, 3> g{};
    for (int p = 0; p < 3; ++p) {
      for (int q = 0; q < 3; ++q)
        for (int i = 0; i < 3; ++i) a[p][q] += j[i][p] * j[i][q];
      for (int i = 0; i < 3; ++i) g[p] -= j[i][p] * component(r, i);
    }
    for (int p = 0; p < 3; ++p) a[p][p] *= 1 + mu, a[p][p] += 1e-15;
    const std::array<double, 3> step = apply(inverse(a), g);
    const Attempt next =
        evaluate(to_rgb, {best.c[0] + step[0], best.c[1] + step[1], best.c[2] + step[2]}, target);
    if (std::isfinite(next.cost) && next.cost < best.cost) {
      best = next;
      mu = std::max(mu / 4, 1e-9);
    } else {
      mu *= 8;
      if (mu > 1e12) break;
    }
  }
  return best;
}

}  // namespace

SpectrumFit RgbToSpectrum::fit(const Rgb& target) const {
  if (!target.finite()) throw std::invalid_argument("spectrum: cannot fit a non-finite RGB value");
  const Rgb t{std::max(target.r, 0.0), std::max(target.g, 0.0), std::max(target.b, 0.0)};
  const double m = t.max_channel();
  SpectrumFit best;
  if (!(m > 0)) return best;  // black: the zero spectrum
  best.error = INFINITY;
  // The brightness the sigmoid has to reach: its values are < 1, so a target is fitted at a few
  // heights below 1; saturated colours need the taller ones, bright greys any.
  for (double height : {0.5, 0.8, 0.25, 0.95, 0.1}) {
    const double scale = m / height;
    const Rgb y = t / scale;
    const double grey = std::clamp((y.r + y.g + y.b) / 3, 0.01, 0.99);
    Attempt a = levenberg_marquardt(to_rgb_, {0, 0, inverse_sigmoid(grey)}, y);
    if (a.cost > 1e-12) {
      // Continuation from the grey of the same brightness, as Jakob & Hanika fill their tables.
      std::array<double, 3> c{0, 0, inverse_sigmoid(grey)};
      for (double f : {0.25, 0.5, 0.75, 1.0})
        c = levenberg_marquardt(to_rgb_, c, Rgb{grey, grey, grey} * (1 - f) + y * f).c;
      const Attempt b = evaluate(to_rgb_, c, y);
      if (b.cost < a.cost) a = b;
    }
    const Rgb rgb = a.rgb * scale;
    const Rgb d = rgb - t;
    const double error = std::max({std::abs(d.r), std::abs(d.g), std::abs(d.b)}) / m;
    if (error < best.error) best = {{a.c, scale}, rgb, error};
    if (error < 1e-6) break;
  }
  return best;
}

}  // namespace halfback::spectral
