// The RGL writer (docs/formats.md, "RGL writer"): power iteration for the NDF, σ, the VNDF
// tables, the incident elevations, and ρ averaged over the tables' hat functions (or sampled at
// their nodes) through the VNDF warp of halfback's own reader.
#include "halfback/formats/rgl_writer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "binary_io.hpp"
#include "halfback/brdf/rho_bound.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/core/spectrum.hpp"
#include "halfback/util/atomic_file.hpp"

namespace halfback {

namespace {

using io_detail::store_le;

constexpr double kPi = std::numbers::pi;

double u_to_theta(double u) {
  return u * u * (kPi / 2);
}
double node_u(std::size_t k, std::size_t n) {
  return double(k) / double(n - 1);
}

// ∫_0^{2π} max(0, ω·m) dφm for ω at elevation θ and m at elevation θm: the azimuthal integral of
// the projected-area kernel, in closed form (docs/formats.md, "σ").
double azimuthal_kernel(double theta, double theta_m) {
  const double a = std::cos(theta) * std::cos(theta_m);
  const double b = std::sin(theta) * std::sin(theta_m);
  if (a >= b) return 2 * kPi * a;
  if (a <= -b) return 0;
  const double phi0 = std::acos(-a / b);
  return 2 * (a * phi0 + b * std::sin(phi0));
}

// Weights w with σ(θ) = Σ_j w_j D_j for D linear in u between the nodes: 6-point Gauss–Legendre
// on every interval of ∫_0^1 D(u) K(θ, θm(u)) sin θm π u du.
std::vector<double> sigma_weights(double theta, std::size_t nodes) {
  static constexpr std::array<double, 6> x = {-0.9324695142031521, -0.6612093864662645,
                                              -0.2386191860831969, 0.2386191860831969,
                                              0.6612093864662645,  0.9324695142031521};
  static constexpr std::array<double, 6> w = {0.1713244923791704, 0.3607615730481386,
                                              0.4679139345726910, 0.4679139345726910,
                                              0.3607615730481386, 0.1713244923791704};
  std::vector<double> out(nodes, 0.0);
  const double h = 1.0 / double(nodes - 1);
  for (std::size_t j = 0; j + 1 < nodes; ++j) {
    for (std::size_t q = 0; q < x.size(); ++q) {
      const double t = 0.5 * (x[q] + 1);
      const double u = (double(j) + t) * h;
      const double theta_m = u_to_theta(u);
      const double f =
          0.5 * w[q] * h * azimuthal_kernel(theta, theta_m) * std::sin(theta_m) * kPi * u;
      out[j] += (1 - t) * f;
      out[j + 1] += t * f;
    }
  }
  return out;
}

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

Vec3<double> direction(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

std::string format_dir(const Vec3<double>& v) {
  return fmt::format("({:.6g}, {:.6g}, {:.6g})", v.x, v.y, v.z);
}

// ρ(ω, ω) cos θ at the NDF nodes, the power iteration's weight; refuses NaN/∞ and all-zero.
std::vector<double> backscatter_weights(const Brdf& brdf, std::size_t nodes, int threads) {
  std::vector<double> f(nodes);
  std::vector<Rgb> rho(nodes);
  parallel_for(
      nodes, 8,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t k = begin; k < end; ++k) {
          const Vec3<double> w = direction(u_to_theta(node_u(k, nodes)), 0);
          rho[k] = brdf.eval({w, w});
        }
      },
      threads);
  for (std::size_t k = 0; k < nodes; ++k) {
    const double theta = u_to_theta(node_u(k, nodes));
    if (!rho[k].finite())
      throw std::invalid_argument(
          fmt::format("{}: ρ(ω, ω) is not finite at ω = {} (θ = {:.4g}°): cannot recover a "
                      "microfacet distribution",
                      brdf.name(), format_dir(direction(theta, 0)), theta * 180 / kPi));
    f[k] = std::max(rho[k].luminance(), 0.0) * std::cos(theta);
  }
  // Zero up to rounding: test:F's 1 − cos θd is 1e-16 there, and an NDF recovered from rounding
  // noise would be silent garbage. No measured material comes near the bound (the networks of
  // MERL's black-obsidian and black-phenolic give 6.6e-5 and 3.2e-4 sr⁻¹ at θ = 64°).
  constexpr double kNoBackscatter = 1e-12;  // sr⁻¹, ρ·cos θ
  if (std::all_of(f.begin(), f.end(), [](double v) { return !(v > kNoBackscatter); }))
    throw std::invalid_argument(brdf.name() +
                                ": ρ(ω, ω) is zero in every backscattering direction: there is no "
                                "microfacet distribution to recover (an RGL file needs one)");
  return f;
}

}  // namespace

