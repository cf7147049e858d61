// The RGL material of a tensor file (docs/formats.md, "RGL"): its fields checked (names, dtypes,
// shapes, values) and read into RglBrdf's tables (rgl_impl.hpp). The container itself is parsed by
// tensor_file.cpp.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "binary_io.hpp"
#include "halfback/brdf/rho_bound.hpp"
#include "halfback/core/spectrum.hpp"
#include "halfback/formats/rgl.hpp"
#include "halfback/util/format_error.hpp"
#include "rgl_impl.hpp"

namespace halfback {
namespace {

using io_detail::load_le;
using rgl_detail::IncidenceAxis;
using rgl_detail::kPi;
using rgl_detail::Table;

// The checks of a tensor file's fields, each throwing FormatError naming the file and the field.
class Validator {
 public:
  Validator(const TensorFile& tf, std::string file) : tf_(tf), file_(std::move(file)) {}

  const TensorField& field(std::string_view name, TensorDtype dtype, std::size_t ndim) const {
    const TensorField* f = tf_.find(name);
    if (!f) fail(name, "missing (required by the RGL material format)");
    if (f->dtype != dtype)
      fail(name, "has dtype " + std::string(name_of(f->dtype)) + ", expected " +
                     std::string(name_of(dtype)));
    if (f->shape.size() != ndim)
      fail(name, "has " + std::to_string(f->shape.size()) + " dimensions, expected " +
                     std::to_string(ndim));
    return *f;
  }

  std::vector<double> floats(const TensorField& f) const {
    std::vector<double> v(static_cast<std::size_t>(f.count()));
    for (std::size_t i = 0; i < v.size(); ++i) {
      const float x = load_le<float>(f.bytes.data() + 4 * i);
      if (!std::isfinite(x))
        fail(f.name, fmt::format("value {} is {}", i, std::isnan(x) ? "NaN" : "infinite"));
      v[i] = x;
    }
    return v;
  }

  void require_positive(const TensorField& f, const std::vector<double>& v) const {
    for (std::size_t i = 0; i < v.size(); ++i)
      if (!(v[i] > 0)) fail(f.name, fmt::format("value {} is {:g}, must be positive", i, v[i]));
  }

  // A density measured with noise: negative values within kRglNoiseFraction of the field's largest
  // value are set to 0 (the reference loader uses them as they are); larger ones are refused.
  // Returns how many were set to 0.
  std::size_t clamp_noise(const TensorField& f, std::vector<double>& v) const {
    double largest = 0;
    for (double x : v) largest = std::max(largest, x);
    const double floor = -kRglNoiseFraction * largest;
    std::size_t clamped = 0;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (v[i] >= 0) continue;
      if (v[i] < floor)
        fail(f.name, fmt::format("value {} is {:g}, below the noise tolerance {:g} ({:g} times the "
                                 "field's largest value {:g}): not a density",
                                 i, v[i], floor, -kRglNoiseFraction, largest));
      v[i] = 0;
      ++clamped;
    }
    return clamped;
  }

  void require_dim(const TensorField& f, std::size_t axis, std::uint64_t expected,
                   const std::string& why) const {
    if (f.shape[axis] != expected)
      fail(f.name,
           fmt::format("dimension {} is {}, expected {} ({})", axis, f.shape[axis], expected, why));
  }

  void require_at_least(const TensorField& f, std::size_t axis, std::uint64_t min) const {
    if (f.shape[axis] < min)
      fail(f.name, "dimension " + std::to_string(axis) + " is " + std::to_string(f.shape[axis]) +
                       ", must be at least " + std::to_string(min));
  }

  const std::string& file() const { return file_; }

  [[noreturn]] void fail(std::string_view field, const std::string& problem) const {
    throw FormatError(file_, "field '" + std::string(field) + "'", problem);
  }

