// The renderer: white furnace (constant environment of radiance 1: each pixel is the BRDF's
// directional albedo), black environment, convergence rate, MIS against each strategy alone,
// determinism, time budget, camera conventions, image files and bad input.
#include "halfback/render/renderer.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <memory>
#include <numbers>
#include <random>
#include <span>
#include <stdexcept>
#include <string>

#include "halfback/brdf/albedo.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/models/analytic.hpp"
#include "support/exr_offsets.hpp"
#include "support/test_brdfs.hpp"
#include "support/test_support.hpp"

namespace halfback::render {
namespace {

constexpr double kOrthoHalfHeight = 1.25;

using test::Opaque;  // hides the model's own sampler

BrdfPtr ggx(double alpha, double f0 = 1) {
  models::MicrofacetParams p;
  p.alpha_x = p.alpha_y = alpha;
  p.fresnel.kind = models::Fresnel::Kind::schlick;
  p.fresnel.f0 = {f0, f0, f0};
  return std::make_shared<models::Microfacet>(p);
}

RenderSettings small(int size, int spp) {
  RenderSettings s;
  s.width = s.height = size;
  s.spp = spp;
  s.variance = true;
  s.tabulation.radial = 32;
  s.tabulation.azimuthal = 64;
  s.tabulation.theta_slices = 16;
  return s;
}

// The pixel's footprint lies entirely on the sphere (orthographic view).
bool fully_on_sphere(const RenderSettings& s, int x, int y, Vec3<double>* normal = nullptr) {
  for (int cx = 0; cx < 2; ++cx)
    for (int cy = 0; cy < 2; ++cy) {
      const double px = (2.0 * (x + cx) / s.width - 1) * kOrthoHalfHeight;
      const double py = (1 - 2.0 * (y + cy) / s.height) * kOrthoHalfHeight;
      if (px * px + py * py >= 0.999) return false;
    }
  if (normal) {
    const double px = (2.0 * (x + 0.5) / s.width - 1) * kOrthoHalfHeight;
    const double py = (1 - 2.0 * (y + 0.5) / s.height) * kOrthoHalfHeight;
    *normal = {px, py, std::sqrt(1 - px * px - py * py)};
  }
  return true;
}

std::filesystem::path shared_dir() {
  const char* d = std::getenv("HALFBACK_SHARED_DIR");
  return d ? std::filesystem::path(d) : std::filesystem::path();
}

// Lambert in a white furnace: every pixel is the albedo; the deviation is within the estimator's
// own standard error, and the background is exactly the environment.
TEST(Renderer, WhiteFurnaceLambert) {
  const models::Lambert lambert({0.7, 0.7, 0.7});
  const EnvMap white = EnvMap::constant({1, 1, 1});
  for (const bool tabulated : {false, true}) {
    const Opaque opaque(std::make_shared<models::Lambert>(Rgb{0.7, 0.7, 0.7}));
    const Brdf& b = tabulated ? static_cast<const Brdf&>(opaque) : lambert;
    const RenderSettings s = small(32, 64);
    const RenderResult r = render(b, white, s);
    EXPECT_EQ(r.spp, 64);
    int n = 0, outliers = 0;
    double sum = 0, worst = 0;
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) {
        const float* p = r.image.pixel(x, y);
        const float sd = std::sqrt(r.variance[std::size_t(y * s.width + x)]);
        if (fully_on_sphere(s, x, y)) {
          ++n;
          sum += p[1];
          worst = std::max(worst, std::abs(p[1] - 0.7) / std::max(sd, 1e-6f));
          outliers += std::abs(p[1] - 0.7) > 4 * sd + 1e-6;
        } else if (!(p[0] > 0.6f && p[0] <= 1.000001f)) {  // sphere and background mixed
          ADD_FAILURE() << "pixel " << x << "," << y << " = " << p[0];
        }
      }
    EXPECT_LE(outliers, 1) << "worst deviation " << worst << " sd";
    EXPECT_NEAR(sum / n, 0.7, 2e-3) << (tabulated ? "tabulated" : "own sampler");
    // Corner pixels show the environment exactly.
    EXPECT_EQ(r.image.pixel(0, 0)[2], 1.0f);
  }
}

// A glossy GGX (F = 1) in a white furnace: each pixel is its directional albedo at θo.
TEST(Renderer, WhiteFurnaceGgx) {
  const auto g = ggx(0.3);
  const RenderSettings s = small(24, 128);
  const RenderResult r = render(*g, EnvMap::constant({1, 1, 1}), s);
  int checked = 0;
  for (int y = 0; y < s.height; y += 3)
    for (int x = 0; x < s.width; x += 3) {
      Vec3<double> n;
      if (!fully_on_sphere(s, x, y, &n)) continue;
      // ωo = +z in the local frame is (0, 0, n.z) up to an azimuth, which GGX ignores.
      const Vec3<double> wo{std::sqrt(1 - n.z * n.z), 0, n.z};
      const AlbedoEstimate a = directional_albedo(*g, wo, 256, 9);
      const double sd = std::sqrt(r.variance[std::size_t(y * s.width + x)]);
      // The pixel integrates over its footprint, the reference is at its centre.
      const double spread = std::abs(
          directional_albedo(*g, {std::sqrt(1 - std::pow(n.z * 0.98, 2)), 0, n.z * 0.98}, 64, 9)
              .mean.r -
          a.mean.r);
      EXPECT_NEAR(r.image.pixel(x, y)[0], a.mean.r, 5 * sd + 4 * a.standard_error.r + spread + 1e-3)
          << "pixel " << x << "," << y << " cos θo " << n.z;
      ++checked;
    }
  EXPECT_GT(checked, 20);
}

TEST(Renderer, BlackEnvironmentIsBlack) {
  const RenderResult r = render(*ggx(0.2), EnvMap::from_spec("constant:0"), small(16, 4));
  for (float v : r.image.rgb) EXPECT_EQ(v, 0.0f);
}

double rmse(const Image& a, const Image& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) s += std::pow(double(a.rgb[i]) - b.rgb[i], 2);
  return std::sqrt(s / double(a.rgb.size()));
}

