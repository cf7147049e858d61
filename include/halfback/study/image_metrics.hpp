// Image-space error metrics for `halfback study`: how far a rendering of a reconstructed BRDF is
// from the rendering of the ground truth under the same scene (a sphere under the same lighting).
// Two numbers are reported: a relative RMSE of the linear radiance (what the reconstruction gets
// wrong physically) and the CIEDE2000 colour difference of the two images tone mapped identically
// for display (how visible that is).
//
// Conventions: images are linear radiance in the sRGB primaries (render::Image, row 0 at the top);
// colours are linear sRGB with the D65 white (Xn, Yn, Zn) = (0.95047, 1, 1.08883); Lab is CIELAB
// relative to that white, L in [0, 100] for colours in [0, 1]³.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "halfback/render/image.hpp"

namespace halfback::study {

struct Lab {
  double L, a, b;
};

// Linear (not gamma-encoded) sRGB → CIE XYZ (the sRGB primaries of IEC 61966-2-1, D65) → CIELAB
// with the D65 white above and the CIE f(t): t^⅓ above (6/29)³, linear below. White (1, 1, 1)
// maps to (100, 0, 0) and black to (0, 0, 0). Values outside [0, 1] are converted as they are.
Lab srgb_linear_to_lab(double r, double g, double b);

// The CIEDE2000 colour difference ΔE00 of two CIELAB colours, with kL = kC = kH = 1, as in
// Sharma, Wu & Dalal, "The CIEDE2000 color-difference formula: implementation notes,
// supplementary test data, and mathematical observations", Color Res. Appl. 30(1), 2005.
// Symmetric in its arguments; 0 for equal colours; about 1 is a just-noticeable difference.
double ciede2000(const Lab& x, const Lab& y);

// Which pixels of a width × height rendering of the unit sphere lie well inside its silhouette:
// the image spans [−half_height, half_height] vertically and width · (2 half_height / height)
// horizontally (square pixels), centred on the sphere; a pixel is 1 when its centre is inside the
// disc of radius 1 by at least margin_pixels pixels (leaving out the antialiased edge, whose
// values mix in the background), 0 otherwise. Row-major, row 0 at the top, width × height
// entries. Throws std::invalid_argument unless width, height and half_height are positive and
// margin_pixels is finite and nonnegative.
std::vector<std::uint8_t> sphere_mask(int width, int height, double half_height = 1.25,
                                      double margin_pixels = 1.5);

struct ImageError {
  // (Σ (t − r)² / Σ r²)^½ over the masked pixels and the three channels: 0 when both images are
  // 0 there, +∞ when only the reference is.
  double relative_rmse;
  // ΔE00 per masked pixel of the tone-mapped images: its mean and its 95th percentile.
  double mean_delta_e;
  double p95_delta_e;
  std::size_t pixels;  // the number of masked pixels
  // The image-space protocol of Sztrajman et al. 2021 (docs/study.md), on the tone-mapped images
  // (the same tone mapping as ΔE00, values in [0, 1]): the mean absolute and root-mean-square
  // differences over the masked pixels and the three channels, and ssim() of their luminances
  // (NaN when no masked pixel has its whole window inside the image).
  double mae = 0, rmse = 0, ssim = 0;
};

// The structural similarity of Wang, Bovik, Sheikh & Simoncelli 2004 of two width × height
// single-channel images (row-major) with values in [0, 1]: the local statistics under their
// 11 × 11 Gaussian window of σ = 1.5 (normalized to sum 1), C1 = (0.01)², C2 = (0.03)² (K1 =
// 0.01, K2 = 0.03, L = 1), SSIM(p) = (2 μx μy + C1)(2 σxy + C2) / ((μx² + μy² + C1)(σx² + σy² +
// C2)) at each pixel p whose whole window lies inside the image, averaged over those where mask is
// nonzero. 1 for equal images. Throws std::invalid_argument when the sizes do not match or no
// masked pixel has its whole window inside the image.
double ssim(std::span<const double> x, std::span<const double> y, int width, int height,
            std::span<const std::uint8_t> mask);

// Compares `test` with `reference` over the pixels where mask is nonzero. For ΔE00 both images
// are tone mapped the same way: scaled by 1 / (the 99th percentile of the reference's luminance
// Y = 0.2126 r + 0.7152 g + 0.0722 b over the mask; by 1 if that is not positive), clamped to
// [0, 1] per channel, and converted with srgb_linear_to_lab. Percentiles interpolate linearly
// between order statistics (the p-th percentile of n values sorted is at rank p/100 · (n − 1)).
// Throws std::invalid_argument when the images differ in size or do not hold width × height × 3
// values, when mask does not hold width × height entries or selects no pixel, or when a masked
// pixel of either image is not finite.
ImageError compare_images(const render::Image& test, const render::Image& reference,
                          std::span<const std::uint8_t> mask);

}  // namespace halfback::study
