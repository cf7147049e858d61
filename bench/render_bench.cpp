// halfback_render_bench: the renderer's speed and the efficiency of its sampling strategies
// (docs/performance.md, "Renderer"). Prints Markdown tables.
//
// 1. Time for a 512 × 512 sphere at 256 samples per pixel under the built-in sky, with 1 and all
//    threads, for an analytic GGX, a MERL-format table (a model tabulated by tabulate_merl, read
//    through MerlBrdf: the measured-data code path without a 35 MB download) and an RGL material
//    (the embedded metallic paint).
// 2. Error at equal time: for a glossy, a diffuse and a measured material, a 128 × 128 reference
//    at 4096 samples per pixel (MIS), then each strategy — MIS, BRDF sampling only, environment
//    sampling only — with the same time budget; relative RMSE over the sphere's pixels, scaled to
//    exactly the budget (RMSE ∝ 1/√time). The reference's own error (MIS at 4096 spp) is below
//    the MIS figure by √(4096/spp): a floor, not a bias, of the comparison.
// 3. Which parameterization the tabulated sampler of measured data should use: equal-time error of
//    MIS with the table in hybrid, halfdiff and spherical coordinates, for measured materials
//    and a tabulated glossy model (forced tabulation).
// 4. Throughput (the issue-16 target): pixel samples per second per core of CPU time (user + sys,
//    the process's CPU clock), set-up included (loading the environment and building its
//    sampling tables, the BRDF's sampler), for GGX and the RGL metallic file under uffizi.hdr from
//    ../shared/data (or $HALFBACK_SHARED_DIR/data). The same source builds against an older tree
//    (the API it uses is unchanged), so the baseline is that build, run alternately with this one
//    (docs/performance.md, "Renderer"). Options: --size N (512), --spp N (256), --threads N (1),
//    --material ggx|rgl|all, --repeat N, --hash (a hash of each image, to check that two builds
//    render bit-identical images).
// 5. The RGL file's sampling-interface calls as the renderer makes them (packets of 64 rows
//    sharing one ωo): CPU ns per row of sample_batch, pdf_batch and eval_batch (--repeat N;
//    --hash prints a hash of each call's outputs, to check that two builds compute the same bits).
// 6. Samplers compared (render/sampling_metric.hpp): the relative variance of the
//    one-sample albedo estimator over ωo, time per sample and efficiency against the cosine, for
//    each material's own sampler and the tabulated sampler in every parameterization at 64 KB,
//    1 MB and 16 MB of tables (--part 6; not in the default parts).
// 7. The table's size (the renderer's default): equal-time error of MIS with halfdiff's
//    table at 64 KB, 1 MB and the default size, and with cosine sampling, for measured materials
//    (RGL files and neural BRDFs) and a tabulated glossy model (--part 7; not by default).
// 8. The automatic choice of the BRDF sampler (docs/render.md "Choosing the BRDF sampler"): the
//    threshold per environment, the albedo-variance ratio the choice is made by (cosine's ÷
//    table's), and the error of MIS with the table, the cosine and the automatic choice at an
//    equal CPU time (set-up and choice counted; print_equal_cpu_time_error), for neural BRDFs of
//    the MERL and RGL databases (from ../shared/data; the embedded two without it), tabulated
//    GGX lobes and two near-delta lobes, under the built-in sky and studio and two of the shared
//    environments (--part 8; not by default).
// 9. The RGL files' own sampler (Dupuy & Jakob's VNDF warp, what render() uses for them) against
//    the table, the cosine and the automatic choice of the same data with the warp hidden, at
//    an equal CPU time (--part 9; not by default).
// --quick shrinks every part (for a smoke run); --part N runs part N only (parts 1-3 by default).
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "halfback/formats/merl.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/render/brdf_sampler.hpp"
#include "halfback/render/envmap.hpp"
#include "halfback/render/renderer.hpp"
#include "halfback/render/sampling_metric.hpp"
#include "support/test_brdfs.hpp"

