#include "halfback/study/image_metrics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "halfback/core/rgb.hpp"

namespace halfback::study {

namespace {

constexpr double kXn = 0.95047, kYn = 1.0, kZn = 1.08883;

// The CIE f(t) of CIELAB: a cube root, replaced near 0 by the tangent line through (0, 4/29) at
// t = (6/29)³ so that the slope stays finite.
double lab_f(double t) {
  constexpr double kDelta = 6.0 / 29.0;
  if (t > kDelta * kDelta * kDelta) return std::cbrt(t);
  return t / (3 * kDelta * kDelta) + 4.0 / 29.0;
}

double degrees(double radians) {
  return radians * (180 / std::numbers::pi);
}
double radians(double degrees) {
  return degrees * (std::numbers::pi / 180);
}

// The hue angle in [0, 360) degrees; 0 for a neutral colour, where atan2(0, 0) is undefined
// (Sharma et al. 2005, eq. 4).
double hue_degrees(double b, double a) {
  if (a == 0 && b == 0) return 0;
  double h = degrees(std::atan2(b, a));
  if (h < 0) h += 360;
  return h >= 360 ? h - 360 : h;
}

// The p-th percentile (p in [0, 100]) of nonempty `values`, interpolated linearly between order
// statistics; reorders `values`.
double percentile(std::vector<double>& values, double p) {
  const double rank = p / 100 * double(values.size() - 1);
  const std::size_t lo = std::size_t(std::floor(rank));
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(lo), values.end());
  const double v_lo = values[lo];
  if (lo + 1 >= values.size()) return v_lo;
  // The next order statistic is the smallest of those above the lo-th.
  const double v_hi = *std::min_element(values.begin() + std::ptrdiff_t(lo) + 1, values.end());
  return v_lo + (rank - double(lo)) * (v_hi - v_lo);
}

// The display transform shared by both images: a scale, then a clamp to the displayable range.
Lab display_lab(const float* rgb, double scale) {
  auto channel = [scale](float v) { return std::clamp(scale * double(v), 0.0, 1.0); };
  return srgb_linear_to_lab(channel(rgb[0]), channel(rgb[1]), channel(rgb[2]));
}

void check_image(const render::Image& image, const char* which) {
  if (image.width < 0 || image.height < 0 ||
      image.rgb.size() != 3 * std::size_t(image.width) * std::size_t(image.height))
    throw std::invalid_argument(std::string("compare_images: the ") + which + " image (" +
                                std::to_string(image.width) + " × " + std::to_string(image.height) +
                                ") holds " + std::to_string(image.rgb.size()) +
                                " values, not width × height × 3");
}

}  // namespace