 private:
  const TensorFile& tf_;
  std::string file_;
};

// The spectral variant's `spectra` [φi, θi, wavelengths, h, w] integrated to RGB tables
// (core/spectrum.hpp: the CIE 1931 observer under the illuminant the writer upsamples with), so
// that spectral files read like RGB ones. docs/formats.md, "Spectra".
Table spectra_as_rgb(const Validator& v, const TensorField& lum, std::size_t n_phi,
                     std::size_t n_theta, std::size_t& n_wavelengths) {
  const TensorField& wl = v.field("wavelengths", TensorDtype::float32, 1);
  v.require_at_least(wl, 0, 2);
  std::vector<double> lambda = v.floats(wl);
  for (std::size_t k = 0; k < lambda.size(); ++k)
    if (!(lambda[k] > 0) || (k > 0 && !(lambda[k] > lambda[k - 1])))
      v.fail("wavelengths", fmt::format("value {} is {:g} nm: wavelengths must be positive and "
                                        "strictly increasing",
                                        k, lambda[k]));
  const TensorField& f = v.field("spectra", TensorDtype::float32, 5);
  v.require_dim(f, 0, n_phi, "number of phi_i values");
  v.require_dim(f, 1, n_theta, "number of theta_i values");
  v.require_dim(f, 2, lambda.size(), "number of wavelengths");
  v.require_dim(f, 3, lum.shape[2], "the luminance grid's resolution");
  v.require_dim(f, 4, lum.shape[3], "the luminance grid's resolution");
  const spectral::SpectrumToRgb to_rgb(lambda);
  const std::vector<double> values = v.floats(f);
  Table t;
  t.h = static_cast<std::size_t>(f.shape[3]);
  t.w = static_cast<std::size_t>(f.shape[4]);
  const std::size_t n = t.h * t.w, nl = lambda.size();
  t.v.assign(n_phi * n_theta * 3 * n, 0.0);
  std::vector<double> spectrum(nl);
  for (std::size_t s = 0; s < n_phi * n_theta; ++s)
    for (std::size_t node = 0; node < n; ++node) {
      for (std::size_t k = 0; k < nl; ++k) spectrum[k] = values[(s * nl + k) * n + node];
      const Rgb c = to_rgb(spectrum);
      t.v[(s * 3 + 0) * n + node] = c.r;
      t.v[(s * 3 + 1) * n + node] = c.g;
      t.v[(s * 3 + 2) * n + node] = c.b;
    }
  n_wavelengths = nl;
  return t;
}

// Reads the material fields of a tensor file into an Impl, in the order the checks are made (the
// first field that fails names the error).
class MaterialReader {
 public:
  MaterialReader(const TensorFile& tf, std::string file, RglBrdf::Impl& m)
      : tf_(tf), v_(tf, std::move(file)), m_(m) {}

  void read() {
    read_description();
    read_incidence_grids();
    read_ndf_and_sigma();
    read_vndf();
    const TensorField& lum = check_luminance();
    read_rgb(lum);
    read_jacobian();
    check_rho_bound();
    constexpr std::size_t kSide = INT32_MAX;
    m_.lanes = std::max({m_.vndf.w, m_.vndf.h, m_.rgb.w, m_.rgb.h, m_.ndf.w, m_.ndf.h, m_.sigma.w,
                         m_.sigma.h}) < kSide;
  }

 private:
  // The description (trailing NULs dropped); a version field, if any, of 2 uint32 values.
  void read_description() {
    const TensorField& desc = v_.field("description", TensorDtype::uint8, 1);
    m_.description.assign(reinterpret_cast<const char*>(desc.bytes.data()), desc.bytes.size());
    while (!m_.description.empty() && m_.description.back() == '\0') m_.description.pop_back();
    if (const TensorField* ver = tf_.find("version")) {
      if (ver->dtype != TensorDtype::uint32 || ver->shape.size() != 1 || ver->shape[0] != 2)
        v_.fail("version", "expected 2 uint32 values");
    }
  }

  // An incidence grid: at least one value, in [lo, hi] (radians), strictly increasing. Returns
  // its size.
  std::size_t read_incidence(std::string_view name, double lo, double hi, std::vector<float>& raw,
                             IncidenceAxis& axis) {
    const TensorField& f = v_.field(name, TensorDtype::float32, 1);
    v_.require_at_least(f, 0, 1);
    axis.values = v_.floats(f);
    raw.assign(axis.values.begin(), axis.values.end());
    for (std::size_t i = 0; i < axis.values.size(); ++i) {
      const double x = axis.values[i];
      if (x < lo || x > hi)
        v_.fail(name, fmt::format("value {} is {:g} rad, outside [{:g}, {:g}]", i, x, lo, hi));
      if (i > 0 && !(x > axis.values[i - 1])) v_.fail(name, "values are not strictly increasing");
    }
    return axis.values.size();
  }