// The slope of log RMSE against log N, by least squares.
double slope(const std::vector<double>& n, const std::vector<double>& e) {
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < n.size(); ++i) {
    mx += std::log(n[i]);
    my += std::log(e[i]);
  }
  mx /= double(n.size());
  my /= double(n.size());
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < n.size(); ++i) {
    sxy += (std::log(n[i]) - mx) * (std::log(e[i]) - my);
    sxx += std::pow(std::log(n[i]) - mx, 2);
  }
  return sxy / sxx;
}

TEST(Renderer, ConvergesAsOneOverSqrtN) {
  const auto g = ggx(0.2, 0.9);
  const EnvMap env = EnvMap::default_sky();
  RenderSettings ref = small(16, 8192);
  ref.seed = 99;
  ref.variance = false;
  const Image reference = render(*g, env, ref).image;
  for (const Sequence seq : {Sequence::random, Sequence::sobol}) {
    std::vector<double> ns, errs;
    for (int spp : {4, 16, 64, 256}) {
      double e2 = 0;
      for (int seed = 1; seed <= 4; ++seed) {  // average the squared error over seeds
        RenderSettings s = small(16, spp);
        s.sequence = seq;
        s.seed = std::uint64_t(seed);
        s.variance = false;
        e2 += std::pow(rmse(render(*g, env, s).image, reference), 2);
      }
      ns.push_back(spp);
      errs.push_back(std::sqrt(e2 / 4));
    }
    const double k = slope(ns, errs);
    RecordProperty(seq == Sequence::random ? "slope_random" : "slope_sobol", std::to_string(k));
    if (seq == Sequence::random)
      EXPECT_NEAR(k, -0.5, 0.08) << "independent samples: 1/sqrt(N)";
    else
      EXPECT_LT(k, -0.45) << "stratified samples: at least as fast as 1/sqrt(N)";
    for (std::size_t i = 1; i < errs.size(); ++i) EXPECT_LT(errs[i], errs[i - 1]);
  }
}

double mean_variance(const Brdf& b, const EnvMap& env, Strategy st) {
  RenderSettings s = small(48, 32);
  s.strategy = st;
  s.sequence = Sequence::random;
  const RenderResult r = render(b, env, s);
  double v = 0;
  int n = 0;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x)
      if (fully_on_sphere(s, x, y)) {
        v += r.variance[std::size_t(y * s.width + x)];
        ++n;
      }
  return v / n;
}

// MIS (with compensation) beats both strategies alone, at the same number of light samples, on a
// glossy and a diffuse material under an environment with a small bright source (the built-in
// sky), and under a real map (grace: bright windows in a dim church).
TEST(Renderer, MisHasLowerVarianceThanEitherStrategy) {
  const EnvMap env = EnvMap::default_sky();
  const models::Lambert lambert({0.8, 0.8, 0.8});
  const auto glossy = ggx(0.15, 0.9);
  for (const Brdf* b : {static_cast<const Brdf*>(&lambert), glossy.get()}) {
    const double mis = mean_variance(*b, env, Strategy::mis);
    const double brdf = mean_variance(*b, env, Strategy::brdf);
    const double light = mean_variance(*b, env, Strategy::env);
    EXPECT_LT(mis, brdf) << b->name();
    EXPECT_LT(mis, light) << b->name();
    RecordProperty(b->name() + "_variance_ratio_brdf", std::to_string(brdf / mis));
    RecordProperty(b->name() + "_variance_ratio_env", std::to_string(light / mis));
  }
}

