// The published losses (Loss::bbm_*) against a restatement written here from BBM's definitions
// (include/loss/cosine_weighted_l2.h, cosine_weighted_log.h, linearizer/spherical_linearizer.h,
// bbm/sampledlossfunction.h): plain loops over the (φ, θ) grids, the error of each pair summed
// over the channels, the sum divided by the number of pairs.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "halfback/fit/fit.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::fit {
namespace {
namespace bbm_loss_test {  // (named: the unity build shares one anonymous namespace)

constexpr double kPi = std::numbers::pi;

// BBM sets components below the machine epsilon to 0 (the equator's cos θ is then exactly 0, and
// the models' horizon tests see it there).
double snapped(double x) {
  return std::abs(x) < 2.220446049250313e-16 ? 0.0 : x;
}

Vec3<double> direction(double phi, double theta) {
  return {snapped(std::cos(phi) * std::sin(theta)), snapped(std::sin(phi) * std::sin(theta)),
          snapped(std::cos(theta))};
}

// BBM's error of one pair, summed over the channels, for each published loss.
double pair_error(Loss loss, const Rgb& m, const Rgb& t, double theta_i, double theta_o) {
  const double ci = std::max(std::cos(theta_i), 0.0), co = std::max(std::cos(theta_o), 0.0);
  const double si = std::sin(theta_i), so = std::sin(theta_o);
  double l2 = 0, lg = 0;
  for (int ch = 0; ch < 3; ++ch) {
    const double mv = ch == 0 ? m.r : ch == 1 ? m.g : m.b;
    const double tv = ch == 0 ? t.r : ch == 1 ? t.g : t.b;
    l2 += std::pow((mv - tv) * ci, 2);
    lg += std::pow(std::log(1 + mv * ci) - std::log(1 + tv * ci), 2);
  }
  switch (loss) {
    case Loss::bbm_ngan:
      return l2 * si * so;
    case Loss::bbm_low_e1:
      return l2 * si;
    case Loss::bbm_low_e2:
      return lg * si;
    case Loss::bbm_bieron_l2:
      return l2 * co * si * so;
    case Loss::bbm_bieron_log:
      return lg * co * si * so;
    case Loss::bbm_standard_log:
      return lg * si * so;
    default:
      throw std::logic_error("not a published loss");
  }
}

// The loss over the grid: incident (nφi × nθi), outgoing (nφo × nθo), θ from 0 to π/2 included.
double restated_loss(Loss loss, const Brdf& target, const Brdf& model, const BbmGrid& g) {
  const auto theta = [](std::size_t j, std::size_t n) {
    return n == 1 ? 0.0 : double(j) * (kPi / 2) / double(n - 1);
  };
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t a = 0; a < g.in_phi; ++a)
    for (std::size_t b = 0; b < g.in_theta; ++b)
      for (std::size_t c = 0; c < g.out_phi; ++c)
        for (std::size_t d = 0; d < g.out_theta; ++d) {
          const double ti = theta(b, g.in_theta), to = theta(d, g.out_theta);
          const DirPair<double> pair{direction(2 * kPi * double(a) / double(g.in_phi), ti),
                                     direction(2 * kPi * double(c) / double(g.out_phi), to)};
          sum += pair_error(loss, model.eval(pair), target.eval(pair), ti, to);
          ++count;
        }
  return sum / double(count);
}

const Loss kPublished[] = {Loss::bbm_ngan,      Loss::bbm_low_e1,     Loss::bbm_low_e2,
                           Loss::bbm_bieron_l2, Loss::bbm_bieron_log, Loss::bbm_standard_log};

bool low(Loss l) {
  return l == Loss::bbm_low_e1 || l == Loss::bbm_low_e2;
}

TEST(BbmLoss, EachIsItsRestatementOnFixedBrdfs) {
  const BrdfPtr target = load_brdf("lambert:albedo_r=0.3,albedo_g=0.2,albedo_b=0.1+ggx:alpha=0.2");
  const BrdfPtr model = load_brdf("lambert:albedo=0.25+beckmann:alpha=0.35,f0=0.6");
  for (Loss loss : kPublished)
    for (const BbmGrid& g : {BbmGrid{8, 7, low(loss) ? 1u : 6u, 5}, default_grid(loss)}) {
      const double want = restated_loss(loss, *target, *model, g);
      const double got = loss_of(*target, *model, loss, 1, 1, g);
      EXPECT_GT(want, 0) << name_of(loss);
      EXPECT_NEAR(got, want, 1e-9 * want)
          << name_of(loss) << " grid " << g.in_phi << "x" << g.in_theta << " by " << g.out_phi
          << "x" << g.out_theta;
    }
}

TEST(BbmLoss, TheLossOfATargetAgainstItselfIsZero) {
  const BrdfPtr target = load_brdf("lambert:albedo=0.3+ggx:alpha=0.1,f0=0.9");
  for (Loss loss : kPublished) EXPECT_EQ(loss_of(*target, *target, loss, 1, 1), 0) << name_of(loss);
}

TEST(BbmLoss, GridIsBbmsLinearizer) {
  const Samples low_grid = bbm_grid_samples(Loss::bbm_low_e2, {4, 3, 1, 5});
  ASSERT_EQ(low_grid.pairs.size(), 60u);
  for (const DirPair<double>& p : low_grid.pairs) EXPECT_EQ(p.wo.y, 0) << "Löw's ωo at φo = 0";
  // θ = 0 and θ = π/2 both on the grid; the first pair is at the pole; the last θo = π/2 has
  // cos 0 and weight sin θi.
  EXPECT_EQ(low_grid.pairs.front().wi.z, 1);
  EXPECT_EQ(low_grid.weight.front(), 0);
  EXPECT_EQ(low_grid.pairs[4].wo.z, 0);
  const Samples ngan = bbm_grid_samples(Loss::bbm_ngan, {4, 3, 4, 3});
  ASSERT_EQ(ngan.pairs.size(), 144u);
  // Pair 1·(3·4·3) + 2·(4·3) + 1·3 + 2: wi at φ = π/2, θ = π/2; wo at φ = π/2, θ = π/2.
  const DirPair<double>& p = ngan.pairs[36 + 24 + 3 + 2];
  EXPECT_EQ(p.wi.x, 0);
  EXPECT_DOUBLE_EQ(p.wi.y, 1);
  EXPECT_EQ(p.wi.z, 0);
  EXPECT_DOUBLE_EQ(ngan.weight[36 + 24 + 3 + 2], 1);
}

// BBM's last elevation, (n − 1)·(π/2)/(n − 1), is π/2 minus an ulp for some n (12, 31): its cos θ,
// 2.8e-16, escapes BBM's epsilon snap, and the grazing mirror pair then gives a microfacet lobe
// 1/(cos θi cos θo) ≈ 10³¹ (Ngan's published Cook–Torrance scored 10²⁹ on 24 × 12 by 24 × 12).
// The default grids avoid such n: their equator is exactly on the horizon.
TEST(BbmLoss, DefaultGridsPutTheirEquatorOnTheHorizon) {
  for (Loss loss : kPublished) {
    const Samples s = bbm_grid_samples(loss, default_grid(loss));
    double min_z = 1;
    for (const DirPair<double>& p : s.pairs) min_z = std::min({min_z, p.wi.z, p.wo.z});
    EXPECT_EQ(min_z, 0) << name_of(loss);
  }
  const Samples twelve = bbm_grid_samples(Loss::bbm_ngan, {4, 12, 4, 12});
  EXPECT_GT(twelve.pairs.back().wo.z, 0);  // BBM's arithmetic, restated as it is
  EXPECT_LT(twelve.pairs.back().wo.z, 1e-15);
}

TEST(BbmLoss, BadGridsAreRefused) {
  EXPECT_THROW(bbm_grid_samples(Loss::bbm_low_e1, {8, 8, 2, 8}), std::invalid_argument);
  EXPECT_THROW(bbm_grid_samples(Loss::bbm_ngan, {8, 0, 8, 8}), std::invalid_argument);
  EXPECT_THROW(bbm_grid_samples(Loss::ngan, {8, 8, 8, 8}), std::invalid_argument);
  const std::size_t huge = std::size_t(1) << 40;
  EXPECT_THROW(bbm_grid_samples(Loss::bbm_ngan, {huge, huge, huge, huge}), std::invalid_argument);
}

TEST(BbmLoss, FitUnderAPublishedLossReportsItsValue) {
  const BrdfPtr target = load_brdf("lambert:albedo=0.2+beckmann:alpha=0.3,f0=0.5");
  FitOptions o;
  o.loss = Loss::bbm_low_e2;
  o.grid = BbmGrid{24, 10, 1, 10};
  const FitResult r = fit(*target, "lambert+beckmann", o);
  EXPECT_EQ(r.layout, kBbmGridLayoutName);
  EXPECT_EQ(r.samples, 2400u);
  EXPECT_NEAR(r.loss_value, loss_of(*target, *load_brdf(r.spec), o.loss, 1, 0, o.grid),
              1e-12 + 1e-9 * r.loss_value);
  EXPECT_LT(r.loss_value, 1e-8);  // the target is in the model
}

}  // namespace bbm_loss_test
}  // namespace
}  // namespace halfback::fit