  // θi and φi, the slices' order [φi][θi], and the symmetry: as in the reference loader, at most 2
  // φi values means isotropic data, whose tables are indexed by the azimuth of the half vector
  // relative to ωi. Anisotropic data may cover a fraction 1/reduction of the azimuths, the rest
  // following by symmetry.
  void read_incidence_grids() {
    const double tol = 1e-5;
    n_theta_ = read_incidence("theta_i", -tol, kPi / 2 + tol, m_.theta_i_raw, m_.theta);
    n_phi_ = read_incidence("phi_i", -kPi - tol, kPi + tol, m_.phi_i_raw, m_.phi);
    m_.theta.stride = n_theta_ > 1 ? 1 : 0;
    m_.phi.stride = n_phi_ > 1 ? n_theta_ : 0;
    m_.n_slices = n_theta_ * n_phi_;
    m_.isotropic = n_phi_ <= 2;
    if (m_.isotropic) return;
    const double span = m_.phi.values.back() - m_.phi.values.front();
    m_.reduction = static_cast<int>(std::lround(2 * kPi / span));
    if (m_.reduction != 1 && m_.reduction != 2 && m_.reduction != 4)
      v_.fail("phi_i", fmt::format("covers {:g} rad: expected 2π, π or π/2 (full, half or quarter "
                                   "symmetry)",
                                   span));
  }

  // A 2D table of at least 2 × 2 values.
  const TensorField& read_table(std::string_view name, Table& t) {
    const TensorField& f = v_.field(name, TensorDtype::float32, 2);
    v_.require_at_least(f, 0, 2);
    v_.require_at_least(f, 1, 2);
    t.h = static_cast<std::size_t>(f.shape[0]);
    t.w = static_cast<std::size_t>(f.shape[1]);
    t.v = v_.floats(f);
    return f;
  }

  void read_ndf_and_sigma() {
    m_.noise_clamped += v_.clamp_noise(read_table("ndf", m_.ndf), m_.ndf.v);
    v_.require_positive(read_table("sigma", m_.sigma), m_.sigma.v);  // divides ρ
  }

  // A field of one table per incidence slice, [φi, θi, ...].
  void require_slices(const TensorField& f) const {
    v_.require_dim(f, 0, n_phi_, "number of phi_i values");
    v_.require_dim(f, 1, n_theta_, "number of theta_i values");
  }

  // The VNDF warp: a density of at least 2 × 2 values per slice, none integrating to 0.
  void read_vndf() {
    const TensorField& f = v_.field("vndf", TensorDtype::float32, 4);
    require_slices(f);
    v_.require_at_least(f, 2, 2);
    v_.require_at_least(f, 3, 2);
    m_.vndf.h = static_cast<std::size_t>(f.shape[2]);
    m_.vndf.w = static_cast<std::size_t>(f.shape[3]);
    std::vector<double> data = v_.floats(f);
    m_.noise_clamped += v_.clamp_noise(f, data);
    if (!m_.vndf.build(data, m_.n_slices))
      v_.fail("vndf", "a slice integrates to zero (or beyond the float range)");
  }

  // The luminance warp, checked only (the evaluation does not use it): square grids of densities.
  // Its grid is the RGB tables' one.
  const TensorField& check_luminance() {
    const TensorField& lum = v_.field("luminance", TensorDtype::float32, 4);
    require_slices(lum);
    v_.require_at_least(lum, 2, 2);
    v_.require_dim(lum, 3, lum.shape[2], "the sample grid is square");
    std::vector<double> luminance = v_.floats(lum);
    m_.noise_clamped += v_.clamp_noise(lum, luminance);
    return lum;
  }