TEST(Renderer, MisOnRealMap) {
  const auto path = shared_dir() / "data" / "envmaps" / "grace.hdr";
  if (!std::filesystem::exists(path)) {
    const char* ci = std::getenv("CI");
    if (ci && std::string(ci) == "true") FAIL() << "missing " << path;
    GTEST_SKIP() << "shared data not found: " << path;
  }
  const EnvMap env = EnvMap::load(path);
  const models::Lambert lambert({0.8, 0.8, 0.8});
  const auto glossy = ggx(0.3, 0.9);
  for (const Brdf* b : {static_cast<const Brdf*>(&lambert), glossy.get()}) {
    const double mis = mean_variance(*b, env, Strategy::mis);
    EXPECT_LT(mis, mean_variance(*b, env, Strategy::brdf)) << b->name();
    EXPECT_LT(mis, mean_variance(*b, env, Strategy::env)) << b->name();
  }
}

// Renders equal in expectation (docs/render.md, "Speed"): the mean of two seeds' MIS images (guide
// tables, packets, the fast pixel lookup) against an independent reference, a long render by
// cosine-weighted BRDF sampling alone (no environment sampling tables, no BRDF sampler), pixel by
// pixel within the three images' own standard errors, and over the whole sphere (where the error
// is small enough that a bias of 3 % fails it).
TEST(Renderer, EqualInExpectationToCosineSampledReference) {
  const EnvMap env = EnvMap::studio({-30, 0});
  const auto glossy = ggx(0.3, 0.9);
  const Opaque tabulated(ggx(0.3, 0.9));
  const models::Lambert lambert({0.6, 0.5, 0.4});
  for (const Brdf* b : {static_cast<const Brdf*>(glossy.get()),
                        static_cast<const Brdf*>(&tabulated), static_cast<const Brdf*>(&lambert)}) {
    RenderSettings s = small(12, 1024);
    const RenderResult a = render(*b, env, s);
    s.seed = 2;
    const RenderResult c = render(*b, env, s);
    s.seed = 3;
    s.spp = 65536;
    s.strategy = Strategy::brdf;
    const RenderResult ref = render_sampled(*with_cosine_sampling(*b), env, s);
    double sum_z2 = 0, sum_mean = 0, sum_ref = 0, sum_var = 0;
    int n = 0, outliers = 0;
    auto lum = [](const float* p) { return Rgb{p[0], p[1], p[2]}.luminance(); };
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) {
        if (!fully_on_sphere(s, x, y)) continue;
        const std::size_t i = std::size_t(y * s.width + x);
        const double mean = 0.5 * (lum(a.image.pixel(x, y)) + lum(c.image.pixel(x, y)));
        const double var = 0.25 * (a.variance[i] + c.variance[i]) + ref.variance[i];
        ASSERT_GT(var, 0);
        const double z = (mean - lum(ref.image.pixel(x, y))) / std::sqrt(var);
        sum_z2 += z * z;
        outliers += std::abs(z) > 5;
        sum_mean += mean;
        sum_ref += lum(ref.image.pixel(x, y));
        sum_var += var;
        ++n;
      }
    ASSERT_GT(n, 40);
    EXPECT_LT(sum_z2 / n, 2.0) << b->describe_sampling();
    EXPECT_LE(outliers, 1) << b->describe_sampling();
    // The sphere's total: within 4 standard errors, which are small enough to see a 3 % bias.
    const double sd = std::sqrt(sum_var) / sum_ref;
    EXPECT_LT(sd, 0.006) << b->describe_sampling();
    EXPECT_NEAR(sum_mean / sum_ref, 1, 4 * sd) << b->describe_sampling();
    RecordProperty(b->name() + "_total_ratio", std::to_string(sum_mean / sum_ref));
    RecordProperty(b->name() + "_total_sd", std::to_string(sd));
    RecordProperty(b->name() + "_mean_z2", std::to_string(sum_z2 / n));
  }
}

// A BRDF that forwards evaluation and its model's own one-pair sampling (sample, pdf) to another;
// the batch functions are Brdf's defaults (through eval, sample and pdf) unless a test overrides
// them. No tabulation before the first pass.
class ForwardingBrdf : public Brdf {
 public:
  explicit ForwardingBrdf(BrdfPtr b) : b_(std::move(b)) {}
  std::string description() const override { return b_->description(); }
  bool isotropic() const override { return b_->isotropic(); }
  bool reciprocal() const override { return b_->reciprocal(); }
  Rgb eval(const DirPair<double>& p) const override { return b_->eval(p); }
  BrdfSample sample(const Vec3<double>& wo, double u1, double u2) const override {
    return b_->sample(wo, u1, u2);
  }
  double pdf(const Vec3<double>& wo, const Vec3<double>& wi) const override {
    return b_->pdf(wo, wi);
  }
  bool has_importance_sampling() const override { return b_->has_importance_sampling(); }

 protected:
  BrdfPtr b_;
};

// A BRDF's own sampling one sample at a time: sample() and pdf() through the defaults of
// sample_batch() and pdf_batch(), which hides a model's batched sampler (the renderer's old path).
class OneAtATime final : public ForwardingBrdf {
 public:
  using ForwardingBrdf::ForwardingBrdf;
  std::string name() const override { return "one-at-a-time"; }
  void eval_batch(std::span<const DirPair<double>> p, std::span<Rgb> out) const override {
    b_->eval_batch(p, out);
  }
};

