// `halfback figure`: the figures of Barla et al. 2015 (docs/figures.md).
//
//   halfback figure hemisphere  Figure 1: ωi over the hemisphere for fixed ωo, coloured by the
//                               pair's coordinates
//   halfback figure slices      Figure 2: slices of the isotropic forms, with the test functions
//                               S, G, F as isolines, or any BRDF in false colour
//   halfback figure paper       Figures 1 and 2 on their defaults, PNG + SVG + PDF, into a folder
//
// All the work is in the library (include/halfback/figure/); this file parses options. Every
// file is written atomically (the library's save(), through AtomicFile): an unwritable
// destination fails before any drawing, and no partial file is left behind.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "command.hpp"
#include "halfback/brdf/test_functions.hpp"
#include "halfback/core/space.hpp"
#include "halfback/figure/hemisphere.hpp"
#include "halfback/figure/material.hpp"
#include "halfback/figure/paper.hpp"
#include "halfback/figure/render.hpp"
#include "halfback/figure/slices.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/render/envmap.hpp"
#include "halfback/util/atomic_file.hpp"

namespace halfback::cli {

namespace {

using figure::Format;

// Lists are taken as one comma-separated string each and split here, so that an empty list or a
// bad item gets a message naming the option.
struct HemisphereArgs {
  std::string params = "halfdiff,ortho,hybrid";
  std::string elevations = "0,40,80";
  std::string projection = "equal-area";
  std::string centre = "normal";
  double scale = 2;
  bool no_markers = false, no_isolines = false;
  int threads = 0;
  std::string out = "hemisphere.png";
};

struct SliceArgs {
  std::string brdf = "test:S,G,F";
  std::string params = "halfdiff,ortho,hybrid";
  std::string azimuths = "0,45,90";
  std::string levels = "0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9";
  std::string colour = "rgb";
  double scale = 2;
  int threads = 0;
  std::string out = "slices.png";
};

struct PaperArgs {
  std::string out;
  std::string formats = "png,svg,pdf";
  std::vector<std::string> materials;  // replace the default Figures 3-5
  std::string merl_dir;                // every MERL file in it: Figures 3, 4, 5...
  std::string envs = "sky,studio,sunset";
  bool no_materials = false;
  int render_pixels = 176, spp = 48;
  int threads = 0;
};

struct MaterialArgs {
  std::string brdf, heading;
  std::string envs = "sky,studio,sunset";
  std::string params = "halfdiff,ortho,hybrid";
  std::string azimuths = "0,45,90";
  std::string colour = "rgb";
  int render_pixels = 176, spp = 48;
  double scale = 2;
  int threads = 0;
  std::string out = "material.png";
};

std::vector<Space> parameterization_list(const std::string& list) {
  std::vector<Space> spaces;
  for (const std::string& n : split_list(list, "--params", "parameterization")) {
    std::string problem;
    const auto s = space_or_message(n, problem);
    if (!problem.empty()) throw UsageError("--params " + problem);
    if (!s || *s == Space::dirs)
      throw UsageError(fmt::format("--params: unknown parameterization '{}' (expected {})", n,
                                   parameterization_names()));
    spaces.push_back(*s);
  }
  return spaces;
}

// The output's format, checked before any work.
void check_output(const std::string& out) {
  if (out.empty()) throw UsageError("--output: no file name given");
  if (!figure::format_from_path(out))
    throw UsageError(fmt::format(
        "--output '{}': cannot tell the figure format: use a .png, .svg or .pdf file name", out));
}

void check_scale(double scale) {
  if (!(scale >= 0.25 && scale <= 8))
    throw UsageError(fmt::format("--scale {}: must be between 0.25 and 8 pixels per point", scale));
}

void finish(const figure::Scene& scene, const std::string& out, double scale, double seconds) {
  figure::save(scene, out, {scale});
  fmt::print("wrote {} ({:.2f} s)\n", out, seconds);
}

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A figure whose options make it larger than an image can be: the command line's fault (status 2).
template <class Make>
auto built(Make&& make) {
  try {
    return make();
  } catch (const figure::FigureSizeError& e) {
    throw UsageError(e.what());
  }
}

int run_hemisphere(const HemisphereArgs& a) {
  check_output(a.out);
  check_scale(a.scale);
  figure::HemisphereOptions o;
  o.params = parameterization_list(a.params);
  o.elevations_deg = number_list(a.elevations, "--elevations", "elevation");
  for (double e : o.elevations_deg)
    if (!(e >= 0 && e <= 90))
      throw UsageError(fmt::format(
          "--elevations: {}° is outside [0°, 90°] (the polar angle θo of ωo from the normal)", e));
  const auto projection = figure::projection_from_name(a.projection);
  if (!projection)
    throw UsageError(fmt::format(
        "--projection: unknown projection '{}' (expected equal-area, orthographic or equidistant)",
        a.projection));
  o.projection = *projection;
  const auto centre = figure::view_centre_from_name(a.centre);
  if (!centre)
    throw UsageError(
        fmt::format("--centre: unknown centre '{}' (expected normal, mirror or back)", a.centre));
  o.centre = *centre;
  o.pixels_per_point = a.scale;
  o.markers = !a.no_markers;
  o.isolines = !a.no_isolines;
  o.threads = a.threads;
  check_writable(a.out);
  const auto t0 = std::chrono::steady_clock::now();
  // Figure 1 reads no data: whatever its options make impossible is the command line's fault.
  const auto fig = [&] {
    try {
      return figure::hemisphere_figure(o);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
  }();
  finish(fig.scene, a.out, a.scale, since(t0));
  return kExitOk;
}

int run_slices(const SliceArgs& a) {
  check_output(a.out);
  check_scale(a.scale);
  figure::SliceOptions o;
  o.params = parameterization_list(a.params);
  o.azimuths_deg = number_list(a.azimuths, "--azimuths", "azimuth");
  if (a.colour == "luminance")
    o.colouring = figure::SliceColouring::luminance;
  else if (a.colour == "rgb")
    o.colouring = figure::SliceColouring::rgb;
  else
    throw UsageError(
        fmt::format("--colour: unknown colouring '{}' (expected luminance or rgb)", a.colour));
  o.pixels_per_point = a.scale;
  o.threads = a.threads;

  // test:LIST of the paper's test functions (S, G, F, or their names) draws them as isolines;
  // anything else, "test:fn=G" included, is a BRDF for load_brdf(), drawn in colour.
  bool isolines = false;
  const std::string prefix = "test:";
  if (a.brdf.rfind(prefix, 0) == 0) {
    std::vector<TestFunction> fns;
    bool all = true;
    for (const std::string& name :
         split_list(a.brdf.substr(prefix.size()), "--brdf", "test function")) {
      const auto f = test_function_from_name(name);
      if (!f) all = false;
      if (f) fns.push_back(*f);
    }
    if (all) {
      isolines = true;
      o.test_functions = fns;
      o.levels = number_list(a.levels, "--levels", "level");
    }
  }
  check_writable(a.out);
  if (!isolines) o.brdf = brdf_argument(a.brdf, "--brdf");
  const auto t0 = std::chrono::steady_clock::now();
  const auto fig = built([&] { return figure::slice_figure(o); });
  finish(fig.scene, a.out, a.scale, since(t0));
  return kExitOk;
}

// The environments, each loaded (or built) once: a bad spec is a usage error naming it, an
// unreadable file a data error (as in `halfback render`).
std::vector<render::Environment> load_environments(const std::string& list) {
  std::vector<render::Environment> envs;
  for (const std::string& e : environment_list(list, "--env")) {
    try {
      envs.push_back(render::load_environment(e));
    } catch (...) {
      rethrow_environment_error("--env", e);
    }
  }
  return envs;
}

int run_material(const MaterialArgs& a) {
  check_scale(a.scale);
  figure::MaterialFigureOptions o;
  o.environments = load_environments(a.envs);
  o.slices.params = parameterization_list(a.params);
  o.slices.azimuths_deg = number_list(a.azimuths, "--azimuths", "azimuth");
  if (a.colour == "luminance")
    o.slices.colouring = figure::SliceColouring::luminance;
  else if (a.colour == "rgb")
    o.slices.colouring = figure::SliceColouring::rgb;
  else
    throw UsageError(fmt::format("--colour '{}': expected luminance or rgb", a.colour));
  o.slices.pixels_per_point = a.scale;
  o.slices.threads = a.threads;
  o.render_pixels = a.render_pixels;
  o.spp = a.spp;
  o.heading = a.heading;
  check_writable(a.out);
  o.brdf = brdf_argument(a.brdf, "--brdf");
  const auto t0 = std::chrono::steady_clock::now();
  const auto fig = built([&] { return figure::material_figure(o); });
  finish(fig.scene, a.out, a.scale, since(t0));
  return kExitOk;
}

int run_paper(const PaperArgs& a) {
  if (a.out.empty()) throw UsageError("--output: no folder given");
  figure::PaperFigureOptions o;
  o.png = o.svg = o.pdf = false;
  for (const std::string& f : split_list(a.formats, "--formats", "format")) {
    if (f == "png")
      o.png = true;
    else if (f == "svg")
      o.svg = true;
    else if (f == "pdf")
      o.pdf = true;
    else
      throw UsageError(fmt::format("--formats: unknown format '{}' (expected png, svg, pdf)", f));
  }
  o.threads = a.threads;
  o.environments = load_environments(a.envs);
  o.render_pixels = a.render_pixels;
  o.spp = a.spp;
  std::vector<std::string> specs = a.materials;
  if (!a.merl_dir.empty()) {
    // The MERL files of the folder (by content, whatever their names), in name order: give it
    // the paper's three materials to get its Figures 3-5.
    const auto found = brdf_files_in(a.merl_dir, BrdfFileFormat::merl);
    if (found.empty())
      throw UsageError(fmt::format("--merl-dir '{}': no MERL .binary file in it", a.merl_dir));
    for (const auto& f : found) specs.push_back(f.string());
  }
  if (a.no_materials) {
    if (!specs.empty()) throw UsageError("--no-materials contradicts --material and --merl-dir");
    o.materials.clear();
  } else if (!specs.empty()) {
    // Each SPEC must load before any figure is drawn.
    o.materials.clear();
    for (std::size_t k = 0; k < specs.size(); ++k) {
      const BrdfPtr b = brdf_argument(specs[k], "--material");
      std::string stem = fmt::format("fig{}-", 3 + k);
      for (const char c : b->name()) stem += std::isalnum(static_cast<unsigned char>(c)) ? c : '-';
      o.materials.push_back({stem, specs[k],
                             fmt::format("Figure {} ({}): {}", 3 + k, b->name(), b->description()),
                             b});
    }
  }
  const auto t0 = std::chrono::steady_clock::now();
  const auto written = figure::write_paper_figures(a.out, o);
  for (const auto& w : written) {
    fmt::print("{}:\n", w.description);
    for (const auto& p : w.files) fmt::print("  {}\n", p.string());
  }
  fmt::print(
      "{} files in {:.2f} s\n",
      [&] {
        std::size_t n = 0;
        for (const auto& w : written) n += w.files.size();
        return n;
      }(),
      since(t0));
  return kExitOk;
}

// One function per subcommand of `halfback figure`: its options, and what runs it.

Command add_hemisphere(CLI::App& figure) {
  auto hemi = std::make_shared<HemisphereArgs>();
  CLI::App* h = figure.add_subcommand(
      "hemisphere",
      "Figure 1: every incoming direction of the hemisphere for fixed outgoing directions, "
      "coloured by the pair's two non-azimuthal coordinates (red, green)");
  h->add_option("--params,--param", hemi->params,
                "Parameterizations, comma-separated, one row each (" +
                    parameterization_names(", ") + "; --param is an alias)")
      ->type_name("PARAM,...")
      ->capture_default_str();
  h->add_option("--elevations", hemi->elevations,
                "Polar angles θo of ωo from the normal, in degrees, one column each")
      ->capture_default_str();
  h->add_option("--projection", hemi->projection,
                "Disk projection: equal-area, orthographic or equidistant")
      ->capture_default_str();
  h->add_option("--centre", hemi->centre,
                "Disk centre: normal, mirror (the mirror direction of ωo) or back (ωo)")
      ->capture_default_str();
  h->add_option("--scale", hemi->scale, "Pixels per point of the PNG (and of the rasters)")
      ->capture_default_str();
  h->add_flag("--no-markers", hemi->no_markers, "Do not mark ωo and its mirror direction");
  h->add_flag("--no-isolines", hemi->no_isolines, "Colours only");
  h->add_option("--threads", hemi->threads,
                "Threads: 0 all cores, 1 the calling thread, n at most n")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  h->add_option("-o,--output,--out", hemi->out,
                "Output file: .png, .svg or .pdf (--out is an alias)")
      ->capture_default_str();
  return {h, [hemi] { return run_hemisphere(*hemi); }};
}

Command add_slices(CLI::App& figure) {
  auto sl = std::make_shared<SliceArgs>();
  CLI::App* s = figure.add_subcommand(
      "slices",
      "Figure 2: slices of the isotropic forms at fixed relative azimuths, with the test "
      "functions as isolines or any BRDF in false colour");
  s->add_option("--brdf", sl->brdf,
                "test:S,G,F (any of the paper's test functions, as isolines), or a BRDF: a "
                "file (MERL, RGL, ALTA) or a model spec such as ggx:alpha=0.2")
      ->capture_default_str();
  s->add_option("--params,--param", sl->params,
                "Parameterizations, comma-separated, one row each (" +
                    parameterization_names(", ") + "; --param is an alias)")
      ->type_name("PARAM,...")
      ->capture_default_str();
  s->add_option("--azimuths", sl->azimuths,
                "Relative azimuths in degrees (φd for halfdiff, φk − φh for ortho and hybrid), "
                "one column each")
      ->capture_default_str();
  s->add_option("--levels", sl->levels, "Isoline levels of the test functions")
      ->capture_default_str();
  s->add_option("--colour", sl->colour,
                "For a BRDF: rgb (tone-mapped) or luminance (viridis of log luminance)")
      ->capture_default_str();
  s->add_option("--scale", sl->scale, "Pixels per point of the PNG (and of the rasters)")
      ->capture_default_str();
  s->add_option("--threads", sl->threads, "Threads: 0 all cores, 1 the calling thread, n at most n")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  s->add_option("-o,--output,--out", sl->out, "Output file: .png, .svg or .pdf (--out is an alias)")
      ->capture_default_str();
  return {s, [sl] { return run_slices(*sl); }};
}

Command add_paper(CLI::App& figure) {
  auto pa = std::make_shared<PaperArgs>();
  CLI::App* p = figure.add_subcommand(
      "paper",
      "Figures 1 (three views), 2 and 3-5 (the paper's MERL materials as neural fits, then RGL "
      "measurements and analytic models) on their default settings, into a folder, and print "
      "where they are");
  p->add_option("-o,--output,--out", pa->out,
                "Output folder (created if missing; --out is an alias)")
      ->type_name("DIR")
      ->required();
  p->add_option("--formats", pa->formats, "Formats to write: png, svg, pdf")->capture_default_str();
  p->add_option("--material", pa->materials,
                "A BRDF SPEC for Figures 3, 4, 5... (repeatable; replaces the default measured "
                "and analytic materials)")
      ->take_all();
  p->add_option("--merl-dir", pa->merl_dir,
                "A folder of MERL .binary files (e.g. the paper's three materials): one figure "
                "each, in name order, instead of the default materials");
  p->add_flag("--no-materials", pa->no_materials, "Figures 1 and 2 only");
  p->add_option("--env", pa->envs,
                "Environments of the sphere renderings: default, studio, sunset, constant:V, "
                "constant:R,G,B or .hdr/.exr files, comma-separated")
      ->capture_default_str();
  p->add_option("--render-size", pa->render_pixels, "Pixels of each sphere rendering")
      ->check(CLI::Range(16, 2048))
      ->capture_default_str();
  p->add_option("--spp", pa->spp, "Samples per pixel of the renderings")
      ->check(CLI::Range(1, 1 << 16))
      ->capture_default_str();
  p->add_option("--threads", pa->threads, "Threads: 0 all cores, 1 the calling thread, n at most n")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  return {p, [pa] { return run_paper(*pa); }};
}

Command add_material(CLI::App& figure) {
  auto ma = std::make_shared<MaterialArgs>();
  CLI::App* m = figure.add_subcommand(
      "material",
      "Figures 3-5 for any BRDF: sphere renderings under environments, then its slices");
  m->add_option("--brdf", ma->brdf, "BRDF SPEC: a file (MERL, RGL, ALTA) or a model")->required();
  m->add_option("--title", ma->heading, "Figure title (default: the BRDF's name)");
  m->add_option("--env", ma->envs,
                "Environments: sky, studio, sunset, constant:V, constant:R,G,B or .hdr/.exr "
                "files, comma-separated")
      ->capture_default_str();
  m->add_option("--params,--param", ma->params,
                "Parameterizations, comma-separated, one row of slices each (" +
                    parameterization_names(", ") + "; --param is an alias)")
      ->type_name("PARAM,...")
      ->capture_default_str();
  m->add_option("--azimuths", ma->azimuths, "Relative azimuths of the slices, in degrees")
      ->capture_default_str();
  m->add_option("--colour", ma->colour, "Slices: rgb (tone-mapped) or luminance (viridis)")
      ->capture_default_str();
  m->add_option("--render-size", ma->render_pixels, "Pixels of each sphere rendering")
      ->check(CLI::Range(16, 2048))
      ->capture_default_str();
  m->add_option("--spp", ma->spp, "Samples per pixel of the renderings")
      ->check(CLI::Range(1, 1 << 16))
      ->capture_default_str();
  m->add_option("--scale", ma->scale, "Pixels per point of the PNG (and of the rasters)")
      ->capture_default_str();
  m->add_option("--threads", ma->threads, "Threads: 0 all cores, 1 the calling thread, n at most n")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  m->add_option("-o,--output,--out", ma->out, "Output file: .png, .svg or .pdf (--out is an alias)")
      ->capture_default_str();
  return {m, [ma] { return run_material(*ma); }};
}

}  // namespace

Command register_figure(CLI::App& parent) {
  CLI::App* app = parent.add_subcommand(
      "figure",
      "Draw the figures of Barla et al. 2015 (hemisphere views, slices, materials) as "
      "PNG/SVG/PDF");
  app->require_subcommand(1, 1);
  app->footer(
      "Examples:\n"
      "  halfback figure paper -o figures\n"
      "  halfback figure hemisphere --params halfdiff,hybrid --elevations 0,60 -o fig1.pdf\n"
      "  halfback figure slices --brdf test:S,G,F --azimuths 0,45,90 -o fig2.svg\n"
      "  halfback figure slices --brdf ggx:alpha=0.1 --colour luminance -o ggx.png\n"
      "  halfback figure material --brdf embedded:acrylic_felt_green --env studio -o felt.pdf\n"
      "See docs/figures.md.");
  // In the order of `halfback figure --help`.
  const Command hemisphere = add_hemisphere(*app), slices = add_slices(*app),
                paper = add_paper(*app), material = add_material(*app);
  return {app, [=]() -> int {
            for (const Command* c : {&hemisphere, &slices, &material})
              if (c->app->parsed()) return c->run();
            return paper.run();
          }};
}

}  // namespace halfback::cli