namespace {

using namespace halfback;

struct Material {
  std::string label;
  BrdfPtr brdf;
};

double relative_rmse(const render::Image& a, const render::Image& ref) {
  // Over the pixels of the sphere (the orthographic view's unit disk, radius 1/1.25 of the half
  // height), where the estimate is not the background.
  double se = 0, sr = 0;
  const int w = ref.width, h = ref.height;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double px = (2 * (x + 0.5) / w - 1) * 1.25, py = (1 - 2 * (y + 0.5) / h) * 1.25;
      if (px * px + py * py > 0.95) continue;
      for (int c = 0; c < 3; ++c) {
        const double d = a.pixel(x, y)[c] - ref.pixel(x, y)[c];
        se += d * d;
        sr += double(ref.pixel(x, y)[c]) * ref.pixel(x, y)[c];
      }
    }
  return std::sqrt(se / sr);
}

// The reference image of part 2 and 3: MIS at many samples, another seed than the estimates.
render::Image reference_image(const Brdf& brdf, const render::EnvMap& env, bool quick) {
  render::RenderSettings ref;
  ref.width = ref.height = 128;
  ref.spp = quick ? 256 : 4096;
  ref.seed = 977;
  return render::render(brdf, env, ref).image;
}

// Settings of an estimate with a time budget (128 × 128, as many samples as the budget allows).
render::RenderSettings budgeted(double budget) {
  render::RenderSettings s;
  s.width = s.height = 128;
  s.spp = 1 << 20;
  s.time_budget = budget;
  return s;
}

// The budget stops after whole passes (1, 2, 4, ... samples), so the time used differs a little
// between runs: the error is scaled to the budget by RMSE ∝ 1/√time. Printed as a table cell.
void print_equal_time_error(const render::RenderResult& r, const render::Image& reference,
                            double budget) {
  const double e = relative_rmse(r.image, reference) * std::sqrt(r.seconds / budget);
  std::printf(" %d spp, %.4f |", r.spp, e);
}

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct ThroughputOptions {
  int size = 512, spp = 256, threads = 1, repeat = 1;
  bool hash = false;  // --hash: print each image's hash (builds whose renders must be equal)
  std::string material = "all";
};

