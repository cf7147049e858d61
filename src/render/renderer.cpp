#include "halfback/render/renderer.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <mutex>
#include <numbers>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>

#include "halfback/core/parallel.hpp"
#include "halfback/render/sampling_metric.hpp"
#include "sequence.hpp"

namespace halfback::render {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kOrthoHalfHeight = 1.25;
constexpr double kCameraDistance = 4.5, kPerspectiveFov = 30;
// tan(fov/2) of the perspective camera (sphere_point's tan_persp).
double perspective_tan() {
  return std::tan(0.5 * kPerspectiveFov * kPi / 180);
}
constexpr int kTile = 16;

using V3 = Vec3<double>;
using Clock = std::chrono::steady_clock;

V3 normalize(const V3& v) {
  const double inv = 1 / std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
  return {v.x * inv, v.y * inv, v.z * inv};
}
double dot(const V3& a, const V3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
struct Frame {
  V3 t, b, n;
  V3 to_local(const V3& w) const { return {dot(w, t), dot(w, b), dot(w, n)}; }
  V3 to_world(const V3& w) const {
    return {w.x * t.x + w.y * b.x + w.z * n.x, w.x * t.y + w.y * b.y + w.z * n.y,
            w.x * t.z + w.y * b.z + w.z * n.z};
  }
};

// t along the parallels (+y × n), b = n × t; at the poles, where +y × n vanishes, t = +x.
Frame shading_frame(const V3& n) {
  V3 t{n.z, 0, -n.x};
  const double l = std::sqrt(t.x * t.x + t.z * t.z), inv = 1 / l;
  t = l > 1e-12 ? V3{t.x * inv, 0, t.z * inv} : V3{1, 0, 0};
  return {t, cross(n, t), n};
}

// The sphere (unit radius, at the origin) under the camera ray through `ndc` (x right, y up,
// x scaled by the aspect): its normal n and the direction towards the camera wo, or false when
// the ray misses it. Orthographic: the view along −z, half-height kOrthoHalfHeight; perspective:
// from (0, 0, kCameraDistance) with tan(fov/2) = tan_persp. One camera for every render.
bool sphere_point(Projection projection, double ndc_x, double ndc_y, double tan_persp, V3& n,
                  V3& wo) {
  if (projection == Projection::orthographic) {
    const double x = ndc_x * kOrthoHalfHeight, y = ndc_y * kOrthoHalfHeight;
    const double r2 = x * x + y * y;
    if (r2 >= 1) return false;
    n = {x, y, std::sqrt(1 - r2)};
    wo = {0, 0, 1};
    return true;
  }
  const V3 d = normalize({ndc_x * tan_persp, ndc_y * tan_persp, -1});
  const V3 o{0, 0, kCameraDistance};
  const double b = dot(o, d), c = dot(o, o) - 1, disc = b * b - c;
  if (disc <= 0) return false;
  const double t = -b - std::sqrt(disc);
  n = normalize({o.x + t * d.x, o.y + t * d.y, o.z + t * d.z});
  wo = {-d.x, -d.y, -d.z};
  return true;
}

// The MIS weight over the strategy's density, w(a, b)/a, with one division: 1/(a + b) for the
// balance heuristic, a/(a² + b²) for the power heuristic (the ratio form where the squares
// would overflow or vanish), 1/a when the other density is 0.
double weight_over_pdf(Heuristic h, double a, double b) {
  if (!(b > 0)) return 1 / a;
  if (h == Heuristic::balance) return 1 / (a + b);
  const double d = a * a + b * b;
  if (d > 1e-300 && d < 1e300) return a / d;
  const double r = b / a;
  return 1 / ((1 + r * r) * a);
}

struct Accum {
  std::vector<double> rgb, y, y2;
  void reset(std::size_t n, bool variance) {
    rgb.assign(3 * n, 0.0);
    y.assign(variance ? n : 0, 0.0);
    y2.assign(variance ? n : 0, 0.0);
  }
};

class Progress {
 public:
  Progress(bool enabled, std::uint64_t total)
      : enabled_(enabled && isatty(fileno(stderr))), total_(total), start_(Clock::now()) {}
  ~Progress() {
    if (enabled_ && drawn_) std::fputc('\n', stderr);
  }
  void add(std::uint64_t n) {
    const std::uint64_t done = done_.fetch_add(n) + n;
    if (!enabled_) return;
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock) return;
    const auto now = Clock::now();
    if (drawn_ && done < total_ && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    drawn_ = true;
    const double f = total_ ? std::min(1.0, double(done) / double(total_)) : 1.0;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    constexpr int width = 40;
    const int filled = int(f * width);
    char bar[width + 1];
    for (int i = 0; i < width; ++i) bar[i] = i < filled ? '#' : '-';
    bar[width] = 0;
    const double eta = f > 0 ? elapsed * (1 - f) / f : 0;
    std::fprintf(stderr, "\rrender [%s] %5.1f%%  %.1f s, %.1f s left ", bar, 100 * f, elapsed, eta);
    std::fflush(stderr);
  }

 private:
  bool enabled_;
  std::uint64_t total_;
  std::atomic<std::uint64_t> done_{0};
  Clock::time_point start_, last_;
  std::mutex mutex_;
  bool drawn_ = false;
};

class Renderer {
 public:
  Renderer(const Brdf& brdf, const EnvMap& env, const RenderSettings& s)
      : brdf_(brdf),
        env_(env),
        s_(s),
        kind_(s.sequence == Sequence::sobol ? detail::SequenceKind::sobol
                                            : detail::SequenceKind::random),
        aspect_(double(s.width) / s.height),
        two_over_width_(2.0 / s.width),
        two_over_height_(2.0 / s.height),
        tan_bg_(std::tan(0.5 * s.background_fov_deg * kPi / 180)),
        tan_persp_(perspective_tan()) {
    for (std::uint32_t d = 0; d < kPairs; ++d) keys_[d] = detail::dimension_key(s.seed, d);
  }

  // The sequences of one pixel: the pixel position, then two light samples.
  static constexpr std::uint32_t kPairs = 3;
  struct PixelSequences {
    detail::PixelPair pair[kPairs];
  };
  PixelSequences sequences(std::uint64_t pixel) const {
    PixelSequences q;
    for (std::uint32_t d = 0; d < kPairs; ++d)
      q.pair[d] = detail::PixelPair(kind_, keys_[d], pixel);
    return q;
  }

  // Up to kPacket consecutive samples of one pixel, rendered stage by stage (the camera, then each
  // light sample for the whole packet): the BRDF is evaluated in batches (Brdf::eval_batch) and
  // the lookups of different samples, independent, overlap. Each sample's sum adds the same terms
  // in the same order as one sample at a time would (docs/render.md, "Speed"). 64 rather than 16:
  // fewer calls per sample into the BRDF's batches (RGL's run the batch engine's conversions).
  static constexpr int kPacket = 64;
  // The light samples of one stage that reach the BRDF: the sample, the pair, the radiance, the
  // pdf of the strategy that drew it and the other's (MIS).
  struct Batch {
    int size = 0;
    int sample[kPacket];
    DirPair<double> pair[kPacket];
    Rgb li[kPacket], fr[kPacket];
    double pdf[kPacket], other_pdf[kPacket];
  };

  // The light samples of one stage before the BRDF: numbers, then environment samples, or BRDF
  // samples and the environment's radiance and pdf in their directions.
  struct Stage {
    int size = 0;
    int sample[kPacket];
    double u1[kPacket], u2[kPacket];
    V3 wo[kPacket];
    EnvMap::Sample env[kPacket];
    BrdfSample brdf[kPacket];
    V3 dir[kPacket];
    EnvMap::Lookup light[kPacket];
  };
  struct Packet {
    int size = 0;
    std::uint32_t first = 0;
    std::uint32_t reversed[kPacket];  // reverse_bits of each sample's index (the sequences')
    Rgb sum[kPacket];
    bool shaded[kPacket];  // on the sphere, seen from above its surface
    Frame frame[kPacket];
    V3 wo[kPacket];  // in the shading frame
    Stage stage;     // scratch of the stages
    Batch batch;
  };
  // The camera ray of each sample: the background's radiance, or the shading frame on the sphere.
  // The background samples' radiance in one EnvMap::eval call (the lookups overlap).
  void camera(int px, int py, const PixelSequences& q, Packet& p) const {
    Stage& bg = p.stage;  // the background's directions, before the stages use it
    bg.size = 0;
    for (int k = 0; k < p.size; ++k) {
      p.sum[k] = Rgb{};
      p.shaded[k] = false;
      double jx, jy;
      const std::uint32_t index = p.first + std::uint32_t(k);
      p.reversed[k] = detail::reverse_bits(index);
      q.pair[0].point(index, p.reversed[k], jx, jy);
      const double ndc_x = ((px + jx) * two_over_width_ - 1) * aspect_;
      const double ndc_y = 1 - (py + jy) * two_over_height_;
      V3 n, wo;
      if (!sphere_point(s_.projection, ndc_x, ndc_y, tan_persp_, n, wo)) {
        // The background: the orthographic view shows it through a field of view of its own.
        const bool ortho = s_.projection == Projection::orthographic;
        const double t = ortho ? tan_bg_ : tan_persp_;
        bg.dir[bg.size] = normalize({ndc_x * t, ndc_y * t, -1});
        bg.sample[bg.size++] = k;
        continue;
      }
      p.frame[k] = shading_frame(n);
      p.wo[k] = p.frame[k].to_local(wo);
      p.shaded[k] = p.wo[k].z > 0;
    }
    if (bg.size == 0) return;
    Rgb radiance[kPacket];
    const auto n = std::size_t(bg.size);
    env_.eval(std::span(bg.dir, n), std::span(radiance, n));
    for (int i = 0; i < bg.size; ++i) p.sum[bg.sample[i]] = radiance[i];
  }

  // ρ of the batch's pairs, then each term fr · li · share · w · cos θi / pdf added to its sample.
  void add_batch(Batch& b, double share, Packet& p) const {
    if (b.size == 0) return;
    brdf_.eval_batch(std::span(b.pair, std::size_t(b.size)), std::span(b.fr, std::size_t(b.size)));
    const bool mis = s_.strategy == Strategy::mis;
    for (int j = 0; j < b.size; ++j) {
      const double w = mis ? weight_over_pdf(s_.heuristic, b.pdf[j], b.other_pdf[j]) : 1 / b.pdf[j];
      p.sum[b.sample[j]] += b.fr[j] * b.li[j] * (share * b.pair[j].wi.z * w);
    }
  }

  // One environment sample per shaded sample (pair `dim` of the sequence).
  void env_stage(const PixelSequences& q, std::uint32_t dim, double share, Packet& p) const {
    const bool mis = s_.strategy == Strategy::mis, comp = mis && s_.compensation;
    Batch& b = p.batch;
    Stage& st = p.stage;
    st.size = 0;
    for (int k = 0; k < p.size; ++k) {
      if (!p.shaded[k]) continue;
      q.pair[dim].point(p.first + std::uint32_t(k), p.reversed[k], st.u1[st.size], st.u2[st.size]);
      st.sample[st.size++] = k;
    }
    const auto n = std::size_t(st.size);
    env_.sample(std::span(st.u1, n), std::span(st.u2, n), comp, std::span(st.env, n));
    b.size = 0;
    for (int i = 0; i < st.size; ++i) {
      const EnvMap::Sample& es = st.env[i];
      const int k = st.sample[i];
      if (!(es.pdf > 0)) continue;
      const V3 wi = p.frame[k].to_local(es.dir);
      if (!(wi.z > 0)) continue;
      const int j = b.size++;
      b.sample[j] = k;
      b.pair[j] = {wi, p.wo[k]};
      b.li[j] = es.radiance;
      b.pdf[j] = es.pdf;
    }
    if (mis)
      brdf_.pdf_batch(std::span(b.pair, std::size_t(b.size)),
                      std::span(b.other_pdf, std::size_t(b.size)));
    add_batch(b, share, p);
  }

  // One BRDF sample per shaded sample (pair `dim` of the sequence).
  void brdf_stage(const PixelSequences& q, std::uint32_t dim, double share, Packet& p) const {
    Stage& st = p.stage;
    st.size = 0;
    for (int k = 0; k < p.size; ++k) {
      if (!p.shaded[k]) continue;
      q.pair[dim].point(p.first + std::uint32_t(k), p.reversed[k], st.u1[st.size], st.u2[st.size]);
      st.wo[st.size] = p.wo[k];
      st.sample[st.size++] = k;
    }
    brdf_.sample_batch(
        std::span(st.wo, std::size_t(st.size)), std::span(st.u1, std::size_t(st.size)),
        std::span(st.u2, std::size_t(st.size)), std::span(st.brdf, std::size_t(st.size)));
    int kept = 0;  // the samples with a direction, in order
    for (int i = 0; i < st.size; ++i) {
      const BrdfSample& bs = st.brdf[i];
      if (!(bs.pdf > 0 && bs.wi.z > 0)) continue;
      st.brdf[kept] = bs;
      st.dir[kept] = p.frame[st.sample[i]].to_world(bs.wi);
      st.sample[kept++] = st.sample[i];
    }
    st.size = kept;
    const auto n = std::size_t(st.size);
    env_.lookup(std::span(st.dir, n), s_.compensation, std::span(st.light, n));
    Batch& b = p.batch;
    b.size = 0;
    for (int i = 0; i < st.size; ++i) {
      const Rgb& li = st.light[i].radiance;
      if (li.r == 0 && li.g == 0 && li.b == 0) continue;
      const int j = b.size++, k = st.sample[i];
      b.sample[j] = k;
      b.pair[j] = {st.brdf[i].wi, p.wo[k]};
      b.li[j] = li;
      b.pdf[j] = st.brdf[i].pdf;
      b.other_pdf[j] = st.light[i].pdf;
    }
    add_batch(b, share, p);
  }

  // Orthographic view: whether every sample of pixel (px, py) shows the background in one and
  // the same map pixel, and then its radiance. The pixel's square lies outside the sphere's disk,
  // and the directions that bound it fall in one map pixel: its corners (a map column is a convex
  // wedge, and the directions of the square a convex set) and, when the square straddles the
  // vertical ndc_x = 0, the middles of its top and bottom edges (cos θ of a direction is monotonic
  // in ndc_y, and in |ndc_x| at fixed ndc_y, so its extremes over the square are among these).
  // Such a pixel's samples all get that radiance, as a lookup of each would give them, except
  // within rounding of a map pixel's edge (docs/render.md, "Speed").
  bool uniform_background(int px, int py, Rgb& radiance) const {
    if (s_.projection != Projection::orthographic) return false;
    const double x0 = (px * two_over_width_ - 1) * aspect_;
    const double x1 = ((px + 1) * two_over_width_ - 1) * aspect_;
    const double y0 = 1 - py * two_over_height_, y1 = 1 - (py + 1) * two_over_height_;
    const double cx = std::clamp(0.0, x0, x1) * kOrthoHalfHeight;
    const double cy = std::clamp(0.0, y1, y0) * kOrthoHalfHeight;
    if (cx * cx + cy * cy < 1 + 1e-9) return false;  // the disk, with a margin for rounding
    V3 d[6];
    int n = 0;
    for (double x : {x0, x1})
      for (double y : {y0, y1}) d[n++] = normalize({x * tan_bg_, y * tan_bg_, -1});
    if (x0 < 0 && x1 > 0)
      for (double y : {y0, y1}) d[n++] = normalize({0, y * tan_bg_, -1});
    return env_.uniform(std::span(d, std::size_t(n)), radiance);
  }

  void render_packet(int px, int py, const PixelSequences& q, Packet& p,
                     const Rgb* background) const {
    if (background) {  // every sample shows this background radiance
      for (int k = 0; k < p.size; ++k) p.sum[k] = *background;
      return;
    }
    camera(px, py, q, p);
    switch (s_.strategy) {
      case Strategy::mis:
        env_stage(q, 1, 1, p);
        brdf_stage(q, 2, 1, p);
        break;
      case Strategy::env:
        env_stage(q, 1, 0.5, p);
        env_stage(q, 2, 0.5, p);
        break;
      case Strategy::brdf:
        brdf_stage(q, 1, 0.5, p);
        brdf_stage(q, 2, 0.5, p);
        break;
    }
  }

  // Adds samples [first, first + count) of the pixels of one tile to `acc`.
  void tile(int tx, int ty, std::uint32_t first, std::uint32_t count, Accum& acc,
            std::atomic<std::uint64_t>& nonfinite) const {
    const int x1 = std::min(tx + kTile, s_.width), y1 = std::min(ty + kTile, s_.height);
    Packet packet;
    for (int py = ty; py < y1; ++py)
      for (int px = tx; px < x1; ++px) {
        const std::size_t p = std::size_t(py) * std::size_t(s_.width) + std::size_t(px);
        double r = 0, g = 0, b = 0, y = 0, y2 = 0;
        std::uint64_t bad = 0;
        Rgb radiance;
        const Rgb* background = uniform_background(px, py, radiance) ? &radiance : nullptr;
        const PixelSequences q = background ? PixelSequences{} : sequences(p);
        for (std::uint32_t i = first; i < first + count; i += kPacket) {
          packet.first = i;
          packet.size = int(std::min<std::uint32_t>(kPacket, first + count - i));
          render_packet(px, py, q, packet, background);
          for (int k = 0; k < packet.size; ++k) {
            const Rgb& v = packet.sum[k];
            if (!(std::isfinite(v.r) && std::isfinite(v.g) && std::isfinite(v.b))) {
              ++bad;
              continue;
            }
            r += v.r;
            g += v.g;
            b += v.b;
            const double l = v.luminance();
            y += l;
            y2 += l * l;
          }
        }
        acc.rgb[3 * p] += r;
        acc.rgb[3 * p + 1] += g;
        acc.rgb[3 * p + 2] += b;
        if (!acc.y.empty()) {
          acc.y[p] += y;
          acc.y2[p] += y2;
        }
        if (bad) nonfinite += bad;
      }
  }

 private:
  const Brdf& brdf_;
  const EnvMap& env_;
  const RenderSettings& s_;
  detail::SequenceKind kind_;
  double aspect_, two_over_width_, two_over_height_, tan_bg_, tan_persp_;
  std::uint64_t keys_[kPairs];
};

void validate(const RenderSettings& s) {
  if (s.width < 1 || s.height < 1 || s.width > kMaxRenderSide || s.height > kMaxRenderSide)
    throw std::invalid_argument("render: width and height must be in [1, 16384]");
  if (static_cast<long long>(s.width) * s.height > kMaxRenderPixels)
    throw std::invalid_argument("render: " + pixel_limit_message(s.width, s.height));
  if (s.spp < 1 || s.spp > kMaxRenderSpp)
    throw std::invalid_argument("render: samples per pixel must be in [1, 16777216]");
  if (!(s.time_budget >= 0) || !std::isfinite(s.time_budget))
    throw std::invalid_argument("render: the time budget must be >= 0 seconds");
  if (!(s.background_fov_deg > 0 && s.background_fov_deg < 179))
    throw std::invalid_argument("render: the background field of view must be in (0, 179) degrees");
  if (s.threads < 0) throw std::invalid_argument("render: threads must be >= 0");
}

}  // namespace

std::optional<Strategy> strategy_from_name(std::string_view name) {
  if (name == "mis") return Strategy::mis;
  if (name == "brdf") return Strategy::brdf;
  if (name == "env") return Strategy::env;
  return std::nullopt;
}

std::string pixel_limit_message(int width, int height) {
  return std::to_string(width) + " x " + std::to_string(height) + " = " +
         std::to_string(static_cast<long long>(width) * height) + " pixels is above the limit of " +
         std::to_string(kMaxRenderPixels) +
         " pixels (4096 x 4096; rendering keeps about 100 bytes per pixel)";
}

namespace {
RenderResult render_passes(const Brdf& brdf, const EnvMap& env, const RenderSettings& s,
                           Clock::time_point start);
}

std::optional<BrdfSampling> brdf_sampling_from_name(std::string_view name) {
  if (name == "auto") return BrdfSampling::automatic;
  if (name == "table") return BrdfSampling::table;
  if (name == "cosine") return BrdfSampling::cosine;
  return std::nullopt;
}

double relative_pixel_variance(const RenderResult& r, std::span<const std::uint8_t> mask) {
  if (r.variance.empty()) throw std::invalid_argument("relative_pixel_variance: no variance");
  double variance = 0, square = 0;
  for (std::size_t p = 0; p < r.variance.size(); ++p) {
    if (!mask.empty() && !mask[p]) continue;
    const float* rgb = &r.image.rgb[3 * p];
    const double mean = Rgb{rgb[0], rgb[1], rgb[2]}.luminance();
    variance += double(r.variance[p]) * r.spp;  // the mean's variance × spp: one sample's
    square += mean * mean;
  }
  return square > 0 ? variance / square : 0;
}

namespace {

// The directional albedo summed over the measured ωo, and the variance of that sum.
struct AlbedoSum {
  double value = 0, variance = 0;
};
AlbedoSum albedo_sum(const SamplingMeasure& m, std::size_t samples) {
  AlbedoSum a;
  for (const OutgoingEstimate& e : m.per_wo) {
    a.value += e.mean;
    a.variance += e.variance / double(samples);
  }
  return a;
}

// True when the table finds energy that the cosine's samples miss (a lobe narrower than the
// cosine's samples are dense, e.g. a near-delta one): the table's albedo estimate is above the
// cosine's by more than kMissedSigmas standard errors of the difference and by more than
// kMissedFraction of its value. Both estimators are unbiased, so a significant difference means
// the cosine has not sampled a peak yet (and its variance, measured by its own samples, does not
// show it); a gap of a few per cent is left to the variance ratio (a broad material's small
// peak, which a render's many more samples do reach: 1 of 151 neural BRDFs at 2 %).
constexpr double kMissedSigmas = 4, kMissedFraction = 0.1;
bool cosine_misses_energy(const AlbedoSum& table, const AlbedoSum& cosine) {
  const double gap = table.value - cosine.value;
  return gap > kMissedSigmas * std::sqrt(table.variance + cosine.variance) &&
         gap > kMissedFraction * table.value;
}

}  // namespace

double peaked_ratio(const EnvMap& env) {
  return kPeakedRatio /
         std::pow(std::max(env.residual_fraction(), kMinResidual), kResidualExponent);
}

ChosenSampler choose_brdf_sampler(const Brdf& brdf, const EnvMap& env, const RenderSettings& s) {
  TabulationOptions tab = s.tabulation;
  if (tab.threads == 0) tab.threads = s.threads;
  tab.time_budget = s.time_budget;  // the sampler's set-up counts against the budget
  if (brdf.has_importance_sampling()) return {with_importance_sampling(brdf, tab), ""};
  if (s.brdf_sampling == BrdfSampling::cosine) return {with_cosine_sampling(brdf), ""};
  auto table = with_importance_sampling(brdf, tab);
  if (s.brdf_sampling == BrdfSampling::table || s.strategy == Strategy::env) return {table, ""};
  auto cosine = with_cosine_sampling(brdf);
  const SamplingMetricOptions o{.samples = kChoiceSamples, .seed = s.seed};
  const SamplingMeasure m_table = measure_sampling(brdf, *table, o);
  const SamplingMeasure m_cosine = measure_sampling(brdf, *cosine, o);
  const AlbedoSum a_table = albedo_sum(m_table, o.samples);
  const AlbedoSum a_cosine = albedo_sum(m_cosine, o.samples);
  const double v_table = m_table.relative_variance, v_cosine = m_cosine.relative_variance;
  const double ratio = v_table > 0 ? v_cosine / v_table : 0;
  const double threshold = peaked_ratio(env);
  if (cosine_misses_energy(a_table, a_cosine))
    return {table,
            fmt::format(
                " (chosen: the table's albedo estimate, {:.3g}, is {:.1f} standard errors "
                "above the cosine's, {:.3g}: the cosine misses a peak)",
                a_table.value / double(m_table.per_wo.size()),
                (a_table.value - a_cosine.value) / std::sqrt(a_table.variance + a_cosine.variance),
                a_cosine.value / double(m_cosine.per_wo.size())),
            ratio, threshold};
  // A ratio that cannot be computed (a variance that is not finite) counts as peaked.
  const bool peaked = !(ratio < threshold);
  return {
      peaked ? table : cosine,
      fmt::format(" (chosen: the cosine's albedo variance is {:.3g} times the table's, {} "
                  "{:.3g}, the threshold for an environment that leaves {:.0f} % of its light "
                  "to the BRDF sampler)",
                  ratio, peaked ? "at least" : "below", threshold, 100 * env.residual_fraction()),
      ratio, threshold};
}

ChosenSampler choose_brdf_sampler(const Brdf& brdf, const RenderSettings& s) {
  static const EnvMap sky = EnvMap::default_sky();  // built once per process
  return choose_brdf_sampler(brdf, sky, s);
}

RenderResult render(const Brdf& brdf, const EnvMap& env, const RenderSettings& settings) {
  validate(settings);
  const auto start = Clock::now();
  const ChosenSampler chosen = choose_brdf_sampler(brdf, env, settings);
  const double build = std::chrono::duration<double>(Clock::now() - start).count();
  if (settings.time_budget > 0 && !(build < settings.time_budget))
    throw TimeBudgetExceeded("the time budget of " + format_seconds(settings.time_budget) +
                             " ran out while building the BRDF's sampler (" +
                             format_seconds(build) + ")");
  RenderResult r = render_passes(*chosen.brdf, env, settings, start);
  r.sampler_seconds = build;
  r.sampler += chosen.why;
  return r;
}

RenderResult render_sampled(const Brdf& brdf, const EnvMap& env, const RenderSettings& s) {
  validate(s);
  return render_passes(brdf, env, s, Clock::now());
}

RenderResult render_point_light(const Brdf& brdf, const Vec3<double>& light,
                                const RenderSettings& s) {
  validate(s);
  const double length = std::sqrt(dot(light, light));
  if (!std::isfinite(length) || std::abs(length - 1) > 1e-6)
    throw std::invalid_argument("render: the light's direction must be a finite unit vector");
  const auto start = Clock::now();
  const int k = std::max(1, int(std::sqrt(double(s.spp))));  // k × k positions in each pixel
  const double aspect = double(s.width) / s.height;
  const double tan_persp = perspective_tan();
  RenderResult r;
  r.image.width = s.width;
  r.image.height = s.height;
  r.image.rgb.assign(3 * std::size_t(s.width) * std::size_t(s.height), 0.0f);
  // The time budget ran out: checked at every pixel (a pixel of a sum of hundreds of costly terms
  // takes milliseconds; a row of them seconds).
  std::atomic<bool> out_of_time{false};
  const auto past_budget = [&] {
    return s.time_budget > 0 &&
           std::chrono::duration<double>(Clock::now() - start).count() > s.time_budget;
  };
  parallel_for(
      std::size_t(s.height), 1,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t py = begin; py < end && !out_of_time; ++py) {
          for (int px = 0; px < s.width; ++px) {
            if (past_budget()) {
              out_of_time = true;
              break;
            }
            Rgb sum;
            for (int j = 0; j < k; ++j)
              for (int i = 0; i < k; ++i) {
                const double ndc_x = ((px + (i + 0.5) / k) * 2.0 / s.width - 1) * aspect;
                const double ndc_y = 1 - (double(py) + (j + 0.5) / k) * 2.0 / s.height;
                V3 n, wo;
                if (!sphere_point(s.projection, ndc_x, ndc_y, tan_persp, n, wo)) continue;
                const Frame f = shading_frame(n);
                const DirPair<double> pair{f.to_local(light), f.to_local(wo)};
                if (!(pair.wi.z > 0 && pair.wo.z > 0)) continue;
                sum += brdf.eval(pair) * pair.wi.z;
              }
            float* out = &r.image.rgb[3 * (py * std::size_t(s.width) + std::size_t(px))];
            const double inv = 1.0 / (k * k);
            out[0] = float(sum.r * inv);
            out[1] = float(sum.g * inv);
            out[2] = float(sum.b * inv);
          }
        }
      },
      s.threads);
  if (out_of_time)
    throw TimeBudgetExceeded("the time budget of " + format_seconds(s.time_budget) +
                             " ran out before the point-light image was complete");
  for (std::size_t p = 0; p < r.image.rgb.size(); p += 3)
    r.nonfinite_pixels += !(std::isfinite(r.image.rgb[p]) && std::isfinite(r.image.rgb[p + 1]) &&
                            std::isfinite(r.image.rgb[p + 2]));
  r.spp = k * k;
  r.sampler = "none: a point light, evaluated";
  r.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return r;
}

