// A unit sphere of any BRDF under an environment map: direct lighting only (the sphere is convex,
// so nothing else reaches it), estimated by multiple importance sampling of the environment and
// the BRDF (docs/render.md). The image is returned as an array; image.hpp writes it to files.
//
// Scene: the sphere of radius 1 at the origin; +y up, the camera on +z looking along −z (the
// world frame of envmap.hpp). Orthographic view: the image spans [−1.25, 1.25] vertically, and the
// background shows the environment as seen by a perspective camera of `background_fov_deg`.
// Perspective view: the camera at (0, 0, 4.5) with a vertical field of view of 30°.
// Shading frame at a point of normal n: t = normalize(+y × n) (along the parallels, +x at the
// front), b = n × t; directions are expressed in (t, b, n) before calling the BRDF, with ωi
// towards the light and ωo towards the camera.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/render/brdf_sampler.hpp"
#include "halfback/render/envmap.hpp"
#include "halfback/render/image.hpp"

namespace halfback::render {

enum class Projection { orthographic, perspective };
// mis: one environment and one BRDF sample per pixel sample, weighted by the heuristic;
// brdf, env: two samples of that strategy alone (the same number of light samples as mis).
enum class Strategy { mis, brdf, env };
// "mis", "brdf" or "env"; nullopt for another name.
std::optional<Strategy> strategy_from_name(std::string_view name);
enum class Heuristic { balance, power };
// How render() samples a BRDF that has no sampler of its own (docs/render.md, "Choosing the BRDF
// sampler"): its tabulated sampler (settings.tabulation), the cosine-weighted hemisphere, or
// (automatic) the one that suits the BRDF under the environment:
// - the table when the cosine misses energy: the table's directional-albedo estimate (summed
//   over the ωo of render::measure_sampling, kChoiceSamples each, the render's seed) is
//   significantly above the cosine's (a near-delta lobe the cosine's samples never reach);
// - else the table when the BRDF is peaked for this environment: the cosine's relative variance
//   of the albedo estimator is at least peaked_ratio(env) times the table's;
// - else the cosine.
// Equal-time renderings found the cosine better on broad lobes (its samples cost half as much,
// and scrambled Sobol points stay stratified through its smooth map) and the table on peaked
// ones, the crossing later the less of its light an environment leaves to the BRDF sampler
// (EnvMap::residual_fraction: a dark studio's lights are the environment sampler's). The choice
// depends on the BRDF, the environment and the settings only, not on timings, so the image stays
// a function of the settings. The env strategy (which draws no BRDF sample) keeps the table.
enum class BrdfSampling { automatic, table, cosine };
// "auto", "table" or "cosine"; nullopt for another name.
std::optional<BrdfSampling> brdf_sampling_from_name(std::string_view name);
// peaked_ratio(env) = kPeakedRatio / max(r, kMinResidual)^kResidualExponent, r =
// env.residual_fraction(): 150 under a constant environment, 445 under the built-in sky, 1490
// under the studio, 1060 under uffizi.hdr.
inline constexpr double kPeakedRatio = 150, kResidualExponent = 1.5, kMinResidual = 0.1;
double peaked_ratio(const EnvMap& env);
inline constexpr std::size_t kChoiceSamples = 2048;
enum class Sequence { sobol, random };  // scrambled Sobol (0,2) points per pixel, or independent

// The largest image: width × height pixels. Rendering keeps about 100 bytes per pixel (two
// double-precision accumulators, the variance sums and the float image), 1.6 GB at this limit.
inline constexpr long long kMaxRenderPixels = 1LL << 24;  // 4096 × 4096
inline constexpr int kMaxRenderSide = 16384;
inline constexpr int kMaxRenderSpp = 1 << 24;
// "W x H = N pixels is above the limit of ..." for a size above kMaxRenderPixels.
std::string pixel_limit_message(int width, int height);

struct RenderSettings {
  int width = 512, height = 512;
  int spp = 64;            // pixel samples
  std::uint64_t seed = 1;  // the image is a function of the seed (not of the thread count)
  // Seconds, 0: none. Counts the sampler's set-up; checked at every tile. The render stops after
  // the last pass that fits (>= 1 spp); when not even one sample per pixel fits, it throws
  // TimeBudgetExceeded.
  double time_budget = 0;
  Projection projection = Projection::orthographic;
  double background_fov_deg = 60;  // orthographic view: the background's field of view
  Strategy strategy = Strategy::mis;
  Heuristic heuristic = Heuristic::power;
  // MIS: sample the environment in proportion to its luminance above the mean (EnvMap::sample),
  // leaving the dim directions to the BRDF sampler.
  bool compensation = true;
  Sequence sequence = Sequence::sobol;
  int threads = 0;               // 0: all cores
  bool progress = false;         // a progress bar on stderr, only when stderr is a terminal
  bool variance = false;         // also return the per-pixel variance of the mean (luminance)
  TabulationOptions tabulation;  // for BRDFs without a sampler of their own
  BrdfSampling brdf_sampling = BrdfSampling::automatic;  // for the same
};

struct RenderResult {
  Image image;
  std::vector<float> variance;  // width × height when settings.variance, else empty
  int spp = 0;                  // pixel samples taken (fewer than asked if the budget ran out)
  double seconds = 0;           // rendering time, without building the BRDF sampler
  double sampler_seconds = 0;   // building the BRDF sampler (tabulation) and choosing it
  bool budget_exhausted = false;
  std::uint64_t nonfinite = 0;  // sample values that were NaN or infinite, counted as 0
  // Pixels with a channel that is not finite in the float image: the mean radiance overflows
  // the float range (about 3.4e38), e.g. an environment scaled far too high. Such an image is
  // not a picture of anything; the CLI refuses to write it.
  std::uint64_t nonfinite_pixels = 0;
  std::string sampler;  // which BRDF sampler was used (and why, when render() chose it)
};

// The BRDF as render() samples it under `env` and `settings` (brdf_sampling, tabulation, threads,
// the time budget of the table's build): the BRDF itself when it has a sampler of its own, else its
// table or the cosine; `why` is empty, or says what was measured when the choice was automatic. The
// BRDF must outlive the result. Throws TimeBudgetExceeded as render() does.
struct ChosenSampler {
  std::shared_ptr<const Brdf> brdf;
  std::string why;
  double albedo_variance_ratio = NAN;  // the cosine's ÷ the table's, when measured
  double threshold = NAN;              // peaked_ratio(env), when measured
};
ChosenSampler choose_brdf_sampler(const Brdf& brdf, const EnvMap& env,
                                  const RenderSettings& settings);
// The choice under the built-in sky (render's default environment), for a caller that has none.
ChosenSampler choose_brdf_sampler(const Brdf& brdf, const RenderSettings& settings);

// The image's relative variance per pixel sample, in luminance: Σ variance × spp / Σ mean² over
// the pixels (those whose `mask` entry is not 0 when `mask` is not empty): the expected squared
// relative RMSE of an image of one sample per pixel. 0 when the pixels are all black. Needs a
// result rendered with settings.variance.
double relative_pixel_variance(const RenderResult& result, std::span<const std::uint8_t> mask = {});

// Throws std::invalid_argument for invalid settings (sizes, spp, fov), TimeBudgetExceeded when the
// budget ends before every pixel has a sample.
RenderResult render(const Brdf& brdf, const EnvMap& env, const RenderSettings& settings);
// With the BRDF's sampling as it is (Brdf::sample, even the cosine default): e.g. a
// TabulatedSampler for a BRDF that has its own, or a BRDF rendered by environment sampling only.
RenderResult render_sampled(const Brdf& brdf, const EnvMap& env, const RenderSettings& settings);

// The sphere of render() under one distant light instead of the environment: irradiance 1 (at
// normal incidence) from the unit direction `light` in camera space (+z towards the camera, +x
// right, +y up; (0, 0, 1): from the camera). A pixel is the mean of ρ(ωi, ωo) cos θi over a
// stratified k × k grid of positions in it (k² = spp rounded down to a square): ωi the light, ωo
// the camera, in the shading frame of render(); 0 in the background and where the light or the
// camera is below the surface. No sampling: no noise. Uses width, height, spp, projection,
// threads and time_budget of `settings` (checked at every pixel: past it, TimeBudgetExceeded, no
// image); throws std::invalid_argument for invalid settings or light.
RenderResult render_point_light(const Brdf& brdf, const Vec3<double>& light,
                                const RenderSettings& settings);

}  // namespace halfback::render