// FNV-1a of an array's bytes: equal for bit-identical results.
template <class T>
std::uint64_t bytes_hash(const std::vector<T>& v) {
  std::uint64_t h = 14695981039346656037ull;
  const auto* p = reinterpret_cast<const unsigned char*>(v.data());
  for (std::size_t i = 0; i < v.size() * sizeof(T); ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}
std::uint64_t image_hash(const render::Image& image) {
  return bytes_hash(image.rgb);
}

std::string shared_data_dir() {
  const char* shared = std::getenv("HALFBACK_SHARED_DIR");  // as for the tests
  return (shared && *shared ? std::string(shared) : HALFBACK_SOURCE_DIR "/../shared") + "/data/";
}

// Part 4: one line per material and repetition: CPU seconds of the set-up and of the render,
// and pixel samples per CPU second.
void throughput(const ThroughputOptions& o) {
  const std::string data = shared_data_dir();
  const std::string env_file = data + "envmaps/uffizi.hdr";
  struct Timed {
    std::string key, spec;
  };
  const std::vector<Timed> all{{"ggx", "ggx:alpha=0.2,f0=0.9"},
                               {"rgl", data + "rgl/ilm_l3_37_metallic_rgb.bsdf"}};
  std::printf("| material | set-up CPU s | render CPU s | wall s | M samples/s per CPU s |\n");
  std::printf("|---|---|---|---|---|\n");
  for (int rep = 0; rep < o.repeat; ++rep)
    for (const Timed& m : all) {
      if (o.material != "all" && o.material != m.key) continue;
      const BrdfPtr brdf = load_brdf(m.spec);  // loading the file is not timed
      const double c0 = cpu_seconds();
      const auto w0 = std::chrono::steady_clock::now();
      const render::EnvMap env = render::EnvMap::load(env_file);
      render::RenderSettings s;
      s.width = s.height = o.size;
      s.spp = o.spp;
      s.threads = o.threads;
      const double c1 = cpu_seconds();
      const render::RenderResult r = render::render(*brdf, env, s);
      const double c2 = cpu_seconds();
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
      const double samples = double(o.size) * o.size * o.spp;
      std::printf("| %s | %.3f | %.2f | %.2f | %.2f |\n", m.key.c_str(), c1 - c0, c2 - c1, wall,
                  samples / (c2 - c0) * 1e-6);
      if (o.hash)
        std::printf("image hash %s: %016llx\n", m.key.c_str(),
                    static_cast<unsigned long long>(image_hash(r.image)));
      std::fflush(stdout);
    }
}

// Part 5: the RGL file's calls as the renderer makes them, in packets of 64 rows that share one
// ωo (one pixel's samples): CPU ns per row of sample_batch, pdf_batch and eval_batch, over 2^16
// rows at as many incidences, the numbers uniform (a fixed seed).
void rgl_calls(const ThroughputOptions& o) {
  const std::string file = shared_data_dir() + "rgl/ilm_l3_37_metallic_rgb.bsdf";
  const BrdfPtr brdf = load_brdf(file);
  constexpr std::size_t kPacket = 64, kRows = std::size_t(1) << 16;
  std::vector<Vec3<double>> wo(kRows);
  std::vector<double> u1(kRows), u2(kRows);
  std::uint64_t state = 12345;
  auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) * 0x1p-53;
  };
  for (std::size_t p = 0; p < kRows; p += kPacket) {
    const double z = 0.05 + 0.95 * next(), r = std::sqrt(1 - z * z), phi = 2 * 3.14159265 * next();
    for (std::size_t k = p; k < p + kPacket; ++k) wo[k] = {r * std::cos(phi), r * std::sin(phi), z};
  }
  for (std::size_t k = 0; k < kRows; ++k) u1[k] = next(), u2[k] = next();
  std::vector<BrdfSample> samples(kRows);
  std::vector<DirPair<double>> pairs(kRows);
  std::vector<double> pdfs(kRows);
  std::vector<Rgb> values(kRows);
  auto per_row = [&](auto body) {
    const double c0 = cpu_seconds();
    for (int rep = 0; rep < o.repeat; ++rep)
      for (std::size_t p = 0; p < kRows; p += kPacket) body(p);
    return (cpu_seconds() - c0) / (double(o.repeat) * kRows) * 1e9;
  };
  const double ns_sample = per_row([&](std::size_t p) {
    brdf->sample_batch(std::span(wo).subspan(p, kPacket), std::span(u1).subspan(p, kPacket),
                       std::span(u2).subspan(p, kPacket), std::span(samples).subspan(p, kPacket));
  });
  for (std::size_t k = 0; k < kRows; ++k)
    pairs[k] = {samples[k].pdf > 0 ? samples[k].wi : Vec3<double>{0, 0, 1}, wo[k]};
  const double ns_pdf = per_row([&](std::size_t p) {
    brdf->pdf_batch(std::span(pairs).subspan(p, kPacket), std::span(pdfs).subspan(p, kPacket));
  });
  const double ns_eval = per_row([&](std::size_t p) {
    brdf->eval_batch(std::span(pairs).subspan(p, kPacket), std::span(values).subspan(p, kPacket));
  });
  std::printf(
      "| call | CPU ns per row |\n|---|---|\n| sample_batch | %.1f |\n| pdf_batch | %.1f |\n"
      "| eval_batch | %.1f |\n",
      ns_sample, ns_pdf, ns_eval);
  if (o.hash)  // the calls' outputs (the image's float sums would hide differences of an ulp)
    std::printf("hashes: samples %016llx, pdfs %016llx, values %016llx\n",
                static_cast<unsigned long long>(bytes_hash(samples)),
                static_cast<unsigned long long>(bytes_hash(pdfs)),
                static_cast<unsigned long long>(bytes_hash(values)));
}

}  // namespace