double projected_area(const std::vector<double>& ndf, double theta) {
  return dot(sigma_weights(theta, ndf.size()), ndf);
}

RecoveredNdf recover_ndf(const Brdf& brdf, int nodes_int, int threads) {
  if (nodes_int < 2) throw std::invalid_argument("recover_ndf: at least 2 nodes are needed");
  const auto nodes = static_cast<std::size_t>(nodes_int);
  const std::vector<double> f = backscatter_weights(brdf, nodes, threads);
  std::vector<std::vector<double>> a(nodes);  // σ = A·D
  parallel_for(
      nodes, 4,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t k = begin; k < end; ++k)
          a[k] = sigma_weights(u_to_theta(node_u(k, nodes)), nodes);
      },
      threads);

  RecoveredNdf r;
  r.ndf.assign(nodes, 1.0);
  std::vector<double> next(nodes);
  constexpr int kMaxIterations = 10000;
  constexpr double kTolerance = 1e-10;
  for (r.iterations = 1; r.iterations <= kMaxIterations; ++r.iterations) {
    for (std::size_t k = 0; k < nodes; ++k) next[k] = f[k] * dot(a[k], r.ndf);
    const double norm = dot(a[0], next);  // σ(0) = ∫ D cos θm dωm
    if (!(norm > 0) || !std::isfinite(norm))
      throw std::invalid_argument(brdf.name() + ": the power iteration for the NDF collapsed to " +
                                  "zero (ρ(ω, ω) is zero where the distribution has its mass)");
    double change = 0, largest = 0;
    for (std::size_t k = 0; k < nodes; ++k) {
      next[k] /= norm;
      change = std::max(change, std::abs(next[k] - r.ndf[k]));
      largest = std::max(largest, next[k]);
    }
    r.ndf.swap(next);
    r.change = change / largest;
    if (r.change < kTolerance) break;
  }
  r.iterations = std::min(r.iterations, kMaxIterations);
  r.sigma.resize(nodes);
  for (std::size_t k = 0; k < nodes; ++k) r.sigma[k] = dot(a[k], r.ndf);
  return r;
}

