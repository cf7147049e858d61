// The `halfback` command-line tool: builds the CLI11 app from the command table (commands.cpp),
// parses, runs the selected command and turns every error into a message and an exit status
// (command.hpp). Nothing escapes as an uncaught exception.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "command.hpp"
#include "halfback/core/simd.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/util/signal_cleanup.hpp"

#ifndef HALFBACK_VERSION
#define HALFBACK_VERSION "unknown"
#endif

namespace halfback::cli {
namespace {

// What `halfback --help` says first: what the tool does, and every parameterization it knows
// (the built-in ones and the families), from the registry, in an aligned table.
std::string description() {
  std::string s =
      "halfback: the parameterizations of BRDF direction pairs (Barla et al. 2015) and the BRDF\n"
      "tools built on them: convert between directions and coordinates; inspect, evaluate,\n"
      "resample, export, fit and factor BRDFs (analytic models, MERL, RGL, ALTA, neural); plan "
      "and\n"
      "reconstruct measurements; compare the parameterizations (study); render, draw and explore\n"
      "BRDFs.\n\nParameterizations (the names of convert --from/--to and of every option that "
      "takes "
      "one):\n";
  std::vector<std::pair<std::string, std::string>> rows;
  for (Space p : parameterizations())
    rows.emplace_back(std::string(name_of(p)), std::string(p.param().summary()));
  for (const std::string& family : parameterization_families())
    rows.emplace_back(family, "a family: one parameterization per argument");
  std::size_t width = 0;
  for (const auto& row : rows) width = std::max(width, row.first.size());
  for (const auto& [name, summary] : rows) s += fmt::format("  {:<{}}  {}\n", name, width, summary);
  return s;
}

constexpr const char* kFooter =
    "Run 'halfback COMMAND --help' for the options and examples of a command.\n"
    "Exit status: 0 on success, 1 for bad input data or a file that cannot be read or written,\n"
    "2 for a bad command line. Errors are reported on stderr as 'halfback COMMAND: error: ...'.";

void report_error(const std::string& who, std::string_view message) {
  fmt::print(stderr, "{}: error: {}\n", who, message);
}

void usage_hint(const std::string& who) {
  fmt::print(stderr, "Run '{} --help' for more information.\n", who);
}

std::string command_names(const std::vector<Command>& commands) {
  std::string s;
  for (const Command& c : commands) s += (s.empty() ? "" : ", ") + c.app->get_name();
  return s;
}

// CLI11 says only "A subcommand is required" for "halfback figure" and "halfback figure bogus":
// name the word that is not a subcommand, and the ones there are.
std::string missing_subcommand_message(const CLI::App& parent, int argc, char** argv) {
  std::string names;
  for (const CLI::App* sub : parent.get_subcommands({}))
    names += (names.empty() ? "" : ", ") + sub->get_name();
  int at = 1;
  while (at < argc && argv[at] != parent.get_name()) ++at;
  for (++at; at < argc; ++at) {
    const std::string word = argv[at];
    if (!word.empty() && word.front() != '-')
      return fmt::format("'{}' is not a {} subcommand (the subcommands are: {})", word,
                         parent.get_name(), names);
  }
  return fmt::format("a subcommand is required (one of: {})", names);
}

// The command's deepest parsed subcommand (figure's hemisphere, ...), or the command's own app.
const CLI::App& parsed_app(const Command& command) {
  const CLI::App* app = command.app;
  while (!app->get_subcommands().empty()) app = app->get_subcommands().front();
  return *app;
}

int run_command(const std::string& who, const Command& command) {
  try {
    refuse_outputs_over_inputs(parsed_app(command), command.more_outputs
                                                        ? command.more_outputs()
                                                        : std::vector<std::string>{});
    return command.run();
  } catch (const UsageError& e) {
    report_error(who, e.what());
    usage_hint(who);
    return kExitUsageError;
  } catch (const std::bad_alloc&) {
    report_error(who, "out of memory");
  } catch (const std::exception& e) {
    report_error(who, e.what());
  } catch (...) {
    report_error(who, "unknown error");
  }
  return kExitDataError;
}

// The version, and the instruction set of the SIMD kernels (said with a HALFBACK_ISA that is not
// used, so that a misspelt or unsupported one is not silently ignored).
std::string version_text() {
  std::string text =
      fmt::format("halfback {}\nSIMD kernels: {}", HALFBACK_VERSION, simd_isa_name(simd_isa()));
  if (const std::string_view asked = simd_isa_request_ignored(); !asked.empty())
    text += fmt::format(
        " (HALFBACK_ISA={} not used: not one of scalar, sse2, avx2, avx512 that this CPU runs)",
        asked);
  return text;
}

// "halfback COMMAND SUBCOMMAND" of the deepest subcommand parsed so far; `deepest` is set to it.
std::string parsed_command_name(const CLI::App*& deepest) {
  std::string who = "halfback";
  while (!deepest->get_subcommands().empty()) {
    deepest = deepest->get_subcommands().front();
    who += " " + deepest->get_name();
  }
  return who;
}

int run(int argc, char** argv) {
  register_brdf_parameterization_families();
  CLI::App app(description(), "halfback");
  app.set_version_flag("--version", version_text,
                       "Print the version and the SIMD instruction set in use, and exit");
  app.set_help_flag("-h,--help", "Print this help and exit");
  app.require_subcommand(0, 1);
  app.footer(kFooter);
  app.get_formatter()->column_width(28);

  std::vector<Command> commands;
  for (RegisterCommand add : command_table()) commands.push_back(add(app));
  // Hidden: the command reference generated from the apps above (reference.cpp).
  std::string reference_format;
  app.add_option("--help-reference", reference_format,
                 "Print the command reference, man or markdown, and exit")
      ->group("");
  harden_options(app);  // one rule for every option's value (class G)

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    const CLI::App* deepest = &app;
    const std::string who = parsed_command_name(deepest);
    if (who == "halfback" && dynamic_cast<const CLI::ExtrasError*>(&e) && !app.remaining().empty())
      report_error(who, fmt::format("unknown command '{}' (the commands are: {})",
                                    app.remaining().front(), command_names(commands)));
    else if (dynamic_cast<const CLI::RequiredError*>(&e) && deepest != &app &&
             !deepest->get_subcommands({}).empty())
      report_error(who, missing_subcommand_message(*deepest, argc, argv));
    else
      report_error(who, e.what());
    usage_hint(who);
    return kExitUsageError;
  } catch (const std::bad_alloc&) {
    const CLI::App* deepest = &app;
    report_error(parsed_command_name(deepest), "out of memory");
    return kExitDataError;
  } catch (const std::exception& e) {
    // Thrown by a validator reading a file an option names (dupuy-jakob:FILE): the file cannot
    // be read or holds bad data, a data error as in every command that reads one.
    const CLI::App* deepest = &app;
    report_error(parsed_command_name(deepest), e.what());
    return kExitDataError;
  }
  if (!reference_format.empty()) {
    try {
      fmt::print("{}", command_reference(app, reference_format, HALFBACK_VERSION));
      return kExitOk;
    } catch (const UsageError& e) {
      report_error("halfback", e.what());
      return kExitUsageError;
    }
  }
  for (const Command& command : commands)
    if (command.app->parsed()) return run_command("halfback " + command.app->get_name(), command);
  report_error("halfback",
               fmt::format("a command is required (one of: {})", command_names(commands)));
  usage_hint("halfback");
  return kExitUsageError;
}

}  // namespace
}  // namespace halfback::cli

int main(int argc, char** argv) {
  // Ctrl-C, SIGTERM and SIGHUP remove the hidden temporaries beside the outputs before dying.
  halfback::install_temporary_cleanup_handlers();
  // Past `ulimit -f`, a write fails with a message (and no temporary is left) instead of SIGXFSZ.
  halfback::ignore_file_size_signal();
  try {
    return halfback::cli::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "halfback: error: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "halfback: error: unknown error\n");
  }
  return halfback::cli::kExitDataError;
}
