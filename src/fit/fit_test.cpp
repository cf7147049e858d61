// The fitter: parameters recovered from BRDFs the models generate, the multistart against a
// two-minimum loss, and the errors of bad models and targets.
#include "halfback/fit/fit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>

#include "halfback/loader/load.hpp"
#include "recovery_test_support.hpp"

namespace halfback::fit {
namespace {

std::string with_alpha(const std::string& spec, double alpha) {
  char buf[64];
  std::snprintf(buf, sizeof buf, ",alpha=%.17g", alpha);
  return spec + buf;
}

using recovery_test::expect_recovered;
using recovery_test::value_in;

// Each from a start given (an empty start would be the automatic ones), 3000 samples, every
// fitted parameter to 1e-4 relative, loss < 1e-12.
TEST(FitRecovery, Lambert) {
  expect_recovered("lambert", "lambert:albedo_r=0.7,albedo_g=0.3,albedo_b=0.05",
                   "lambert:albedo_r=0.1,albedo_g=0.9,albedo_b=1");
}

TEST(FitRecovery, GgxFromStartsAcrossTheBounds) {
  const std::string truth = "ggx:alpha=0.15,f0_r=0.9,f0_g=0.6,f0_b=0.3";
  for (const char* start : {"ggx:alpha=0.002,f0_r=0.1,f0_g=0.1,f0_b=0.1",
                            "ggx:alpha=0.5,f0_r=1,f0_g=0.02,f0_b=0.5", "ggx:alpha=3"})
    expect_recovered("ggx", truth, start);
}

TEST(FitRecovery, BeckmannUnderEachLoss) {
  for (Loss loss : kLosses)
    expect_recovered("beckmann", "beckmann:alpha=0.3,f0_r=0.5,f0_g=0.4,f0_b=0.2",
                     "beckmann:alpha=0.05", {.loss = loss});
}

TEST(FitRecovery, Sheen) {
  expect_recovered("sheen", "sheen:alpha=0.4,color_r=0.8,color_g=0.5,color_b=0.3",
                   "sheen:alpha=0.1");
}

TEST(FitRecovery, Abc) {
  expect_recovered("abc", "abc:a=2,b=300,c=1.2,eta=1.6,kd=0.2", "abc:a=1,b=50,c=2,eta=1.3,kd=0.5");
}

TEST(FitRecovery, LambertPlusGgxWithColours) {
  const std::string truth =
      "lambert:albedo_r=0.6,albedo_g=0.2,albedo_b=0.1+ggx:alpha=0.08,f0_r=0.95,f0_g=0.7,f0_b=0.4";
  for (const char* start : {"lambert+ggx:alpha=0.5", "lambert:albedo_r=0.01+ggx:alpha=0.01"})
    expect_recovered("lambert+ggx", truth, start);
}

TEST(FitModel, GivenValuesAreHeldAndTheSpecRoundTrips) {
  const Model m = parse_model("lambert+ggx:f0=0.9");
  ASSERT_EQ(m.terms, (std::vector<std::string>{"lambert", "ggx"}));
  for (const Param& p : m.params) {
    if (p.name == "f0") {
      EXPECT_FALSE(p.fitted);
    }
    EXPECT_NE(p.name, "albedo");   // a grey value with channels: its channels are fitted
    EXPECT_NE(p.name, "alpha_x");  // follows alpha: the fitted models are isotropic
    EXPECT_NE(p.name, "eta");      // switches Schlick to exact Fresnel: held by rule
    EXPECT_NE(p.name, "f0_r");     // follows the given f0
  }
  EXPECT_NO_THROW(load_brdf(spec_of(m)));
}

// The fit differences the three channels of a colour parameter at once (docs/fit.md, "Solver"),
// which holds because NAME_r drives the red channel only: checked for every registered model that
// has colour parameters, at 64 pairs of the layout, each channel shifted by a tenth of its range.
TEST(FitModel, ColourChannelsDriveTheirChannelOnly) {
  const Samples s = halfdiff_samples(64);
  int checked = 0;
  for (const std::string& name : model_registry().names()) {
    Model m;
    try {
      m = parse_model(name);
    } catch (const std::invalid_argument&) {
      continue;  // not a model the fit takes
    }
    const BrdfPtr base = load_brdf(spec_of(m));
    for (Param& p : m.params) {
      const int own = channel_of(p);
      if (!p.fitted || own < 0) continue;
      const double keep = p.value, step = 0.1 * (p.max - p.min);
      p.value = keep + step <= p.max ? keep + step : keep - step;
      const BrdfPtr shifted = load_brdf(spec_of(m));
      p.value = keep;
      bool changed = false;
      for (const auto& pair : s.pairs) {
        const Rgb a = base->eval(pair), b = shifted->eval(pair);
        const double d[3] = {b.r - a.r, b.g - a.g, b.b - a.b};
        for (int k = 0; k < 3; ++k)
          if (k != own) {
            EXPECT_EQ(d[k], 0.0) << name << " " << p.name << " moves channel " << k;
          }
        changed = changed || d[own] != 0;
      }
      EXPECT_TRUE(changed) << name << " " << p.name << " moves nothing";
      ++checked;
    }
  }
  EXPECT_GE(checked, 3 * 8) << "fewer colour parameters than the registry's models have";
}

// Pairs of independent uniformly random directions of the upper hemisphere, weight 1 each: a
// layout that is not fit()'s (as a gonio-reflectometer's plan is not).
Samples random_pairs(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const auto dir = [&] {
    const double z = u(rng), phi = 2 * std::numbers::pi * u(rng), r = std::sqrt(1 - z * z);
    return Vec3<double>{r * std::cos(phi), r * std::sin(phi), z};
  };
  Samples s;
  for (std::size_t i = 0; i < n; ++i) {
    s.pairs.push_back({dir(), dir()});
    s.weight.push_back(1);
    s.cos_i.push_back(s.pairs.back().wi.z);
  }
  return s;
}

// fit_at on the caller's pairs: a Lambert + GGX sum recovered from its values at 10 000 random
// pairs (more than 2 × 4096: the starts run on a random subset first), and a wrong call refused.
TEST(FitAt, RecoversFromTheCallersPairsAndRefusesMismatches) {
  const std::string truth = "lambert:albedo_r=0.3,albedo_g=0.2,albedo_b=0.1+ggx:alpha=0.15,f0=0.8";
  const Samples s = random_pairs(10000, 7);
  std::vector<Rgb> v(s.pairs.size());
  const BrdfPtr b = load_brdf(truth);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = b->eval(s.pairs[i]);
  const FitResult r = fit_at(s, v, "lambert+ggx");
  EXPECT_EQ(r.samples, 10000u);
  EXPECT_LT(r.loss_value, 1e-12) << r.spec;
  EXPECT_NEAR(value_in(r.model, 1, "alpha"), 0.15, 1e-4 * 0.15) << r.spec;
  EXPECT_NEAR(value_in(r.model, 0, "albedo_g"), 0.2, 1e-4 * 0.2) << r.spec;
  EXPECT_THROW(fit_at(s, std::span<const Rgb>(v).first(10), "lambert+ggx"), std::invalid_argument);
  EXPECT_THROW(fit_at(Samples{}, {}, "lambert+ggx"), std::invalid_argument);
  v[5].g = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(fit_at(s, v, "lambert+ggx"), FitDataError);
}

TEST(FitLoss, NamesRoundTrip) {
  for (Loss l : kLosses) EXPECT_EQ(parse_loss(name_of(l)), l);
  EXPECT_FALSE(parse_loss("l2").has_value());
}

TEST(FitSamples, LayoutInTheHemisphereWithMeanWeightOne) {
  const Samples s = halfdiff_samples(5000);
  ASSERT_EQ(s.pairs.size(), 5000u);
  double sum = 0;
  for (std::size_t i = 0; i < s.pairs.size(); ++i) {
    EXPECT_GT(s.pairs[i].wi.z, 0);
    EXPECT_GT(s.pairs[i].wo.z, 0);
    sum += s.weight[i];
  }
  EXPECT_NEAR(sum / 5000, 1, 1e-12);
}

// A sum of a sharp and a broad GGX lobe fitted by one GGX lobe of roughness alone: under the log
// loss, the loss has a minimum near each (α ≈ 0.013 and, higher, α ≈ 0.56). A start at α = 1
// falls into the broad basin and stays there; the automatic starts find the lower minimum, that
// of a fine scan.
TEST(FitMultistart, TwoMinimaOneStartFailsTheStartsSucceed) {
  const BrdfPtr target = load_brdf("ggx:alpha=0.01,f0=1+ggx:alpha=0.7,f0=0.5");
  const std::string model = "ggx:f0=0.75";
  FitOptions o;
  o.samples = 3000;
  o.loss = Loss::log;
  // The scan: the global minimum over a fine grid of roughness.
  const Samples s = halfdiff_samples(o.samples);
  std::vector<Rgb> t(s.pairs.size());
  for (std::size_t i = 0; i < t.size(); ++i) t[i] = target->eval(s.pairs[i]);
  double scan_best = std::numeric_limits<double>::infinity(), scan_alpha = 0;
  for (double la = std::log(1e-3); la < std::log(10); la += 0.01) {
    const double l = loss_value(t, *load_brdf(with_alpha(model, std::exp(la))), o.loss, s);
    if (l < scan_best) scan_best = l, scan_alpha = std::exp(la);
  }
  o.starts = {"ggx:alpha=1"};
  const FitResult one = fit(*target, model, o);
  o.starts.clear();
  const FitResult multi = fit(*target, model, o);
  EXPECT_GT(one.loss_value, 1.5 * multi.loss_value) << one.spec;
  EXPECT_GT(value_in(one.model, 0, "alpha"), 0.2) << "the single start left the broad basin";
  EXPECT_LE(multi.loss_value, scan_best * (1 + 1e-9)) << multi.spec;
  // The value reported is the loss of the spec reported.
  EXPECT_NEAR(multi.loss_value, loss_value(t, *load_brdf(multi.spec), o.loss, s),
              1e-12 * multi.loss_value);
  EXPECT_NEAR(value_in(multi.model, 0, "alpha"), scan_alpha, 0.02 * scan_alpha);
}

// The automatic starts run each distinct start once: the peak's guess sets α, so a model without
// α (Ward's lobe names it roughness) has one start fewer, not the defaults twice.
TEST(FitMultistart, EachDistinctStartRunsOnce) {
  const BrdfPtr target = load_brdf("ggx:alpha=0.3");
  FitOptions o;
  o.samples = 1000;
  EXPECT_EQ(fit(*target, "ggx", o).starts, 7u);   // defaults, the peak's α, a grid of 5
  EXPECT_EQ(fit(*target, "ward", o).starts, 6u);  // defaults, a grid of 5
}

// A BRDF of given value everywhere (NaN, ∞, 0), isotropic or not.
class ConstantBrdf final : public Brdf {
 public:
  explicit ConstantBrdf(double v, bool iso = true) : v_(v), iso_(iso) {}
  std::string name() const override { return "constant"; }
  std::string description() const override { return "constant"; }
  bool isotropic() const override { return iso_; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>&) const override { return {0.1, v_, 0.1}; }