  // The RGB tables, from the `rgb` field or, in the spectral variant, from `spectra`; their
  // values may be slightly negative (out of gamut: see RglOptions), and are counted.
  void read_rgb(const TensorField& lum) {
    std::vector<double> planar;  // slices of 3 channels of h·w
    if (!tf_.find("rgb") && tf_.find("spectra")) {
      Table t = spectra_as_rgb(v_, lum, n_phi_, n_theta_, m_.wavelengths);
      m_.rgb.h = t.h;
      m_.rgb.w = t.w;
      planar = std::move(t.v);
    } else {
      const TensorField& f = v_.field("rgb", TensorDtype::float32, 5);
      require_slices(f);
      v_.require_dim(f, 2, 3, "red, green, blue");
      v_.require_dim(f, 3, lum.shape[2], "the luminance grid's resolution");
      v_.require_dim(f, 4, lum.shape[3], "the luminance grid's resolution");
      m_.rgb.h = static_cast<std::size_t>(f.shape[3]);
      m_.rgb.w = static_cast<std::size_t>(f.shape[4]);
      planar = v_.floats(f);
    }
    m_.rgb.assign(planar, m_.n_slices);
    m_.rgb_negative = static_cast<std::size_t>(
        std::count_if(planar.begin(), planar.end(), [](double x) { return x < 0; }));
    largest_rgb_ = largest(planar, [](double x) { return std::abs(x); });
  }

  // The index and value of the largest of f(v[i]).
  template <class F>
  static std::pair<std::size_t, double> largest(const std::vector<double>& v, F f) {
    std::size_t at = 0;
    for (std::size_t i = 1; i < v.size(); ++i)
      if (f(v[i]) > f(v[at])) at = i;
    return {at, v.empty() ? 0.0 : v[at]};
  }

  // rgl_rho_cos_bound (|rgb| alone without the Jacobian) within the bound on ρ, the fields'
  // extremes named.
  void check_rho_bound() const {
    const auto [rgb_at, rgb] = largest_rgb_;
    double bound = std::abs(rgb);
    std::string why = fmt::format("the largest |rgb|, value {} of field '{}', is {:g}", rgb_at,
                                  m_.wavelengths ? "spectra" : "rgb", std::abs(rgb));
    if (m_.jacobian) {
      const auto [ndf_at, ndf] = largest(m_.ndf.v, [](double x) { return x; });
      const auto [sigma_at, sigma] = largest(m_.sigma.v, [](double x) { return -x; });
      bound = rgl_rho_cos_bound(std::abs(rgb), ndf, sigma);
      why +=
          fmt::format("; the largest 'ndf', value {}, {:g}; the smallest 'sigma', value {}, {:g}",
                      ndf_at, ndf, sigma_at, sigma);
    }
    if (!rho_within_bound(bound))
      throw FormatError(v_.file(), m_.jacobian ? "fields 'rgb', 'ndf' and 'sigma'" : "field 'rgb'",
                        fmt::format("{} (ρ·cos θo ≤ |rgb|{}: {})",
                                    rho_above_bound(bound, "the tables' extremes", "ρ·cos θo"),
                                    m_.jacobian ? " × ndf / (4 sigma)" : "", why));
  }

  // Whether ρ carries the NDF over 4 sigma: a single flag, 0 or 1.
  void read_jacobian() {
    const TensorField& f = v_.field("jacobian", TensorDtype::uint8, 1);
    v_.require_dim(f, 0, 1, "a single flag");
    const auto flag = static_cast<std::uint8_t>(f.bytes[0]);
    if (flag > 1) v_.fail("jacobian", "is " + std::to_string(flag) + ", expected 0 or 1");
    m_.jacobian = flag == 1;
  }

  const TensorFile& tf_;
  Validator v_;
  RglBrdf::Impl& m_;
  std::size_t n_theta_ = 0, n_phi_ = 0;
  std::pair<std::size_t, double> largest_rgb_{0, 0.0};  // index and value of the largest |rgb|
};

}  // namespace

RglBrdf::RglBrdf(const TensorFile& tf, std::string label, RglOptions options)
    : impl_(std::make_unique<Impl>()), label_(std::move(label)), options_(options) {
  MaterialReader(tf, tf.name.empty() ? label_ : tf.name, *impl_).read();
}

RglBrdf::~RglBrdf() = default;

std::shared_ptr<const RglBrdf> load_rgl(const std::filesystem::path& path, RglOptions options) {
  return std::make_shared<const RglBrdf>(read_tensor_file(path), path.stem().string(), options);
}

}  // namespace halfback
