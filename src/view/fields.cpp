#include "fields.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <span>

#include "halfback/core/batch.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/figure/coordinates.hpp"
#include "halfback/figure/field.hpp"
#include "halfback/figure/hemisphere.hpp"

namespace halfback::view {

namespace {

constexpr float kNanF = std::numeric_limits<float>::quiet_NaN();

// ρ of the pairs whose flag is set, as float RGB or luminance (NaN elsewhere); evaluated a block
// of kEvalBlock pairs at a time, `expired` (if given) asked before each: true, and the result is
// empty (a sum of hundreds of costly terms takes about a minute for a field of 512²).
constexpr std::size_t kEvalBlock = 1024;

std::vector<float> eval_where(const Brdf& brdf, const std::vector<DirPair<double>>& pairs,
                              const std::vector<std::uint8_t>& valid, RhoValues values,
                              const std::function<bool()>& expired) {
  std::vector<DirPair<double>> packed;
  packed.reserve(pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (valid[k]) packed.push_back(pairs[k]);
  std::vector<Rgb> rho(packed.size());
  for (std::size_t b = 0; b < packed.size(); b += kEvalBlock) {
    if (expired && expired()) return {};
    const std::size_t m = std::min(kEvalBlock, packed.size() - b);
    brdf.eval_batch(std::span(packed).subspan(b, m), std::span(rho).subspan(b, m));
  }
  const std::size_t channels = channels_of(values);
  std::vector<float> out(channels * pairs.size(), kNanF);
  std::size_t m = 0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (!valid[k]) continue;
    if (values == RhoValues::luminance) {
      out[k] = float(rho[m].luminance());
    } else {
      out[3 * k] = float(rho[m].r);
      out[3 * k + 1] = float(rho[m].g);
      out[3 * k + 2] = float(rho[m].b);
    }
    ++m;
  }
  return out;
}

Vec3<double> normalized(double x, double y, double z) {
  const double len = std::sqrt(x * x + y * y + z * z);
  return {x / len, y / len, z / len};
}

// The unit horizontal vector towards the mirror direction of ωo (+x when ωo is the normal).
void mirror_azimuth(const Vec3<double>& wo, double& cx, double& cy) {
  const double r = std::hypot(wo.x, wo.y);
  cx = r > 0 ? -wo.x / r : 1.0;
  cy = r > 0 ? -wo.y / r : 0.0;
}

// The isotropic coordinates of the pairs whose flag is set in a request's parameterization
// (its own forward map on the pairs as accept_pair() puts them, as the engine does), NaN
// elsewhere; float, 3 per pair.
std::vector<float> own_coordinates(const ParamDescriptor& p, std::vector<DirPair<double>> pairs,
                                   const std::vector<std::uint8_t>& inside) {
  for (DirPair<double>& pair : pairs) accept_pair(pair);
  std::vector<double> q(3 * pairs.size());
  p.forward_rows(true, pairs.data(), pairs.size(), q.data());
  std::vector<float> field(q.size());
  for (std::size_t k = 0; k < q.size(); ++k) field[k] = inside[k / 3] ? float(q[k]) : kNanF;
  return field;
}

}  // namespace

void form_to_pairs(const ViewForm& form, bool isotropic, std::vector<double>& q,
                   std::vector<DirPair<double>>& pairs, std::vector<std::uint8_t>& valid,
                   int threads) {
  const std::size_t d = isotropic ? 3 : 4, n = q.size() / d;
  pairs.assign(n, DirPair<double>{});
  valid.assign(n, 0);
  if (!form.own) {  // the core's batch engine (SIMD, with the domain mask)
    std::vector<ConstColumn<double>> in;
    for (std::size_t c = 0; c < d; ++c) in.push_back({q.data() + c, std::ptrdiff_t(d)});
    double* base = &pairs.data()->wi.x;  // DirPair<double> is six packed doubles
    static_assert(sizeof(DirPair<double>) == 6 * sizeof(double));
    const Column<double> out_cols[6] = {{base, 6},     {base + 1, 6}, {base + 2, 6},
                                        {base + 3, 6}, {base + 4, 6}, {base + 5, 6}};
    ConvertOutput<double> out{out_cols};
    out.valid = valid.data();
    BatchOptions options;
    options.threads = threads;
    convert<double>(Form{form.space, isotropic}, Form{Space::dirs, false}, in, n, out, options);
    return;
  }
  // A request's parameterization: its own checked inverse, in blocks (as the engine runs a
  // registered parameterization outside its kernels).
  const ParamDescriptor& p = *form.own;
  constexpr std::size_t kBlock = 4096;
  parallel_for((n + kBlock - 1) / kBlock, 1,
               [&](std::size_t b0, std::size_t b1) {
                 for (std::size_t b = b0; b < b1; ++b) {
                   const std::size_t r0 = b * kBlock, m = std::min(kBlock, n - r0);
                   wrap_azimuth_rows(p.axes(isotropic), q.data() + r0 * d, m);
                   p.inverse_rows(isotropic, q.data() + r0 * d, m, pairs.data() + r0,
                                  valid.data() + r0);
                 }
               },
               p.concurrent() ? threads : 1);
}

std::vector<float> slice_field(const Brdf& brdf, const ViewForm& form, double azimuth,
                               std::size_t n, int threads, RhoValues values, double pose,
                               const std::function<bool()>& expired) {
  // The grid of figure/slices.hpp (pixel centres), converted to direction pairs by the core's
  // batch engine (SIMD, with the domain mask): the same pairs as figure::sample_slice, which
  // converts one tuple at a time and costs several times more (docs/performance.md, "Viewer").
  const auto axes = form.param().axes(true);
  const figure::Grid grid = figure::Grid::pixel_centres(n, n, 0, axes[0].hi, 0, axes[1].hi);
  std::vector<double> q(3 * grid.size());
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t k = grid.index(i, j);
      q[3 * k] = grid.x(i);
      q[3 * k + 1] = grid.y(j);
      q[3 * k + 2] = azimuth;
    }
  std::vector<DirPair<double>> pairs;
  std::vector<std::uint8_t> valid;
  form_to_pairs(form, true, q, pairs, valid, threads);
  if (pose != 0) {
    const double c = std::cos(pose), s = std::sin(pose);
    const auto turn = [&](Vec3<double>& w) { w = {c * w.x - s * w.y, s * w.x + c * w.y, w.z}; };
    for (DirPair<double>& p : pairs) {
      turn(p.wi);
      turn(p.wo);
    }
  }
  return eval_where(brdf, pairs, valid, values, expired);
}

