// RglBrdf's batch paths (include/halfback/formats/rgl.hpp): eval_batch, sample_batch and
// pdf_batch in blocks of rgl_detail::kBlock rows, the angles by the batch engine's SIMD
// conversions, the values by the block kernel (rgl_kernel.cpp) and the warp's block loops
// (rgl_warp.cpp); the rows the one-pair paths treat apart go through them (rgl.cpp). Compiled with
// the flags of those files (src/formats/CMakeLists.txt).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "halfback/core/batch.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/formats/rgl.hpp"
#include "rgl_impl.hpp"
#include "rgl_kernel.hpp"
#include "rgl_warp.hpp"

namespace halfback {

using rgl_detail::azimuth_u;
using rgl_detail::Flips;
using rgl_detail::flips_for;
using rgl_detail::kBlock;
using rgl_detail::kPi;
using rgl_detail::phi_to_u;
using rgl_detail::Slices;
using rgl_detail::theta_to_u;
using rgl_detail::Warp;

namespace {

// Row k of a block's directions: `given`, the direction whose azimuth indexes the tables, and the
// unit half vector of the pair, both after the flips that bring `given` into the range the data
// covers. True when the row must go through the one-pair path: a direction at or below the
// horizon, `given` or the half vector along the normal (azimuth atan2(±0, ±0)).
template <std::size_t N>
bool put_direction_and_half_vector(int reduction, const Vec3<double>& given,
                                   const Vec3<double>& other, double (&dirs)[6][N], std::size_t k) {
  const Flips flips = flips_for(reduction, given);
  const Vec3<double> g = flips.apply(given), d = flips.apply(other);
  const double hx = g.x + d.x, hy = g.y + d.y, hz = g.z + d.z;
  const double inverse_len = 1 / std::sqrt(hx * hx + hy * hy + hz * hz);
  dirs[0][k] = g.x, dirs[1][k] = g.y, dirs[2][k] = g.z;
  dirs[3][k] = hx * inverse_len, dirs[4][k] = hy * inverse_len, dirs[5][k] = hz * inverse_len;
  return !(g.z > 0) || !(d.z > 0) || (g.x == 0 && g.y == 0) || (hx == 0 && hy == 0);
}

// How close (in units of the unit square) an azimuth coordinate may come to the seam 0 ≡ 1 of the
// tables before the row goes to eval(): there the table value jumps, and the batch's azimuth,
// a few ulps from eval()'s, could fall on the other side.
constexpr double kSeam = 1e-9;

bool near_seam(double u01) {
  return u01 < kSeam || u01 > 1 - kSeam;
}

// An azimuth of [0, 2π) (the batch engine's) in (-π, π] (atan2's).
double signed_azimuth(double phi) {
  return phi > kPi ? phi - 2 * kPi : phi;
}

// The spherical angles (θ, φ) of the two directions of each row (the columns of dirs), φ in
// [0, 2π) as the spherical form gives it, by the batch engine's SIMD conversion; valid[k] = 0
// where the row is not one it accepts (not unit, below the horizon).
void angles_of(double (&dirs)[6][kBlock], std::size_t n, double (&angle)[4][kBlock],
               std::uint8_t* valid) {
  const ConstColumn<double> in[6] = {{dirs[0], 1}, {dirs[1], 1}, {dirs[2], 1},
                                     {dirs[3], 1}, {dirs[4], 1}, {dirs[5], 1}};
  const Column<double> cols[4] = {{angle[0], 1}, {angle[1], 1}, {angle[2], 1}, {angle[3], 1}};
  convert<double>(Form{Space::dirs}, Form{space_of<Spherical>}, in, n,
                  ConvertOutput<double>{cols, {}, valid}, BatchOptions{1});
}

// A block of pairs as eval_block and pdf_block read it: per row, the direction that indexes the
// tables (ωi for eval, ωo for pdf) and the unit half vector (put_direction_and_half_vector), their
// spherical angles (angles_of), and whether the row goes through the one-pair path.
struct PairBlock {
  alignas(64) double dirs[6][kBlock];
  alignas(64) double angle[4][kBlock];
  alignas(64) std::uint8_t valid[kBlock];
  bool apart[kBlock];