// Part 6: every sampler of each material, at equal table memory.
void compare_samplers(bool quick) {
  const std::vector<std::string> specs{"ggx:alpha=0.08,f0=0.9", "embedded:ilm_l3_37_metallic",
                                       "embedded:acrylic_felt_green", "embedded:pink-felt"};
  const render::SamplingMetricOptions o{.samples = quick ? std::size_t(1024) : std::size_t(8192)};
  std::printf("## Samplers at equal table memory (relative variance of the albedo estimator)\n\n");
  std::printf(
      "| material | sampler | tables | relative variance | ns per sample | efficiency vs "
      "cosine |\n|---|---|---|---|---|---|\n");
  for (const std::string& spec : specs) {
    const BrdfPtr b = load_brdf(spec);
    const auto cosine = render::with_cosine_sampling(*b);
    const render::SamplingMeasure cos = render::measure_sampling(*b, *cosine, o);
    const auto row = [&](const std::string& sampler, const std::string& memory,
                         const render::SamplingMeasure& m) {
      std::printf("| %s | %s | %s | %.4g ± %.2g | %.0f | %.3g |\n", spec.c_str(), sampler.c_str(),
                  memory.c_str(), m.relative_variance, m.relative_variance_error,
                  1e9 * m.seconds_per_sample, render::relative_efficiency(m, cos));
    };
    row("cosine", "—", cos);
    if (b->has_importance_sampling())
      row("own: " + b->describe_sampling(), "—", render::measure_sampling(*b, *b, o));
    for (const std::size_t kb : {std::size_t(64), std::size_t(1024), std::size_t(16384)}) {
      if (quick && kb > 64) break;
      std::vector<std::string> charts;  // parameterizations sharing a chart share the sampler
      for (const Space p : parameterizations()) {
        const std::string chart(p.param().sampler_chart().name);
        if (std::find(charts.begin(), charts.end(), chart) != charts.end()) continue;
        charts.push_back(chart);
        const render::TabulatedSampler t(*b, render::tabulation_for_memory(p, kb * 1024));
        row(std::string("tabulated ") + std::string(name_of(p)) + " (" + chart + ")",
            kb >= 1024 ? std::to_string(kb / 1024) + " MB" : std::to_string(kb) + " KB",
            render::measure_sampling(*b, t, o));
      }
    }
  }
  std::printf("\n");
}

void table_size_at_equal_time(bool quick) {
  const render::EnvMap sky = render::EnvMap::default_sky();
  const double budget = quick ? 0.2 : 2.0;
  const std::vector<Material> measured{
      {"RGL metallic paint", load_brdf("embedded:ilm_l3_37_metallic")},
      {"RGL felt", load_brdf("embedded:acrylic_felt_green")},
      {"neural felt (MERL pink-felt)", load_brdf("embedded:pink-felt")},
      {"neural gold-metallic-paint3", load_brdf("embedded:gold-metallic-paint3")},
      {"GGX α = 0.05, tabulated", load_brdf("ggx:alpha=0.05,f0=0.9")}};
  const render::TabulationOptions standard;  // the renderer's default
  std::printf(
      "\n## Tabulated sampler: size of halfdiff's table (MIS, %.1f s, 128 × 128, built-in sky; "
      "relative RMSE at equal time)\n\n| material | cosine | 64 KB | 1 MB | default (%d × %d × "
      "%d cells) |\n|---|---|---|---|---|\n",
      budget, standard.theta_slices, standard.radial, standard.azimuthal);
  for (const Material& m : measured) {
    const render::Image reference = reference_image(*m.brdf, sky, quick);
    std::printf("| %s |", m.label.c_str());
    render::RenderSettings s = budgeted(budget);
    print_equal_time_error(render::render_sampled(*render::with_cosine_sampling(*m.brdf), sky, s),
                           reference, budget);
    for (const std::size_t kb : {std::size_t(64), std::size_t(1024), std::size_t(0)}) {
      s.tabulation = kb ? render::tabulation_for_memory(space_of<HalfDiff>, kb * 1024) : standard;
      s.tabulation.param = space_of<HalfDiff>;
      const auto tabulated = render::with_importance_sampling(*m.brdf, s.tabulation, true);
      print_equal_time_error(render::render_sampled(*tabulated, sky, s), reference, budget);
    }
    std::printf("\n");
    std::fflush(stdout);
  }
}

using test::Opaque;

// The built-in sky and studio, and those of `shared` (files of ../shared/data/envmaps) when the
// shared data are there.
std::vector<std::pair<std::string, render::EnvMap>> environments(
    std::initializer_list<const char*> shared) {
  std::vector<std::pair<std::string, render::EnvMap>> envs;
  envs.emplace_back("sky", render::EnvMap::default_sky());
  envs.emplace_back("studio", render::EnvMap::from_spec("studio"));
  const std::string dir = shared_data_dir() + "envmaps/";
  for (const char* name : shared)
    if (std::filesystem::exists(dir + name))
      envs.emplace_back(name, render::EnvMap::from_spec(dir + name));
  return envs;
}