// The batched samplers (RGL's: SIMD angles and the guided warp; GGX's) render, with the same seed,
// the image of their one-at-a-time sampling up to rounding: the same sample numbers give the same
// directions and densities to about 1e-12, so only a sample that rounding moves across an edge
// (of a map pixel, of the horizon) may differ. And with another seed, the images agree within
// their noise.
TEST(Renderer, BatchedSamplersRenderTheOneAtATimeImage) {
  const EnvMap env = EnvMap::studio({-30, 0});
  for (const char* spec : {"embedded:ilm_l3_37_metallic", "ggx:alpha=0.3,f0=0.9"}) {
    const BrdfPtr b = load_brdf(spec);
    const OneAtATime old(b);
    RenderSettings s = small(24, 64);
    const RenderResult a = render(*b, env, s), o = render(old, env, s);
    double total_a = 0, total_o = 0;
    int differ = 0;
    for (std::size_t i = 0; i < a.image.rgb.size(); ++i) {
      total_a += a.image.rgb[i];
      total_o += o.image.rgb[i];
      differ += std::abs(a.image.rgb[i] - o.image.rgb[i]) > 1e-5f * (1 + o.image.rgb[i]);
    }
    EXPECT_LE(differ, int(a.image.rgb.size() / 200)) << spec;
    EXPECT_NEAR(total_a / total_o, 1, 1e-4) << spec;
    // Another seed: the mean over the sphere within 4 standard errors of the old path's.
    s.seed = 2;
    const RenderResult c = render(*b, env, s);
    double sum_c = 0, sum_o = 0, var = 0;
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) {
        if (!fully_on_sphere(s, x, y)) continue;
        const std::size_t i = std::size_t(y * s.width + x);
        auto lum = [](const Image& im, int px, int py) {
          const float* p = im.pixel(px, py);
          return Rgb{p[0], p[1], p[2]}.luminance();
        };
        sum_c += lum(c.image, x, y);
        sum_o += lum(o.image, x, y);
        var += c.variance[i] + o.variance[i];
      }
    EXPECT_NEAR(sum_c, sum_o, 4 * std::sqrt(var)) << spec;
  }
}

// The background of the orthographic view: a pixel whose samples all fall in one map pixel takes
// its value without looking each up (docs/render.md, "Speed"). Against a dense grid of 32 × 32
// directions in each background pixel of a map with a different value in every pixel (5.6° map
// pixels, 1.25° image pixels): where the grid sees one map pixel, the render has exactly its
// value; where it sees several, the render is their area mean up to the Sobol points' error, and
// not one of them alone (which a pixel wrongly taken as uniform would show).
TEST(Renderer, UniformBackgroundPixelsAreExact) {
  const int mw = 64, mh = 32;
  std::vector<float> rgb(std::size_t(mw) * mh * 3);
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0.1f, 2.0f);
  for (float& v : rgb) v = u(rng);
  const EnvMap env(mw, mh, rgb, "random", {20, 0});
  RenderSettings s = small(48, 256);
  s.background_fov_deg = 60;
  const Image im = render(*ggx(0.3), env, s).image;
  const double t = std::tan(30 * std::numbers::pi / 180);
  int uniform = 0, mixed = 0;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      // Only pixels whose square is well outside the disk.
      bool outside = true;
      double sum = 0, lo = 1e9, hi = -1e9;
      const int n = 32;
      for (int i = 0; i < n && outside; ++i)
        for (int j = 0; j < n; ++j) {
          const double nx = 2 * (x + (i + 0.5) / n) / s.width - 1;
          const double ny = 1 - 2 * (y + (j + 0.5) / n) / s.height;
          if ((nx * nx + ny * ny) * kOrthoHalfHeight * kOrthoHalfHeight < 1.05) {
            outside = false;
            break;
          }
          Vec3<double> d{nx * t, ny * t, -1};
          const double l = std::sqrt(d.x * d.x + d.y * d.y + 1);
          const double g = env.eval({d.x / l, d.y / l, d.z / l}).g;
          sum += g;
          lo = std::min(lo, g);
          hi = std::max(hi, g);
        }
      if (!outside) continue;
      const double value = im.pixel(x, y)[1], mean = sum / (n * n);
      if (lo == hi) {
        ++uniform;
        EXPECT_NEAR(value, lo, 1e-6 * lo) << x << "," << y;
      } else {
        ++mixed;
        EXPECT_NEAR(value, mean, 0.15 * (hi - lo)) << x << "," << y;
        // A straddling pixel is not one map value alone, unless that value dominates the mean.
        if (std::min(mean - lo, hi - mean) > 0.2 * (hi - lo)) {
          EXPECT_TRUE(std::abs(value - lo) > 1e-6 && std::abs(value - hi) > 1e-6) << x << "," << y;
        }
      }
    }
  EXPECT_GT(uniform, 300);
  EXPECT_GT(mixed, 100);
}