  PairBlock(int reduction, std::span<const DirPair<double>> pairs, bool given_is_wi) {
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const DirPair<double>& p = pairs[k];
      apart[k] = given_is_wi ? put_direction_and_half_vector(reduction, p.wi, p.wo, dirs, k)
                             : put_direction_and_half_vector(reduction, p.wo, p.wi, dirs, k);
    }
    angles_of(dirs, pairs.size(), angle, valid);
  }
};

// An azimuth near ±π, where the SIMD azimuth and atan2's may fall on either side of the seam (the
// slices' weights jump there for data with several φi).
bool near_pi(double phi) {
  return std::abs(phi) > kPi - 1e-9;
}

}  // namespace

void RglBrdf::Impl::eval_rows(rgl_kernel::EvalRows& rows, bool clamp_negative) const {
  const rgl_kernel::EvalTables t{vndf.node.data(),
                                 vndf.row.data(),
                                 vndf.inv_total.data(),
                                 vndf.w,
                                 vndf.h,
                                 rgb.v.data(),
                                 rgb.w,
                                 rgb.h,
                                 ndf.v.data(),
                                 ndf.w,
                                 ndf.h,
                                 sigma.v.data(),
                                 sigma.w,
                                 sigma.h,
                                 jacobian,
                                 clamp_negative};
  rgl_kernel::eval_rows(t, rows, slice_count());
}