Lab srgb_linear_to_lab(double r, double g, double b) {
  // The matrix of the sRGB primaries (IEC 61966-2-1) for the white point (kXn, kYn, kZn) at full
  // precision: the standard's four-digit rounding maps white to (0.9505, 1, 1.0890) instead,
  // which would give white a ≈ 0.005 and b ≈ −0.010 against this white.
  const double x = 0.4124564391 * r + 0.3575760776 * g + 0.1804374833 * b;
  const double y = 0.2126728514 * r + 0.7151521553 * g + 0.0721749933 * b;
  const double z = 0.0193338956 * r + 0.1191920259 * g + 0.9503040785 * b;
  const double fx = lab_f(x / kXn), fy = lab_f(y / kYn), fz = lab_f(z / kZn);
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

double ciede2000(const Lab& x, const Lab& y) {
  constexpr double k25To7 = 6103515625.0;  // 25⁷
  // Stretch a* for low-chroma colours, where CIELAB's hue spacing is too wide (eqs. 2–3).
  const double c_ab_mean = (std::hypot(x.a, x.b) + std::hypot(y.a, y.b)) / 2;
  const double c_ab_mean7 = std::pow(c_ab_mean, 7);
  const double g = 0.5 * (1 - std::sqrt(c_ab_mean7 / (c_ab_mean7 + k25To7)));
  const double a1 = (1 + g) * x.a, a2 = (1 + g) * y.a;
  const double c1 = std::hypot(a1, x.b), c2 = std::hypot(a2, y.b);
  const double h1 = hue_degrees(x.b, a1), h2 = hue_degrees(y.b, a2);

  // Differences (eqs. 8–11). A neutral colour has no hue, so then the hue difference is 0.
  const bool chromatic = c1 * c2 != 0;
  const double dl = y.L - x.L;
  const double dc = c2 - c1;
  double dh = 0;
  if (chromatic) {
    dh = h2 - h1;  // the signed shorter way round the hue circle
    if (dh > 180) {
      dh -= 360;
    } else if (dh < -180) {
      dh += 360;
    }
  }
  const double d_hue = 2 * std::sqrt(c1 * c2) * std::sin(radians(dh / 2));

  // Means (eqs. 12–14): the mean hue is taken the shorter way round; with a neutral colour it is
  // the other colour's hue (the sum, not halved).
  const double l_mean = (x.L + y.L) / 2;
  const double c_mean = (c1 + c2) / 2;
  double h_mean = h1 + h2;
  if (chromatic) {
    if (std::abs(h1 - h2) <= 180) {
      h_mean /= 2;
    } else if (h_mean < 360) {
      h_mean = (h_mean + 360) / 2;
    } else {
      h_mean = (h_mean - 360) / 2;
    }
  }

  // Weights and the rotation of the blue region (eqs. 15–22).
  const double t = 1 - 0.17 * std::cos(radians(h_mean - 30)) +
                   0.24 * std::cos(radians(2 * h_mean)) + 0.32 * std::cos(radians(3 * h_mean + 6)) -
                   0.20 * std::cos(radians(4 * h_mean - 63));
  const double d_theta = 30 * std::exp(-std::pow((h_mean - 275) / 25, 2));
  const double c_mean7 = std::pow(c_mean, 7);
  const double r_c = 2 * std::sqrt(c_mean7 / (c_mean7 + k25To7));
  const double l50 = (l_mean - 50) * (l_mean - 50);
  const double s_l = 1 + 0.015 * l50 / std::sqrt(20 + l50);
  const double s_c = 1 + 0.045 * c_mean;
  const double s_h = 1 + 0.015 * c_mean * t;
  const double r_t = -std::sin(radians(2 * d_theta)) * r_c;

  const double tl = dl / s_l, tc = dc / s_c, th = d_hue / s_h;
  // The sum is ≥ 0 in exact arithmetic (|r_t| ≤ 2); the clamp guards against rounding.
  return std::sqrt(std::max(0.0, tl * tl + tc * tc + th * th + r_t * tc * th));
}

std::vector<std::uint8_t> sphere_mask(int width, int height, double half_height,
                                      double margin_pixels) {
  if (width <= 0 || height <= 0 || !(half_height > 0) || !std::isfinite(half_height) ||
      !(margin_pixels >= 0) || !std::isfinite(margin_pixels))
    throw std::invalid_argument(
        "sphere_mask: need width > 0, height > 0, 0 < half_height < ∞ "
        "and 0 ≤ margin_pixels < ∞");
  const double pixel = 2 * half_height / height;  // side of a pixel in scene units
  const double radius = 1 - margin_pixels * pixel;
  std::vector<std::uint8_t> mask(std::size_t(width) * std::size_t(height), 0);
  if (radius <= 0) return mask;
  for (int j = 0; j < height; ++j) {
    const double v = (height / 2.0 - (j + 0.5)) * pixel;  // up, as row 0 is the top
    for (int i = 0; i < width; ++i) {
      const double u = (i + 0.5 - width / 2.0) * pixel;
      if (u * u + v * v <= radius * radius) mask[std::size_t(j) * width + i] = 1;
    }
  }
  return mask;
}

namespace {

// A channel of a rendering as displayed: scaled, clamped to [0, 1]; 0 where not finite (only
// pixels outside the mask can be, and the SSIM window may reach them).
double displayed(float v, double scale) {
  return std::isfinite(v) ? std::clamp(double(v) * scale, 0.0, 1.0) : 0.0;
}

// MAE, RMSE and SSIM of the tone-mapped images (ImageError).
void add_display_errors(const render::Image& test, const render::Image& reference,
                        std::span<const std::uint8_t> mask, double scale, ImageError& e) {
  const std::size_t n = mask.size();
  std::vector<double> yt(n), yr(n);
  double abs_sum = 0, sq_sum = 0;
  for (std::size_t k = 0; k < n; ++k) {
    double t[3], r[3];
    for (int c = 0; c < 3; ++c) {
      t[c] = displayed(test.rgb[3 * k + std::size_t(c)], scale);
      r[c] = displayed(reference.rgb[3 * k + std::size_t(c)], scale);
      if (mask[k]) {
        abs_sum += std::abs(t[c] - r[c]);
        sq_sum += (t[c] - r[c]) * (t[c] - r[c]);
      }
    }
    yt[k] = Rgb{t[0], t[1], t[2]}.luminance();
    yr[k] = Rgb{r[0], r[1], r[2]}.luminance();
  }
  const double values = 3.0 * double(e.pixels);
  e.mae = abs_sum / values;
  e.rmse = std::sqrt(sq_sum / values);
  try {
    e.ssim = ssim(yt, yr, reference.width, reference.height, mask);
  } catch (const std::invalid_argument&) {  // an image too small for the window
    e.ssim = std::numeric_limits<double>::quiet_NaN();
  }
}

}  // namespace

ImageError compare_images(const render::Image& test, const render::Image& reference,
                          std::span<const std::uint8_t> mask) {
  check_image(test, "test");
  check_image(reference, "reference");
  if (test.width != reference.width || test.height != reference.height)
    throw std::invalid_argument("compare_images: the test image is " + std::to_string(test.width) +
                                " × " + std::to_string(test.height) + ", the reference " +
                                std::to_string(reference.width) + " × " +
                                std::to_string(reference.height));
  const std::size_t n = std::size_t(reference.width) * std::size_t(reference.height);
  if (mask.size() != n)
    throw std::invalid_argument("compare_images: the mask has " + std::to_string(mask.size()) +
                                " entries, not width × height = " + std::to_string(n));

  // One pass for the radiance error, collecting the reference's luminance for the tone mapping.
  double squared_error = 0, squared_reference = 0;
  std::vector<std::size_t> selected;
  std::vector<double> luminances;
  for (std::size_t k = 0; k < n; ++k) {
    if (!mask[k]) continue;
    const float* t = &test.rgb[3 * k];
    const float* r = &reference.rgb[3 * k];
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(t[c]) || !std::isfinite(r[c]))
        throw std::invalid_argument(
            "compare_images: masked pixel (" + std::to_string(k % std::size_t(reference.width)) +
            ", " + std::to_string(k / std::size_t(reference.width)) + ") of the " +
            (std::isfinite(t[c]) ? "reference" : "test") + " image is not finite");
      const double d = double(t[c]) - double(r[c]);
      squared_error += d * d;
      squared_reference += double(r[c]) * double(r[c]);
    }
    selected.push_back(k);
    luminances.push_back(Rgb{r[0], r[1], r[2]}.luminance());
  }
  if (selected.empty()) throw std::invalid_argument("compare_images: the mask selects no pixel");

  ImageError e{};
  e.pixels = selected.size();
  if (squared_reference > 0) {
    e.relative_rmse = std::sqrt(squared_error / squared_reference);
  } else {
    e.relative_rmse = squared_error > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  }

  // The 99th percentile rather than the maximum, so that a few highlight pixels do not set the
  // exposure of the whole image.
  const double white = percentile(luminances, 99);
  const double scale = white > 0 ? 1 / white : 1;
  std::vector<double> delta_e;
  delta_e.reserve(selected.size());
  double sum = 0;
  for (std::size_t k : selected) {
    const double d =
        ciede2000(display_lab(&test.rgb[3 * k], scale), display_lab(&reference.rgb[3 * k], scale));
    delta_e.push_back(d);
    sum += d;
  }
  e.mean_delta_e = sum / double(delta_e.size());
  e.p95_delta_e = percentile(delta_e, 95);
  add_display_errors(test, reference, mask, scale, e);
  return e;
}

