// `halfback nbrdf train`: a neural BRDF (Sztrajman et al. 2021) trained from any BRDF
// (neural/train.hpp, docs/neural.md), written as the authors' .h5 + .json that every command
// reads.
#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "command.hpp"
#include "halfback/formats/nbrdf.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/neural/train.hpp"

namespace halfback::cli {

namespace {

struct NbrdfTrainCommandOptions {
  std::string brdf, output, param, hidden = "21,21", loss{kNbrdfLosses[0]};
  std::size_t samples = 640000, epochs = 100, batch = 512;
  double learning_rate = 5e-4, final_learning_rate = 0;
  std::size_t restarts = 1, restart_epochs = 5;
  std::uint64_t seed = 0;
  int threads = 0;
  bool quiet = false;
};

NbrdfTrainOptions train_options(const NbrdfTrainCommandOptions& o) {
  NbrdfTrainOptions options;
  options.param = o.param;
  options.hidden = count_list(o.hidden, "--hidden", "layer width");
  options.samples = o.samples;
  options.epochs = o.epochs;
  options.batch = o.batch;
  options.learning_rate = o.learning_rate;
  options.final_learning_rate = o.final_learning_rate;
  options.restarts = o.restarts;
  options.restart_epochs = o.restart_epochs;
  options.loss = o.loss;
  options.seed = o.seed;
  options.threads = o.threads;
  try {
    check_nbrdf_train_options(options);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  return options;
}

// "6-21-21-3".
std::string architecture(const NbrdfNetwork& network) {
  std::string s = std::to_string(network.layers.front().inputs);
  for (const NbrdfLayer& layer : network.layers) s += "-" + std::to_string(layer.outputs);
  return s;
}

int run_nbrdf_train(const NbrdfTrainCommandOptions& o) {
  if (o.output == "-") throw UsageError("-o: nbrdf train writes files (NAME.h5 and NAME.json)");
  const std::string json = nbrdf_json_path(o.output).string();
  if (json == o.output)
    throw UsageError("-o '" + o.output + "': name the weights file NAME.h5 (NAME.json is the " +
                     "model description written beside it)");
  NbrdfTrainOptions options = train_options(o);
  const BrdfPtr brdf = brdf_argument(o.brdf, "--brdf");
  check_writable(o.output);  // both destinations fail before the training, not after
  check_writable(json);
  if (!o.quiet && isatty(fileno(stderr)))
    options.progress = [](const NbrdfTrainProgress& p) {
      fmt::print(stderr, "\repoch {}/{}  loss {:.6f}  {:.1f} s{}", p.epoch, p.epochs, p.loss,
                 p.seconds, p.epoch == p.epochs ? "\n" : "");
      std::fflush(stderr);
    };
  NbrdfTrainResult r;
  try {
    r = train_nbrdf(*brdf, options);
  } catch (const std::domain_error& e) {
    throw std::runtime_error(std::string(e.what()) + " (nothing written)");
  }
  write_nbrdf(o.output, r.network, nbrdf_train_notes(*brdf, options, r));
  fmt::print(
      "{} and {}: a {} network of {} from {} of {} pairs, {} epochs of batches of {} ({} steps, "
      "{:.3f} ms per step, {:.1f} s), loss {:.6g}\n",
      o.output, json, architecture(r.network), brdf->name(), r.pairs, r.drawn, options.epochs,
      options.batch, r.steps, 1e3 * r.seconds / double(r.steps), r.seconds, r.loss);
  return kExitOk;
}

Command add_train(CLI::App& parent) {
  auto o = std::make_shared<NbrdfTrainCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "train", "Train a neural BRDF (Sztrajman et al. 2021) on a BRDF; write NAME.h5 + NAME.json");
  app->add_option("--brdf", o->brdf, "BRDF SPEC to learn: a file or a model")->required();
  app->add_option("-o,--output", o->output,
                  "Output weights NAME.h5 (NAME.json beside it), replaced only on success")
      ->required()
      ->type_name("FILE");
  app->add_option("--param", o->param,
                  "Input: a built-in parameterization's isotropic coordinates instead of the "
                  "authors' (sin theta_h, 0, cos theta_h, d)")
      ->type_name("PARAM");
  app->add_option("--hidden", o->hidden, "Hidden layer widths, comma-separated (1-64 units)")
      ->capture_default_str();
  app->add_option("--samples", o->samples, "Pairs drawn (as --loss draws them)")
      ->capture_default_str();
  app->add_option("--epochs", o->epochs, "Passes over the pairs")->capture_default_str();
  app->add_option("--batch", o->batch, "Pairs per Adam step")->capture_default_str();
  app->add_option("--learning-rate", o->learning_rate, "Adam's learning rate")
      ->capture_default_str();
  app->add_option("--final-learning-rate", o->final_learning_rate,
                  "Learning rate of the last epoch, reached geometrically (0: constant)")
      ->capture_default_str();
  app->add_option("--restarts", o->restarts,
                  "Networks started; the lowest loss after --restart-epochs goes on (1-64)")
      ->capture_default_str();
  app->add_option("--restart-epochs", o->restart_epochs, "Epochs of each restart before the choice")
      ->capture_default_str();
  app->add_option(
         "--loss", o->loss,
         "sztrajman: the authors' (pairs uniform in theta_h, theta_d, phi_d; mean of "
         "|ln(1 + rho' cos) - ln(1 + rho cos)| over the channels); study-log: the study's "
         "log measure (half the pairs from cos_i cos_o dw_i dw_o, half the authors', weighted to "
         "the former; weighted mean of "
         "(ln(1 + Y') - ln(1 + Y))^2 + 1/3 sum_k (ln(1 + rho'_k) - ln(1 + rho_k))^2, Y "
         "the luminance)")
      ->capture_default_str()
      ->type_name("LOSS");
  app->add_option("--seed", o->seed, "Seed of the pairs, initial weights and shuffles")
      ->capture_default_str();
  app->add_option("--threads", o->threads, "worker threads (0: all cores; same result for any)")
      ->check(CLI::NonNegativeNumber);
  app->add_flag("-q,--quiet", o->quiet, "No progress on the terminal");
  app->footer(
      "The defaults are the authors' (docs/neural.md): 6-21-21-3, ReLU, rho = exp(y) - 1, their\n"
      "loss |log(1 + rho' cos) - log(1 + rho cos)|, Adam 5e-4, 100 epochs of 512.\n"
      "The result is a BRDF that every command reads (info, eval, render, study, fit, ...).\n"
      "\n"
      "Example:\n"
      "  halfback nbrdf train --brdf ../shared/data/rgl/cardboard_rgb.bsdf -o cardboard.h5");
  return {app, [o] { return run_nbrdf_train(*o); },
          [o] { return std::vector<std::string>{nbrdf_json_path(o->output).string()}; }};
}

}  // namespace

Command register_nbrdf(CLI::App& parent) {
  CLI::App* app = parent.add_subcommand("nbrdf", "Neural BRDFs (Sztrajman et al. 2021): train");
  app->require_subcommand(1, 1);
  const Command train = add_train(*app);
  return {app, [=] { return train.run(); }, train.more_outputs};
}

}  // namespace halfback::cli