TEST(Renderer, DeterministicAcrossThreadCounts) {
  const auto g = ggx(0.2);
  const EnvMap env = EnvMap::default_sky();
  RenderSettings s = small(40, 4);
  s.threads = 1;
  const Image a = render(*g, env, s).image;
  s.threads = 3;
  const Image b = render(*g, env, s).image;
  EXPECT_EQ(a.rgb, b.rgb);
  s.seed = 2;
  EXPECT_NE(render(*g, env, s).image.rgb, a.rgb);
}

TEST(Renderer, TimeBudgetStopsEarly) {
  RenderSettings s = small(64, 1 << 16);
  s.time_budget = 0.3;
  const RenderResult r = render(*ggx(0.2), EnvMap::default_sky(), s);
  EXPECT_TRUE(r.budget_exhausted);
  EXPECT_GE(r.spp, 1);
  EXPECT_LT(r.spp, 1 << 16);
  EXPECT_LT(r.seconds, 5);
  for (float v : r.image.rgb) EXPECT_TRUE(std::isfinite(v));
}

// Work is bounded by what was asked (docs/reliability/cli.md): the budget is checked
// at every tile, so a first pass over a large image that does not fit stops within about a tile
// of the budget, with an error that says so (it was checked only between passes: 16384² ran past
// 40 s with a 1 s budget).
// A BRDF that costs about a microsecond an evaluation on any current CPU, so that one pass of the
// renderer costs far more CPU time than the budget, however fast the renderer becomes.
class Costly final : public ForwardingBrdf {
 public:
  using ForwardingBrdf::ForwardingBrdf;
  std::string name() const override { return "costly"; }
  Rgb eval(const DirPair<double>& p) const override {
    volatile double x = p.wi.z;
    for (int i = 0; i < 400; ++i) x = std::sqrt(x * x + 1e-3);
    return b_->eval(p);
  }
};

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// The budget is checked inside a pass. Measured in CPU time of this process (not wall time, which
// another job on the machine stretches): a pass of 1024 x 1024 costly samples on one thread
// costs seconds of CPU, a budget of 0.1 s stops it after about 0.1 s of it.
TEST(Renderer, TimeBudgetBoundsTheFirstPass) {
  RenderSettings s = small(1024, 64);
  s.variance = false;
  s.threads = 1;
  s.time_budget = 0.1;
  const EnvMap sky = EnvMap::default_sky();
  const Costly brdf(ggx(0.2));
  const double start = process_cpu_seconds();
  try {
    render(brdf, sky, s);
    ADD_FAILURE() << "a 0.1 s budget fitted a 1024 x 1024 pass of costly samples on one thread";
  } catch (const TimeBudgetExceeded& e) {
    EXPECT_NE(std::string(e.what()).find("time budget of 0.1 s ran out before every pixel had one "
                                         "sample"),
              std::string::npos)
        << e.what();
  }
  EXPECT_LT(process_cpu_seconds() - start, 1.0);
}

// The sampler's set-up counts against the budget: a tabulated BRDF with a budget shorter than its
// tabulation stops there.
TEST(Renderer, TimeBudgetIncludesTheSamplerSetUp) {
  RenderSettings s = small(64, 4);
  s.tabulation = {};  // the default tables: 32 slices of 64 x 128 cells, 4 points a cell
  s.threads = 1;
  s.time_budget = 1e-4;
  const EnvMap sky = EnvMap::default_sky();
  const Opaque brdf(ggx(0.3));
  const auto start = std::chrono::steady_clock::now();
  try {
    render(brdf, sky, s);
    ADD_FAILURE() << "a 0.1 ms budget fitted the tabulation and a pass";
  } catch (const TimeBudgetExceeded& e) {
    EXPECT_NE(std::string(e.what()).find("sampler"), std::string::npos) << e.what();
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 5.0);
}

// Memory is bounded by a stated pixel limit, whatever the side lengths allow.
TEST(Renderer, PixelLimitStated) {
  RenderSettings s = small(64, 1);
  s.width = 16384;
  s.height = 16384;
  try {
    render(*ggx(0.2), EnvMap::default_sky(), s);
    ADD_FAILURE() << "16384 x 16384 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("above the limit of 16777216 pixels"), std::string::npos)
        << e.what();
  }
  s.width = 4096;
  s.height = 4097;
  EXPECT_THROW(render(*ggx(0.2), EnvMap::default_sky(), s), std::invalid_argument);
}

