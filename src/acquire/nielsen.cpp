#include "halfback/acquire/nielsen.hpp"

#include <fmt/format.h>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <stdexcept>

#include "halfback/core/parallel.hpp"
#include "halfback/core/param.hpp"
#include "halfback/util/sha256.hpp"

namespace halfback::acquire {

namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

double cosines(const DirPair<double>& p) {
  return std::clamp(p.wi.z * p.wo.z, kNielsenMinCosines, 1.0);
}

// The centres of MERL's bins at the options' resolution that the instrument reaches.
std::vector<DirPair<double>> candidate_configurations(const NielsenOptions& o) {
  const double min_z = std::cos(o.max_theta_deg * std::numbers::pi / 180) - 1e-12;
  std::vector<DirPair<double>> pairs;
  for (int i = 0; i < o.theta_h; ++i)
    for (int j = 0; j < o.theta_d; ++j)
      for (int k = 0; k < o.phi_d; ++k) {
        const double u = (i + 0.5) / o.theta_h;
        const Tuple4<double> q{u * u * std::numbers::pi / 2, 0.0,
                               (j + 0.5) / o.theta_d * std::numbers::pi / 2,
                               (k + 0.5) / o.phi_d * std::numbers::pi};
        const Solved<double> s = inverse<HalfDiff>(q);
        if (s.in_domain && s.pair.wi.z >= min_z && s.pair.wo.z >= min_z) pairs.push_back(s.pair);
      }
  return pairs;
}

// The members' mapped channels at `pairs` (pairs × observations, row-major), in parallel over
// blocks of pairs. Throws std::invalid_argument naming a member with a value that is not finite.
template <class T>
std::vector<T> mapped_values(std::span<const std::shared_ptr<const Brdf>> members,
                             std::span<const DirPair<double>> pairs) {
  const std::size_t obs = 3 * members.size();
  std::vector<T> out(pairs.size() * obs);
  parallel_for(pairs.size(), 4096, [&](std::size_t begin, std::size_t end) {
    std::vector<Rgb> rho(end - begin);
    const auto block = pairs.subspan(begin, end - begin);
    for (std::size_t m = 0; m < members.size(); ++m) {
      members[m]->eval_batch(block, rho);
      for (std::size_t i = 0; i < rho.size(); ++i) {
        const double v[3] = {rho[i].r, rho[i].g, rho[i].b};
        for (int c = 0; c < 3; ++c) {
          if (!std::isfinite(v[c]))
            throw std::invalid_argument(fmt::format(
                "Nielsen database: {} has a value that is not finite", members[m]->name()));
          out[(begin + i) * obs + 3 * m + std::size_t(c)] = T(nielsen_map(v[c], block[i]));
        }
      }
    }
  });
  return out;
}

// The condition number of the rows (p × p or taller): √(λmax / λmin) of AᵀA; +∞ when singular.
double condition_of(const Eigen::MatrixXd& a) {
  if (a.cols() == 1) {
    const double n = a.col(0).norm();
    return n > 0 ? 1 / n : std::numeric_limits<double>::infinity();
  }
  const Eigen::MatrixXd ata = a.transpose() * a;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(ata, Eigen::EigenvaluesOnly);
  const double lo = eig.eigenvalues()(0), hi = eig.eigenvalues()(ata.rows() - 1);
  return lo > hi * 1e-300 && lo > 0 ? std::sqrt(hi / lo) : std::numeric_limits<double>::infinity();
}

// The smallest and largest eigenvalues of diag(λ) + w wᵀ (λ ascending, p >= 1): the roots of
// the secular equation f(μ) = 1 + Σ w_i² / (λ_i − μ) = 0 in (λ_0, λ_1) and beyond λ_last (f
// increases between its poles), by bisection, geometric once the bracket is positive so that a
// root near 0 is found to relative precision.
std::pair<double, double> rank_one_extremes(const Eigen::VectorXd& lambda,
                                            const Eigen::VectorXd& w) {
  const Eigen::Index p = lambda.size();
  const Eigen::ArrayXd w2 = w.array().square();
  auto f = [&](double mu) { return 1 + (w2 / (lambda.array() - mu)).sum(); };
  auto root = [&](double lo, double hi) {
    for (int i = 0; i < 200 && hi > lo; ++i) {
      const double mid = lo > 0 ? std::sqrt(lo * hi) : 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      (f(mid) < 0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  };
  const double norm2 = w2.sum();
  const double smallest =
      w2(0) == 0 ? lambda(0) : root(lambda(0), p > 1 ? lambda(1) : lambda(0) + norm2);
  // (A w_i of 0 removes the pole at λ_i, which stays an eigenvalue: the bisection then ends at
  // the bracket's end, λ_i, where that is the extreme one.)
  return {smallest, root(lambda(p - 1), lambda(p - 1) + norm2)};
}

// The first p scaled components at each configuration: a row each.
Eigen::MatrixXd scaled_rows(const NielsenBasis& basis, std::span<const std::size_t> configurations,
                            std::size_t p) {
  Eigen::MatrixXd a(Eigen::Index(configurations.size()), Eigen::Index(p));
  std::vector<double> row(p);
  for (std::size_t r = 0; r < configurations.size(); ++r) {
    basis.scaled_row(configurations[r], p, row);
    for (std::size_t j = 0; j < p; ++j) a(Eigen::Index(r), Eigen::Index(j)) = row[j];
  }
  return a;
}

}  // namespace

double nielsen_map(double rho, const DirPair<double>& pair) {
  return std::log(std::max(rho, 0.0) * cosines(pair) + kNielsenEpsilon);
}

double nielsen_unmap(double g, const DirPair<double>& pair) {
  return std::max((std::exp(g) - kNielsenEpsilon) / cosines(pair), 0.0);
}

void NielsenOptions::validate() const {
  if (theta_h < 1 || theta_d < 1 || phi_d < 1 || theta_h > 180 || theta_d > 180 || phi_d > 360)
    throw std::invalid_argument(
        "Nielsen: the candidate grid needs 1 to 180 bins in θh and θd, 1 to 360 in φd");
  if (!(max_theta_deg >= 1 && max_theta_deg <= 90))
    throw std::invalid_argument("Nielsen: the reach must be in [1, 90] degrees");
  if (!(eta >= 0 && std::isfinite(eta)))
    throw std::invalid_argument("Nielsen: the Tikhonov weight must be finite and >= 0");
  if (candidates_per_step < 1)
    throw std::invalid_argument("Nielsen: at least one candidate per step");
}

// ---------------------------------------------------------------------------------------------
// Database
// ---------------------------------------------------------------------------------------------

NielsenDatabase::NielsenDatabase(std::vector<std::shared_ptr<const Brdf>> members,
                                 NielsenOptions options, std::vector<DirPair<double>> cached_pairs)
    : members_(std::move(members)), options_(options), cached_pairs_(std::move(cached_pairs)) {
  options_.validate();
  if (members_.size() < 2)
    throw std::invalid_argument("Nielsen database: at least two members are needed");
  for (const auto& m : members_)
    if (!m || !m->isotropic())
      throw std::invalid_argument(fmt::format("Nielsen database: {} is not isotropic",
                                              m ? m->name() : std::string("a member")));
  configurations_ = candidate_configurations(options_);
  if (configurations_.size() < 2)
    throw std::invalid_argument("Nielsen database: fewer than two candidate configurations");
  mapped_ = mapped_values<double>(members_, configurations_);
  const auto n = Eigen::Index(observations());
  const Eigen::Map<const RowMatrix> x(mapped_.data(), Eigen::Index(configurations_.size()), n);
  gram_.resize(observations() * observations());
  Eigen::Map<Eigen::MatrixXd>(gram_.data(), n, n) = x.transpose() * x;
  if (!cached_pairs_.empty()) cached_ = mapped_values<float>(members_, cached_pairs_);
}

std::span<const double> NielsenDatabase::mapped_at(std::size_t configuration) const {
  return std::span(mapped_).subspan(configuration * observations(), observations());
}

std::vector<std::size_t> NielsenDatabase::members_like(const Brdf& brdf) const {
  std::vector<Rgb> rho(configurations_.size());
  brdf.eval_batch(configurations_, rho);
  std::vector<std::size_t> like;
  for (std::size_t m = 0; m < members(); ++m) {
    bool same = true;
    for (std::size_t k = 0; k < configurations_.size() && same; ++k) {
      const double v[3] = {rho[k].r, rho[k].g, rho[k].b};
      for (std::size_t c = 0; c < 3 && same; ++c)
        same = std::abs(nielsen_map(v[c], configurations_[k]) - mapped_at(k)[3 * m + c]) < 1e-4;
    }
    if (same) like.push_back(m);
  }
  return like;
}

void NielsenDatabase::combine(const std::array<std::vector<double>, 3>& weights,
                              std::span<const DirPair<double>> pairs,
                              std::span<std::array<double, 3>> out) const {
  const std::size_t obs = observations();
  for (const auto& w : weights)
    if (w.size() != obs) throw std::invalid_argument("Nielsen: one weight per observation");
  if (out.size() != pairs.size()) throw std::invalid_argument("Nielsen: one output per pair");
  const bool cached = pairs.size() == cached_pairs_.size() &&
                      std::equal(pairs.begin(), pairs.end(), cached_pairs_.begin(),
                                 [](const DirPair<double>& a, const DirPair<double>& b) {
                                   return a.wi.x == b.wi.x && a.wi.y == b.wi.y &&
                                          a.wi.z == b.wi.z && a.wo.x == b.wo.x &&
                                          a.wo.y == b.wo.y && a.wo.z == b.wo.z;
                                 });
  auto weigh = [&](const auto& values) {
    parallel_for(pairs.size(), 4096, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i)
        for (std::size_t c = 0; c < 3; ++c) {
          double sum = 0;
          for (std::size_t o = 0; o < obs; ++o) sum += weights[c][o] * double(values[i * obs + o]);
          out[i][c] = sum;
        }
    });
  };
  if (cached)
    weigh(cached_);
  else
    weigh(mapped_values<double>(members_, pairs));
}