namespace {

TensorFieldData float_field(std::string name, std::vector<std::uint64_t> shape,
                            const std::vector<double>& values) {
  TensorFieldData f{std::move(name), TensorDtype::float32, std::move(shape), {}};
  f.data.resize(values.size() * 4);
  for (std::size_t i = 0; i < values.size(); ++i)
    store_le<float>(f.data.data() + 4 * i, static_cast<float>(values[i]));
  return f;
}

TensorFieldData byte_field(std::string name, std::string_view bytes) {
  TensorFieldData f{std::move(name), TensorDtype::uint8, {bytes.size()}, {}};
  for (char c : bytes) f.data.push_back(static_cast<std::byte>(c));
  return f;
}

void check_option(const char* name, int value, int lo, int hi) {
  if (value < lo || value > hi)
    throw std::invalid_argument(
        fmt::format("{} is {}: must be an integer from {} to {}", name, value, lo, hi));
}

// The incident elevations: θ0 = 0, θ_{n-1} = π/2 and evenly spaced values of σ between, as in
// the published files (σ decreases with θ; the first crossing of each level in the σ table,
// linear in u). Falls back to even spacing in θ where σ is not decreasing.
std::vector<double> incidence_grid(const std::vector<double>& sigma, int count) {
  const std::size_t nodes = sigma.size();
  const auto n = static_cast<std::size_t>(count);
  std::vector<double> theta(n);
  for (std::size_t t = 0; t < n; ++t) {
    const double level = sigma[0] + (sigma[nodes - 1] - sigma[0]) * double(t) / double(n - 1);
    double u = node_u(t, n);  // fallback
    for (std::size_t k = 0; k + 1 < nodes; ++k) {
      if (sigma[k] >= level && sigma[k + 1] <= level && sigma[k] > sigma[k + 1]) {
        u = node_u(k, nodes) + (sigma[k] - level) / (sigma[k] - sigma[k + 1]) / double(nodes - 1);
        break;
      }
    }
    theta[t] = t == 0 ? 0 : t + 1 == n ? kPi / 2 : u_to_theta(u);
  }
  for (std::size_t t = 1; t < n; ++t)
    if (!(theta[t] > theta[t - 1]))
      for (std::size_t s = 0; s < n; ++s) theta[s] = kPi / 2 * double(s) / double(n - 1);
  return theta;
}

// The visible normals' density on the unit square of (u, v), slice by slice:
// D(m) max(0, ωi·m) / σ(ωi) · 2π² u sin θm, divided by the table size as in the published files.
std::vector<double> vndf_tables(const std::vector<double>& ndf,
                                const std::vector<double>& theta_i) {
  const std::size_t n = ndf.size();
  std::vector<double> out(theta_i.size() * n * n);
  for (std::size_t s = 0; s < theta_i.size(); ++s) {
    const double sigma = projected_area(ndf, theta_i[s]);
    const Vec3<double> wi = direction(theta_i[s], 0);
    for (std::size_t j = 0; j < n; ++j) {
      const double phi = (2 * node_u(j, n) - 1) * kPi;
      for (std::size_t i = 0; i < n; ++i) {
        const double u = node_u(i, n), theta_m = u_to_theta(u);
        const Vec3<double> m = direction(theta_m, phi);
        const double cos_im = std::max(0.0, wi.x * m.x + wi.y * m.y + wi.z * m.z);
        out[(s * n + j) * n + i] =
            ndf[i] * cos_im / sigma * 2 * kPi * kPi * u * std::sin(theta_m) / double(n * n);
      }
    }
  }
  return out;
}

struct Geometry {
  std::vector<TensorFieldData> fields;  // everything but luminance and rgb
  std::vector<double> theta_i;
  std::vector<double> ndf, sigma;  // the tables' values as stored (rounded to float)
};

std::vector<double> rounded_to_float(const std::vector<double>& v) {
  std::vector<double> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out[i] = static_cast<float>(v[i]);
  return out;
}

// A table over u in [0, 1] (nodes k/(N-1)), linear between nodes, as the readers interpolate it.
double table_at(const std::vector<double>& t, double u) {
  const double x = std::clamp(u, 0.0, 1.0) * double(t.size() - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(x), t.size() - 2);
  return t[i] + (x - double(i)) * (t[i + 1] - t[i]);
}

Geometry geometry_fields(const RecoveredNdf& ndf, std::vector<double> theta_i,
                         const std::string& desc) {
  Geometry g;
  g.theta_i = std::move(theta_i);
  g.ndf = rounded_to_float(ndf.ndf);
  g.sigma = rounded_to_float(ndf.sigma);
  const auto n = static_cast<std::uint64_t>(ndf.ndf.size());
  std::vector<double> two_rows(ndf.ndf), sigma_rows(ndf.sigma);
  two_rows.insert(two_rows.end(), ndf.ndf.begin(), ndf.ndf.end());
  sigma_rows.insert(sigma_rows.end(), ndf.sigma.begin(), ndf.sigma.end());
  TensorFieldData version{"version", TensorDtype::uint32, {2}, std::vector<std::byte>(8)};
  store_le<std::uint32_t>(version.data.data(), 1);
  g.fields.push_back(std::move(version));
  g.fields.push_back(byte_field("description", desc));
  g.fields.push_back(float_field("phi_i", {1}, {0.0}));
  g.fields.push_back(float_field("theta_i", {g.theta_i.size()}, g.theta_i));
  g.fields.push_back(float_field("sigma", {2, n}, sigma_rows));
  g.fields.push_back(float_field("ndf", {2, n}, two_rows));
  g.fields.push_back(
      float_field("vndf", {1, g.theta_i.size(), n, n}, vndf_tables(ndf.ndf, g.theta_i)));
  return g;
}

// The material of geometry `g` with luminance and RGB tables of res × res ones: its warps are
// the file's, its values the Jacobian factor alone.
std::shared_ptr<const RglBrdf> geometry_material(const Geometry& g, std::size_t res,
                                                 const std::string& label) {
  const std::size_t slices = g.theta_i.size();
  std::vector<TensorFieldData> fields = g.fields;
  fields.push_back(float_field("luminance", {1, slices, res, res},
                               std::vector<double>(slices * res * res, 1.0)));
  fields.push_back(float_field("rgb", {1, slices, 3, res, res},
                               std::vector<double>(slices * 3 * res * res, 1.0)));
  fields.push_back({"jacobian", TensorDtype::uint8, {1}, {std::byte{1}}});
  return std::make_shared<const RglBrdf>(parse_tensor_file(serialize_tensor_file(fields), label),
                                         label, RglOptions{.clamp_negative = false});
}

// The stored quantity f = ρ cos θo · 4σ(ωi)/D(m) at the point `s` of the warped square of one
// incidence slice, through the VNDF warp of `warp` (the file being written, read by halfback's
// reader), with D and σ interpolated from the stored tables as every reader does; 0 where ωo is
// below the horizon.
Rgb stored_value(const Brdf& brdf, const RglBrdf& warp, const Geometry& g, double theta_i,
                 double sigma, RglWarpPoint s) {
  const Vec3<double> wi = direction(theta_i, 0);
  const RglWarpPoint um = warp.vndf_forward(s, theta_i, 0.0);
  const Vec3<double> m = direction(u_to_theta(um.x), (2 * um.y - 1) * kPi);
  const double c = wi.x * m.x + wi.y * m.y + wi.z * m.z;
  const Vec3<double> wo{2 * c * m.x - wi.x, 2 * c * m.y - wi.y, 2 * c * m.z - wi.z};
  if (!(c > 0 && wo.z > 0)) return {};
  const Rgb rho = brdf.eval({wi, wo});
  if (!rho.finite())
    throw std::invalid_argument(
        fmt::format("{}: ρ is not finite at ωi = {}, ωo = {}: cannot "
                    "tabulate it",
                    brdf.name(), format_dir(wi), format_dir(wo)));
  // What the file stores is ρ·cos θo (ρ itself grows without bound at grazing ωo).
  if (!rho_within_bound(rho * wo.z))
    throw std::invalid_argument(fmt::format(
        "{}: {}: an RGL file cannot hold it", brdf.name(),
        rho_above_bound((rho * wo.z).max_channel(), describe_halfdiff({wi, wo}), "ρ·cos θo")));
  const double scale = table_at(g.ndf, um.x) / (4 * sigma);
  return scale > 0 ? rho * (wo.z / scale) : Rgb{};
}

// The tables of one incidence slice: each node holds the average of f over its hat function
// (the bilinear interpolant's basis function on the res × res grid of the warped square), by the
// midpoint rule on `kSubsamples`² points per cell. The readers interpolate the table bilinearly,
// and the slice's directional albedo is ∫∫ f ds (the warp's Jacobian is the VNDF, which cancels
// D/(4σ) and the 4 (ωi·m) of the reflection: docs/formats.md, "Energy"); the hat averages keep
// that integral exactly, where point samples of a lobe narrower than a cell created or lost
// energy in proportion to the cell's size (a near-mirror's tail, a grazing Fresnel peak).
constexpr std::size_t kSubsamples = 12;

void store_node(Rgb value, std::size_t node, std::size_t res, double* rgb, double* luminance) {
  rgb[node] = value.r;
  rgb[res * res + node] = value.g;
  rgb[2 * res * res + node] = value.b;
  luminance[node] = std::max(value.luminance(), 0.0);
}

void tabulate_slice(const Brdf& brdf, const RglBrdf& warp, const Geometry& g, std::size_t slice,
                    std::size_t res, RglTabulation tabulation, int threads, double* rgb,
                    double* luminance) {
  const double theta_i = g.theta_i[slice];
  const double sigma = table_at(g.sigma, std::sqrt(theta_i * (2 / kPi)));
  if (tabulation == RglTabulation::point) {
    parallel_for(
        res * res, 16,
        [&](std::size_t begin, std::size_t end) {
          for (std::size_t node = begin; node < end; ++node)
            store_node(stored_value(brdf, warp, g, theta_i, sigma,
                                    {node_u(node % res, res), node_u(node / res, res)}),
                       node, res, rgb, luminance);
        },
        threads);
    return;
  }
  const std::size_t cells = res - 1, fine = cells * kSubsamples;
  const double h = 1.0 / double(fine);
  // One row of the fine grid a task: the values at its points and their cell coordinates.
  std::vector<Rgb> values(fine * fine);
  parallel_for(
      fine, 4,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t y = begin; y < end; ++y)
          for (std::size_t x = 0; x < fine; ++x)
            values[y * fine + x] =
                stored_value(brdf, warp, g, theta_i, sigma, {(x + 0.5) * h, (y + 0.5) * h});
      },
      threads);
  // Node (i, j) gathers the fine points of its (up to four) cells, weighted by its hat.
  parallel_for(
      res * res, 16,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t node = begin; node < end; ++node) {
          const std::size_t i = node % res, j = node / res;
          Rgb sum;
          double weight = 0;
          for (std::size_t y = j > 0 ? (j - 1) * kSubsamples : 0;
               y < std::min(fine, (j + 1) * kSubsamples); ++y) {
            const double wy = 1 - std::abs((y + 0.5) / kSubsamples - double(j));
            for (std::size_t x = i > 0 ? (i - 1) * kSubsamples : 0;
                 x < std::min(fine, (i + 1) * kSubsamples); ++x) {
              const double w = wy * (1 - std::abs((x + 0.5) / kSubsamples - double(i)));
              sum += values[y * fine + x] * w;
              weight += w;
            }
          }
          store_node(sum * (1 / weight), node, res, rgb, luminance);
        }
      },
      threads);
}