TEST(Renderer, CameraConventions) {
  // A map whose right half (+x) is red and left half blue, the sky brighter than the ground.
  std::vector<float> rgb(8 * 4 * 3, 0);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) {
      float* p = &rgb[std::size_t(3 * (y * 8 + x))];
      (x >= 4 ? p[0] : p[2]) = y < 2 ? 1.0f : 0.25f;
    }
  const EnvMap env(8, 4, rgb, "halves");
  for (const Projection proj : {Projection::orthographic, Projection::perspective}) {
    RenderSettings s = small(33, 2);
    s.projection = proj;
    const Image img = render(models::Lambert({1, 1, 1}), env, s).image;
    // The background: red on the right, blue on the left, brighter at the top.
    EXPECT_GT(img.pixel(32, 16)[0], 0.2f);
    EXPECT_EQ(img.pixel(32, 16)[2], 0.0f);
    EXPECT_GT(img.pixel(0, 16)[2], 0.2f);
    EXPECT_GT(img.pixel(32, 0)[0], img.pixel(32, 32)[0]);
    // The sphere: its right side faces the red half, its left side the blue one.
    const float* right = img.pixel(24, 16);
    const float* left = img.pixel(8, 16);
    EXPECT_GT(right[0], right[2]);
    EXPECT_GT(left[2], left[0]);
  }
}

TEST(Renderer, ImageFiles) {
  const RenderResult r =
      render(models::Lambert({0.5, 0.5, 0.5}), EnvMap::default_sky(), small(8, 2));
  const test::TempDir tmp;
  const std::filesystem::path& dir = tmp.path();
  write_image(dir / "a.exr", r.image, {});
  EXPECT_EQ(read_exr(dir / "a.exr").rgb, r.image.rgb);
  // The scan-line offset table is written (readers would otherwise have to rebuild it).
  const std::string exr = test::read_file(dir / "a.exr");
  const std::vector<std::uint64_t> offsets = test::exr_scanline_offsets(exr);
  ASSERT_EQ(offsets.size(), std::size_t(r.image.height + 15) / 16) << "ZIP chunks of 16 lines";
  for (std::uint64_t o : offsets) {
    EXPECT_GT(o, 0u);
    EXPECT_LT(o, exr.size());
  }
  write_image(dir / "a.PNG", r.image, {1, true});
  std::ifstream png(dir / "a.PNG", std::ios::binary);
  char magic[4] = {};
  png.read(magic, 4);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  for (const auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << "left a temp file";
  EXPECT_THROW(write_image(dir / "a.jpg", r.image, {}), std::invalid_argument);
  try {
    write_image(dir / "no" / "such" / "dir.png", r.image, {});
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("dir.png"), std::string::npos) << e.what();
  }
  // Tone mapping: 0 → 0, 1 → 255, exposure doubles, filmic compresses.
  const Image grey{3, 1, {0, 0, 0, 1, 1, 1, 0.25f, 0.25f, 0.25f}};
  const auto plain = tonemap_srgb8(grey, {});
  EXPECT_EQ(plain[0], 0);
  EXPECT_EQ(plain[3], 255);
  EXPECT_EQ(tonemap_srgb8(grey, {1, false})[6], tonemap_srgb8({1, 1, {0.5f, 0.5f, 0.5f}}, {})[0]);
  EXPECT_LT(tonemap_srgb8(grey, {0, true})[3], 255);
}