// Relative RMSE at an equal CPU time of `cpu_budget` seconds (the process's CPU clock, all
// threads): the BRDF's sampler as render() takes it under `choice` (set-up and choice timed),
// then `spp` pixel samples with it (timed); the error is scaled to the time the budget leaves
// after the set-up, RMSE ∝ 1/√time. Unlike a wall-clock budget, neither other processes on the
// machine nor the budget's whole passes (1, 2, 4, ... samples) move it. Printed as a table cell;
// returns the error and the sampler used.
std::pair<double, std::string> print_equal_cpu_time_error(const Brdf& brdf,
                                                          const render::EnvMap& env,
                                                          render::BrdfSampling choice,
                                                          const render::Image& reference,
                                                          double cpu_budget, int spp) {
  render::RenderSettings s;
  s.width = s.height = 128;
  s.spp = spp;
  s.brdf_sampling = choice;
  double t0 = cpu_seconds();
  const render::ChosenSampler chosen = render::choose_brdf_sampler(brdf, env, s);
  const double setup = cpu_seconds() - t0;
  t0 = cpu_seconds();
  const render::RenderResult r = render::render_sampled(*chosen.brdf, env, s);
  const double seconds = cpu_seconds() - t0;
  const double e = relative_rmse(r.image, reference) *
                   std::sqrt(seconds / std::max(cpu_budget - setup, 1e-3 * cpu_budget));
  std::printf(" %.4f |", e);
  return {e, chosen.brdf->describe_sampling()};
}

// The cells "| table | cosine | auto | chose | auto ÷ better |" of a row: `brdf` with each
// RenderSettings::brdf_sampling at equal CPU time, what auto chose, and its error over the
// better of table and cosine.
void print_choices(const Brdf& brdf, const render::EnvMap& env, const render::Image& reference,
                   double cpu_budget, int spp) {
  using render::BrdfSampling;
  const double table =
      print_equal_cpu_time_error(brdf, env, BrdfSampling::table, reference, cpu_budget, spp).first;
  const double cosine =
      print_equal_cpu_time_error(brdf, env, BrdfSampling::cosine, reference, cpu_budget, spp).first;
  const auto [automatic, sampler] =
      print_equal_cpu_time_error(brdf, env, BrdfSampling::automatic, reference, cpu_budget, spp);
  std::printf(" %s | %.2f |\n", sampler.find("cosine") == 0 ? "cosine" : "table",
              automatic / std::min(table, cosine));
  std::fflush(stdout);
}

// Part 8: table, cosine and the automatic choice at equal time, per material and environment.
void sampler_choice_at_equal_time(bool quick) {
  const double cpu_budget = quick ? 0.4 : 3.0;  // CPU seconds: 1.5 s on two cores
  const int spp = quick ? 16 : 256;
  const std::string data = shared_data_dir();
  const bool shared = std::filesystem::exists(data + "envmaps/grace.hdr");
  std::vector<Material> materials{
      {"neural pink-felt", load_brdf("embedded:pink-felt")},
      {"neural gold-metallic-paint3", load_brdf("embedded:gold-metallic-paint3")},
      {"GGX α = 0.05, tabulated", std::make_shared<Opaque>(load_brdf("ggx:alpha=0.05,f0=0.9"))},
      {"GGX α = 0.25, tabulated", std::make_shared<Opaque>(load_brdf("ggx:alpha=0.25,f0=0.9"))},
      {"Ward α = 0.001 (near-delta)", load_brdf("ward:roughness=0.001,albedo=1")},
      {"Blinn-Phong n = 10⁶ (near-delta)", load_brdf("blinn-phong:sharpness=1e6,albedo=1")}};
  const auto envs = environments({"grace.hdr", "uffizi.hdr"});
  if (shared) {
    // From broad to peaked; the middle ones (albedo ratios 330-1600) are where the environment
    // decides.
    for (const char* name :
         {"beige-fabric", "red-plastic", "light-red-paint", "teflon", "black-soft-plastic", "nylon",
          "dark-red-paint", "silver-paint", "white-acrylic", "blue-acrylic", "chrome"})
      materials.push_back(
          {std::string("neural ") + name, load_brdf(data + "nbrdf/merl_nbrdf/" + name + ".h5")});
    for (const char* name : {"acrylic_felt_green_rgb"})
      materials.push_back({std::string("neural RGL ") + name,
                           load_brdf(data + "nbrdf/rgl-isotropic_nbrdf/" + name + ".h5")});
  }
  std::printf(
      "\n## The threshold of the automatic choice per environment\n\n| environment | "
      "residual fraction | threshold |\n|---|---|---|\n");
  for (const auto& [env_name, env] : envs)
    std::printf("| %s | %.3f | %.0f |\n", env_name.c_str(), env.residual_fraction(),
                render::peaked_ratio(env));
  std::printf(
      "\n## The albedo-variance ratio of the automatic choice (cosine's ÷ table's)\n\n| "
      "material | ratio |\n|---|---|\n");
  for (const Material& m : materials)
    std::printf("| %s | %.3g |\n", m.label.c_str(),
                render::choose_brdf_sampler(*m.brdf, budgeted(1)).albedo_variance_ratio);
  std::printf(
      "\n## Choosing the BRDF sampler (MIS, 128 × 128, %d spp; relative RMSE at an equal CPU "
      "time of %.1f s, set-up and choice included)\n\n| material | environment | table | cosine "
      "| auto | auto chose | auto ÷ better |\n|---|---|---|---|---|---|---|\n",
      spp, cpu_budget);
  for (const auto& [env_name, env] : envs)
    for (const Material& m : materials) {
      const render::Image reference = reference_image(*m.brdf, env, quick);
      std::printf("| %s | %s |", m.label.c_str(), env_name.c_str());
      print_choices(*m.brdf, env, reference, cpu_budget, spp);
    }
}