// ---------------------------------------------------------------------------------------------
// Basis
// ---------------------------------------------------------------------------------------------

NielsenBasis::NielsenBasis(std::shared_ptr<const NielsenDatabase> database,
                           std::vector<std::size_t> left_out)
    : database_(std::move(database)), left_out_(std::move(left_out)) {
  const NielsenDatabase& db = *database_;
  std::sort(left_out_.begin(), left_out_.end());
  for (std::size_t m : left_out_)
    if (m >= db.members())
      throw std::invalid_argument("Nielsen basis: no such member to leave out");
  for (std::size_t o = 0; o < db.observations(); ++o)
    if (!std::binary_search(left_out_.begin(), left_out_.end(), o / 3)) kept_.push_back(o);
  if (kept_.size() < 2 * 3)
    throw std::invalid_argument("Nielsen basis: fewer than two members are left in the database");
  const auto n = Eigen::Index(kept_.size());
  Eigen::MatrixXd g(n, n);
  for (Eigen::Index a = 0; a < n; ++a)
    for (Eigen::Index b = 0; b < n; ++b) g(a, b) = db.gram(kept_[a], kept_[b]);
  // The Gram matrix of the centred observations: H G H, H = I − 11ᵀ/n.
  const Eigen::VectorXd row_mean = g.rowwise().mean();
  const double mean = row_mean.mean();
  Eigen::MatrixXd centred = g;
  centred.colwise() -= row_mean;
  centred.rowwise() -= row_mean.transpose();
  centred.array() += mean;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(centred);
  const Eigen::VectorXd lambda = eig.eigenvalues();  // ascending
  const double largest = lambda(n - 1);
  // Components above the rounding of the Gram matrix (at most n − 1: the centring removes one).
  for (Eigen::Index j = n - 1; j >= 0; --j) {
    if (!(lambda(j) > largest * 1e-12) || Eigen::Index(singular_.size()) >= n - 1) break;
    singular_.push_back(std::sqrt(lambda(j)));
    for (Eigen::Index o = 0; o < n; ++o) u_.push_back(eig.eigenvectors()(o, j));
  }
}