TEST(Renderer, BadInput) {
  const models::Lambert l({0.5, 0.5, 0.5});
  const EnvMap env = EnvMap::constant({1, 1, 1});
  RenderSettings s = small(8, 1);
  s.width = 0;
  EXPECT_THROW(render(l, env, s), std::invalid_argument);
  s = small(8, 0);
  EXPECT_THROW(render(l, env, s), std::invalid_argument);
  s = small(8, 1);
  s.time_budget = -1;
  EXPECT_THROW(render(l, env, s), std::invalid_argument);
  // Unknown BRDFs are refused by load_brdf with a message naming them.
  try {
    load_brdf("no_such_model:alpha=1");
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_model"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(load_brdf("ggx:alpha=0.2"));
}

// The automatic choice of the BRDF sampler (docs/render.md, "Choosing the BRDF sampler"): the
// cosine for a Lambertian (which it samples exactly), the table for a sharp GGX; forced choices
// are kept; the choice is a function of the settings.
TEST(Renderer, BrdfSamplerChoice) {
  const Opaque lambert(std::make_shared<models::Lambert>(Rgb{0.7, 0.7, 0.7}));
  const Opaque sharp(ggx(0.05, 0.9)), broad(ggx(0.6, 0.9));
  RenderSettings s = small(32, 16);
  const ChosenSampler diffuse = choose_brdf_sampler(lambert, s);
  EXPECT_NE(diffuse.brdf->describe_sampling().find("cosine"), std::string::npos);
  EXPECT_NE(diffuse.why.find("chosen: the cosine's albedo variance is"), std::string::npos);
  EXPECT_NE(diffuse.why.find("e-2"), std::string::npos) << diffuse.why;  // 0 up to rounding
  const ChosenSampler glossy = choose_brdf_sampler(sharp, s);
  EXPECT_NE(glossy.brdf->describe_sampling().find("tabulated"), std::string::npos);
  EXPECT_NE(glossy.why.find("at least"), std::string::npos) << glossy.why;
  EXPECT_EQ(choose_brdf_sampler(sharp, s).why, glossy.why);  // the same settings, the same
  // A rough lobe is broad: the cosine's albedo variance is within kPeakedRatio of the table's.
  EXPECT_NE(choose_brdf_sampler(broad, s).brdf->describe_sampling().find("cosine"),
            std::string::npos)
      << choose_brdf_sampler(broad, s).why;

  s.brdf_sampling = BrdfSampling::cosine;
  EXPECT_NE(choose_brdf_sampler(sharp, s).brdf->describe_sampling().find("cosine"),
            std::string::npos);
  s.brdf_sampling = BrdfSampling::table;
  const ChosenSampler forced = choose_brdf_sampler(lambert, s);
  EXPECT_NE(forced.brdf->describe_sampling().find("tabulated"), std::string::npos);
  EXPECT_EQ(forced.why, "");
  // The env strategy draws no BRDF sample: the table, unmeasured; a BRDF's own sampler is kept.
  s.brdf_sampling = BrdfSampling::automatic;
  s.strategy = Strategy::env;
  EXPECT_EQ(choose_brdf_sampler(lambert, s).why, "");
  const auto own = ggx(0.05, 0.9);
  EXPECT_EQ(choose_brdf_sampler(*own, s).brdf.get(), own.get());
  EXPECT_EQ(brdf_sampling_from_name("auto"), BrdfSampling::automatic);
  EXPECT_EQ(brdf_sampling_from_name("cosine"), BrdfSampling::cosine);
  EXPECT_EQ(brdf_sampling_from_name("Table"), std::nullopt);
}

// Near-delta lobes: the cosine's 2048 samples per ωo never reach the peak, so its albedo estimate
// is near 0 and its measured variance says nothing (0/0); the table finds the energy, and the
// choice must be the table (the cosine renders the sphere as if it were black).
TEST(Renderer, BrdfSamplerChoiceNearDelta) {
  const RenderSettings s = small(32, 16);
  for (const char* spec : {"ward:roughness=0.001,albedo=1", "blinn-phong:sharpness=1e6,albedo=1"}) {
    const BrdfPtr brdf = load_brdf(spec);
    ASSERT_FALSE(brdf->has_importance_sampling()) << spec;  // else there is no choice to test
    const ChosenSampler c = choose_brdf_sampler(*brdf, s);
    EXPECT_NE(c.brdf->describe_sampling().find("tabulated"), std::string::npos)
        << spec << ": " << c.why;
    EXPECT_NE(c.why.find("the cosine misses a peak"), std::string::npos) << spec << ": " << c.why;
  }
}

// The environment moves the threshold: a glossy GGX (α = 0.25, albedo-variance ratio about 880)
// renders better with the table under the built-in sky (1.4× lower error at equal time) and with
// the cosine under the studio, whose lights the environment sampler carries (1.9× lower;
// halfback_render_bench --part 8, docs/render.md). A sharp lobe keeps the table under both.
TEST(Renderer, BrdfSamplerChoiceFollowsTheEnvironment) {
  const RenderSettings s = small(32, 16);
  const EnvMap sky = EnvMap::default_sky(), studio = EnvMap::studio();
  EXPECT_GT(sky.residual_fraction(), 2 * studio.residual_fraction());
  EXPECT_DOUBLE_EQ(EnvMap::constant({0.5, 0.5, 0.5}).residual_fraction(), 1);
  EXPECT_LT(peaked_ratio(sky), peaked_ratio(studio));
  const Opaque glossy(ggx(0.25, 0.9)), sharp(ggx(0.05, 0.9));
  const ChosenSampler under_sky = choose_brdf_sampler(glossy, sky, s);
  const ChosenSampler under_studio = choose_brdf_sampler(glossy, studio, s);
  EXPECT_NE(under_sky.brdf->describe_sampling().find("tabulated"), std::string::npos)
      << under_sky.why;
  EXPECT_NE(under_studio.brdf->describe_sampling().find("cosine"), std::string::npos)
      << under_studio.why;
  EXPECT_EQ(under_sky.albedo_variance_ratio, under_studio.albedo_variance_ratio);  // the BRDF's
  EXPECT_NE(under_studio.why.find("the threshold for an environment that leaves 22 %"),
            std::string::npos)
      << under_studio.why;
  EXPECT_NE(choose_brdf_sampler(sharp, studio, s).brdf->describe_sampling().find("tabulated"),
            std::string::npos);
  // Without an environment, the choice is the sky's (render's default).
  EXPECT_EQ(choose_brdf_sampler(glossy, s).why, under_sky.why);
}

TEST(Renderer, StrategyNames) {
  EXPECT_EQ(strategy_from_name("mis"), Strategy::mis);
  EXPECT_EQ(strategy_from_name("brdf"), Strategy::brdf);
  EXPECT_EQ(strategy_from_name("env"), Strategy::env);
  EXPECT_FALSE(strategy_from_name("MIS").has_value());
  EXPECT_FALSE(strategy_from_name("").has_value());
}

// Images that are not finite (docs/reliability/numerics.md, "Images that are not finite are not
// written"): an environment scaled beyond the float range gives an image of +Inf; the result counts
// such pixels (the CLI refuses to write the image). The same radiance 2^64 times lower is finite
// everywhere.
TEST(Renderer, PixelsBeyondTheFloatRangeAreCounted) {
  const auto lambert = load_brdf("lambert:albedo=0.5");
  const RenderSettings s = small(8, 2);
  const RenderResult over =
      render(*lambert, EnvMap::from_spec("constant:1e30", {0, 64}), s);  // 1.8e49 > 3.4e38
  EXPECT_EQ(over.nonfinite_pixels, 64u);
  EXPECT_TRUE(std::isinf(over.image.rgb[0]));
  const RenderResult fine = render(*lambert, EnvMap::from_spec("constant:1e30"), s);
  EXPECT_EQ(fine.nonfinite_pixels, 0u);
  EXPECT_NEAR(fine.image.rgb[0], 1e30, 1e24);  // the background is the environment itself
}

}  // namespace
}  // namespace halfback::render