// The reader's bound on the tables (rgl_rho_cos_bound), checked before anything is written: the
// values are each within the bound on ρ, but their extremes may come from different places.
void require_tables_within_bound(const Brdf& brdf, const std::vector<double>& rgb,
                                 const Geometry& g) {
  double largest_rgb = 0;
  for (double v : rgb) largest_rgb = std::max(largest_rgb, std::abs(v));
  const double bound = rgl_rho_cos_bound(largest_rgb, *std::max_element(g.ndf.begin(), g.ndf.end()),
                                         *std::min_element(g.sigma.begin(), g.sigma.end()));
  if (!rho_within_bound(bound))
    throw std::invalid_argument(fmt::format(
        "{}: its RGL tables would give {} (ρ·cos θo ≤ |rgb| × ndf / (4 sigma): the largest "
        "|rgb| {:g}), which the reader refuses",
        brdf.name(), rho_above_bound(bound, "the tables' extremes", "ρ·cos θo"), largest_rgb));
}

// The spectra of the RGB tables (slices × 3 × res², channel-major per slice), one sigmoid
// spectrum fitted per entry, as slices × wavelengths × res² (docs/formats.md, "Spectra").
std::vector<double> spectra_of_rgb(const std::vector<double>& rgb, std::size_t slices,
                                   std::size_t res, const std::vector<double>& wavelengths,
                                   int threads) {
  const spectral::RgbToSpectrum upsample(wavelengths);
  const std::size_t n = res * res, nl = wavelengths.size();
  std::vector<double> out(slices * nl * n);
  parallel_for(
      slices * n, 64,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t e = begin; e < end; ++e) {
          const std::size_t s = e / n, node = e % n;
          const double* in = rgb.data() + s * 3 * n + node;
          const spectral::SpectrumFit f = upsample.fit({in[0], in[n], in[2 * n]});
          for (std::size_t k = 0; k < nl; ++k)
            out[(s * nl + k) * n + node] = f.spectrum.scale > 0 ? f.spectrum(wavelengths[k]) : 0;
        }
      },
      threads);
  return out;
}

