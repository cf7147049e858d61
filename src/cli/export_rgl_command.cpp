// `halfback export-rgl`: any isotropic BRDF as an RGL tensor file (formats/rgl_writer.hpp): the
// RGB variant (RGL's powitacq_rgb.h, Mitsuba 3's RGB variants), the spectral one (powitacq.h,
// pbrt-v4's `measured` material, Mitsuba 3's spectral variants), or both fields in one file.
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <string>

#include "command.hpp"
#include "halfback/formats/rgl_writer.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::cli {

namespace {

struct ExportRglOptions {
  std::string brdf, output, description, variant = "rgb", incidences = "albedo",
                                         tabulation = "average";
  RglExportOptions table;
  bool quiet = false;
};

const std::map<std::string, RglVariant> kVariants{
    {"rgb", RglVariant::rgb}, {"spectral", RglVariant::spectral}, {"both", RglVariant::both}};

const std::map<std::string, RglIncidences> kIncidences{{"albedo", RglIncidences::albedo},
                                                       {"sigma", RglIncidences::sigma}};
const std::map<std::string, RglTabulation> kTabulations{{"average", RglTabulation::hat_average},
                                                        {"point", RglTabulation::point}};

int run_export_rgl(ExportRglOptions& o) {
  o.table.variant = kVariants.at(o.variant);
  o.table.incidences = kIncidences.at(o.incidences);
  o.table.tabulation = kTabulations.at(o.tabulation);
  if (o.output == "-") throw UsageError("-o: export-rgl writes a file, not standard output");
  AtomicFile probe(o.output);  // an unwritable destination fails before the work
  probe.discard();
  const auto start = std::chrono::steady_clock::now();
  const BrdfPtr brdf = brdf_argument(o.brdf, "--brdf");
  o.table.description =
      o.description.empty()
          ? fmt::format("{} (exported by halfback export-rgl from '{}'; NDF by power iteration{})",
                        brdf->description(), o.brdf,
                        o.table.variant == RglVariant::rgb ? "" : "; spectra upsampled from RGB")
          : o.description;
  const bool terminal = !o.quiet && isatty(fileno(stderr));
  if (terminal)
    o.table.progress = [](int done, int total) {
      std::fprintf(stderr, "\rhalfback export-rgl: incidence slice %d of %d", done, total);
      std::fflush(stderr);
    };
  write_rgl(o.output, *brdf, o.table);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (terminal) std::fprintf(stderr, "\r\033[K");
  if (!o.quiet)
    fmt::print(stderr,
               "halfback export-rgl: {} written ({} variant, {} incidence elevations, {}x{} "
               "colour and luminance, {}x{} VNDF) in {:.2f} s\n",
               o.output, o.variant, o.table.theta_i, o.table.resolution, o.table.resolution,
               o.table.vndf_resolution, o.table.vndf_resolution, seconds);
  return kExitOk;
}

}  // namespace

Command register_export_rgl(CLI::App& parent) {
  auto o = std::make_shared<ExportRglOptions>();
  CLI::App* app = parent.add_subcommand(
      "export-rgl",
      "Write an isotropic BRDF as an RGL .bsdf tensor file (Dupuy & Jakob 2018; RGB or spectral "
      "variant: RGL's loaders, Mitsuba 3's and pbrt-v4's measured material read it)");
  app->add_option("--brdf", o->brdf, "BRDF SPEC: a file or a model such as ggx:alpha=0.2")
      ->required();
  app->add_option("-o,--output", o->output, "Output .bsdf file, replaced only on success")
      ->required()
      ->type_name("FILE");
  app->add_option("--theta-i", o->table.theta_i,
                  "incident elevations from 0 to 90 degrees, placed by --incidences")
      ->check(CLI::Range(2, 90))
      ->capture_default_str();
  app->add_option("--incidences", o->incidences,
                  "albedo: half of the elevations evenly spaced in projected area, the others "
                  "where the directional albedo needs them; sigma: all evenly spaced in projected "
                  "area (the published files' layout)")
      ->check(CLI::IsMember(kIncidences))
      ->capture_default_str();
  app->add_option("--tabulation", o->tabulation,
                  "average: a table node holds the average over its bilinear hat function, which "
                  "keeps the directional albedo; point: the value at the node (as measured)")
      ->check(CLI::IsMember(kTabulations))
      ->capture_default_str();
  app->add_option("--resolution", o->table.resolution,
                  "RGB and luminance samples per side, per incident elevation")
      ->check(CLI::Range(2, 512))
      ->capture_default_str();
  app->add_option("--vndf-resolution", o->table.vndf_resolution,
                  "VNDF table side; also the NDF and projected-area tables' length")
      ->check(CLI::Range(2, 1024))
      ->capture_default_str();
  app->add_option("--variant", o->variant,
                  "colour fields: rgb (3 channels), spectral (wavelengths and spectra, for pbrt-v4 "
                  "and Mitsuba 3's spectral variants) or both")
      ->check(CLI::IsMember(kVariants))
      ->capture_default_str();
  app->add_option("--description", o->description,
                  "the file's description field (default: the source and how it was made)");
  app->add_option("--threads", o->table.threads,
                  "Threads: 0 all cores, 1 the calling thread, n at most n")
      ->check(non_negative_integer())
      ->capture_default_str();
  app->add_flag("-q,--quiet", o->quiet, "no progress or summary on stderr");
  app->footer(
      "The microfacet distribution is recovered from the BRDF's backscattering by power\n"
      "iteration (Dupuy et al. 2015); the projected area, the visible-normal distributions and\n"
      "their warps follow from it, and the RGB and luminance tables hold rho sampled through the\n"
      "warp at each incident elevation. --theta-i 8 --incidences sigma --tabulation point\n"
      "writes the published RGL files' layout. The spectral\n"
      "variant holds, per table entry, a smooth spectrum (360-830 nm every 5 nm) whose RGB is\n"
      "the RGB table's (a sigmoid of a quadratic, Jakob & Hanika 2019). Isotropic BRDFs\n"
      "only; a BRDF that is NaN where sampled, or zero in every backscattering direction, is\n"
      "refused and nothing is written. docs/formats.md, \"RGL writer\".\n"
      "\n"
      "Example:\n"
      "  halfback export-rgl --brdf embedded:pink-felt -o pink-felt.bsdf\n"
      "  halfback export-rgl --brdf ggx:alpha=0.2 --variant spectral -o ggx-spectral.bsdf");
  return {app, [o] { return run_export_rgl(*o); }};
}

}  // namespace halfback::cli
