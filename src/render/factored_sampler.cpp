#include "halfback/render/factored_sampler.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "chart_cells.hpp"
#include "halfback/core/parallel.hpp"

namespace halfback::render {

using namespace detail;

namespace {

// A ≈ W H with A (rows × cols), W (rows × terms), H (terms × cols), all ≥ 0, row-major.
struct Factors {
  std::vector<double> w, h;
};

// Lee & Seung's multiplicative updates for the generalized KL divergence D(A ‖ WH), started
// from a split of the rows into `terms` contiguous groups (each term the mean of a group's rows,
// each row in its own group's term): deterministic, and a fair start for rows that vary smoothly
// with θo. Zero rows of A stay zero in W.
Factors factor_kl(const std::vector<double>& a, int rows, int cols, int terms, int iterations,
                  int threads) {
  const auto R = std::size_t(rows), C = std::size_t(cols), J = std::size_t(terms);
  Factors f{std::vector<double>(R * J, 0.0), std::vector<double>(J * C, 0.0)};
  for (std::size_t r = 0; r < R; ++r) {
    const std::size_t group = r * J / R;
    for (std::size_t j = 0; j < J; ++j) f.w[r * J + j] = j == group ? 1.0 : 0.1;
    for (std::size_t c = 0; c < C; ++c) f.h[group * C + c] += a[r * C + c];
  }
  // A floor keeps a cell that one group never saw reachable by the updates (they cannot revive
  // an exact 0).
  double mean = 0;
  for (double x : a) mean += x;
  mean /= double(a.size());
  for (double& x : f.h) x += 1e-6 * mean;

  std::vector<double> column_sum_w(J), row_sum_h(J);
  const std::size_t grain = 256;
  for (int it = 0; it < iterations; ++it) {
    std::fill(column_sum_w.begin(), column_sum_w.end(), 0.0);
    for (std::size_t r = 0; r < R; ++r)
      for (std::size_t j = 0; j < J; ++j) column_sum_w[j] += f.w[r * J + j];
    parallel_for(
        C, grain,
        [&](std::size_t begin, std::size_t end) {
          std::vector<double> acc(J);
          for (std::size_t c = begin; c < end; ++c) {
            std::fill(acc.begin(), acc.end(), 0.0);
            for (std::size_t r = 0; r < R; ++r) {
              const double x = a[r * C + c];
              if (!(x > 0)) continue;
              double wh = 0;
              for (std::size_t j = 0; j < J; ++j) wh += f.w[r * J + j] * f.h[j * C + c];
              const double ratio = x / std::max(wh, 1e-300);
              for (std::size_t j = 0; j < J; ++j) acc[j] += f.w[r * J + j] * ratio;
            }
            for (std::size_t j = 0; j < J; ++j)
              if (column_sum_w[j] > 0) f.h[j * C + c] *= acc[j] / column_sum_w[j];
          }
        },
        threads);
    std::fill(row_sum_h.begin(), row_sum_h.end(), 0.0);
    for (std::size_t j = 0; j < J; ++j)
      for (std::size_t c = 0; c < C; ++c) row_sum_h[j] += f.h[j * C + c];
    parallel_for(
        R, 1,
        [&](std::size_t begin, std::size_t end) {
          std::vector<double> acc(J);
          for (std::size_t r = begin; r < end; ++r) {
            std::fill(acc.begin(), acc.end(), 0.0);
            for (std::size_t c = 0; c < C; ++c) {
              const double x = a[r * C + c];
              if (!(x > 0)) continue;
              double wh = 0;
              for (std::size_t j = 0; j < J; ++j) wh += f.w[r * J + j] * f.h[j * C + c];
              const double ratio = x / std::max(wh, 1e-300);
              for (std::size_t j = 0; j < J; ++j) acc[j] += f.h[j * C + c] * ratio;
            }
            for (std::size_t j = 0; j < J; ++j)
              f.w[r * J + j] = row_sum_h[j] > 0 ? f.w[r * J + j] * acc[j] / row_sum_h[j] : 0.0;
          }
        },
        threads);
  }
  return f;
}

// Mean over the non-zero rows of A (each a distribution) of the total-variation distance to the
// same row of W H normalized.
double total_variation(const std::vector<double>& a, const Factors& f, std::size_t R, std::size_t C,
                       std::size_t J) {
  double sum = 0;
  std::size_t counted = 0;
  std::vector<double> row(C);
  for (std::size_t r = 0; r < R; ++r) {
    double total = 0, total_a = 0;
    for (std::size_t c = 0; c < C; ++c) {
      double wh = 0;
      for (std::size_t j = 0; j < J; ++j) wh += f.w[r * J + j] * f.h[j * C + c];
      row[c] = wh;
      total += wh;
      total_a += a[r * C + c];
    }
    if (!(total_a > 0 && total > 0)) continue;
    double l1 = 0;
    for (std::size_t c = 0; c < C; ++c) l1 += std::abs(a[r * C + c] / total_a - row[c] / total);
    sum += l1 / 2;
    ++counted;
  }
  return counted ? sum / double(counted) : 0;
}

}  // namespace

FactoredSampler::FactoredSampler(const Brdf& brdf, const FactorOptions& o)
    : SamplingWrapper(brdf),
      options_(o),
      chart_(o.param.param().sampler_chart()),
      isotropic_(brdf.isotropic()) {
  const auto start = std::chrono::steady_clock::now();
  if (o.terms < 1 || o.terms > kMaxTerms || o.radial < 2 || o.azimuthal < 2 || o.theta_views < 1 ||
      o.aniso_theta_views < 1 || o.aniso_phi_views < 1 || o.supersample < 1 || o.iterations < 1 ||
      !(o.defensive >= 0 && o.defensive < 1))
    throw std::invalid_argument("FactoredSampler: invalid factorization options");
  n_theta_ = isotropic_ ? o.theta_views : o.aniso_theta_views;
  n_phi_ = isotropic_ ? 1 : o.aniso_phi_views;
  const SliceGrid grid{n_theta_, n_phi_};
  const auto views = std::size_t(grid.count());
  n_terms_ = int(std::min<std::size_t>(std::size_t(o.terms), views));
  const std::size_t cells = std::size_t(o.radial) * std::size_t(o.azimuthal);

  // Each view's distribution over the cells, a row of A.
  std::vector<double> a(views * cells, 0.0);
  const ParamMap map{chart_, o.warp};
  parallel_for(
      views, 1,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t v = begin; v < end; ++v) {
          std::vector<double> row =
              tabulate_cells(brdf, map, grid.view(int(v)), o.radial, o.azimuthal, o.supersample);
          double total = 0;
          for (double x : row) total += x;
          if (total > 0)
            for (std::size_t c = 0; c < cells; ++c) a[v * cells + c] = row[c] / total;
        }
      },
      o.threads);

  const Factors f = factor_kl(a, int(views), int(cells), n_terms_, o.iterations, o.threads);
  const auto J = std::size_t(n_terms_);
  approximation_error_ = total_variation(a, f, views, cells, J);
  // h_j becomes a distribution; its mass moves into the views' weights.
  weights_.assign(views * J, 0.0);
  for (std::size_t j = 0; j < J; ++j) {
    tables_.emplace_back(std::size_t(o.radial), std::size_t(o.azimuthal),
                         std::span<const double>(f.h).subspan(j * cells, cells));
    double mass = 0;
    for (std::size_t c = 0; c < cells; ++c) mass += f.h[j * cells + c];
    for (std::size_t v = 0; v < views; ++v) weights_[v * J + j] = f.w[v * J + j] * mass;
  }
  build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::size_t FactoredSampler::bytes() const {
  return tables_.size() * std::size_t(options_.radial) * std::size_t(options_.azimuthal) * 20 +
         weights_.size() * sizeof(double);
}