// The directional albedo (luminance) of the BRDF at every slice of geometry `g`: the mean of f
// over a midpoint grid of the warped square (∫∫ f ds, as tabulate_slice keeps it).
std::vector<double> slice_albedos(const Brdf& brdf, const Geometry& g, int threads) {
  constexpr std::size_t kGrid = 48;
  const std::shared_ptr<const RglBrdf> warp = geometry_material(g, 2, "incidences");
  std::vector<double> rows(g.theta_i.size() * kGrid);
  parallel_for(
      rows.size(), 4,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t r = begin; r < end; ++r) {
          const double theta_i = g.theta_i[r / kGrid];
          const double sigma = table_at(g.sigma, std::sqrt(theta_i * (2 / kPi)));
          const double y = (double(r % kGrid) + 0.5) / kGrid;
          double sum = 0;
          for (std::size_t x = 0; x < kGrid; ++x)
            sum += stored_value(brdf, *warp, g, theta_i, sigma, {(double(x) + 0.5) / kGrid, y})
                       .luminance();
          rows[r] = sum / double(kGrid * kGrid);
        }
      },
      threads);
  std::vector<double> albedo(g.theta_i.size(), 0.0);
  for (std::size_t r = 0; r < rows.size(); ++r) albedo[r / kGrid] += rows[r];
  return albedo;
}

