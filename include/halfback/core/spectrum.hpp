// Spectra and RGB: reflectance-like spectra sampled at a few wavelengths integrated to halfback's
// linear Rec. 709 RGB, and the inverse, an RGB value upsampled to a smooth non-negative spectrum
// (a scaled sigmoid of a quadratic, after Jakob & Hanika 2019, fitted per value by damped
// Gauss–Newton). The CIE 1931 colour matching functions are the multi-lobe piecewise-Gaussian fit
// of Wyman, Sloan & Shirley 2013; the illuminant is a 6504 K Planck spectrum standing in for D65.
// docs/formats.md ("Spectra") derives and bounds all of it.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "halfback/core/rgb.hpp"

namespace halfback::spectral {

// The range over which spectra are integrated (the CIE 1931 tables' and pbrt-v4's), in nm.
inline constexpr double kLambdaMin = 360, kLambdaMax = 830;

// x̄, ȳ, z̄ of the CIE 1931 2° observer at λ (nm), by Wyman, Sloan & Shirley's multi-lobe fit.
std::array<double, 3> cie_1931(double lambda_nm);

// Planck's law at temperature_k, relative: 1 at 560 nm.
double planck(double lambda_nm, double temperature_k);

// The illuminant every conversion uses: planck(λ, 6504 K), D65's correlated colour temperature.
double illuminant(double lambda_nm);

using Matrix3 = std::array<std::array<double, 3>, 3>;

// The matrix from CIE XYZ to linear RGB with the Rec. 709 primaries and the white point whose XYZ
// is `white` (that white maps to (1, 1, 1)): derived from the primaries' chromaticities.
Matrix3 rgb_from_xyz(const std::array<double, 3>& white);

// The wavelengths written to spectral files by default: kLambdaMin to kLambdaMax every 5 nm.
std::vector<double> default_wavelengths();

// Integrates spectra sampled at `wavelengths` (increasing, nm), linear between samples and
// constant beyond the ends (as the readers interpolate them), to RGB: RGB = M ∫ s I x̄ȳz̄ dλ / ∫ I ȳ
// over [kLambdaMin, kLambdaMax], M = rgb_from_xyz(white of I); the spectrum 1 gives (1, 1, 1).
class SpectrumToRgb {
 public:
  // Throws std::invalid_argument unless there are ≥ 2 finite, increasing wavelengths.
  explicit SpectrumToRgb(std::vector<double> wavelengths);

  const std::vector<double>& wavelengths() const { return wavelengths_; }
  // values.size() must equal wavelengths().size().
  Rgb operator()(std::span<const double> values) const;
  Rgb operator()(std::span<const float> values) const;
  // The RGB weights of sample k: RGB = Σ_k weight(k) · s_k.
  const Rgb& weight(std::size_t k) const { return weights_[k]; }

 private:
  std::vector<double> wavelengths_;
  std::vector<Rgb> weights_;
};

// s(λ) = scale · S(c0 t² + c1 t + c2), S(x) = ½ + x / (2√(1 + x²)), t = (λ − 595 nm) / 235 nm.
struct SigmoidSpectrum {
  std::array<double, 3> c{};
  double scale = 0;
  double operator()(double lambda_nm) const;
};

struct SpectrumFit {
  SigmoidSpectrum spectrum;
  Rgb rgb;           // the fitted spectrum's RGB on the converter's wavelengths
  double error = 0;  // max |rgb − target| / max(target), 0 for a black target
};

// Fits a sigmoid spectrum to RGB values on the wavelengths of a converter. Negative channels are
// raised to 0 first (no non-negative spectrum has them); a target with no positive channel gives
// the zero spectrum. Several brightness scales are tried; the one with the smallest error wins.
class RgbToSpectrum {
 public:
  explicit RgbToSpectrum(std::vector<double> wavelengths) : to_rgb_(std::move(wavelengths)) {}
  const SpectrumToRgb& to_rgb() const { return to_rgb_; }
  // Throws std::invalid_argument for a non-finite target.
  SpectrumFit fit(const Rgb& target) const;

 private:
  SpectrumToRgb to_rgb_;
};

}  // namespace halfback::spectral