std::string FactoredSampler::describe_sampling() const {
  return "factored (" + std::string(name_of(options_.param)) + (options_.warp ? ", warped" : "") +
         ", " + std::to_string(n_terms_) + " terms of " + std::to_string(options_.radial) + " x " +
         std::to_string(options_.azimuthal) + " cells over " + std::to_string(n_theta_) +
         (isotropic_ ? "" : " x " + std::to_string(n_phi_)) + " views) of " + brdf_.name();
}

FactoredSampler::TermWeights FactoredSampler::term_weights(const Vec3<double>& wo) const {
  const SliceGrid::Blend b = SliceGrid{n_theta_, n_phi_}.blend(wo);
  const auto J = std::size_t(n_terms_);
  TermWeights w{};
  for (int i = 0; i < b.count; ++i)
    if (b.weight[i] > 0)
      for (std::size_t j = 0; j < J; ++j)
        w[j] += b.weight[i] * weights_[std::size_t(b.index[i]) * J + j];
  return w;
}

BrdfSample FactoredSampler::sample(const Vec3<double>& wo_in, double u1, double u2) const {
  if (!(wo_in.z > 0)) return {};
  const double eps = options_.defensive;
  if (u1 < eps) {
    const Vec3<double> wi = sample_cosine_hemisphere(u1 / eps, u2);
    if (!(wi.z > 0)) return {};
    return {wi, pdf(wo_in, wi)};
  }
  u1 = std::min((u1 - eps) / (1 - eps), kOneMinusEpsilon);
  const CanonicalPose pose = canonical_pose(wo_in, isotropic_);
  const TermWeights w = term_weights(pose.wo);
  const int pick = pick_weighted(w.data(), n_terms_, u1);
  if (pick < 0) return {};
  const auto cell = tables_[std::size_t(pick)].sample(u1, u2);
  if (!(cell.probability > 0)) return {};
  const double s = (double(cell.row) + cell.remapped_row) / options_.radial;
  const double t = (double(cell.col) + cell.remapped_col) / options_.azimuthal;
  Vec3<double> wi{0, 0, 0};
  double jac = 0;
  if (!ParamMap{chart_, options_.warp}.forward(pose.wo, s, t, wi, jac)) return {};
  wi = rotate_z(wi, pose.c, pose.s);
  // pdf(ωo, ωi) from the cell, weights and Jacobian at hand.
  double table = 0, total = 0;
  for (std::size_t j = 0; j < tables_.size(); ++j) {
    table += w[j] * tables_[j].probability(cell.row, cell.col);
    total += w[j];
  }
  table *= double(options_.radial) * double(options_.azimuthal) / (total * jac);
  return {wi, (1 - eps) * table + eps * cosine_hemisphere_pdf(wi)};
}