// Part 9: the RGL files' own sampler (Dupuy & Jakob's VNDF warp) against the table, the cosine
// and the automatic choice of the same data with the warp hidden.
void rgl_warp_against_choice(bool quick) {
  const double cpu_budget = quick ? 0.4 : 3.0;  // CPU seconds: 1.5 s on two cores
  const int spp = quick ? 16 : 256;
  const std::string data = shared_data_dir();
  std::vector<Material> files{{"RGL metallic paint", load_brdf("embedded:ilm_l3_37_metallic")},
                              {"RGL felt", load_brdf("embedded:acrylic_felt_green")}};
  const auto envs = environments({"uffizi.hdr"});
  if (std::filesystem::exists(data + "rgl")) {
    for (const char* name : {"paper_white_rgb", "cc_ibiza_sunset_rgb", "irid_flake_paint2_rgb"})
      files.push_back({std::string("RGL ") + name, load_brdf(data + "rgl/" + name + ".bsdf")});
  }
  std::printf(
      "\n## RGL files: their VNDF warp against table, cosine and auto (MIS, 128 × 128, %d spp; "
      "relative RMSE at an equal CPU time of %.1f s)\n\n| material | environment | own warp | "
      "table | cosine | auto | auto chose | auto ÷ better |\n|---|---|---|---|---|---|---|---|\n",
      spp, cpu_budget);
  for (const auto& [env_name, env] : envs)
    for (const Material& m : files) {
      const render::Image reference = reference_image(*m.brdf, env, quick);
      std::printf("| %s | %s |", m.label.c_str(), env_name.c_str());
      print_equal_cpu_time_error(*m.brdf, env, render::BrdfSampling::automatic, reference,
                                 cpu_budget, spp);
      print_choices(Opaque(m.brdf), env, reference, cpu_budget, spp);
    }
}