// The incident elevations of the file: half of them (rounded up) evenly spaced in σ as in the
// published files (incidence_grid), the others, one at a time, where the directional albedo is
// worst predicted by linear interpolation between the elevations chosen so far (the readers
// interpolate every table linearly in θi), among candidates 1° apart. The albedo of many
// materials turns sharply at grazing (a Fresnel peak between 70° and 85°, where σ-spaced
// elevations are 8–10° apart): there, evenly spaced σ alone missed a tenth of the energy.
std::vector<double> chosen_incidences(const Brdf& brdf, const RecoveredNdf& ndf,
                                      const RglExportOptions& o) {
  if (o.incidences == RglIncidences::sigma) return incidence_grid(ndf.sigma, o.theta_i);
  const int base_count = std::max(2, (o.theta_i + 1) / 2);
  std::vector<double> chosen = incidence_grid(ndf.sigma, base_count);
  if (base_count >= o.theta_i) return chosen;
  std::vector<double> candidates = chosen;
  for (int d = 1; d < 90; ++d) {
    const double t = d * kPi / 180;
    const bool near = std::any_of(chosen.begin(), chosen.end(),
                                  [&](double c) { return std::abs(c - t) < 0.25 * kPi / 180; });
    if (!near) candidates.push_back(t);
  }
  std::sort(candidates.begin(), candidates.end());
  const std::vector<double> albedo =
      slice_albedos(brdf, geometry_fields(ndf, candidates, ""), o.threads);
  const double largest = *std::max_element(albedo.begin(), albedo.end());
  std::vector<bool> in(candidates.size(), false);
  for (double c : chosen)
    in[std::size_t(std::find(candidates.begin(), candidates.end(), c) - candidates.begin())] = true;
  for (int added = base_count; added < o.theta_i; ++added) {
    std::size_t best = 0;
    double worst = -1;
    std::size_t left = 0;
    for (std::size_t k = 1; k < candidates.size(); ++k) {
      if (in[k]) {
        left = k;
        continue;
      }
      std::size_t right = k + 1;
      while (!in[right]) ++right;  // the last candidate (90°) is always in
      const double t = (candidates[k] - candidates[left]) / (candidates[right] - candidates[left]);
      const double predicted = albedo[left] + t * (albedo[right] - albedo[left]);
      const double error =
          std::abs(albedo[k] - predicted) / std::max(albedo[k], 0.1 * largest + 1e-300);
      if (error > worst) worst = error, best = k;
    }
    if (worst <= 0) break;
    in[best] = true;
  }
  std::vector<double> out;
  for (std::size_t k = 0; k < candidates.size(); ++k)
    if (in[k]) out.push_back(candidates[k]);
  return out;
}

}  // namespace