double FactoredSampler::pdf(const Vec3<double>& wo_in, const Vec3<double>& wi_in) const {
  if (!(wo_in.z > 0 && wi_in.z > 0)) return 0;
  const CanonicalPose pose = canonical_pose(wo_in, isotropic_);
  const Vec3<double> wi = rotate_z(wi_in, pose.c, -pose.s);
  const double eps = options_.defensive;
  double table = 0, s = 0, t = 0, jac = 0;
  if (ParamMap{chart_, options_.warp}.inverse(pose.wo, wi, s, t, jac)) {
    const auto row = std::min(std::size_t(s * options_.radial), std::size_t(options_.radial - 1));
    const auto col =
        std::min(std::size_t(t * options_.azimuthal), std::size_t(options_.azimuthal - 1));
    const TermWeights w = term_weights(pose.wo);
    double total = 0;
    for (std::size_t j = 0; j < tables_.size(); ++j) {
      table += w[j] * tables_[j].probability(row, col);
      total += w[j];
    }
    if (total > 0)
      table *= double(options_.radial) * double(options_.azimuthal) / (total * jac);
    else
      table = 0;
  }
  return (1 - eps) * table + eps * cosine_hemisphere_pdf(wi_in);
}

FactorOptions factoring_for_memory(Space param, std::size_t bytes, int terms) {
  FactorOptions o;
  o.param = param;
  o.terms = std::max(1, terms);
  const double weight_bytes = double(o.theta_views) * o.terms * 8.0;
  const double cells = std::max(0.0, double(bytes) - weight_bytes) / (20.0 * o.terms);
  o.radial = std::max(4, int(std::lround(std::sqrt(cells / 2))));
  o.azimuthal = 2 * o.radial;
  return o;
}

}  // namespace halfback::render