double NielsenBasis::kept_mean(std::size_t configuration) const {
  const std::span<const double> g = database_->mapped_at(configuration);
  double mean = 0;
  for (std::size_t o : kept_) mean += g[o];
  return mean / double(kept_.size());
}

void NielsenBasis::scaled_row(std::size_t configuration, std::size_t p,
                              std::span<double> out) const {
  const std::span<const double> g = database_->mapped_at(configuration);
  const double mean = kept_mean(configuration);
  const std::size_t n = kept_.size();
  for (std::size_t j = 0; j < p; ++j) {
    double z = 0;
    for (std::size_t k = 0; k < n; ++k) z += u_[j * n + k] * (double(g[kept_[k]]) - mean);
    out[j] = z;
  }
}

double NielsenBasis::condition_number(std::span<const std::size_t> configurations) const {
  return condition_of(
      scaled_rows(*this, configurations, std::min(configurations.size(), components())));
}

std::vector<std::size_t> NielsenBasis::directions(std::size_t count,
                                                  std::vector<double>* conditions) const {
  const NielsenDatabase& db = *database_;
  const std::size_t candidates = db.configurations().size();
  if (count > candidates)
    throw std::invalid_argument(
        fmt::format("Nielsen: {} directions asked, the database has {} candidate configurations",
                    count, candidates));
  std::vector<std::size_t> chosen;
  if (count == 0) return chosen;
  // The first: the largest row of Z, ‖Z(x)‖ = ‖X(x)‖ over all components (U spans the centred
  // observations), the configuration where the database varies most.
  std::vector<double> variance(candidates);
  for (std::size_t k = 0; k < candidates; ++k) {
    const std::span<const double> g = db.mapped_at(k);
    const double mean = kept_mean(k);
    double sq = 0;
    for (std::size_t o : kept_) sq += (g[o] - mean) * (g[o] - mean);
    variance[k] = sq;
  }
  chosen.push_back(
      std::size_t(std::max_element(variance.begin(), variance.end()) - variance.begin()));
  std::vector<char> taken(candidates, 0);
  taken[chosen[0]] = 1;
  std::mt19937_64 rng(db.options().seed);
  const std::size_t per_step = std::min(db.options().candidates_per_step, candidates);
  if (conditions) conditions->assign(1, condition_number(chosen));
  while (chosen.size() < count) {
    // The rows measured so far, B, on the first p components; a candidate's row z makes the
    // matrix [B; z], whose AᵀA = BᵀB + z zᵀ: with BᵀB = Q Λ Qᵀ once per step, each candidate's
    // extreme eigenvalues are those of Λ + w wᵀ, w = Qᵀ z (rank_one_extremes).
    const std::size_t p = std::min(chosen.size() + 1, components());
    const Eigen::MatrixXd b = scaled_rows(*this, chosen, p);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> btb(b.transpose() * b);
    // Random candidates not yet taken (all of them when fewer remain).
    std::vector<std::size_t> pool;
    const std::size_t free_left = candidates - chosen.size();
    if (free_left <= per_step) {
      for (std::size_t k = 0; k < candidates; ++k)
        if (!taken[k]) pool.push_back(k);
    } else {
      std::vector<char> in_pool(candidates, 0);
      while (pool.size() < per_step) {
        const std::size_t k = std::size_t(rng() % candidates);
        if (taken[k] || in_pool[k]) continue;
        in_pool[k] = 1;
        pool.push_back(k);
      }
    }
    std::vector<double> cond(pool.size());
    parallel_for(pool.size(), 64, [&](std::size_t begin, std::size_t end) {
      Eigen::VectorXd z(static_cast<Eigen::Index>(p));
      for (std::size_t i = begin; i < end; ++i) {
        scaled_row(pool[i], p, std::span(z.data(), p));
        const auto [lo, hi] =
            rank_one_extremes(btb.eigenvalues(), btb.eigenvectors().transpose() * z);
        cond[i] = lo > 0 ? std::sqrt(hi / lo) : std::numeric_limits<double>::infinity();
      }
    });
    const std::size_t best = std::size_t(std::min_element(cond.begin(), cond.end()) - cond.begin());
    chosen.push_back(pool[best]);
    taken[pool[best]] = 1;
    if (conditions) conditions->push_back(cond[best]);
  }
  return chosen;
}

