// `halfback export-merl`: any BRDF tabulated at the MERL bin centres, as a MERL .binary file that
// every MERL reader accepts (io/merl.hpp, write_merl).
#include <fmt/format.h>

#include <string>

#include "command.hpp"
#include "halfback/formats/merl.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::cli {

namespace {

struct ExportMerlOptions {
  std::string brdf, output;
};

int run_export_merl(const ExportMerlOptions& o) {
  if (o.output == "-") throw UsageError("-o: export-merl writes a file, not standard output");
  AtomicFile probe(o.output);  // an unwritable destination fails before tabulating
  probe.discard();
  const BrdfPtr brdf = brdf_argument(o.brdf, "--brdf");
  const MerlData data = tabulate_merl(*brdf);
  write_merl(o.output, data);
  const auto missing = data.missing[0];
  fmt::print(stderr,
             "halfback export-merl: {} written ({} of {} bins that hold no valid pair or "
             "not finite, stored as -1)\n",
             o.output, missing, merl::kBins);
  return kExitOk;
}

}  // namespace

Command register_export_merl(CLI::App& parent) {
  auto o = std::make_shared<ExportMerlOptions>();
  CLI::App* app = parent.add_subcommand(
      "export-merl", "Tabulate a BRDF into a MERL .binary file (90 x 90 x 180 bins, RGB)");
  app->add_option("--brdf", o->brdf, "BRDF SPEC: a file or a model such as ggx:alpha=0.2")
      ->required();
  app->add_option("-o,--output", o->output, "Output .binary file, replaced only on success")
      ->required()
      ->type_name("FILE");
  app->footer(
      "Each bin holds rho at its centre in MERL's stored coordinates (theta_h = ((i+1/2)/90)^2\n"
      "pi/2, theta_d = (j+1/2)/90 pi/2, phi_d = (k+1/2)/180 pi, phi_h = 0) divided by the\n"
      "channel's scale; reading the file back gives rho at the bin centres. Bins whose centre\n"
      "puts a direction below the horizon are written as -1 (unmeasured), as MERL does.\n"
      "\n"
      "Example:\n"
      "  halfback export-merl --brdf ggx:alpha=0.1,f0=0.9 -o ggx.binary");
  return {app, [o] { return run_export_merl(*o); }};
}

}  // namespace halfback::cli