double ssim(std::span<const double> x, std::span<const double> y, int width, int height,
            std::span<const std::uint8_t> mask) {
  constexpr int kRadius = 5;  // an 11 × 11 window
  constexpr double kSigma = 1.5, kC1 = 0.01 * 0.01, kC2 = 0.03 * 0.03;
  const std::size_t n = std::size_t(std::max(width, 0)) * std::size_t(std::max(height, 0));
  if (width <= 0 || height <= 0 || x.size() != n || y.size() != n || mask.size() != n)
    throw std::invalid_argument("ssim: the images and the mask must hold width × height values");
  std::array<double, 2 * kRadius + 1> g{};
  double total = 0;
  for (int i = -kRadius; i <= kRadius; ++i)
    total += g[std::size_t(i + kRadius)] = std::exp(-i * i / (2 * kSigma * kSigma));
  for (double& v : g) v /= total;  // the 2D window is g gᵀ, of sum 1
  double sum = 0;
  std::size_t count = 0;
  for (int j = kRadius; j + kRadius < height; ++j)
    for (int i = kRadius; i + kRadius < width; ++i) {
      if (!mask[std::size_t(j) * std::size_t(width) + std::size_t(i)]) continue;
      double mx = 0, my = 0, xx = 0, yy = 0, xy = 0;
      for (int b = -kRadius; b <= kRadius; ++b)
        for (int a = -kRadius; a <= kRadius; ++a) {
          const double w = g[std::size_t(a + kRadius)] * g[std::size_t(b + kRadius)];
          const std::size_t k = std::size_t(j + b) * std::size_t(width) + std::size_t(i + a);
          mx += w * x[k];
          my += w * y[k];
          xx += w * x[k] * x[k];
          yy += w * y[k] * y[k];
          xy += w * x[k] * y[k];
        }
      const double vx = xx - mx * mx, vy = yy - my * my, cxy = xy - mx * my;
      sum += (2 * mx * my + kC1) * (2 * cxy + kC2) / ((mx * mx + my * my + kC1) * (vx + vy + kC2));
      ++count;
    }
  if (count == 0)
    throw std::invalid_argument("ssim: no masked pixel has its 11 × 11 window inside the image");
  return sum / double(count);
}

}  // namespace halfback::study