std::shared_ptr<const RglBrdf> rgl_warp_material(const Brdf& brdf, const RglWarpOptions& o) {
  if (!brdf.isotropic() && !o.allow_anisotropic)
    throw std::invalid_argument(brdf.name() +
                                " is anisotropic: the warp of its NDF is isotropic (one φi slice)");
  if (!(o.ndf_floor_share >= 0 && o.ndf_floor_share < 1))
    throw std::invalid_argument(
        fmt::format("ndf floor share {}: must be in [0, 1)", o.ndf_floor_share));
  RglExportOptions e;
  e.theta_i = o.theta_i;
  e.vndf_resolution = o.vndf_resolution;
  e.threads = o.threads;
  check_option("theta_i", e.theta_i, 2, 90);
  check_option("vndf_resolution", e.vndf_resolution, 2, 1024);
  RecoveredNdf ndf = recover_ndf(brdf, e.vndf_resolution, e.threads);
  const double floor = o.ndf_floor_share / kPi;  // a constant c holds π c of ∫ D cos θm dωm = 1
  for (double& d : ndf.ndf) d = std::max(d, floor);
  for (std::size_t k = 0; k < ndf.ndf.size(); ++k)
    ndf.sigma[k] = projected_area(ndf.ndf, u_to_theta(node_u(k, ndf.ndf.size())));
  const Geometry g = geometry_fields(ndf, incidence_grid(ndf.sigma, e.theta_i),
                                     brdf.name() + ": the VNDF warp of its NDF");
  return geometry_material(g, 2, brdf.name());
}

std::vector<TensorFieldData> rgl_fields(const Brdf& brdf, const RglExportOptions& o) {
  if (!brdf.isotropic())
    throw std::invalid_argument(brdf.name() +
                                " is anisotropic: the RGL writer supports isotropic BRDFs only "
                                "(one φi slice)");
  if (o.variant != RglVariant::rgb && o.variant != RglVariant::spectral &&
      o.variant != RglVariant::both)
    throw std::invalid_argument(
        fmt::format("--variant is {}: must be rgb, spectral or both", static_cast<int>(o.variant)));
  check_option("--theta-i", o.theta_i, 2, 90);
  check_option("--resolution", o.resolution, 2, 512);
  check_option("--vndf-resolution", o.vndf_resolution, 2, 1024);
  const std::string desc =
      o.description.empty()
          ? fmt::format("{}: {} (exported by halfback; NDF by power iteration{})", brdf.name(),
                        brdf.description(),
                        o.variant == RglVariant::rgb ? "" : "; spectra upsampled from RGB")
          : o.description;
  const RecoveredNdf ndf = recover_ndf(brdf, o.vndf_resolution, o.threads);
  Geometry g = geometry_fields(ndf, chosen_incidences(brdf, ndf, o), desc);

  const auto res = static_cast<std::size_t>(o.resolution);
  const std::size_t slices = g.theta_i.size();
  const std::shared_ptr<const RglBrdf> warp = geometry_material(g, res, "export");
  TensorFieldData jacobian{"jacobian", TensorDtype::uint8, {1}, {std::byte{1}}};

  std::vector<double> rgb(slices * 3 * res * res), luminance(slices * res * res);
  for (std::size_t s = 0; s < slices; ++s) {
    tabulate_slice(brdf, *warp, g, s, res, o.tabulation, o.threads, rgb.data() + s * 3 * res * res,
                   luminance.data() + s * res * res);
    if (o.progress) o.progress(int(s + 1), int(slices));
  }
  require_tables_within_bound(brdf, rgb, g);
  g.fields.push_back(float_field("luminance", {1, slices, res, res}, luminance));
  if (o.variant != RglVariant::spectral)
    g.fields.push_back(float_field("rgb", {1, slices, 3, res, res}, rgb));
  if (o.variant != RglVariant::rgb) {
    const std::vector<double> wavelengths = spectral::default_wavelengths();
    g.fields.push_back(float_field("wavelengths", {wavelengths.size()}, wavelengths));
    g.fields.push_back(float_field("spectra", {1, slices, wavelengths.size(), res, res},
                                   spectra_of_rgb(rgb, slices, res, wavelengths, o.threads)));
  }
  g.fields.push_back(std::move(jacobian));
  return std::move(g.fields);
}

void write_rgl(const std::filesystem::path& path, const Brdf& brdf,
               const RglExportOptions& options) {
  AtomicFile file(path);  // an unwritable destination fails before the work
  const std::vector<std::byte> bytes = serialize_tensor_file(rgl_fields(brdf, options));
  file.write({reinterpret_cast<const char*>(bytes.data()), bytes.size()});
  file.commit();
}

}  // namespace halfback
