// The pieces shared by the subcommands of the `halfback` tool.
//
// Each subcommand lives in its own file (convert_command.cpp, ...) and exposes a registration
// function that adds its CLI::App to the main app and returns a Command; main.cpp calls the
// functions listed in command_table() (commands.cpp), parses, and runs the selected command.
//
// Errors: a command throws. UsageError (a command line that parses but makes no sense: an
// option's value, options together, a BRDF or environment spec that names nothing or holds a bad
// value) exits with code 2, like the CLI11 parse errors; any other exception (bad data, a file
// that cannot be read or written, a failure while running) exits with code 1 (docs/cli.md, "Exit
// status"). main.cpp prints "halfback NAME: error: MESSAGE" on stderr.
#pragma once

#include <CLI/CLI.hpp>
#include <cstddef>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/core/space.hpp"
#include "halfback/util/atomic_file.hpp"
#include "halfback/util/csv.hpp"

namespace halfback::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitDataError = 1;
inline constexpr int kExitUsageError = 2;

// Rows per block of the streaming commands (convert, eval): the input is read, checked, processed
// and written a block at a time, so that memory stays bounded on inputs of any length
// (docs/performance.md, "Streaming").
inline constexpr std::size_t kBlockRows = std::size_t{1} << 16;

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A registered subcommand: its CLI11 app, and what runs it after a successful parse (returns the
// exit code, or throws).
struct Command {
  Command() = default;
  Command(CLI::App* a, std::function<int()> r, std::function<std::vector<std::string>()> more = {})
      : app(a), run(std::move(r)), more_outputs(std::move(more)) {}

  CLI::App* app = nullptr;
  std::function<int()> run;
  // The files the command writes that no option names (plan: the sidecar beside -o), for the
  // output rule (refuse_outputs_over_inputs); empty for most commands.
  std::function<std::vector<std::string>()> more_outputs;
};

using RegisterCommand = Command (*)(CLI::App& parent);

// The subcommands, in the order of `halfback --help` (commands.cpp).
std::span<const RegisterCommand> command_table();

Command register_convert(CLI::App& parent);
Command register_render(CLI::App& parent);
Command register_figure(CLI::App& parent);
Command register_info(CLI::App& parent);
Command register_eval(CLI::App& parent);
Command register_resample(CLI::App& parent);
Command register_export_merl(CLI::App& parent);
Command register_export_rgl(CLI::App& parent);
Command register_models(CLI::App& parent);
Command register_study(CLI::App& parent);
Command register_view(CLI::App& parent);
Command register_fit(CLI::App& parent);
Command register_plan(CLI::App& parent);
Command register_reconstruct(CLI::App& parent);
Command register_factor(CLI::App& parent);
Command register_nbrdf(CLI::App& parent);
Command register_compare(CLI::App& parent);

// The command reference, generated from the apps registered under `root` (the options, their
// values, defaults and descriptions, each app's description and footer): "man", the man page
// docs/halfback.1; "markdown", the option tables of docs/cli.md, one block per command and
// subcommand between the lines "<!-- BEGIN generated: halfback NAME -->" and "<!-- END generated:
// halfback NAME -->". Printed by the hidden `halfback --help-reference=man|markdown`;
// scripts/cli_reference.py writes both into docs/ (reference.cpp). Another format: UsageError.
std::string command_reference(const CLI::App& root, std::string_view format,
                              std::string_view version);

// "halfback COMMAND: warning: MESSAGE" on stderr.
void warn(std::string_view command, std::string_view message);

// A CSV input given as a path, or "-" for standard input ("<stdin>" in messages), read a block of
// rows at a time. Throws as CsvStreamReader's constructors.
std::unique_ptr<CsvStreamReader> open_csv_input(const std::string& path);

// An output given as a path, or "-" for standard output. A file is written through an
// AtomicFile, created by the constructor (so an unwritable destination fails before any work)
// and renamed into place by commit(): on error, nothing is left and an existing file is kept.
// Standard output is written directly; streaming commands (convert, eval) hold their first
// block's output until it is checked, so that a data error in a small input prints nothing there.
class Output {
 public:
  explicit Output(const std::string& path);
  void write(std::string_view data);
  void commit();
  CsvSink sink() {
    return [this](std::string_view s) { write(s); };
  }
  bool is_stdout() const noexcept { return !file_; }

 private:
  std::unique_ptr<AtomicFile> file_;
};

// The output rule (docs/reliability/cli.md, "Files and outputs"): an output never replaces an
// input of the same command. Called by main.cpp on the parsed command (`app`, its deepest parsed
// subcommand) before it runs. Outputs: the values of -o/--output/--out/--json (their defaults when
// not given), the FILE of --emit TARGET:FILE, and `more_outputs`. Inputs: the values of every other
// option and positional, each also split at ',' and '+' (lists, sums) and after a ':' (a
// family's member, dupuy-jakob:FILE). UsageError (status 2) naming both options when an output
// that exists is the same file as an input (std::filesystem::equivalent: links and hard links
// included), or when an output declared a folder (type name DIR) is a folder and an input is a
// file inside it of a kind the
// commands write into folders (.csv, .md, .html, .png, .svg, .pdf, .exr, .part, .profile, .txt).
// Devices, FIFOs and standard streams are not compared (nothing is replaced there).
void refuse_outputs_over_inputs(const CLI::App& app, const std::vector<std::string>& more_outputs);

// Fails (std::system_error, "cannot write 'PATH': ...") unless `path` can be written, creating
// and removing a temporary file beside it: commands call it before any long work.
void check_writable(const std::string& path);

// Option values given as one comma-separated string, so that an empty list or a bad item gets a
// message naming the option (UsageError):
//   "a, b,c" -> {"a", "b", "c"} (items trimmed of spaces; an empty list or item is an error);
//   numbers (finite, any std::from_chars form); positive whole numbers.
std::vector<std::string> split_list(const std::string& list, const char* option, const char* what);
std::vector<double> number_list(const std::string& list, const char* option, const char* what);
std::vector<std::size_t> count_list(const std::string& list, const char* option, const char* what);
// A comma-separated list of environment specs, where "constant:R,G,B" keeps its own commas: an
// item that is a number continues the constant before it ("constant:0.5,0.2,0.1,studio" -> 2).
std::vector<std::string> environment_list(const std::string& list, const char* option);
// Called in a catch block around the loading of an environment given as `option`: a bad spec
// (std::invalid_argument) becomes a UsageError naming the option; anything else (an unreadable
// or malformed file: a data error) is rethrown as it is.
[[noreturn]] void rethrow_environment_error(const char* option, const std::string& spec);
// A BRDF given on the command line (`option`: "--brdf", "SPEC", "--material"), by load_brdf(): a
// spec that names nothing or a model with a bad value (std::invalid_argument) is a usage error,
// status 2; a file that cannot be read or holds bad data is rethrown as it is, status 1.
BrdfPtr brdf_argument(const std::string& spec, const char* option);
// One finite number; the message names `what` (e.g. "--range k=0:x").
double parse_number(std::string_view text, const std::string& what);

// A CLI11 validator for parameterization names ("dirs", "hybrid", ...), with a message listing
// the names.
// One rule for the values of every option of every command (docs/reliability/cli.md, "Option
// values"), added to the whole tree of apps after registration: a value given empty is refused (an
// empty --env or --budgets is not the default); a FLOAT option takes a finite number (no nan,
// no inf); an INT or UINT option a whole number written as one and within 64 bits (no 1e3, no
// −1 for a UINT, no 2⁶⁴ quietly saturated). Violations are usage errors (exit status 2).
void harden_options(CLI::App& app);

// For counts that may be 0 (--threads): "a whole number >= 0", with a readable message.
CLI::Validator non_negative_integer();

// The space of a name given on the command line (space_from_name), or nullopt with `message`
// saying why when the name is known but cannot be used here: a family's member whose argument is
// wrong (the family's own message), or the study's per-material placeholder outside the study.
// An unknown name: nullopt and an empty message (each option says what it expects). A file
// that a family's member names and that cannot be read or holds bad data is not the command
// line's fault: its error (FormatError, std::system_error) propagates, status 1, also out of the
// validators below (main.cpp reports an error thrown while parsing as a data error).
std::optional<Space> space_or_message(const std::string& name, std::string& message);

CLI::Validator space_name_validator();
// The same for a parameterization (not "dirs").
CLI::Validator parameterization_validator();

}  // namespace halfback::cli