namespace halfback::render {
namespace {

// A point light from the camera on a Lambertian sphere (orthographic): each pixel centre shows
// (albedo/π) n·l, n the normal there (computed here from the pixel's position); 0 outside.
TEST(PointLight, LambertIsAlbedoOverPiTimesTheCosine) {
  const auto lambert = load_brdf("lambert:albedo=0.6");
  RenderSettings s;
  s.width = s.height = 32;
  s.spp = 1;  // the pixel centres
  s.threads = 2;
  const RenderResult r = render_point_light(*lambert, {0, 0, 1}, s);
  int lit = 0;
  for (int py = 0; py < s.height; ++py)
    for (int px = 0; px < s.width; ++px) {
      const double x = ((px + 0.5) * 2.0 / s.width - 1) * 1.25,
                   y = (1 - (py + 0.5) * 2.0 / s.height) * 1.25;
      const double r2 = x * x + y * y,
                   expected = r2 < 1 ? 0.6 / std::numbers::pi * std::sqrt(1 - r2) : 0;
      const float* v = &r.image.rgb[3 * (py * s.width + px)];
      EXPECT_NEAR(v[1], expected, 1e-6) << px << "," << py;
      lit += expected > 0;
    }
  EXPECT_GT(lit, 400);
  EXPECT_EQ(r.spp, 1);
}

// A light from the right lights the right half only; a mirror-like GGX is brightest where the
// half vector of light and camera is the normal: at the normal halfway between them.
TEST(PointLight, LightFromTheSideAndTheHighlight) {
  RenderSettings s;
  s.width = s.height = 65;
  s.spp = 4;
  const Vec3<double> side{std::sqrt(0.5), 0, std::sqrt(0.5)};  // 45° to the right
  const RenderResult r = render_point_light(*load_brdf("ggx:alpha=0.05,f0=1"), side, s);
  int best = 0;
  for (int p = 0; p < s.width * s.height; ++p)
    if (r.image.rgb[3 * p] > r.image.rgb[3 * best]) best = p;
  // The normal at 22.5° to the right: x = sin(22.5°) in [-1.25, 1.25] across 65 pixels.
  const double x = std::sin(std::numbers::pi / 8);
  const int expected_px = int((x / 1.25 + 1) / 2 * s.width);
  EXPECT_NEAR(best % s.width, expected_px, 1);
  EXPECT_NEAR(best / s.width, s.height / 2, 1);
  EXPECT_EQ(r.image.rgb[3 * (32 * s.width + 3)], 0.0f);  // far left: the light is behind
  EXPECT_THROW(render_point_light(*load_brdf("lambert"), {0, 0, 2}, s), std::invalid_argument);
  EXPECT_THROW(render_point_light(*load_brdf("lambert"), {NAN, 0, 1}, s), std::invalid_argument);
}

// The point-light image keeps its time budget, checked at every pixel: an image of a sum of 300
// He lobes at 256² × 16 positions (about 15 s) with a budget of 0.2 s throws TimeBudgetExceeded
// soon after it; with no budget (0) or a budget it keeps, the image is the same.
TEST(PointLight, KeepsItsTimeBudget) {
  std::string he;
  for (int k = 0; k < 300; ++k) he += (k ? "+" : "") + std::string("he");
  const BrdfPtr heavy = load_brdf(he);
  RenderSettings s;
  s.width = s.height = 256;
  s.spp = 16;
  s.threads = 1;
  s.time_budget = 0.2;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_THROW(render_point_light(*heavy, {0, 0, 1}, s), TimeBudgetExceeded);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
#if defined(__SANITIZE_ADDRESS__)
  EXPECT_LT(seconds, 5.0);
#else
  EXPECT_LT(seconds, 1.0);
#endif
  RenderSettings small;
  small.width = small.height = 16;
  small.spp = 4;
  const BrdfPtr ggx = load_brdf("ggx:alpha=0.3");
  const RenderResult free = render_point_light(*ggx, {0, 0, 1}, small);
  small.time_budget = 60;
  EXPECT_EQ(render_point_light(*ggx, {0, 0, 1}, small).image.rgb, free.image.rgb);
}

}  // namespace
}  // namespace halfback::render