namespace {

// The passes of a render whose time budget started at `start` (before the sampler's set-up).
RenderResult render_passes(const Brdf& brdf, const EnvMap& env, const RenderSettings& s,
                           Clock::time_point start) {
  const auto render_start = Clock::now();
  const Renderer renderer(brdf, env, s);
  const std::size_t pixels = std::size_t(s.width) * std::size_t(s.height);
  const int tiles_x = (s.width + kTile - 1) / kTile, tiles_y = (s.height + kTile - 1) / kTile;
  const int tiles = tiles_x * tiles_y;

  Accum total, pass;
  total.reset(pixels, s.variance);
  std::atomic<std::uint64_t> nonfinite{0};
  Progress progress(s.progress, std::uint64_t(pixels) * std::uint64_t(s.spp));
  bool exhausted = false;
  int done = 0;
  // Passes: the whole count at once without a budget; with one, passes of 1, 2, 4, ... pixel
  // samples (1, 3, 7, ... in all),
  // and a pass that the budget interrupts is dropped (every pixel keeps the same sample count).
  int pass_size = s.time_budget > 0 ? 1 : s.spp;
  while (done < s.spp) {
    const int count = std::min(pass_size, s.spp - done);
    pass.reset(pixels, s.variance);
    std::atomic<bool> abort{false};
    std::atomic<int> tiles_done{0};
    auto render_tiles = [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end && !abort; ++i) {
        // Checked at every tile, the first pass included: a pass over a large image is long.
        if (s.time_budget > 0 &&
            std::chrono::duration<double>(Clock::now() - start).count() > s.time_budget) {
          abort = true;
          return;
        }
        const int t = int(i), x0 = (t % tiles_x) * kTile, y0 = (t / tiles_x) * kTile;
        try {
          renderer.tile(x0, y0, std::uint32_t(done), std::uint32_t(count), pass, nonfinite);
        } catch (...) {
          abort = true;  // the other blocks stop at their next tile
          throw;
        }
        ++tiles_done;
        progress.add(std::uint64_t(std::min(kTile, s.width - x0)) *
                     std::uint64_t(std::min(kTile, s.height - y0)) * std::uint64_t(count));
      }
    };
    parallel_for(std::size_t(tiles), 1, render_tiles, s.threads);
    if (abort && done == 0)
      throw TimeBudgetExceeded("the time budget of " + format_seconds(s.time_budget) +
                               " ran out before every pixel had one sample (" +
                               std::to_string(tiles_done.load()) + " of " + std::to_string(tiles) +
                               " tiles of the first pass): raise the budget or lower the size");
    if (abort) {
      exhausted = true;
      break;
    }
    for (std::size_t i = 0; i < total.rgb.size(); ++i) total.rgb[i] += pass.rgb[i];
    for (std::size_t i = 0; i < total.y.size(); ++i) {
      total.y[i] += pass.y[i];
      total.y2[i] += pass.y2[i];
    }
    done += count;
    pass_size = std::min(2 * pass_size, 1 << 20);
    if (s.time_budget > 0 && done < s.spp &&
        std::chrono::duration<double>(Clock::now() - start).count() > s.time_budget) {
      exhausted = true;
      break;
    }
  }

  RenderResult r;
  r.spp = done;
  r.budget_exhausted = exhausted;
  r.nonfinite = nonfinite;
  r.sampler = brdf.describe_sampling();
  r.image.width = s.width;
  r.image.height = s.height;
  r.image.rgb.resize(3 * pixels);
  for (std::size_t i = 0; i < 3 * pixels; ++i) r.image.rgb[i] = float(total.rgb[i] / done);
  for (std::size_t p = 0; p < pixels; ++p) {
    const float* v = &r.image.rgb[3 * p];
    r.nonfinite_pixels += !(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]));
  }
  if (s.variance) {
    r.variance.resize(pixels);
    for (std::size_t i = 0; i < pixels; ++i) {
      const double m = total.y[i] / done;
      const double var =
          done > 1 ? std::max(0.0, total.y2[i] / done - m * m) * done / (done - 1) : 0.0;
      r.variance[i] = float(var / done);
    }
  }
  r.seconds = std::chrono::duration<double>(Clock::now() - render_start).count();
  return r;
}

}  // namespace

}  // namespace halfback::render