int main(int argc, char** argv) {
  bool quick = false;
  int only = 0;
  ThroughputOptions tp;
  for (int i = 1; i < argc; ++i) {
    const bool more = i + 1 < argc;
    if (std::strcmp(argv[i], "--quick") == 0) quick = true;
    if (std::strcmp(argv[i], "--part") == 0 && more) only = std::atoi(argv[++i]);
    if (std::strcmp(argv[i], "--size") == 0 && more) tp.size = std::atoi(argv[++i]);
    if (std::strcmp(argv[i], "--spp") == 0 && more) tp.spp = std::atoi(argv[++i]);
    if (std::strcmp(argv[i], "--threads") == 0 && more) tp.threads = std::atoi(argv[++i]);
    if (std::strcmp(argv[i], "--repeat") == 0 && more) tp.repeat = std::atoi(argv[++i]);
    if (std::strcmp(argv[i], "--hash") == 0) tp.hash = true;
    if (std::strcmp(argv[i], "--material") == 0 && more) tp.material = argv[++i];
  }
  if (only == 4) {
    throughput(tp);
    return 0;
  }
  if (only == 5) {
    rgl_calls(tp);
    return 0;
  }
  if (only == 6) {
    compare_samplers(quick);
    return 0;
  }
  if (only == 7) {
    table_size_at_equal_time(quick);
    return 0;
  }
  if (only == 8) {
    sampler_choice_at_equal_time(quick);
    return 0;
  }
  if (only == 9) {
    rgl_warp_against_choice(quick);
    return 0;
  }
  const unsigned all = std::max(1u, std::thread::hardware_concurrency());
  const render::EnvMap sky = render::EnvMap::default_sky();

  const BrdfPtr ggx = load_brdf("ggx:alpha=0.2,f0=0.9");
  const auto merl = std::make_shared<MerlBrdf>(
      tabulate_merl(*load_brdf("lambert:albedo=0.3+ggx:alpha=0.15,f0=0.5")), MerlOptions{},
      "tabulated");
  const BrdfPtr rgl = load_brdf("embedded:ilm_l3_37_metallic");
  const std::vector<Material> timed{{"GGX α = 0.2 (analytic)", ggx},
                                    {"MERL table (Lambert + GGX, tabulated)", merl},
                                    {"RGL metallic paint (measured)", rgl}};

  if (only == 0 || only == 1) {
    std::printf("## Time for a %d × %d sphere at %d spp (built-in sky)\n\n", quick ? 128 : 512,
                quick ? 128 : 512, quick ? 16 : 256);
    std::printf(
        "| material | sampler | 1 thread | %u threads | sampler set-up |\n|---|---|---|---|---|\n",
        all);
    for (const Material& m : timed) {
      render::RenderSettings s;
      s.width = s.height = quick ? 128 : 512;
      s.spp = quick ? 16 : 256;
      double t[2] = {0, 0};
      render::RenderResult r;
      for (int k = 0; k < 2; ++k) {
        s.threads = k == 0 ? 1 : int(all);
        r = render::render(*m.brdf, sky, s);
        t[k] = r.seconds;
      }
      std::printf("| %s | %s | %.1f s | %.1f s | %.2f s |\n", m.label.c_str(), r.sampler.c_str(),
                  t[0], t[1], r.sampler_seconds);
      std::fflush(stdout);
    }
  }

  const double budget = quick ? 0.3 : 2.0;
  if (only == 0 || only == 2) {
    const std::vector<Material> compared{
        {"glossy: GGX α = 0.05", load_brdf("ggx:alpha=0.05,f0=0.9")},
        {"diffuse: Lambert 0.5", load_brdf("lambert:albedo=0.5")},
        {"measured: RGL metallic paint", rgl}};
    std::printf("\n## Error at equal time (%.1f s, 128 × 128, built-in sky, %u threads)\n\n",
                budget, all);
    std::printf(
        "| material | MIS: spp, rel. RMSE | BRDF only | environment only |\n|---|---|---|---|\n");
    for (const Material& m : compared) {
      const render::Image reference = reference_image(*m.brdf, sky, quick);
      std::printf("| %s |", m.label.c_str());
      for (render::Strategy st :
           {render::Strategy::mis, render::Strategy::brdf, render::Strategy::env}) {
        render::RenderSettings s = budgeted(budget);
        s.strategy = st;
        print_equal_time_error(render::render(*m.brdf, sky, s), reference, budget);
      }
      std::printf("\n");
      std::fflush(stdout);
    }
  }

  if (only == 0 || only == 3) {
    const std::vector<Material> measured{
        {"RGL metallic paint", rgl},
        {"RGL felt", load_brdf("embedded:acrylic_felt_green")},
        {"RGL wall paint", load_brdf("embedded:colodur_azure_4e")},
        {"neural felt (MERL network)", load_brdf("embedded:pink-felt")},
        {"GGX α = 0.05, tabulated", load_brdf("ggx:alpha=0.05,f0=0.9")}};
    std::printf(
        "\n## Tabulated sampler: parameterization of the table (MIS, %.1f s, 128 × 128, "
        "built-in sky; relative RMSE at equal time)\n\n",
        budget);
    std::printf("| material | hybrid | halfdiff | spherical |\n|---|---|---|---|\n");
    for (const Material& m : measured) {
      const render::Image reference = reference_image(*m.brdf, sky, quick);
      std::printf("| %s |", m.label.c_str());
      for (Space tp : {space_of<Hybrid>, space_of<HalfDiff>, space_of<Spherical>}) {
        render::RenderSettings s = budgeted(budget);
        s.tabulation.param = tp;
        const auto tabulated = render::with_importance_sampling(*m.brdf, s.tabulation, true);
        print_equal_time_error(render::render_sampled(*tabulated, sky, s), reference, budget);
      }
      std::printf("\n");
      std::fflush(stdout);
    }
  }
  return 0;
}