// One block: the angles of every row by the batch engine's SIMD conversion (ωi and the unit half
// vector as a pair of directions, to spherical coordinates), the table coordinates of every row,
// then the values. Rows that eval() treats apart go through it: NaN, at or below the horizon, not
// unit (the conversion rejects them), ωi or the half vector along the normal (whose azimuth is
// atan2(±0, ±0)), an azimuth within kSeam of a seam.
void RglBrdf::eval_block(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const {
  const Impl& m = *impl_;
  const std::size_t n = pairs.size();
  PairBlock block(m.reduction, pairs, true);
  auto& [dirs, angle, valid, apart] = block;

  // The table coordinates of every row, in a loop without calls that the compiler vectorizes.
  alignas(64) double um_x[kBlock], um_y[kBlock], uwi_x[kBlock], uwi_y[kBlock];
  for (std::size_t k = 0; k < n; ++k) {
    const double phi_i = signed_azimuth(angle[1][k]), phi_m = signed_azimuth(angle[3][k]);
    angle[1][k] = phi_i;
    um_x[k] = theta_to_u(angle[2][k]);
    um_y[k] = azimuth_u(phi_m, phi_i, m.isotropic);
    uwi_x[k] = theta_to_u(angle[0][k]);
    uwi_y[k] = phi_to_u(phi_i);
  }
  // The common rows packed for the block kernel (rgl_kernel), the others through eval().
  rgl_kernel::EvalRows rows;
  std::size_t at[kBlock];  // the rows' places in the block
  for (std::size_t k = 0; k < n; ++k) {
    apart[k] = apart[k] || !valid[k] || near_seam(um_y[k]) || near_seam(uwi_y[k]) || !m.lanes;
    if (apart[k]) continue;
    const std::size_t r = rows.n++;
    at[r] = k;
    Slices s;
    m.slices(angle[1][k], angle[0][k], s);
    for (int c = 0; c < s.count; ++c)
      rows.slice[c][r] = s.index[c], rows.weight[c][r] = s.weight[c];
    rows.um_x[r] = um_x[k], rows.um_y[r] = um_y[k];
    rows.uwi_x[r] = uwi_x[k], rows.uwi_y[r] = uwi_y[k];
    rows.wo[0][r] = pairs[k].wo.x, rows.wo[1][r] = pairs[k].wo.y, rows.wo[2][r] = pairs[k].wo.z;
  }
  m.eval_rows(rows, options_.clamp_negative);
  for (std::size_t r = 0; r < rows.n; ++r)
    out[at[r]] = {rows.fr[0][r], rows.fr[1][r], rows.fr[2][r]};
  for (std::size_t k = 0; k < n; ++k)
    if (apart[k]) out[k] = eval(pairs[k]);
}

void RglBrdf::eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const {
  if (out.size() != pairs.size())
    throw std::invalid_argument("RglBrdf::eval_batch: " + std::to_string(pairs.size()) +
                                " pairs but " + std::to_string(out.size()) + " outputs");
  // Tasks of 16 blocks (tens of microseconds, well above the start-up of a thread).
  const std::size_t n = pairs.size(), blocks = (n + kBlock - 1) / kBlock;
  parallel_for(blocks, 16, [&](std::size_t begin, std::size_t end) {
    for (std::size_t b = begin; b < end; ++b) {
      const std::size_t first = b * kBlock, count = std::min(kBlock, n - first);
      eval_block(pairs.subspan(first, count), out.subspan(first, count));
    }
  });
}
void RglBrdf::sample_batch(std::span<const Vec3<double>> wo, std::span<const double> u1,
                           std::span<const double> u2, std::span<BrdfSample> out) const {
  if (wo.size() != out.size() || u1.size() != out.size() || u2.size() != out.size()) {
    Brdf::sample_batch(wo, u1, u2, out);  // the size check
    return;
  }
  for (std::size_t first = 0; first < out.size(); first += kBlock) {
    const std::size_t n = std::min(kBlock, out.size() - first);
    sample_block(wo.subspan(first, n), u1.subspan(first, n), u2.subspan(first, n),
                 out.subspan(first, n));
  }
}

// One block of sample(): the angles of ωo (flipped into the data's range) by the SIMD conversion,
// the warps, then the normals' directions by the inverse conversion (spherical to directions).
// Rows that sample() treats apart go through it: ωo at or below the horizon or along the normal,
// not accepted by the conversion, an azimuth at the seam.
void RglBrdf::sample_block(std::span<const Vec3<double>> wo, std::span<const double> u1,
                           std::span<const double> u2, std::span<BrdfSample> out) const {
  const Impl& m = *impl_;
  const std::size_t n = wo.size();
  alignas(64) double dirs[6][kBlock];
  alignas(64) double angle[4][kBlock];
  alignas(64) std::uint8_t valid[kBlock];
  bool apart[kBlock];
  Flips flips[kBlock];
  // Two samples per row of the conversions, each way a pair of directions: sample k in half
  // k % 2 of row k / 2 (columns 3 (k % 2) .. +2 of the directions, 2 (k % 2) .. +1 of the
  // angles). A row's second half when n is odd, and the rows of samples that go apart, hold +z,
  // which every conversion accepts.
  const std::size_t rows = (n + 1) / 2;
  for (std::size_t k = 0; k < 2 * rows; ++k) {
    Vec3<double> g{0, 0, 1};
    if (k < n) {
      flips[k] = flips_for(m.reduction, wo[k]);
      const Vec3<double> d = flips[k].apply(wo[k]);
      apart[k] = !(d.z > 0) || (d.x == 0 && d.y == 0);
      if (!apart[k]) g = d;
    }
    dirs[3 * (k % 2)][k / 2] = g.x;
    dirs[3 * (k % 2) + 1][k / 2] = g.y;
    dirs[3 * (k % 2) + 2][k / 2] = g.z;
  }
  angles_of(dirs, rows, angle, valid);
  double theta_g[kBlock], phi_g[kBlock];
  for (std::size_t k = 0; k < n; ++k) {
    theta_g[k] = angle[2 * (k % 2)][k / 2];
    phi_g[k] = signed_azimuth(angle[2 * (k % 2) + 1][k / 2]);
    apart[k] = apart[k] || !valid[k / 2] || near_pi(phi_g[k]);
  }
  double pdf_u[kBlock] = {}, um_x[kBlock] = {};
  // The warp's draws in steps over the block (Warp::draw_row), each prefetching for the next.
  Slices slices[kBlock];
  Warp::Drawing drawing[kBlock];
  for (std::size_t k = 0; k < n; ++k) {
    if (apart[k]) continue;
    m.slices(phi_g[k], theta_g[k], slices[k]);
    m.vndf.draw_row(slices[k], {u1[k], u2[k]}, drawing[k]);
  }
  for (std::size_t k = 0; k < n; ++k)
    if (!apart[k]) m.vndf.prefetch_nodes(drawing[k]);
  Warp::Drawn drawn[kBlock];
  draw_columns(m.vndf, slices, drawing, apart, n, drawn);
  for (std::size_t k = 0; k < 2 * rows; ++k) {
    double theta_m = 0, phi_m = 0;  // any valid angles for the rows apart
    if (k < n && !apart[k]) {
      const auto [um, density] = drawn[k];
      pdf_u[k] = density;
      um_x[k] = um.x;
      // The normal's angles, φm in [0, 2π) as the inverse conversion takes it.
      const double phi = (2 * um.y - 1) * kPi + (m.isotropic ? phi_g[k] : 0.0);
      theta_m = um.x * um.x * (kPi / 2);
      phi_m = phi < 0 ? phi + 2 * kPi : phi >= 2 * kPi ? 0.0 : phi;
    }
    angle[2 * (k % 2)][k / 2] = theta_m;
    angle[2 * (k % 2) + 1][k / 2] = phi_m;
  }
  {
    const ConstColumn<double> in[4] = {{angle[0], 1}, {angle[1], 1}, {angle[2], 1}, {angle[3], 1}};
    const Column<double> cols[6] = {{dirs[0], 1}, {dirs[1], 1}, {dirs[2], 1},
                                    {dirs[3], 1}, {dirs[4], 1}, {dirs[5], 1}};
    convert<double>(Form{space_of<Spherical>}, Form{Space::dirs}, in, rows,
                    ConvertOutput<double>{cols, {}, valid}, BatchOptions{1});
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (apart[k] || !valid[k / 2]) {
      out[k] = sample(wo[k], u1[k], u2[k]);
      continue;
    }
    const Vec3<double> g = flips[k].apply(wo[k]);
    const std::size_t c = 3 * (k % 2), r = k / 2;
    const Vec3<double> nm{dirs[c][r], dirs[c + 1][r], dirs[c + 2][r]};
    const double dot = g.x * nm.x + g.y * nm.y + g.z * nm.z;
    const Vec3<double> wi =
        flips[k].apply({2 * dot * nm.x - g.x, 2 * dot * nm.y - g.y, 2 * dot * nm.z - g.z});
    // sin θm = ‖nm_xy‖; the Jacobian of reflection_jacobian().
    const double jacobian =
        2 * kPi * kPi * um_x[k] * std::sqrt(nm.x * nm.x + nm.y * nm.y) * 4 * std::abs(dot);
    out[k] = {wi, jacobian > 0 && wi.z > 0 ? pdf_u[k] / jacobian : 0.0};
  }
}

void RglBrdf::pdf_batch(std::span<const DirPair<double>> pairs, std::span<double> out) const {
  if (out.size() != pairs.size()) {
    Brdf::pdf_batch(pairs, out);  // the size check
    return;
  }
  for (std::size_t first = 0; first < out.size(); first += kBlock) {
    const std::size_t n = std::min(kBlock, out.size() - first);
    pdf_block(pairs.subspan(first, n), out.subspan(first, n));
  }
}

// One block of pdf(): the angles of ωo and of the half vector (both flipped into the data's
// range) by one SIMD conversion, then the density of the warp. Rows that pdf() treats apart go
// through it: a direction at or below the horizon, ωo or the half vector along the normal, not
// accepted by the conversion, an azimuth at a seam.
void RglBrdf::pdf_block(std::span<const DirPair<double>> pairs, std::span<double> out) const {
  const Impl& m = *impl_;
  const std::size_t n = pairs.size();
  const PairBlock block(m.reduction, pairs, false);
  const auto& [dirs, angle, valid, apart] = block;
  // The rows' points and Jacobians, then their densities in passes (densities_at).
  Slices slices[kBlock];
  std::size_t at[kBlock], rows = 0;
  alignas(64) double um_x[kBlock], um_y[kBlock], jacobian[kBlock], pdf_u[kBlock];
  for (std::size_t k = 0; k < n; ++k) {
    const double phi_g = signed_azimuth(angle[1][k]);
    const double phi_m = signed_azimuth(angle[3][k]);
    const double v = azimuth_u(phi_m, phi_g, m.isotropic);
    if (apart[k] || !valid[k] || near_pi(phi_g) || near_seam(v)) {
      out[k] = pdf(pairs[k].wo, pairs[k].wi);
      continue;
    }
    const std::size_t q = rows++;
    at[q] = k;
    const double theta_m = angle[2][k];
    um_x[q] = std::sqrt(theta_m / (kPi / 2)), um_y[q] = v;
    m.slices(phi_g, angle[0][k], slices[q]);
    const double sin_m = std::sqrt(dirs[3][k] * dirs[3][k] + dirs[4][k] * dirs[4][k]);
    const double cos_gm =
        dirs[0][k] * dirs[3][k] + dirs[1][k] * dirs[4][k] + dirs[2][k] * dirs[5][k];
    jacobian[q] = 2 * kPi * kPi * um_x[q] * sin_m * 4 * std::abs(cos_gm);
  }
  densities_at(m.vndf, slices, um_x, um_y, rows, pdf_u);
  for (std::size_t q = 0; q < rows; ++q)
    out[at[q]] = jacobian[q] > 0 && std::isfinite(pdf_u[q]) ? pdf_u[q] / jacobian[q] : 0;
}

}  // namespace halfback