 private:
  double v_;
  bool iso_;
};

void expect_data_error(const Brdf& target, const std::string& words) {
  FitOptions o;
  o.samples = 500;
  try {
    fit(target, "lambert", o);
    ADD_FAILURE() << "no error; expected one saying " << words;
  } catch (const FitDataError& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(FitErrors, TargetsTheFitCannotUse) {
  expect_data_error(ConstantBrdf(std::numeric_limits<double>::quiet_NaN()), "not finite");
  expect_data_error(ConstantBrdf(std::numeric_limits<double>::infinity()), "not finite");
  expect_data_error(ConstantBrdf(-1), "negative");
  expect_data_error(*load_brdf("lambert:albedo=0"), "zero at all 500 samples");
  expect_data_error(ConstantBrdf(0.5, false), "anisotropic");
  expect_data_error(*load_brdf("ggx:alpha_x=0.1,alpha_y=0.3"), "anisotropic");
}

void expect_model_error(const std::string& model, const std::string& words) {
  try {
    parse_model(model);
    ADD_FAILURE() << model << ": no error; expected one saying " << words;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(FitErrors, BadModelsAndStarts) {
  expect_model_error("phong", "phong");
  expect_model_error("ggx:roughness=0.1", "roughness");
  expect_model_error("ggx:alpha=-1", "alpha");
  expect_model_error("+ggx", "empty");
  FitOptions o;
  o.samples = 500;
  try {
    fit(*load_brdf("ggx"), "lambert:albedo_r=0.5,albedo_g=0.5,albedo_b=0.5", o);
    ADD_FAILURE() << "no error for a model with nothing to fit";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("nothing to fit"), std::string::npos) << e.what();
  }
  o.starts = {"beckmann:alpha=0.1"};
  EXPECT_THROW(fit(*load_brdf("ggx"), "ggx", o), std::invalid_argument);
  o.starts = {"ggx:eta=1.5"};  // held by rule, not fitted: a start cannot set it
  EXPECT_THROW(fit(*load_brdf("ggx"), "ggx", o), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::fit

namespace halfback::fit {
namespace {

// loss_of is the loss fit() reports: of the fitted spec, against the same target and layout.
TEST(FitLoss, LossOfTheFittedSpecIsTheReportedLoss) {
  const BrdfPtr target = load_brdf("lambert:albedo=0.2+ggx:alpha=0.25,f0=0.6");
  FitOptions o;
  o.samples = 1500;
  o.loss = Loss::low_e2;
  const FitResult r = fit(*target, "ggx", o);  // a lobe short: a loss well above zero
  EXPECT_GT(r.loss_value, 1e-4);
  EXPECT_NEAR(loss_of(*target, *load_brdf(r.spec), Loss::low_e2, 1500), r.loss_value,
              1e-12 * r.loss_value);
  EXPECT_EQ(loss_of(*target, *target, Loss::ngan, 1500), 0.0);
  EXPECT_THROW((void)loss_of(*load_brdf("lambert:albedo=0"), *target, Loss::ngan, 100),
               FitDataError);
}

}  // namespace
}  // namespace halfback::fit
