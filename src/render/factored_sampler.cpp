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

static_assert(FactoredSampler::kMaxTerms <= CellMixture::kMax);

MixtureSampling FactoredSampler::sampling() const {
  return {{chart_, options_.warp}, options_.radial, options_.azimuthal,
          options_.defensive,      isotropic_,      tables_};
}

CellMixture FactoredSampler::term_weights(const Vec3<double>& wo) const {
  const SliceGrid::Blend b = SliceGrid{n_theta_, n_phi_}.blend(wo);
  const auto J = std::size_t(n_terms_);
  CellMixture m;
  m.count = n_terms_;
  for (std::size_t j = 0; j < J; ++j) m.table[j] = int(j);
  for (int i = 0; i < b.count; ++i)
    if (b.weight[i] > 0)
      for (std::size_t j = 0; j < J; ++j)
        m.weight[j] += b.weight[i] * weights_[std::size_t(b.index[i]) * J + j];
  return m;
}

BrdfSample FactoredSampler::sample(const Vec3<double>& wo, double u1, double u2) const {
  return sampling().sample(wo, u1, u2, [this](const Vec3<double>& w) { return term_weights(w); });
}

double FactoredSampler::pdf(const Vec3<double>& wo, const Vec3<double>& wi) const {
  return sampling().pdf(wo, wi, [this](const Vec3<double>& w) { return term_weights(w); });
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