std::vector<float> hemisphere_field(const Brdf* brdf, const ViewForm& space, const Vec3<double>& wo,
                                    std::size_t n, int threads, RhoValues values,
                                    const std::function<bool()>& expired) {
  const auto view = figure::HemisphereView::around({0, 0, 1}, figure::Projection::equal_area);
  const figure::Grid grid = figure::Grid::pixel_centres(n, n, -1, 1, -1, 1);
  std::vector<DirPair<double>> pairs(grid.size());
  std::vector<std::uint8_t> inside(grid.size(), 0);
  parallel_for(
      n, 8,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j)
          for (std::size_t i = 0; i < n; ++i) {
            const auto wi = view.direction(grid.x(i), grid.y(j));
            const std::size_t k = grid.index(i, j);
            if (!wi) continue;
            pairs[k] = {normalized(wi->x, wi->y, std::max(wi->z, 0.0)), wo};
            inside[k] = 1;
          }
      },
      threads);
  if (space.is_dirs()) return eval_where(*brdf, pairs, inside, values, expired);
  if (space.own) return own_coordinates(*space.own, pairs, inside);
  // The coordinates, through the batch engine (the numbers `halfback convert` gives).
  std::vector<double> wi_x(grid.size()), wi_y(grid.size()), wi_z(grid.size());
  for (std::size_t k = 0; k < grid.size(); ++k) {
    const Vec3<double> w = inside[k] ? pairs[k].wi : Vec3<double>{0, 0, -1};  // rejected below
    wi_x[k] = w.x;
    wi_y[k] = w.y;
    wi_z[k] = w.z;
  }
  const std::vector<double> wo_x(grid.size(), wo.x), wo_y(grid.size(), wo.y),
      wo_z(grid.size(), wo.z);
  const ConstColumn<double> in[6] = {{wi_x.data()}, {wi_y.data()}, {wi_z.data()},
                                     {wo_x.data()}, {wo_y.data()}, {wo_z.data()}};
  std::vector<double> q(3 * grid.size());
  const Column<double> out_cols[3] = {{q.data(), 3}, {q.data() + 1, 3}, {q.data() + 2, 3}};
  ConvertOutput<double> out{out_cols};
  BatchOptions options;
  options.threads = threads;
  convert<double>(Form{Space::dirs, false}, Form{space.space, true}, in, grid.size(), out, options);
  std::vector<float> field(q.size());
  for (std::size_t k = 0; k < q.size(); ++k) field[k] = inside[k / 3] ? float(q[k]) : kNanF;
  return field;
}

Vec3<double> polar_in_plane(const Vec3<double>& wo, double t) {
  double cx = 0, cy = 0;
  mirror_azimuth(wo, cx, cy);
  return {std::sin(t) * cx, std::sin(t) * cy, std::cos(t)};
}

Vec3<double> polar_across(const Vec3<double>& wo, double t) {
  double cx = 0, cy = 0;
  mirror_azimuth(wo, cx, cy);
  const Vec3<double> mirror{-wo.x, -wo.y, wo.z};
  // mirror·cos t + b·sin t, with b = (−cy, cx, 0) horizontal and perpendicular to the plane.
  return normalized(mirror.x * std::cos(t) - cy * std::sin(t),
                    mirror.y * std::cos(t) + cx * std::sin(t), mirror.z * std::cos(t));
}

PolarCurves polar_curves(const Brdf& brdf, const Vec3<double>& wo, std::size_t n) {
  PolarCurves c;
  std::vector<DirPair<double>> in(n), across(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double deg = n > 1 ? -90.0 + 180.0 * double(k) / double(n - 1) : 0.0;
    const double t = deg * std::numbers::pi / 180.0;
    c.angles_deg.push_back(deg);
    Vec3<double> a = polar_in_plane(wo, t), b = polar_across(wo, t);
    a.z = std::max(a.z, 0.0);  // cos(±90°) rounds to 6e-17: on the horizon, not below
    b.z = std::max(b.z, 0.0);
    in[k] = {a, wo};
    across[k] = {b, wo};
  }
  c.in_plane.resize(n);
  c.across.resize(n);
  brdf.eval_batch(in, c.in_plane);
  brdf.eval_batch(across, c.across);
  return c;
}

}  // namespace halfback::view