std::array<std::vector<double>, 3> NielsenBasis::solve(std::span<const std::size_t> configurations,
                                                       std::span<const Rgb> values,
                                                       double eta) const {
  if (configurations.size() != values.size())
    throw std::invalid_argument("Nielsen: one value per measured configuration");
  const NielsenDatabase& db = *database_;
  const std::size_t n_kept = kept_.size();
  std::array<std::vector<double>, 3> weights;
  for (std::size_t c = 0; c < 3; ++c) {
    // The finite measurements of this channel.
    std::vector<std::size_t> at;
    std::vector<double> b;
    for (std::size_t r = 0; r < configurations.size(); ++r) {
      const double v = c == 0 ? values[r].r : c == 1 ? values[r].g : values[r].b;
      if (!std::isfinite(v)) continue;
      at.push_back(configurations[r]);
      b.push_back(nielsen_map(v, db.configurations()[configurations[r]]));
    }
    if (at.empty()) throw std::runtime_error("Nielsen: no finite measurement");
    const std::size_t p = std::min(at.size(), components());
    const Eigen::MatrixXd a = scaled_rows(*this, at, p);
    Eigen::VectorXd rhs(Eigen::Index(at.size()));
    for (std::size_t r = 0; r < at.size(); ++r) rhs(Eigen::Index(r)) = b[r] - kept_mean(at[r]);
    // x = V diag(s / (s² + η)) Uᵀ b (their ProjectToPCSpace).
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeThinU | Eigen::ComputeThinV);
    Eigen::VectorXd s = svd.singularValues();
    for (Eigen::Index j = 0; j < s.size(); ++j) s(j) = s(j) > 0 ? s(j) / (s(j) * s(j) + eta) : 0;
    const Eigen::VectorXd x = svd.matrixV() * s.asDiagonal() * (svd.matrixU().transpose() * rhs);
    // ĝ = μ + Σ_j x_j Σ_o U_oj (g_o − μ) = Σ_o (w_o + (1 − Σ w) / n) g_o, w = U x.
    std::vector<double> w(n_kept, 0.0);
    for (std::size_t j = 0; j < p; ++j)
      for (std::size_t k = 0; k < n_kept; ++k) w[k] += u_[j * n_kept + k] * x(Eigen::Index(j));
    const double rest = (1 - std::accumulate(w.begin(), w.end(), 0.0)) / double(n_kept);
    weights[c].assign(db.observations(), 0.0);
    for (std::size_t k = 0; k < n_kept; ++k) weights[c][kept_[k]] = w[k] + rest;
  }
  return weights;
}

