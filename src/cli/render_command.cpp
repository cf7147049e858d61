// halfback render: a unit sphere of any BRDF under an environment map, direct lighting by
// multiple importance sampling (docs/render.md).

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "command.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/render/renderer.hpp"

namespace halfback::cli {

namespace {

struct RenderOptions {
  std::string brdf, env = "sky", output, strategy = "mis", heuristic = "power",
                    sampling = "halfdiff", brdf_sampling = "auto";
  int width = 512, height = 512, spp = 64, threads = 0;
  std::uint64_t seed = 1;
  double time_budget = 0, exposure = 0, env_rotation = 0, env_exposure = 0;
  bool filmic = false, perspective = false, quiet = false;
};

std::string lower_extension(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

int run_render(const RenderOptions& o) {
  const std::string ext = lower_extension(o.output);
  if (ext != ".png" && ext != ".exr")
    throw UsageError("the output must be a .png (tone-mapped sRGB) or .exr (linear) file: '" +
                     o.output + "'");
  if (static_cast<long long>(o.width) * o.height > render::kMaxRenderPixels)
    throw UsageError("--width, --height: " + render::pixel_limit_message(o.width, o.height));
  {
    // Fail before rendering when the destination cannot be written.
    AtomicFile probe(o.output);
    probe.discard();
  }
  render::RenderSettings s;
  s.width = o.width;
  s.height = o.height;
  s.spp = o.spp;
  s.seed = o.seed;
  s.time_budget = o.time_budget;
  s.threads = o.threads;
  s.projection = o.perspective ? render::Projection::perspective : render::Projection::orthographic;
  s.strategy = render::strategy_from_name(o.strategy).value();  // checked by the parser
  s.heuristic = o.heuristic == "balance" ? render::Heuristic::balance : render::Heuristic::power;
  s.tabulation.param = *space_from_name(o.sampling);  // checked by the parser
  s.brdf_sampling = render::brdf_sampling_from_name(o.brdf_sampling).value();  // checked too
  s.progress = !o.quiet;  // drawn only when stderr is a terminal

  const BrdfPtr brdf = brdf_argument(o.brdf, "--brdf");
  const render::EnvMap env = [&] {
    try {
      return render::EnvMap::from_spec(o.env, {o.env_rotation, o.env_exposure});
    } catch (...) {
      rethrow_environment_error("--env", o.env);
    }
  }();
  const render::RenderResult r = render::render(*brdf, env, s);
  if (r.nonfinite_pixels)
    throw std::runtime_error(
        std::to_string(r.nonfinite_pixels) + " of " +
        std::to_string(std::size_t(o.width) * o.height) +
        " pixels are infinite or NaN (the radiance overflows the image's float range, about "
        "3.4e38): lower --env-exposure or the environment's values; " +
        o.output + " was not written");
  render::write_image(o.output, r.image, {o.exposure, o.filmic});

  if (r.budget_exhausted)
    warn("render", "the time budget ran out after " + std::to_string(r.spp) + " of " +
                       std::to_string(o.spp) + " samples per pixel");
  if (r.nonfinite)
    warn("render",
         std::to_string(r.nonfinite) +
             " samples were NaN or infinite and were counted as 0 (those pixels are biased dark)");
  // One line, on a terminal or not: a script learns which BRDF sampler was used (with
  // --brdf-sampling auto: which one was chosen, and the measurement that chose it).
  if (!o.quiet)
    std::fprintf(stderr,
                 "halfback render: %s: %d x %d, %d spp, %.2f s (+%.2f s sampler set-up); BRDF "
                 "sampler: %s\n",
                 o.output.c_str(), o.width, o.height, r.spp, r.seconds, r.sampler_seconds,
                 r.sampler.c_str());
  return kExitOk;
}

}  // namespace

Command register_render(CLI::App& parent) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* app = parent.add_subcommand(
      "render",
      "Render a unit sphere of a BRDF under an environment map (direct lighting, multiple "
      "importance sampling of the environment and the BRDF)");
  app->add_option("--brdf", o->brdf,
                  "BRDF SPEC: a MERL, RGL or ALTA file, or a model such as ggx:alpha=0.2")
      ->required();
  app->add_option("--env", o->env,
                  "environment: a latitude-longitude .hdr or .exr file, constant:V, "
                  "constant:R,G,B, or a built-in: sky (a sky with a sun; \"default\" is its older "
                  "name), studio, sunset")
      ->capture_default_str();
  app->add_option("-o,--output", o->output, "output image: .exr (linear) or .png (sRGB)")
      ->required();
  app->add_option("--width", o->width, "image width in pixels")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  app->add_option("--height", o->height, "image height in pixels")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  app->add_option("--spp", o->spp, "samples per pixel (each: one environment + one BRDF sample)")
      ->check(CLI::Range(1, 1 << 24))
      ->capture_default_str();
  app->add_option("--seed", o->seed, "random seed (the image does not depend on --threads)")
      ->capture_default_str();
  app->add_option(
         "--time-budget", o->time_budget,
         "stop after about SEC seconds, sampler set-up included, keeping the finished passes "
         "(0: no limit; an error if not one sample per pixel fits)")
      ->check(CLI::Range(0.0, 1e9))
      ->capture_default_str();
  app->add_option("--exposure", o->exposure, "PNG exposure in stops, in [-64, 64]")
      ->check(CLI::Range(-64.0, 64.0))
      ->capture_default_str();
  app->add_flag("--filmic", o->filmic, "PNG: ACES filmic tone curve instead of a plain clamp");
  app->add_flag("--perspective", o->perspective, "perspective camera (default: orthographic)");
  app->add_option("--env-rotation", o->env_rotation,
                  "turn the environment about the up axis, in degrees")
      ->capture_default_str();
  app->add_option("--env-exposure", o->env_exposure, "scale the environment by 2^E")
      ->capture_default_str();
  app->add_option("--strategy", o->strategy, "mis, or one strategy alone: brdf or env")
      ->check(CLI::IsMember({"mis", "brdf", "env"}))
      ->capture_default_str();
  app->add_option("--heuristic", o->heuristic, "MIS weights: power or balance")
      ->check(CLI::IsMember({"power", "balance"}))
      ->capture_default_str();
  app->add_option("--param,--sampling-param", o->sampling,
                  "parameterization whose chart the tabulated sampler of measured BRDFs uses: " +
                      parameterization_names() + " (--sampling-param is an alias)")
      ->type_name("PARAM")
      ->check(parameterization_validator())
      ->capture_default_str();
  app->add_option("--brdf-sampling", o->brdf_sampling,
                  "how a BRDF without a sampler of its own is sampled: table (the tabulated "
                  "sampler), cosine, or auto: both samplers estimate the BRDF's directional "
                  "albedo (8 directions, 2048 samples each), and auto takes the table when the "
                  "cosine's estimate misses energy the table's finds, or when the ratio of the "
                  "two estimates' variances (cosine over table) is at least a threshold that "
                  "rises as the environment leaves less of its light to the BRDF sampler (150 "
                  "under a constant environment, 445 under sky, 1499 under studio); else the "
                  "cosine. E.g. embedded:pink-felt (a ratio of 30) gets the cosine and "
                  "embedded:gold-metallic-paint3 (7.6e3) the table under both; a ratio of 900 "
                  "gets the table under sky and the cosine under studio. The summary says which "
                  "and why (docs/render.md)")
      ->check(CLI::IsMember({"auto", "table", "cosine"}))
      ->capture_default_str();
  app->add_option("--threads", o->threads, "worker threads (0: all cores)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app->add_flag("-q,--quiet", o->quiet,
                "no progress bar, and no summary line on stderr (the image's size, samples, "
                "times and the BRDF sampler used: with auto, the one chosen and why)");
  app->footer(
      "Examples:\n"
      "  halfback render --brdf ggx:alpha=0.2,f0=0.9 -o ggx.png\n"
      "  halfback render --brdf embedded:gold-metallic-paint3 --env studio --spp 256 -o gold.exr\n"
      "  halfback render --brdf embedded:pink-felt --brdf-sampling cosine -o felt.png\n"
      "  halfback render --brdf merl.binary --env uffizi.hdr --brdf-sampling table --filmic \\\n"
      "      --time-budget 10 -o merl.png\n"
      "See docs/render.md.");
  return {app, [o] { return run_render(*o); }};
}

}  // namespace halfback::cli
