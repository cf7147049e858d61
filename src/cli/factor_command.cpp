// `halfback factor`: a data-driven factored model of a BRDF in a parameterization (fit/factor.hpp,
// docs/fit.md, "Factored models"), written as a file that every command reads.
#include <fmt/format.h>

#include <string>

#include "command.hpp"
#include "halfback/fit/factor.hpp"
#include "halfback/fit/fit.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::cli {

namespace {

struct FactorCommandOptions {
  std::string brdf, param = "hybrid", counts = "32,32,32", output;
  std::size_t rank = 2;
  int threads = 0;
};

int run_factor(const FactorCommandOptions& o) {
  if (o.output == "-") throw UsageError("-o: factor writes a file (its summary goes to stdout)");
  std::string message;
  const auto space = space_or_message(o.param, message);
  if (!space || space->is_dirs()) throw UsageError("--param: " + message);
  if (o.param.find(':') != std::string::npos)
    throw UsageError("--param '" + o.param +
                     "': a factored file names a built-in or registered parameterization, not a "
                     "family's member (reading it back would load another BRDF)");
  const std::vector<std::size_t> counts = count_list(o.counts, "--counts", "cell count");
  if (counts.size() != 3) throw UsageError("--counts: expected three cell counts (a, b, phi)");
  fit::FactorOptions options{
      .rank = o.rank, .counts = {counts[0], counts[1], counts[2]}, .threads = o.threads};
  const BrdfPtr target = brdf_argument(o.brdf, "--brdf");
  Output out(o.output);  // an unwritable destination fails before the work
  fit::FactorResult r;
  try {
    r = fit::factor_brdf(*target, *space, options);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  out.write(factored_text(r.model));
  const FactoredBrdf factored(r.model);
  const double ngan = fit::loss_of(*target, factored, fit::Loss::ngan, 20000, o.threads);
  out.commit();
  fmt::print(
      "{}: rank {}, {} numbers ({} bytes as float32), relative error {:.4g} in log(1 + rho) "
      "on its grid, ngan loss {:.6g} (halfback fit's, 20000 samples)\n",
      o.output, r.model.rank(), r.model.numbers(), 4 * r.model.numbers(), r.relative_error, ngan);
  return kExitOk;
}

}  // namespace

Command register_factor(CLI::App& parent) {
  auto o = std::make_shared<FactorCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "factor", "Fit a factored model (sum of separable terms) of a BRDF in a parameterization");
  app->add_option("--brdf", o->brdf, "BRDF SPEC to factor: a file or a model")->required();
  app->add_option("--param", o->param, "Parameterization whose isotropic coordinates separate")
      ->type_name("PARAM")
      ->check(parameterization_validator())
      ->capture_default_str();
  app->add_option("--rank", o->rank, "Separable terms per colour channel")
      ->check(CLI::Range(std::size_t{1}, std::size_t{64}))
      ->capture_default_str();
  app->add_option("--counts", o->counts, "Cells of the axes a, b, phi, comma-separated")
      ->capture_default_str();
  app->add_option("--threads", o->threads, "worker threads (0: all cores)")
      ->check(CLI::NonNegativeNumber);
  app->add_option("-o,--output", o->output, "Output .json file, replaced only on success")
      ->required()
      ->type_name("FILE");
  app->footer(
      "The file is a BRDF that every command reads (info, eval, render, study, ...).\n"
      "\n"
      "Example:\n"
      "  halfback factor --brdf embedded:gold-metallic-paint3 --param halfdiff --rank 2 -o g.json");
  return {app, [o] { return run_factor(*o); }};
}

}  // namespace halfback::cli