// ---------------------------------------------------------------------------------------------
// Reconstruction
// ---------------------------------------------------------------------------------------------

NielsenReconstruction::NielsenReconstruction(std::shared_ptr<const NielsenDatabase> database,
                                             std::array<std::vector<double>, 3> weights,
                                             std::string measured, std::size_t measurements)
    : database_(std::move(database)),
      weights_(std::move(weights)),
      measured_(std::move(measured)),
      measurements_(measurements) {}

std::string NielsenReconstruction::name() const {
  return fmt::format("nielsen({}, {})", measured_, measurements_);
}

std::string NielsenReconstruction::description() const {
  return fmt::format(
      "{} reconstructed from {} measurements as a combination of the principal components of a "
      "database of {} BRDFs (Nielsen et al. 2015)",
      measured_, measurements_, database_->members());
}

Rgb NielsenReconstruction::eval(const DirPair<double>& pair) const {
  Rgb out;
  eval_batch(std::span(&pair, 1), std::span(&out, 1));
  return out;
}

void NielsenReconstruction::eval_batch(std::span<const DirPair<double>> pairs,
                                       std::span<Rgb> out) const {
  std::vector<std::array<double, 3>> g(pairs.size());
  database_->combine(weights_, pairs, g);
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (pairs[i].wi.z <= 0 || pairs[i].wo.z <= 0) {
      out[i] = Rgb{};
      continue;
    }
    out[i] = Rgb{nielsen_unmap(g[i][0], pairs[i]), nielsen_unmap(g[i][1], pairs[i]),
                 nielsen_unmap(g[i][2], pairs[i])};
  }
}

namespace {

// Whether each channel has a finite value among `values` (what NielsenBasis::solve needs).
bool every_channel_measured(std::span<const Rgb> values) {
  bool r = false, g = false, b = false;
  for (const Rgb& v : values) {
    r = r || std::isfinite(v.r);
    g = g || std::isfinite(v.g);
    b = b || std::isfinite(v.b);
  }
  return r && g && b;
}

}  // namespace

NielsenAcquisition nielsen_acquisition(std::shared_ptr<const NielsenDatabase> database,
                                       const Brdf& brdf, std::span<const std::size_t> counts) {
  if (!brdf.isotropic())
    throw std::invalid_argument("Nielsen: " + brdf.name() + " is anisotropic; the basis is not");
  std::size_t largest = 0;
  for (std::size_t n : counts) {
    if (n == 0) throw std::invalid_argument("Nielsen: a count of 0 measurements");
    largest = std::max(largest, n);
  }
  NielsenAcquisition a;
  a.left_out = database->members_like(brdf);
  const NielsenBasis basis(database, a.left_out);
  a.directions = basis.directions(largest);
  std::vector<DirPair<double>> pairs;
  for (std::size_t k : a.directions) pairs.push_back(database->configurations()[k]);
  std::vector<Rgb> values(pairs.size());
  brdf.eval_batch(pairs, values);
  for (std::size_t n : counts) {
    const auto first = std::span(a.directions).first(n);
    const auto measured = std::span(values).first(n);
    if (!every_channel_measured(measured)) {
      a.unmeasured.push_back(n);
      continue;
    }
    a.reconstructions.push_back(std::make_shared<NielsenReconstruction>(
        database, basis.solve(first, measured, database->options().eta), brdf.name(), n));
  }
  return a;
}

std::string nielsen_fingerprint(const NielsenDatabase& db) {
  // The options, the members' names and their values (through the Gram matrix of their mapped
  // values: two models of one name with other parameters differ there).
  const NielsenOptions& o = db.options();
  std::string text = fmt::format("{} {} {} {} {} {} {}", o.theta_h, o.theta_d, o.phi_d,
                                 o.max_theta_deg, o.eta, o.candidates_per_step, o.seed);
  for (std::size_t m = 0; m < db.members(); ++m) {
    text += '\n';  // appended apart: GCC 12 bug 105329 (CMakeLists.txt)
    text += db.member(m).name();
  }
  for (std::size_t a = 0; a < db.observations(); ++a)
    for (std::size_t b = 0; b < db.observations(); ++b) {
      const double g = db.gram(a, b);
      text.append(reinterpret_cast<const char*>(&g), sizeof g);
    }
  const std::string hash = sha256_hex(std::as_bytes(std::span(text)));
  return fmt::format("{} members, {}", db.members(), hash.substr(0, 16));
}

}  // namespace halfback::acquire
