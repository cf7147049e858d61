// Tests of the `halfback` binary (its path is HALFBACK_CLI_PATH): runs it with arguments and
// standard input, and checks its standard output, standard error, exit status and files.
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/mount.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "halfback/core/batch.hpp"
#include "halfback/core/simd.hpp"
#include "halfback/core/space.hpp"
#include "halfback/formats/merl.hpp"
#include "halfback/formats/rgl.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/util/csv.hpp"
#include "support/fifo_reader.hpp"
#include "support/spawn.hpp"
#include "support/test_support.hpp"

extern char** environ;

namespace halfback {
namespace {

namespace fs = std::filesystem;
using namespace std::string_literals;

constexpr double kPi = std::numbers::pi;
constexpr const char* kDirsHeader = "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n";
constexpr const char* kTimePath = "/usr/bin/time";  // GNU time, for peak resident memory

struct Result {
  int status = -1;  // exit status, or -1 when killed by a signal
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void put(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

// The lines of a section of a help text ("Options", "Subcommands"): those after its title line
// ("Options:") up to the next empty line.
std::vector<std::string> help_section(const std::string& help, const std::string& title) {
  std::vector<std::string> lines;
  std::istringstream in(help);
  bool inside = false;
  for (std::string line; std::getline(in, line);) {
    if (!inside) {
      inside = line == title + ":";
      continue;
    }
    if (line.empty()) break;
    lines.push_back(line);
  }
  return lines;
}

class CliTest : public testing::Test {
 protected:
  // A test may leave a read-only folder "ro": made writable again so that the directory can be
  // removed.
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_.path() / "ro", fs::perms::owner_all, fs::perm_options::add, ec);
  }

  fs::path path(const std::string& name) const { return dir_.path() / name; }

  // Runs halfback with `args` in the test's directory, `input` on stdin.
  // With `max_rss_kb`, the command's peak resident memory is stored there, measured by
  // /usr/bin/time (its fork starts small; the ru_maxrss of a posix_spawn child would include this
  // process's memory, from before the exec).
  Result run(const std::vector<std::string>& args, const std::string& input = "",
             long* max_rss_kb = nullptr, double* cpu_seconds = nullptr) const {
    const fs::path in = path(".stdin"), out = path(".stdout"), err = path(".stderr");
    put(in, input);
    const fs::path rss = path(".rss");
    std::vector<std::string> argv{HALFBACK_CLI_PATH};
    const bool timed = max_rss_kb || cpu_seconds;
    if (timed) argv = {kTimePath, "-f", "%M %U %S", "-o", rss.string(), HALFBACK_CLI_PATH};
    argv.insert(argv.end(), args.begin(), args.end());
    if (file_limit_kib_ > 0)
      argv.insert(argv.begin(),
                  {"/bin/bash", "-c",
                   "ulimit -f " + std::to_string(file_limit_kib_) + " && exec \"$@\"", "bash"});
    const test::Spawned spawned = test::spawn_and_wait(dir_.path(), std::move(argv), in, out, err);
    Result r;
    if (!spawned.started) {
      ADD_FAILURE() << "cannot run " << HALFBACK_CLI_PATH << ": " << spawned.error;
      return r;
    }
    if (timed) {  // the last line is "%M %U %S" (earlier ones: a signal's note)
      std::istringstream lines(slurp(rss));
      long rss_kb = 0;
      double user = 0, sys = 0;
      for (std::string line; std::getline(lines, line);)
        std::istringstream(line) >> rss_kb >> user >> sys;
      if (max_rss_kb) *max_rss_kb = rss_kb;
      if (cpu_seconds) *cpu_seconds = user + sys;
      fs::remove(rss);
    }
    r.status = spawned.status;
    r.out = slurp(out);
    r.err = slurp(err);
    fs::remove(in);
    fs::remove(out);
    fs::remove(err);
    return r;
  }

  // The files of the test's directory, sorted (no leftover temporary files).
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_.path())) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  }

  // Every output option the tool registers, read from its help as a user reads it (`halfback
  // --help`, then each command's and each subcommand's): "COMMAND [SUBCOMMAND]" -> the names of
  // each option that the output rule treats as an output (-o, --output, --out, --json, --emit), as
  // the help lists them ("-o,--output"). A command added with an output is in it with no test's
  // edit.
  std::map<std::string, std::vector<std::vector<std::string>>> registered_outputs() const {
    static const std::set<std::string> kOutputNames{"-o", "--output", "--out", "--json", "--emit"};
    std::map<std::string, std::vector<std::vector<std::string>>> found;
    std::vector<std::vector<std::string>> todo{{}};
    while (!todo.empty()) {
      const std::vector<std::string> words = todo.back();
      todo.pop_back();
      std::vector<std::string> args = words;
      args.push_back("--help");
      const Result r = run(args);
      std::string command;
      for (const std::string& w : words) command += (command.empty() ? "" : " ") + w;
      EXPECT_EQ(r.status, 0) << command << " --help: " << r.err;
      for (const std::string& line : help_section(r.out, "Options")) {
        if (!line.starts_with("  -")) continue;  // a description's continued line
        std::vector<std::string> names;
        std::istringstream first(line.substr(2, line.find(' ', 2) - 2));
        for (std::string name; std::getline(first, name, ',');) names.push_back(name);
        if (std::ranges::any_of(names,
                                [](const std::string& n) { return kOutputNames.contains(n); }))
          found[command].push_back(names);
      }
      for (const std::string& line : help_section(r.out, "Subcommands"))
        if (line.size() > 2 && line[2] != ' ') {
          std::vector<std::string> sub = words;
          sub.push_back(line.substr(2, line.find(' ', 2) - 2));
          todo.push_back(std::move(sub));
        }
    }
    return found;
  }

  // Fails for each registered output (registered_outputs) that none of `command_lines` writes
  // through: a line of the command (its words first) that gives one of the option's names.
  void expect_every_output_written(
      const std::vector<std::vector<std::string>>& command_lines) const {
    const auto registered = registered_outputs();
    std::size_t options = 0;
    for (const auto& [command, outputs] : registered) {
      std::vector<std::string> words;
      std::istringstream in(command);
      for (std::string w; in >> w;) words.push_back(w);
      for (const std::vector<std::string>& names : outputs) {
        ++options;
        const bool written = std::ranges::any_of(command_lines, [&](const auto& args) {
          if (args.size() < words.size() || !std::equal(words.begin(), words.end(), args.begin()))
            return false;
          return std::ranges::any_of(args, [&](const std::string& a) {
            return std::ranges::any_of(
                names, [&](const std::string& n) { return a == n || a.starts_with(n + "="); });
          });
        });
        std::string all;
        for (const std::string& n : names) all += (all.empty() ? "" : ",") + n;
        EXPECT_TRUE(written) << "no case writes through `halfback " << command << " " << all << "`";
      }
    }
    // The help was read: 19 output options in 17 commands when this was written (more is fine).
    EXPECT_GE(options, 19u);
  }

  // The inputs of write_cases(): pairs.csv, a 300-point plan p.csv and lab.csv (a value a row).
  void write_case_inputs();
  // A write that failed as it must: status 1, `message` in the error, every output still "old"
  // and no temporary (a dot file) anywhere in the test's folder.
  void expect_failed_write_left_old_files(const std::string& line, const Result& r,
                                          const std::vector<std::string>& outputs,
                                          const std::string& message);

  test::TempDir dir_;        // the test's own, removed after it
  long file_limit_kib_ = 0;  // > 0: run() runs the tool under bash's `ulimit -f` of this many KiB
};

// Parses the tool's output (nan allowed).
CsvTable parse(const std::string& text) {
  CsvReadOptions options;
  options.allow_non_finite = true;
  return read_csv(text, "output", {}, options);
}

// Rows of a CSV text with text fields (quoted fields on one line), for the study's files.
std::vector<std::vector<std::string>> csv_rows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) rows.push_back(split_csv_line(line));
  return rows;
}

std::vector<std::string> header_of(std::span<const std::string_view> names,
                                   std::vector<std::string> extra = {}) {
  std::vector<std::string> h(names.begin(), names.end());
  h.insert(h.end(), extra.begin(), extra.end());
  return h;
}

// Well-conditioned pairs: away from the pole, the horizon, and the mirror and retro
// configurations, where some coordinates are ill-defined.
std::vector<DirPair<double>> well_conditioned_pairs(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> z(0.15, 0.95), phi(0, 2 * kPi);
  std::vector<DirPair<double>> pairs;
  while (pairs.size() < n) {
    auto dir = [&] {
      const double c = z(rng), s = std::sqrt((1 - c) * (1 + c)), p = phi(rng);
      return Vec3<double>{s * std::cos(p), s * std::sin(p), c};
    };
    const DirPair<double> p{dir(), dir()};
    const double hx = p.wi.x + p.wo.x, hy = p.wi.y + p.wo.y;
    const double kx = p.wi.x - p.wo.x, ky = p.wi.y - p.wo.y;
    if (std::hypot(hx, hy) < 0.1 || std::hypot(kx, ky) < 0.1) continue;
    pairs.push_back(p);
  }
  return pairs;
}

std::string dirs_csv(const std::vector<DirPair<double>>& pairs) {
  std::vector<std::vector<double>> c(6);
  for (const auto& p : pairs) {
    const double v[6] = {p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z};
    for (int i = 0; i < 6; ++i) c[i].push_back(v[i]);
  }
  const auto names = column_names({Space::dirs, false});
  const std::vector<std::string> header(names.begin(), names.end());
  const std::vector<std::span<const double>> cols(c.begin(), c.end());
  return to_csv(header, cols);
}

// One CSV row of six numbers, %.17g.
std::string fmt_row(const std::array<double, 6>& v) {
  std::string s;
  for (double x : v) {
    if (!s.empty()) s += ',';
    s += format_csv_number(x);
  }
  return s;
}

// Distance between two angles on the circle.
double angle_diff(double a, double b) {
  const double d = std::fmod(std::abs(a - b), 2 * kPi);
  return std::min(d, 2 * kPi - d);
}

bool is_angle_column(std::string_view name) {
  return name.rfind("phi", 0) == 0 || name == "dphi";
}

// ---------------------------------------------------------------------------------------------
// Help, version, usage errors
// ---------------------------------------------------------------------------------------------

TEST_F(CliTest, HelpAndVersion) {
  Result r = run({"--help"});
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("convert"), std::string::npos);
  EXPECT_NE(r.out.find("Exit status"), std::string::npos);
  r = run({"convert", "--help"});
  EXPECT_EQ(r.status, 0);
  for (const char* s : {"--from", "--to", "--isotropic", "--jacobian", "--skip-invalid", "--input",
                        "--output", "Examples:", "hbar,phi_h,k,phi_k", "with --isotropic",
                        "hbar,k,dphi", "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s;
  r = run({"--version"});
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out,
            "halfback 0.1.0\nSIMD kernels: " + std::string(simd_isa_name(simd_isa())) + "\n");
  // A HALFBACK_ISA that names no instruction set is said, not silently ignored.
  const char* had = std::getenv("HALFBACK_ISA");
  const std::string before = had ? had : "";
  ::setenv("HALFBACK_ISA", "avx3", 1);
  r = run({"--version"});
  if (had)
    ::setenv("HALFBACK_ISA", before.c_str(), 1);
  else
    ::unsetenv("HALFBACK_ISA");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("(HALFBACK_ISA=avx3 not used: not one of scalar, sse2, avx2, avx512"),
            std::string::npos)
      << r.out;
}

TEST_F(CliTest, UsageErrorsExitWithTwo) {
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::string hint = "Run 'halfback convert --help' for more information.\n";
  // The parameterizations with a parameter, after the others (the CLI registers the family).
  const std::string kFamilies = ", or dupuy-jakob:BRDF";
  const Case cases[] = {
      {{"convert", "--from", "hybird", "--to", "dirs"},
       "halfback convert: error: --from: unknown coordinates 'hybird' (expected one of: " +
           space_names() + kFamilies + ")\n" + hint},
      {{"render", "--brdf", "lambert", "--sampling-param", "polar", "-o", "never.png"},
       "halfback render: error: --param: unknown parameterization 'polar' (expected one "
       "of: " +
           parameterization_names(", ") + kFamilies +
           ")\nRun 'halfback render --help' for more information.\n"},
      {{"convert", "--from", "dirs", "--to", "polar"},
       "halfback convert: error: --to: unknown coordinates 'polar' (expected one of: " +
           space_names() + kFamilies + ")\n" + hint},
      {{"convert", "--from", "dirs"}, "halfback convert: error: --to is required\n" + hint},
      {{"convert", "--from", "dirs", "--to", "hybrid", "--bogus"},
       "halfback convert: error: The following argument was not expected: --bogus\n" + hint},
      {{"convert", "--from", "dirs", "--to", "dirs", "--isotropic"},
       "halfback convert: error: --isotropic needs a parameterization on one side (--from or "
       "--to)\n" +
           hint},
      {{"convert", "--from", "dirs", "--to", "dirs", "--jacobian"},
       "halfback convert: error: --jacobian needs a parameterization on one side (--from or "
       "--to)\n" +
           hint},
  };
  // (The list of commands grows: only its start is checked.)
  Result r = run({});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err.rfind("halfback: error: a command is required (one of: convert", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(")\nRun 'halfback --help' for more information.\n"), std::string::npos);
  r = run({"frobnicate"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(
      r.err.rfind("halfback: error: unknown command 'frobnicate' (the commands are: convert", 0),
      0u)
      << r.err;
  for (const Case& c : cases) {
    r = run(c.args);
    EXPECT_EQ(r.status, 2) << c.message;
    EXPECT_EQ(r.err, c.message);
    EXPECT_EQ(r.out, "");
  }
}

// docs/reliability/cli.md: one rule for option values (harden_options): non-finite
// numbers, negative or overflowing whole numbers and empty values are usage errors naming the
// option, and nothing is written (render --exposure nan wrote a black image with status 0; --seed
// -1 and --seed 1e23 both became 2^64 - 1; study --budgets "" fell back to the default budgets).
TEST_F(CliTest, OptionValuesFollowOneRule) {
  const std::string png = path("never.png");
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const Case cases[] = {
      {{"render", "--brdf", "lambert", "--exposure", "nan", "-o", png},
       "--exposure: 'nan' is not a number"},
      // The rule comes before an option's range ("nan" was "must be >= 0" and then status 1).
      {{"render", "--brdf", "lambert", "--time-budget", "nan", "-o", png},
       "--time-budget: 'nan' is not a number"},
      // --exposure is bounded as --env-exposure is (1e308 wrote an all-white image).
      {{"render", "--brdf", "lambert", "--exposure", "1e308", "-o", png}, "--exposure: "},
      {{"render", "--brdf", "lambert", "--exposure", "-1e308", "-o", png}, "--exposure: "},
      {{"render", "--brdf", "lambert", "--exposure", "65", "-o", png}, "--exposure: "},
      // --nielsen-eta is checked by itself, with or without a database.
      {{"study", "--nielsen-eta", "-1", "lambert"}, "--nielsen-eta -1: "},
      {{"render", "--brdf", "lambert", "--exposure", "-inf", "-o", png}, "is not a finite number"},
      {{"render", "--brdf", "lambert", "--seed", "-1", "-o", png},
       "--seed: '-1' is not a whole number >= 0"},
      {{"render", "--brdf", "lambert", "--seed", "99999999999999999999999", "-o", png},
       "--seed: '99999999999999999999999' is too large (at most 18446744073709551615)"},
      {{"render", "--brdf", "lambert", "--spp", "1e3", "-o", png}, "--spp: "},
      {{"render", "--brdf", "lambert", "--brdf-sampling", "pilot", "-o", png}, "--brdf-sampling"},
      {{"render", "--brdf", "lambert", "--env", "", "-o", png}, "--env: an empty value"},
      {{"study", "--budgets", "", "lambert"}, "--budgets: an empty value"},
      {{"study", "--budgets-4d", "", "lambert"}, "--budgets-4d: an empty value"},
      {{"study", "--env", "", "lambert"}, "--env: an empty value"},
      {{"view", "--host", "", "lambert"}, "--host: an empty value"},
      {{"export-rgl", "--brdf", "lambert", "--threads", "-1", "-o", path("x.bsdf")},
       "--threads: '-1' is not a whole number >= 0"},
  };
  for (const Case& c : cases) {
    const Result r = run(c.args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_LT(r.err.size(), 400u) << r.err;  // no 300-digit ranges
  }
  EXPECT_FALSE(std::filesystem::exists(png));
  EXPECT_FALSE(std::filesystem::exists(path("x.bsdf")));
}

// ---------------------------------------------------------------------------------------------
// Round trips
// ---------------------------------------------------------------------------------------------

TEST_F(CliTest, RoundTripThroughEveryParameterization) {
  const auto pairs = well_conditioned_pairs(500, 1);
  put(path("pairs.csv"), dirs_csv(pairs));
  for (Space space : kKernelSpaces) {
    const std::string name(name_of(space));
    SCOPED_TRACE(name);
    Result r = run({"convert", "--from", "dirs", "--to", name, "-i", "pairs.csv", "-o", "p.csv"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err, "");
    const CsvTable q = parse(slurp(path("p.csv")));
    EXPECT_EQ(q.header, header_of(column_names({space, false})));  // dirs input: no valid column
    ASSERT_EQ(q.rows(), pairs.size());

    r = run({"convert", "--from", name, "--to", "dirs", "-i", "p.csv", "-o", "back.csv"});
    ASSERT_EQ(r.status, 0) << r.err;
    const CsvTable back = parse(slurp(path("back.csv")));
    EXPECT_EQ(back.header, header_of(column_names({Space::dirs, false}), {"valid"}));
    ASSERT_EQ(back.rows(), pairs.size());
    double worst = 0;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const auto& p = pairs[i];
      const double v[6] = {p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z};
      for (int c = 0; c < 6; ++c) worst = std::max(worst, std::abs(back.columns[c][i] - v[c]));
      EXPECT_EQ(back.columns[6][i], 1.0);
    }
    EXPECT_LE(worst, 1e-12);
  }
}

TEST_F(CliTest, IsotropicRoundTrip) {
  const auto pairs = well_conditioned_pairs(500, 2);
  put(path("pairs.csv"), dirs_csv(pairs));
  for (Space space : kKernelSpaces) {
    const std::string name(name_of(space));
    SCOPED_TRACE(name);
    Result r = run({"convert", "--from", "dirs", "--to", name, "--isotropic", "-i", "pairs.csv",
                    "-o", "q.csv"});
    ASSERT_EQ(r.status, 0) << r.err;
    const CsvTable q = parse(slurp(path("q.csv")));
    ASSERT_EQ(q.header, header_of(column_names({space, true})));
    ASSERT_EQ(q.rows(), pairs.size());

    // The canonical pose: the same pair up to a rotation about n.
    r = run({"convert", "--from", name, "--to", "dirs", "--isotropic", "-i", "q.csv", "-o",
             "pose.csv"});
    ASSERT_EQ(r.status, 0) << r.err;
    const CsvTable pose = parse(slurp(path("pose.csv")));
    ASSERT_EQ(pose.rows(), pairs.size());
    double worst = 0;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const auto& p = pairs[i];
      const auto& c = pose.columns;
      const double dot_in = p.wi.x * p.wo.x + p.wi.y * p.wo.y + p.wi.z * p.wo.z;
      const double dot_out = c[0][i] * c[3][i] + c[1][i] * c[4][i] + c[2][i] * c[5][i];
      worst = std::max({worst, std::abs(c[2][i] - p.wi.z), std::abs(c[5][i] - p.wo.z),
                        std::abs(dot_out - dot_in)});
      EXPECT_EQ(c[6][i], 1.0);
    }
    EXPECT_LE(worst, 1e-12);

    // And back to the same isotropic coordinates.
    r = run({"convert", "--from", "dirs", "--to", name, "--isotropic", "-i", "pose.csv", "-o",
             "q2.csv"});
    EXPECT_EQ(r.status, 1);  // pose.csv has a valid column: not a dirs header
    EXPECT_NE(r.err.find("header does not match"), std::string::npos);
    std::vector<std::string> six(pose.header.begin(), pose.header.begin() + 6);
    std::vector<std::span<const double>> cols(pose.columns.begin(), pose.columns.begin() + 6);
    put(path("pose6.csv"), to_csv(six, cols));
    r = run({"convert", "--from", "dirs", "--to", name, "--isotropic", "-i", "pose6.csv"});
    ASSERT_EQ(r.status, 0) << r.err;
    const CsvTable q2 = parse(r.out);
    ASSERT_EQ(q2.rows(), pairs.size());
    worst = 0;
    for (std::size_t c = 0; c < 3; ++c)
      for (std::size_t i = 0; i < pairs.size(); ++i)
        worst = std::max(worst, is_angle_column(q.header[c])
                                    ? angle_diff(q2.columns[c][i], q.columns[c][i])
                                    : std::abs(q2.columns[c][i] - q.columns[c][i]));
    EXPECT_LE(worst, 1e-12);
  }
}

TEST_F(CliTest, ParameterizationToParameterization) {
  // hybrid -> halfdiff equals dirs -> halfdiff, 4D and isotropic.
  const auto pairs = well_conditioned_pairs(200, 3);
  put(path("pairs.csv"), dirs_csv(pairs));
  for (bool iso : {false, true}) {
    std::vector<std::string> extra;
    if (iso) extra.push_back("--isotropic");
    auto args = [&](std::vector<std::string> a) {
      a.insert(a.end(), extra.begin(), extra.end());
      return a;
    };
    ASSERT_EQ(run(args({"convert", "--from", "dirs", "--to", "hybrid", "-i", "pairs.csv", "-o",
                        "hy.csv"}))
                  .status,
              0);
    const Result direct =
        run(args({"convert", "--from", "dirs", "--to", "halfdiff", "-i", "pairs.csv"}));
    const Result via =
        run(args({"convert", "--from", "hybrid", "--to", "halfdiff", "-i", "hy.csv"}));
    ASSERT_EQ(direct.status, 0);
    ASSERT_EQ(via.status, 0) << via.err;
    const CsvTable a = parse(direct.out), b = parse(via.out);
    EXPECT_EQ(b.header, header_of(column_names({space_of<HalfDiff>, iso}), {"valid"}));
    ASSERT_EQ(b.rows(), a.rows());
    for (std::size_t c = 0; c < a.header.size(); ++c)
      for (std::size_t i = 0; i < a.rows(); ++i) {
        const double d = is_angle_column(a.header[c]) ? angle_diff(a.columns[c][i], b.columns[c][i])
                                                      : std::abs(a.columns[c][i] - b.columns[c][i]);
        ASSERT_LE(d, 1e-12) << a.header[c] << " row " << i;
      }
  }
}

TEST_F(CliTest, StdinStdoutAndDash) {
  const std::string in = std::string(kDirsHeader) + "0,0,1,0.6,0,0.8\n";
  const Result a = run({"convert", "--from", "dirs", "--to", "halfdiff"}, in);
  const Result b = run({"convert", "--from", "dirs", "--to", "halfdiff", "-i", "-", "-o", "-"}, in);
  put(path("in.csv"), in);
  const Result c = run({"convert", "--from", "dirs", "--to", "halfdiff", "--input", "in.csv"});
  ASSERT_EQ(a.status, 0);
  EXPECT_EQ(a.out,
            "theta_h,phi_h,theta_d,phi_d\n"
            "0.32175055439664219,0,0.32175055439664219,3.1415926535897931\n");
  EXPECT_EQ(b.out, a.out);
  EXPECT_EQ(c.out, a.out);
  EXPECT_EQ(entries(), (std::vector<std::string>{"in.csv"}));
}

TEST_F(CliTest, CrlfBlanksAndTrailingLines) {
  const std::string in =
      "\xEF\xBB\xBF wi_x , wi_y,wi_z,wo_x,wo_y,wo_z\r\n 0 , 0 "
      ",1,0.6,0,0.8\r\n0,0,1,0.6,0,0.8\r\n\r\n";
  const Result r = run({"convert", "--from", "dirs", "--to", "halfdiff"}, in);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(parse(r.out).rows(), 2u);
}

TEST_F(CliTest, HeaderOnlyInputGivesHeaderOnlyOutput) {
  Result r = run({"convert", "--from", "dirs", "--to", "hybrid", "--jacobian"}, kDirsHeader);
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out, "hbar,phi_h,k,phi_k,jacobian\n");
  r = run({"convert", "--from", "ortho", "--to", "dirs", "--isotropic"}, "hbar,kbar,dphi");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out, "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z,valid\n");
}

// The output rule holds for convert too (OutputThatNamesAnInputIsRefusedBeforeAnyWork).
TEST_F(CliTest, InputAndOutputMayNotBeTheSameFile) {
  const std::string data = std::string(kDirsHeader) + "0,0,1,0.6,0,0.8\n";
  put(path("data.csv"), data);
  const Result r =
      run({"convert", "--from", "dirs", "--to", "ortho", "-i", "data.csv", "-o", "data.csv"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("never replaces an input"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(path("data.csv")), data);
  EXPECT_EQ(entries(), (std::vector<std::string>{"data.csv"}));
}

TEST_F(CliTest, ManyRows) {
  const auto pairs = well_conditioned_pairs(30000, 4);  // several tiles: the threaded path
  const Result q = run({"convert", "--from", "dirs", "--to", "hybrid"}, dirs_csv(pairs));
  ASSERT_EQ(q.status, 0) << q.err;
  const Result back = run({"convert", "--from", "hybrid", "--to", "dirs"}, q.out);
  ASSERT_EQ(back.status, 0) << back.err;
  const CsvTable t = parse(back.out);
  ASSERT_EQ(t.rows(), pairs.size());
  double worst = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    worst = std::max(worst, std::abs(t.columns[0][i] - pairs[i].wi.x));
    worst = std::max(worst, std::abs(t.columns[5][i] - pairs[i].wo.z));
  }
  EXPECT_LE(worst, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// valid and jacobian columns
// ---------------------------------------------------------------------------------------------

TEST_F(CliTest, JacobianColumnMatchesTheLibraryAndTheSphericalFormula) {
  const auto pairs = well_conditioned_pairs(100, 5);
  put(path("pairs.csv"), dirs_csv(pairs));
  for (Space space : kKernelSpaces) {
    for (bool iso : {false, true}) {
      const std::string name(name_of(space));
      SCOPED_TRACE(name + (iso ? " isotropic" : ""));
      std::vector<std::string> args{"convert",    "--from", "dirs",      "--to", name,
                                    "--jacobian", "-i",     "pairs.csv", "-o",   "q.csv"};
      if (iso) args.push_back("--isotropic");
      Result r = run(args);
      ASSERT_EQ(r.status, 0) << r.err;
      const CsvTable q = parse(slurp(path("q.csv")));
      ASSERT_EQ(q.header, header_of(column_names({space, iso}), {"jacobian"}));
      // And from the parameterization back to dirs: the jacobian of the input tuple.
      args = {"convert", "--from", name, "--to", "dirs", "--jacobian", "-i", "q.csv"};
      if (iso) args.push_back("--isotropic");
      std::vector<std::string> coords(q.header.begin(), q.header.end() - 1);
      std::vector<std::span<const double>> cols(q.columns.begin(), q.columns.end() - 1);
      put(path("q.csv"), to_csv(coords, cols));
      r = run(args);
      ASSERT_EQ(r.status, 0) << r.err;
      const CsvTable back = parse(r.out);
      ASSERT_EQ(back.header, header_of(column_names({Space::dirs, false}), {"valid", "jacobian"}));

      const Form to{space, iso};
      const std::size_t dim = dimension(to);
      for (std::size_t i = 0; i < pairs.size(); ++i) {
        const auto& p = pairs[i];
        const double in[6] = {p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z};
        double out[4], jac = 0;
        ASSERT_TRUE(convert_one<double>({Space::dirs, false}, to, in, std::span(out, dim), &jac));
        const double j = q.columns[dim][i];
        EXPECT_NEAR(j, jac, 1e-12 * std::abs(jac)) << i;
        EXPECT_NEAR(back.columns[7][i], jac, 1e-10 * std::abs(jac)) << i;
        EXPECT_EQ(back.columns[6][i], 1.0);
        if (space == space_of<Spherical>) {  // dwi dwo = sin(theta_i) sin(theta_o) dq
          const double expected = std::sqrt(1 - p.wi.z * p.wi.z) * std::sqrt(1 - p.wo.z * p.wo.z) *
                                  (iso ? 2 * kPi : 1.0);
          EXPECT_NEAR(j, expected, 1e-12 * expected) << i;
        }
      }
    }
  }
}

TEST_F(CliTest, OutOfDomainTuplesAreValidZeroRows) {
  const std::string in =
      "hbar,phi_h,k,phi_k\n"
      "0.3,0,0.3,0\n"    // valid
      "0.9,0,0.9,0\n"    // outside the domain
      "0.3,1e9,0.3,0\n"  // an azimuth beyond 65536 rad (7 is 7 − 2π: periodic)
      "0.3,1,0.2,2\n";   // valid
  const Result r = run({"convert", "--from", "hybrid", "--to", "dirs", "--jacobian"}, in);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");  // not an error, not a warning
  const CsvTable t = parse(r.out);
  ASSERT_EQ(t.header, header_of(column_names({Space::dirs, false}), {"valid", "jacobian"}));
  ASSERT_EQ(t.rows(), 4u);
  EXPECT_EQ(t.columns[6], (std::vector<double>{1, 0, 0, 1}));
  for (std::size_t row : {1u, 2u})
    for (std::size_t c : {0u, 1u, 2u, 3u, 4u, 5u, 7u}) EXPECT_TRUE(std::isnan(t.columns[c][row]));
  for (std::size_t row : {0u, 3u})
    for (std::size_t c : {0u, 1u, 2u, 3u, 4u, 5u, 7u})
      EXPECT_TRUE(std::isfinite(t.columns[c][row]));
  // The invalid rows print `nan` (not -nan).
  EXPECT_NE(r.out.find("\nnan,nan,nan,nan,nan,nan,0,nan\n"), std::string::npos);
}

// Relative azimuths are periodic (docs/reliability/numerics.md): φd = -π/2 and 3π/2 are
// the same pair, both valid (the first was invalid before, without a word).
TEST_F(CliTest, RelativeAzimuthsArePeriodic) {
  const Result r = run({"convert", "--from", "halfdiff", "--isotropic", "--to", "dirs"},
                       "theta_h,theta_d,phi_d\n0.3,0.5,-1.5707963267948966\n"
                       "0.3,0.5,4.7123889803846897\n0.3,0.5,-20\n0.3,0.5,5.1327412287183449\n");
  ASSERT_EQ(r.status, 0) << r.err;
  const CsvTable t = parse(r.out);
  ASSERT_EQ(t.rows(), 4u);
  for (std::size_t row = 0; row < 4; ++row) EXPECT_EQ(t.columns[6][row], 1) << row;
  for (std::size_t c = 0; c < 6; ++c) {
    EXPECT_NEAR(t.columns[c][0], t.columns[c][1], 1e-12) << c;
    EXPECT_NEAR(t.columns[c][2], t.columns[c][3], 1e-12) << c;  // -20 = -20 + 4·2π
  }
}

// One rule for the exit status of every command (docs/reliability/cli.md, "Exit statuses";
// docs/cli.md, "Exit status"): 2 for the command line — an option or its value, options together, a
// BRDF or environment spec that names nothing or holds a bad value, a figure its options make too
// large, the same BRDF twice; 1 for what is read, written or computed — a file that cannot be read
// or holds bad data, a destination that cannot be written. Each row fails on the code before where
// the status was the other one (a model spec out of range was 1 in info, eval, render, ...; a
// missing environment file 1; a figure too large 1 in slices and material; the same BRDF twice 1).
TEST_F(CliTest, ExitStatusesFollowOneRule) {
  put(path("junk.bsdf"), "junk, not a BRDF file\n");
  put(path("junk.hdr"), "#?RADIANCE\njunk\n");
  const std::string pair_csv = "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,1,0,0,1\n";
  const std::string bad_csv = "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,x,0,0,1\n";
  std::string many;
  for (int k = 0; k < 200; ++k) many += (k ? "," : "") + std::to_string(k);
  const std::string no_dir = path("no/such/dir/x").string();
  struct Row {
    std::vector<std::string> args;
    int status;
    std::string input = "";
  };
  const std::vector<Row> rows = {
      // The command line: options and their values.
      {{"convert", "--nope"}, 2},
      {{"convert", "--from", "hybird", "--to", "dirs"}, 2},
      {{"info", "lambert", "--albedo-samples", "x"}, 2},
      {{"models", "--nope"}, 2},
      {{"render", "--brdf", "lambert", "--spp", "-3", "-o", "x.png"}, 2},
      {{"fit", "--brdf", "lambert", "--model", "ggx", "--loss", "l2", "-o", "f.json"}, 2},
      {{"fit", "--brdf", "lambert", "--model", "nosuch", "-o", "f.json"}, 2},
      {{"factor", "--brdf", "lambert", "--rank", "0", "-o", "f.json"}, 2},
      {{"factor", "--brdf", "lambert", "--counts", "8,8", "-o", "f.json"}, 2},
      {{"factor", "--brdf", "lambert", "--param", "dirs", "-o", "f.json"}, 2},
      {{"factor", "--brdf", "ggx:alpha_x=0.1,alpha_y=0.3", "-o", "f.json"}, 2},
      {{"fit", "--brdf", "lambert", "--model", "ward", "--emit", "pbrt-v4:f.pbrt", "-o", "f.json"},
       2},
      // BRDF specs that name nothing or hold a bad value, for every command that takes one.
      {{"info", "ggx:alpha=-1"}, 2},
      {{"info", "nosuch"}, 2},
      {{"eval", "--brdf", "ggx:alpha=-1"}, 2, pair_csv},
      {{"resample", "--brdf", "ggx:alpha=-1", "-o", "x.npy"}, 2},
      {{"export-merl", "--brdf", "ggx:alpha=-1", "-o", "x.binary"}, 2},
      {{"export-rgl", "--brdf", "ggx:alpha=-1", "-o", "x.bsdf"}, 2},
      {{"render", "--brdf", "ggx:alpha=-1", "-o", "x.png"}, 2},
      {{"figure", "slices", "--brdf", "ggx:alpha=-1", "--out", "x.png"}, 2},
      {{"figure", "material", "--brdf", "nosuch", "--out", "x.png"}, 2},
      {{"figure", "paper", "--material", "ggx:alpha=-1", "--out", "figs"}, 2},
      {{"study", "ggx:alpha=-1", "-o", "st"}, 2},
      {{"study", "lambert", "lambert", "-o", "st"}, 2},
      {{"view", "ggx:alpha=-1", "--port", "0"}, 2},
      {{"fit", "--brdf", "ggx:alpha=-1", "--model", "ggx", "-o", "f.json"}, 2},
      // Environment specs, in both commands that take one.
      {{"render", "--brdf", "lambert", "--env", "nosuch", "-o", "x.png"}, 2},
      {{"render", "--brdf", "lambert", "--env", "constant:-1", "-o", "x.png"}, 2},
      {{"figure", "material", "--brdf", "lambert", "--env", "nosuch", "--out", "x.png"}, 2},
      // Figures their options make larger than an image can be.
      {{"figure", "hemisphere", "--elevations", many, "--scale", "8", "--out", "x.png"}, 2},
      {{"figure", "slices", "--brdf", "lambert", "--azimuths", many, "--scale", "8", "--out",
        "x.png"},
       2},
      {{"figure", "material", "--brdf", "lambert", "--azimuths", many, "--scale", "8",
        "--render-size", "16", "--out", "x.png"},
       2},
      // Data: files that cannot be read or hold bad data; destinations that cannot be written.
      {{"convert", "--from", "dirs", "--to", "hybrid"}, 1, bad_csv},
      {{"info", "junk.bsdf"}, 1},
      {{"eval", "--brdf", "junk.bsdf"}, 1, pair_csv},
      {{"eval", "--brdf", "lambert"}, 1, bad_csv},
      {{"resample", "--brdf", "junk.bsdf", "-o", "x.npy"}, 1},
      {{"export-merl", "--brdf", "junk.bsdf", "-o", "x.binary"}, 1},
      {{"export-rgl", "--brdf", "junk.bsdf", "-o", "x.bsdf"}, 1},
      {{"render", "--brdf", "junk.bsdf", "-o", "x.png"}, 1},
      {{"render", "--brdf", "lambert", "--env", "junk.hdr", "-o", "x.png"}, 1},
      {{"render", "--brdf", "lambert", "--width", "16", "-o", no_dir + ".png"}, 1},
      {{"figure", "slices", "--brdf", "junk.bsdf", "--out", "x.png"}, 1},
      {{"figure", "material", "--brdf", "lambert", "--env", "junk.hdr", "--out", "x.png"}, 1},
      {{"study", "junk.bsdf", "-o", "st"}, 1},
      {{"view", "junk.bsdf", "--port", "0"}, 1},
      {{"fit", "--brdf", "junk.bsdf", "--model", "ggx", "-o", "f.json"}, 1},
      {{"factor", "--brdf", "junk.bsdf", "-o", "f.json"}, 1},
      {{"factor", "--brdf", "lambert", "--counts", "4,4,4", "-o", no_dir + ".json"}, 1},
      {{"fit", "--brdf", "lambert", "--model", "ggx", "--samples", "100", "-o", no_dir + ".json"},
       1},
  };
  for (const Row& row : rows) {
    const Result r = run(row.args, row.input);
    std::string line;
    for (const std::string& a : row.args) line += " " + a.substr(0, 40);
    EXPECT_EQ(r.status, row.status) << "halfback" << line << "\n" << r.err.substr(0, 300);
    EXPECT_NE(r.err.find("error:"), std::string::npos) << "halfback" << line;
    if (row.status == 2) {
      EXPECT_NE(r.err.find("--help' for more information"), std::string::npos) << line;
    }
  }
}

// The exit status rule reaches files that an option's value names and that the option's check
// reads (dupuy-jakob:FILE in --to, --sampling-param, --nielsen-database): bad data there is status
// 1, as in --brdf, not a usage error; a count that the command line makes impossible is status 2.
// A factored file of the largest counts loads (it was status 2, blamed on "SPEC").
TEST_F(CliTest, ExitStatusesOfFilesThatOptionsName) {
  put(path("junk.bsdf"), "junk, not a BRDF file\n");
  ASSERT_EQ(run({"export-merl", "--brdf", "lambert", "-o", "holes.binary"}).status, 0);
  {  // a MERL file with unmeasured bins (-1) where Nielsen's configurations are: NaN there
    std::fstream f(path("holes.binary"), std::ios::in | std::ios::out | std::ios::binary);
    const double missing = -1;
    f.seekp(12);
    for (int k = 0; k < 90 * 180 * 30; ++k)
      f.write(reinterpret_cast<const char*>(&missing), sizeof missing);
  }
  const std::string pair_csv = "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,1,0,0,1\n";
  const std::vector<std::string> nielsen{"study",
                                         "--quick",
                                         "--params",
                                         "halfdiff",
                                         "--no-images",
                                         "--no-sampling",
                                         "--no-fit",
                                         "--test-pairs",
                                         "1000",
                                         "-o",
                                         "st",
                                         "ggx:alpha=0.2",
                                         "--nielsen-database",
                                         "ggx:alpha=0.3"};
  struct Row {
    std::vector<std::string> args;
    int status;
    std::string words;
  };
  std::vector<Row> rows = {
      {{"convert", "--from", "dirs", "--to", "dupuy-jakob:/dev/zero"}, 1, "not a regular file"},
      {{"convert", "--from", "dirs", "--to", "dupuy-jakob:holes.binary"}, 1, "holes.binary"},
      {{"render", "--brdf", "lambert", "--sampling-param", "dupuy-jakob:junk.bsdf", "-o", "x.png"},
       1,
       "junk.bsdf"},
      {{"convert", "--from", "dirs", "--to", "dupuy-jakob:nosuch"}, 2, "nosuch"},
  };
  rows.push_back({nielsen, 1, "not finite"});
  rows.back().args.insert(rows.back().args.end(), {"--nielsen-database", "holes.binary"});
  rows.push_back({nielsen, 2, "--nielsen-budgets: 1000000 measurements asked"});
  rows.back().args.insert(rows.back().args.end(),
                          {"--nielsen-database", "lambert", "--nielsen-counts", "1000000"});
  for (const Row& row : rows) {
    const Result r = run(row.args, pair_csv);
    std::string line;
    for (const std::string& a : row.args) line += " " + a;
    EXPECT_EQ(r.status, row.status) << line << "\n" << r.err;
    EXPECT_NE(r.err.find(row.words), std::string::npos) << line << "\n" << r.err;
    EXPECT_EQ(r.err.find("SPEC"), std::string::npos) << line << "\n" << r.err;
  }
  std::string big = R"({"format": "halfback-factored-brdf", "version": 1, "name": "big",
    "parameterization": "hybrid", "rank": 1, "counts": [4096, 4096, 4096], "max_log": [1, 1, 1],
    "factors": {)";
  std::string ones = "[1";
  for (int k = 1; k < 4096; ++k) ones += ",1";
  ones += "]";
  for (const char* c : {"r", "g", "b"})
    big += std::string(c == std::string("r") ? "" : ",") + "\"" + c + "\": [{\"a\": " + ones +
           ", \"b\": " + ones + ", \"phi\": " + ones + "}]";
  put(path("big.json"), big + "}}\n");
  const Result r = run({"info", "big.json"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("4096x4096x4096 cells"), std::string::npos) << r.out;
}

// `fit --model` given a BRDF (a file that exists, an embedded material) says it is a BRDF, not a
// model (it said "neither an existing file nor a known BRDF model" of a file that exists).
TEST_F(CliTest, FitModelThatIsABrdfSaysSo) {
  put(path("m.bsdf"), "not read\n");
  for (const char* model : {"m.bsdf", "embedded:pink-felt", "lambert+m.bsdf"}) {
    const Result r = run({"fit", "--brdf", "lambert", "--model", model, "-o", "f.json"});
    EXPECT_EQ(r.status, 2) << model << ": " << r.err;
    EXPECT_NE(r.err.find("a BRDF, not a model"), std::string::npos) << model << ": " << r.err;
    EXPECT_EQ(r.err.find("neither an existing file"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(path("f.json")));
}

// `halfback factor` (docs/fit.md, "Factored models"): the factored model is a file that every
// command reads, written only on success (an existing file is kept when the command fails).
TEST_F(CliTest, FactorWritesABrdfThatCommandsRead) {
  Result r = run({"factor", "--brdf", "lambert:albedo=0.5", "--param", "halfdiff", "--rank", "1",
                  "--counts", "4,4,4", "-o", "l.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("rank 1, 39 numbers"), std::string::npos) << r.out;
  r = run({"eval", "--brdf", path("l.json").string()},
          "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,1,0.6,0,0.8\n");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("0.1591549"), std::string::npos) << r.out;  // 0.5 / π
  put(path("keep.json"), "kept\n");
  r = run({"factor", "--brdf", "lambert", "--param", "dupuy-jakob:ggx", "-o", "keep.json"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(slurp(path("keep.json")), "kept\n");
}

// `halfback plan` (docs/acquisition.md): the positions to measure, each configuration once, with a
// JSON sidecar saying which row each point of the design takes; bad options leave nothing.
TEST_F(CliTest, PlanWritesPositionsAndItsSidecar) {
  Result r = run({"plan", "--param", "halfdiff", "--budget", "500", "-o", "p.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  const CsvTable t = parse(slurp(path("p.csv")));
  ASSERT_GT(t.rows(), 100u);
  EXPECT_EQ(t.header[1], "light_theta_deg");
  for (std::size_t k = 0; k < t.rows(); ++k) {
    EXPECT_EQ(t.columns[2][k], 0) << k;                       // the light at azimuth 0: isotropy
    EXPECT_LE(t.columns[1][k], t.columns[3][k] + 1e-7) << k;  // reciprocity: the lower light
    const double z = t.columns[7][k], theta = std::acos(z) * 180 / std::numbers::pi;
    EXPECT_NEAR(theta, t.columns[1][k], 1e-6) << k;
  }
  const std::string json = slurp(path("p.json"));
  EXPECT_NE(json.find("\"format\":\"halfback-plan\""), std::string::npos);
  EXPECT_NE(json.find("\"rows\":" + std::to_string(t.rows())), std::string::npos)
      << json.substr(0, 600);
  EXPECT_NE(json.find("\"row_of_point\":["), std::string::npos);
  EXPECT_NE(r.err.find("fewer by reciprocity"), std::string::npos) << r.err;
  // The sample-turning instrument: its motors in the columns, the same rows; the tilt is θi.
  r = run({"plan", "--param", "halfdiff", "--budget", "500", "--instrument", "sample-turning", "-o",
           "s.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  const CsvTable st = parse(slurp(path("s.csv")));
  EXPECT_EQ(st.header[1], "sample_tilt_deg");
  EXPECT_EQ(st.header[3], "detector_zenith_deg");
  EXPECT_EQ(st.rows(), t.rows());
  for (std::size_t k = 0; k < st.rows(); ++k)
    EXPECT_NEAR(std::acos(st.columns[7][k]) * 180 / std::numbers::pi, st.columns[1][k], 1e-6);
  EXPECT_NE(slurp(path("s.json")).find("\"instrument\":\"sample-turning\""), std::string::npos);
  std::filesystem::remove(path("s.csv"));
  std::filesystem::remove(path("s.json"));
  for (const auto& args :
       std::vector<std::vector<std::string>>{{"plan", "--param", "dirs", "-o", "q.csv"},
                                             {"plan", "--instrument", "turntable", "-o", "q.csv"},
                                             {"plan", "--design", "sobol", "-o", "q.csv"},
                                             {"plan", "--spacing", "learned", "-o", "q.csv"},
                                             {"plan", "--max-theta", "0", "-o", "q.csv"},
                                             {"plan", "-o", "q.txt"}}) {
    r = run(args);
    EXPECT_EQ(r.status, 2) << args[1] << ": " << r.err;
  }
  r = run({"plan", "-o", "missing/q.csv"});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(entries(), (std::vector<std::string>{"p.csv", "p.json"}));
}

// `halfback reconstruct` (docs/acquisition.md): a lab's values at a plan's rows, some missing, back
// to a BRDF that every command reads; a constant ρ comes back as itself. Bad measurements and a
// plan that does not match its setup are data errors naming the line or field; nothing is left.
TEST_F(CliTest, ReconstructFromAPlansMeasurements) {
  Result r = run({"plan", "--param", "hybrid", "--budget", "800", "-o", "p.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  const CsvTable plan = parse(slurp(path("p.csv")));
  std::string lab = "row,value\n";
  const double rho = 0.3 / std::numbers::pi;  // Lambert, albedo 0.3
  for (std::size_t k = 0; k < plan.rows(); ++k)
    if (k % 10 != 3) lab += std::to_string(k) + "," + std::to_string(rho) + "\n";  // 10 % missing
  lab += "3,nan\n";
  put(path("lab.csv"), lab);
  r = run({"reconstruct", "--plan", "p.json", "--measurements", "lab.csv", "-o", "m.binary"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("rows measured"), std::string::npos) << r.err;
  r = run({"eval", "--brdf", "m.binary"},
          std::string(kDirsHeader) + "0.6,0,0.8,-0.3,0.2,0.9327379\n");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NEAR(std::stod(r.out.substr(r.out.find('\n') + 1)), rho, 1e-6) << r.out;

  put(path("twice.csv"), "row,value\n1,0.1\n1,0.2\n");
  put(path("far.csv"), "row,value\n100000,0.1\n");
  put(path("header.csv"), "index,value\n1,0.1\n");
  put(path("negative.csv"), "row,r,g,b\n1,0.1,0.1,0.1\n3,0.1,-0.5,0.1\n");  // was 0 silently
  std::string edited = slurp(path("p.json"));
  edited.replace(edited.find("\"budget\":800"), 12, "\"budget\":900");
  put(path("edited.json"), edited);
  struct Case {
    std::vector<std::string> args;
    int status;
    std::string words;
  };
  for (const Case& c : std::vector<Case>{
           {{"--plan", "p.json", "--measurements", "twice.csv"}, 1, "row 1 is given twice"},
           {{"--plan", "p.json", "--measurements", "far.csv"}, 1, "not a row of the plan"},
           {{"--plan", "p.json", "--measurements", "header.csv"}, 1, "expected the columns row"},
           {{"--plan", "p.json", "--measurements", "negative.csv"},
            1,
            "line 3: row 3: the value is negative"},
           {{"--plan", "edited.json", "--measurements", "lab.csv"}, 1, "row_of_point"},
           {{"--plan", "lab.csv", "--measurements", "lab.csv"}, 1, "lab.csv: json"},
           {{"--plan", "none.json", "--measurements", "lab.csv"}, 1, "none.json"}}) {
    std::vector<std::string> args{"reconstruct", "-o", "n.bsdf"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    r = run(args);
    EXPECT_EQ(r.status, c.status) << c.words << ": " << r.err;
    EXPECT_NE(r.err.find(c.words), std::string::npos) << r.err;
  }
  r = run({"reconstruct", "--plan", "p.json", "--measurements", "lab.csv", "-o", "n.exr"});
  EXPECT_EQ(r.status, 2) << r.err;
  ASSERT_EQ(run({"plan", "--full", "--budget", "500", "-o", "f.csv"}).status, 0);
  r = run({"reconstruct", "--plan", "f.json", "--measurements", "lab.csv", "-o", "n.binary"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_FALSE(std::filesystem::exists(path("n.bsdf")));
  EXPECT_FALSE(std::filesystem::exists(path("n.binary")));
}

// Noisy measurements (rows alternating 0 and 0.6) are not amplified by the reconstruction: the
// fill's and the edges' linear extrapolations are slope-limited (minmod), so no value exceeds
// the largest measurement by much (it reached 1.58 and 2.87, 2.6 and 4.8 times 0.6).
TEST_F(CliTest, ReconstructionDoesNotAmplifyNoisyMeasurements) {
  for (const char* reach : {"80", "90"}) {
    Result r = run({"plan", "--budget", "2000", "--max-theta", reach, "-o", "p.csv"});
    ASSERT_EQ(r.status, 0) << r.err;
    std::string lab = "row,value\n";
    for (std::size_t k = 0; k < parse(slurp(path("p.csv"))).rows(); ++k)
      lab += std::to_string(k) + (k % 2 ? ",0.6\n" : ",0\n");
    put(path("lab.csv"), lab);
    r = run({"reconstruct", "--plan", "p.json", "--measurements", "lab.csv", "-o", "m.binary"});
    ASSERT_EQ(r.status, 0) << r.err;
    r = run({"info", "m.binary"});
    ASSERT_EQ(r.status, 0) << r.err;
    const std::size_t at = r.out.find("max stored ρ:");
    ASSERT_NE(at, std::string::npos) << r.out;
    const std::size_t red = r.out.find('R', at + 14);
    const double largest = std::stod(r.out.substr(red + 1));
    EXPECT_LE(largest, 0.6 * 1.1) << reach << ": " << r.out.substr(at, 80);
    EXPECT_GE(largest, 0.6) << reach;
  }
}

// A parameter's value in a spec's text ("...,alpha=0.2,..." → 0.2).
double spec_value(const std::string& spec, const std::string& name) {
  const std::size_t at = spec.find(name + "=");
  return at == std::string::npos ? std::nan("") : std::stod(spec.substr(at + name.size() + 1));
}

// `fit --plan --measurements` (docs/fit.md): a lab's noisy values at a plan's rows, 10 % missing,
// fitted directly, give the truth's parameters within the noise; a fit to the plan's
// reconstruction is no closer (on a 2000-row plan it is far: α 0.30, f0 1, albedo 0.035 for
// 0.2, 0.6, 0.3: the table's interpolation smears the lobe). The rows not measured and those
// beyond --max-theta are counted.
TEST_F(CliTest, FitToAPlansMeasurementsIsTheFitToItsReconstruction) {
  Result r = run({"plan", "--budget", "2000", "-o", "p.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  const CsvTable plan = parse(slurp(path("p.csv")));
  const auto num = [](double v) {
    std::ostringstream o;
    o.precision(17);
    o << v;
    return o.str();
  };
  std::string dirs = kDirsHeader;
  for (std::size_t k = 0; k < plan.rows(); ++k) {
    for (std::size_t c = 5; c <= 10; ++c) dirs += num(plan.columns[c][k]) + (c < 10 ? "," : "\n");
  }
  const std::string truth = "lambert:albedo=0.3+ggx:alpha=0.2,f0=0.6";
  r = run({"eval", "--brdf", truth}, dirs);
  ASSERT_EQ(r.status, 0) << r.err;
  const CsvTable rho = parse(r.out);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0, 0.02);  // 2 % multiplicative noise
  std::string lab = "row,r,g,b\n";
  std::size_t missing = 0;
  for (std::size_t k = 0; k < plan.rows(); ++k) {
    if (k % 10 == 3) {
      ++missing;
      continue;
    }
    const double f = 1 + noise(rng);
    lab += std::to_string(k) + "," + num(rho.columns[0][k] * f) + "," + num(rho.columns[1][k] * f) +
           "," + num(rho.columns[2][k] * f) + "\n";
  }
  put(path("lab.csv"), lab);
  r = run({"fit", "--plan", "p.json", "--measurements", "lab.csv", "--model", "lambert+ggx", "-o",
           "direct.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string direct = r.out;
  EXPECT_NE(r.err.find(std::to_string(missing) + " samples missing"), std::string::npos) << r.err;
  ASSERT_EQ(run({"reconstruct", "--plan", "p.json", "--measurements", "lab.csv", "-o", "m.binary"})
                .status,
            0);
  r = run({"fit", "--brdf", "m.binary", "--model", "lambert+ggx", "--samples", "20000", "-o",
           "rec.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string reconstructed = r.out;
  for (const char* name : {"alpha", "f0_r", "albedo_r"}) {
    const double truth_value = spec_value(truth, name == std::string("f0_r")       ? "f0"
                                                 : name == std::string("albedo_r") ? "albedo"
                                                                                   : name);
    const double a = spec_value(direct, name), b = spec_value(reconstructed, name);
    EXPECT_NEAR(a, truth_value, 0.05 * truth_value) << name << ": " << direct;
    EXPECT_LE(std::abs(a - truth_value), std::abs(b - truth_value))
        << name << ": " << direct << " vs " << reconstructed;
  }
  // The instrument's reach: rows beyond 60° are counted and left out.
  r = run({"fit", "--plan", "p.json", "--measurements", "lab.csv", "--model", "lambert+ggx",
           "--max-theta", "60", "-o", "reach.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("out of reach (theta above 60 deg)"), std::string::npos) << r.err;
  // Bad pairs of options: usage errors, nothing written.
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"fit", "--plan", "p.json", "--model", "ggx", "-o", "x.json"},
           {"fit", "--measurements", "lab.csv", "--model", "ggx", "-o", "x.json"},
           {"fit", "--brdf", "ggx", "--plan", "p.json", "--measurements", "lab.csv", "--model",
            "ggx", "-o", "x.json"},
           {"fit", "--model", "ggx", "-o", "x.json"},
           {"fit", "--brdf", "ggx", "--model", "ggx", "--max-theta", "95", "-o", "x.json"},
           {"fit", "--plan", "p.json", "--measurements", "lab.csv", "--model", "ggx", "-o",
            "lab.csv"}}) {
    r = run(args);
    EXPECT_EQ(r.status, 2) << r.err;
  }
  // Bad measurements: a value that is not a number, a truncated line, a negative value, a row
  // out of the plan, an empty file: data errors naming the problem, nothing written.
  put(path("word.csv"), "row,r,g,b\n1,0.1,abc,0.1\n");
  put(path("short.csv"), "row,r,g,b\n1,0.1\n");
  put(path("negative.csv"), "row,r,g,b\n1,0.1,-0.2,0.1\n");
  put(path("far.csv"), "row,r,g,b\n100000,0.1,0.1,0.1\n");
  put(path("empty.csv"), "");
  for (const char* bad : {"word.csv", "short.csv", "negative.csv", "far.csv", "empty.csv"}) {
    r = run({"fit", "--plan", "p.json", "--measurements", bad, "--model", "ggx", "-o", "x.json"});
    EXPECT_EQ(r.status, 1) << bad << ": " << r.err;
    EXPECT_NE(r.err.find(bad), std::string::npos) << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(path("x.json")));
  EXPECT_EQ(slurp(path("lab.csv")), lab);
}

// The sequential design for an instrument: the pilot's plan, its measurements, the main stage's
// plan (with the warps in its sidecar), its measurements, the reconstruction.
TEST_F(CliTest, SequentialPlanThroughItsTwoStages) {
  Result r = run({"plan", "--param", "halfdiff", "--design", "sequential", "--budget", "3000", "-o",
                  "pilot.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("the pilot of a sequential design of 3000"), std::string::npos) << r.err;
  const double rho = 0.3 / std::numbers::pi;  // Lambert, albedo 0.3
  auto lab = [&](const std::string& plan, const std::string& out) {
    std::string text = "row,value\n";
    for (std::size_t k = 0; k < parse(slurp(path(plan))).rows(); ++k)
      text += std::to_string(k) + "," + std::to_string(rho) + "\n";
    put(path(out), text);
  };
  lab("pilot.csv", "pv.csv");
  r = run({"plan", "--pilot", "pilot.json", "--pilot-measurements", "pv.csv", "-o", "main.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string sidecar = slurp(path("main.json"));
  EXPECT_NE(sidecar.find("\"learned_warps\""), std::string::npos);
  EXPECT_NE(sidecar.find("\"stage\":\"main\""), std::string::npos);
  lab("main.csv", "mv.csv");
  r = run({"reconstruct", "--plan", "main.json", "--measurements", "mv.csv", "-o", "m.binary"});
  ASSERT_EQ(r.status, 0) << r.err;
  r = run({"eval", "--brdf", "m.binary"},
          std::string(kDirsHeader) + "0.6,0,0.8,-0.3,0.2,0.9327379\n");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NEAR(std::stod(r.out.substr(r.out.find('\n') + 1)), rho, 1e-6) << r.out;

  // A pilot without its measurements, a plan that is no pilot, the pilot's rows twice, nothing
  // measured: refused, nothing written.
  ASSERT_EQ(run({"plan", "--budget", "500", "-o", "grid.csv"}).status, 0);
  put(path("twice.csv"), "row,value\n1,0.1\n1,0.2\n");
  put(path("none.csv"), "row,value\n1,nan\n");
  std::string negative = "row,value\n";  // every pilot value -1: a main stage was written
  for (std::size_t k = 0; k < parse(slurp(path("pilot.csv"))).rows(); ++k)
    negative += std::to_string(k) + ",-1\n";
  put(path("negative.csv"), negative);
  struct Case {
    std::vector<std::string> args;
    int status;
    std::string words;
  };
  for (const Case& c : std::vector<Case>{
           {{"--pilot", "pilot.json"}, 2, "go together"},
           {{"--pilot", "grid.json", "--pilot-measurements", "pv.csv"}, 2, "not the pilot"},
           {{"--pilot", "main.json", "--pilot-measurements", "pv.csv"}, 2, "not the pilot"},
           {{"--pilot", "pilot.json", "--pilot-measurements", "twice.csv"}, 1, "given twice"},
           {{"--pilot", "pilot.json", "--pilot-measurements", "none.csv"}, 1, "no row"},
           {{"--pilot", "pilot.json", "--pilot-measurements", "negative.csv"},
            1,
            "row 0: the value is negative"},
           {{"--design", "sequential", "--full"}, 2, "sequential (isotropic)"},
           // The setup is the pilot's: an option of the setup beside --pilot is refused (the
           // main stage of a sample-turning pilot was written for it when light-detector was
           // asked).
           {{"--pilot", "pilot.json", "--pilot-measurements", "pv.csv", "--instrument",
             "sample-turning"},
            2,
            "--instrument with --pilot"},
           {{"--pilot", "pilot.json", "--pilot-measurements", "pv.csv", "--budget", "100"},
            2,
            "--budget with --pilot"},
           {{"--pilot", "pilot.json", "--pilot-measurements", "pv.csv", "--param", "halfdiff",
             "--design", "regular"},
            2,
            "--param with --pilot"},
           // A reach that no cell's point is within: nothing to measure (a plan of 0 positions
           // was written, status 0).
           {{"--max-theta", "1"}, 2, "nothing to measure"}}) {
    std::vector<std::string> args{"plan", "-o", "bad.csv"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    r = run(args);
    EXPECT_EQ(r.status, c.status) << c.words << ": " << r.err;
    EXPECT_NE(r.err.find(c.words), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(path("bad.csv"))) << c.words;
    EXPECT_FALSE(std::filesystem::exists(path("bad.json"))) << c.words;
  }
}

// A laboratory: `truth` measured at the rows of the plan `plan` (its wi, wo columns), written as
// `halfback reconstruct --measurements` reads them; `skip`: a row left unmeasured.
void measure_plan(const fs::path& plan, const Brdf& truth, const fs::path& out, long skip = -1) {
  const CsvTable t = parse(slurp(plan));
  std::string text = "row,r,g,b\n";
  for (std::size_t k = 0; k < t.rows(); ++k) {
    if (long(k) == skip) continue;
    const DirPair<double> p{{t.columns[5][k], t.columns[6][k], t.columns[7][k]},
                            {t.columns[8][k], t.columns[9][k], t.columns[10][k]}};
    const Rgb v = truth.eval(p);
    text += std::to_string(k) + "," + format_csv_number(v.r) + "," + format_csv_number(v.g) + "," +
            format_csv_number(v.b) + "\n";
  }
  put(out, text);
}

// Dupuy & Jakob's layout planned in its two stages, measured and reconstructed as an RGL file:
// the file export-rgl writes of the truth in the same layout (the study's dupuy-jakob design),
// value for value; the wrong stage, a row not measured, an edited sidecar refused, nothing written.
TEST_F(CliTest, DupuyJakobPlanThroughItsTwoStages) {
  const BrdfPtr truth = load_brdf("lambert:albedo=0.2+ggx:alpha=0.2,f0=0.8");
  Result r = run({"plan", "--design", "dupuy-jakob", "--budget", "1000", "-o", "retro.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("the retro-reflection of Dupuy & Jakob's layout of 1000"), std::string::npos)
      << r.err;
  measure_plan(path("retro.csv"), *truth, path("rv.csv"));
  r = run({"plan", "--pilot", "retro.json", "--pilot-measurements", "rv.csv", "-o", "slices.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(path("slices.json")).find("\"retro_values\""), std::string::npos);
  measure_plan(path("slices.csv"), *truth, path("sv.csv"));
  r = run({"reconstruct", "--plan", "slices.json", "--measurements", "sv.csv", "-o", "m.bsdf"});
  ASSERT_EQ(r.status, 0) << r.err;
  // Layout of 1000: 62 retro-reflection nodes, 8 slices of 10 x 10.
  r = run({"export-rgl", "--brdf", "lambert:albedo=0.2+ggx:alpha=0.2,f0=0.8", "--theta-i", "8",
           "--resolution", "10", "--vndf-resolution", "62", "--incidences", "sigma", "--tabulation",
           "point", "-o", "study.bsdf"});
  ASSERT_EQ(r.status, 0) << r.err;
  const BrdfPtr lab = load_brdf(path("m.bsdf").string()),
                study = load_brdf(path("study.bsdf").string());
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (int k = 0; k < 500; ++k) {
    const auto dir = [&] {
      const double z = u(rng), phi = 2 * kPi * u(rng), s = std::sqrt(1 - z * z);
      return Vec3<double>{s * std::cos(phi), s * std::sin(phi), z};
    };
    const DirPair<double> p{dir(), dir()};
    const Rgb a = lab->eval(p), b = study->eval(p);
    ASSERT_EQ(a.g, b.g) << k;
    ASSERT_EQ(a.r, b.r) << k;
  }
  r = run({"reconstruct", "--plan", "slices.json", "--measurements", "sv.csv", "-o", "m.binary"});
  ASSERT_EQ(r.status, 0) << r.err;

  measure_plan(path("retro.csv"), *truth, path("rv-missing.csv"), 2);
  measure_plan(path("slices.csv"), *truth, path("sv-missing.csv"), 5);
  std::string edited = slurp(path("slices.json"));
  edited.insert(edited.find("\"retro_values\":[[") + 17, "2");
  put(path("edited.json"), edited);
  struct Case {
    std::vector<std::string> args;
    int status;
    std::string words;
  };
  for (const Case& c : std::vector<Case>{
           {{"plan", "--design", "dupuy-jakob", "--param", "halfdiff"}, 2, "--param with"},
           {{"plan", "--design", "dupuy-jakob", "--max-theta", "80"}, 2, "--max-theta with"},
           {{"plan", "--design", "dupuy-jakob", "--budget", "40"}, 2, "below its smallest"},
           {{"plan", "--pilot", "slices.json", "--pilot-measurements", "sv.csv"},
            2,
            "not the pilot"},
           {{"plan", "--pilot", "retro.json", "--pilot-measurements", "rv-missing.csv"},
            1,
            "row 2 was not measured"},
           {{"plan", "--pilot", "edited.json", "--pilot-measurements", "rv.csv"}, 1, "edited"},
           {{"reconstruct", "--plan", "retro.json", "--measurements", "rv.csv"},
            2,
            "not a material"},
           {{"reconstruct", "--plan", "slices.json", "--measurements", "sv-missing.csv"},
            1,
            "row 5 was not measured"},
           {{"reconstruct", "--plan", "edited.json", "--measurements", "sv.csv"}, 1, "edited"}}) {
    std::vector<std::string> args = c.args;
    const bool plan = args[0] == "plan";
    args.insert(args.end(), {"-o", plan ? "bad.csv" : "bad.bsdf"});
    r = run(args);
    EXPECT_EQ(r.status, c.status) << c.words << ": " << r.err;
    EXPECT_NE(r.err.find(c.words), std::string::npos) << r.err;
    for (const char* f : {"bad.csv", "bad.json", "bad.bsdf"})
      EXPECT_FALSE(fs::exists(path(f))) << c.words;
  }
  // The main stage's sidecar would replace the pilot's: refused (the output rule), nothing written.
  r = run({"plan", "--pilot", "retro.json", "--pilot-measurements", "rv.csv", "-o", "retro.csv"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(slurp(path("retro.json")).find("\"stage\":\"retro-reflection\""), std::string::npos);
}

// Nielsen's design planned from a database, measured and reconstructed through its basis; the
// learned design planned from BRDFs' profiles. Without their inputs, or with others, refused.
TEST_F(CliTest, NielsenAndLearnedPlans) {
  const BrdfPtr truth = load_brdf("lambert:albedo=0.3+ggx:alpha=0.25,f0=0.7");
  const std::vector<std::string> database{"--database", "lambert:albedo=0.5",
                                          "--database", "lambert:albedo=0.1+ggx:alpha=0.2,f0=0.9",
                                          "--database", "lambert:albedo=0.3+ggx:alpha=0.4"};
  // Without regularization (--eta 0), a member of the database measured at as many directions as
  // the basis has components is the member: the reconstruction goes through the basis.
  const BrdfPtr member = load_brdf("lambert:albedo=0.1+ggx:alpha=0.2,f0=0.9");
  std::vector<std::string> args{"plan", "--design",    "nielsen", "--count", "8",    "--eta",
                                "0",    "--max-theta", "85",      "-o",      "n.csv"};
  args.insert(args.end(), database.begin(), database.end());
  Result r = run(args);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(parse(slurp(path("n.csv"))).rows(), 8u);
  measure_plan(path("n.csv"), *member, path("nv.csv"));
  args = {"reconstruct", "--plan", "n.json", "--measurements", "nv.csv", "-o", "n.binary"};
  args.insert(args.end(), database.begin(), database.end());
  r = run(args);
  ASSERT_EQ(r.status, 0) << r.err;
  const DirPair<double> p{{0.6, 0, 0.8}, {-0.3, 0.2, 0.9327379}};
  const BrdfPtr nielsen = load_brdf(path("n.binary").string());
  for (const DirPair<double>& q : {p, DirPair<double>{{0.3, 0, 0.9539392}, {0.5, -0.5, 0.7071068}}})
    EXPECT_NEAR(nielsen->eval(q).g, member->eval(q).g, 0.02 * member->eval(q).g);  // MERL's bins

  r = run({"plan", "--design", "learned", "--param", "halfdiff", "--budget", "2000", "--database",
           "lambert:albedo=0.5+ggx:alpha=0.05", "--database", "lambert:albedo=0.2+ggx:alpha=0.3",
           "-o", "l.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(path("l.json")).find("\"learned_warps\""), std::string::npos);
  measure_plan(path("l.csv"), *truth, path("lv.csv"));
  r = run({"reconstruct", "--plan", "l.json", "--measurements", "lv.csv", "-o", "l.binary"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NEAR(load_brdf(path("l.binary").string())->eval(p).g, truth->eval(p).g,
              0.05 * truth->eval(p).g);

  struct Case {
    std::vector<std::string> args;
    int status;
    std::string words;
  };
  std::vector<std::string> other_db{"--database", "lambert:albedo=0.5", "--database",
                                    "lambert:albedo=0.2+ggx:alpha=0.3"};
  std::vector<std::string> reconstruct_other{"reconstruct", "--plan", "n.json", "--measurements",
                                             "nv.csv"};
  reconstruct_other.insert(reconstruct_other.end(), other_db.begin(), other_db.end());
  std::vector<std::string> too_many{"plan", "--design", "nielsen", "--count", "1000000"};
  too_many.insert(too_many.end(), database.begin(), database.end());
  for (const Case& c : std::vector<Case>{
           {{"plan", "--design", "nielsen", "--count", "3"}, 2, "needs its --database"},
           {{"plan", "--design", "nielsen", "--database", "lambert", "--database", "ggx"},
            2,
            "needs --budget"},
           {{"plan", "--design", "nielsen", "--count", "3", "--database", "lambert"},
            2,
            "at least two"},
           {{"plan", "--design", "nielsen", "--count", "3", "--database", "no-such.binary",
             "--database", "lambert"},
            2,
            "no-such.binary"},
           {too_many, 2, "--budget 1000000: expected 1 to"},
           {{"plan", "--design", "nielsen", "--budget", "3", "--eta", "1", "--database", "lambert",
             "--database", "ggx", "--full"},
            2,
            "--full with --design nielsen"},
           {{"plan", "--design", "learned"}, 2, "needs what to learn from"},
           {{"plan", "--design", "learned", "--database", "lambert", "--leave-out", "lambert"},
            2,
            "needs the profiles of other BRDFs"},
           {{"plan", "--design", "learned", "--profiles", "none.profile"}, 1, "none.profile"},
           {{"plan", "--design", "regular", "--database", "lambert"}, 2, "--database with"},
           {{"reconstruct", "--plan", "n.json", "--measurements", "nv.csv"},
            2,
            "give its --database"},
           {reconstruct_other, 1, "planned in the database"},
           {{"reconstruct", "--plan", "l.json", "--measurements", "lv.csv", "--database", "ggx"},
            2,
            "only a plan of Nielsen's design"}}) {
    std::vector<std::string> a = c.args;
    const bool plan = a[0] == "plan";
    a.insert(a.end(), {"-o", plan ? "bad.csv" : "bad.binary"});
    r = run(a);
    EXPECT_EQ(r.status, c.status) << c.words << ": " << r.err;
    EXPECT_NE(r.err.find(c.words), std::string::npos) << r.err;
    for (const char* f : {"bad.csv", "bad.json", "bad.binary"})
      EXPECT_FALSE(fs::exists(path(f))) << c.words;
  }
}

// A large plan's sidecar (one JSON line of megabytes) is read back whole: the sidecar's bound is
// that of the largest plan, not the 1 MiB of a text line (plan → reconstruct failed above a
// budget of about 170 000; the pilot of a sequential 10⁶, 1.5 MB, could not be planned on).
TEST_F(CliTest, LargePlansReadBackTheirSidecars) {
  const auto measure_all = [&](const std::string& plan, const std::string& out) {
    std::string text = "row,value\n";
    const std::string csv = slurp(path(plan));
    const std::size_t rows = std::size_t(std::count(csv.begin(), csv.end(), '\n')) - 1;
    for (std::size_t k = 0; k < rows; ++k) text += std::to_string(k) + ",0.1\n";
    put(path(out), text);
  };
  Result r = run({"plan", "--budget", "300000", "-o", "big.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_GT(fs::file_size(path("big.json")), std::uintmax_t(1) << 20);
  measure_all("big.csv", "lab.csv");
  r = run({"reconstruct", "--plan", "big.json", "--measurements", "lab.csv", "-o", "m.binary"});
  EXPECT_EQ(r.status, 0) << r.err;
  r = run({"plan", "--design", "sequential", "--budget", "1000000", "-o", "pilot.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_GT(fs::file_size(path("pilot.json")), std::uintmax_t(1) << 20);
  measure_all("pilot.csv", "pv.csv");
  r = run({"plan", "--pilot", "pilot.json", "--pilot-measurements", "pv.csv", "-o", "main.csv"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("the main stage of a sequential design of 1000000"), std::string::npos)
      << r.err;
}

// ---------------------------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------------------------

struct BadInput {
  std::string name;
  std::vector<std::string> args;
  std::string input;
  std::string message;  // stderr after "halfback convert: error: "
};

TEST_F(CliTest, BadInputIsAnErrorNamingTheLine) {
  const std::string h = kDirsHeader, ok = "0,0,1,0.6,0,0.8\n";
  const std::vector<std::string> d2h{"convert", "--from", "dirs", "--to", "hybrid", "-i", "in.csv"};
  const BadInput cases[] = {
      {"wrong column count", d2h, h + ok + ok + "0,0,1,0.6,0\n",
       "in.csv:4: expected 6 fields (wi_x,wi_y,wi_z,wo_x,wo_y,wo_z), found 5"},
      {"trailing comma", d2h, h + ok + "0,0,1,0.6,0,0.8,\n",
       "in.csv:3: expected 6 fields (wi_x,wi_y,wi_z,wo_x,wo_y,wo_z), found 7 (a trailing comma?)"},
      {"not a number", d2h, h + ok + "0,0,1,0.6,zero,0.8\n",
       "in.csv:3: column wo_y: 'zero' is not a number"},
      {"empty field", d2h, h + "0,0,1,,0,0.8\n", "in.csv:2: column wo_x: empty field"},
      {"nan", d2h, h + ok + "0,0,1,0.6,nan,0.8\n",
       "in.csv:3: column wo_y: 'nan' is not a finite number"},
      {"inf", d2h, h + "0,0,inf,0.6,0,0.8\n",
       "in.csv:2: column wi_z: 'inf' is not a finite number"},
      {"out of range", d2h, h + "0,0,1e999,0.6,0,0.8\n",
       "in.csv:2: column wi_z: '1e999' is out of the range of a double"},
      {"not unit", d2h, h + ok + ok + ok + "0,0,1,0.6,0,0.8002\n",
       "in.csv:5: wo is not a unit vector (|wo|^2 - 1 = 3.2e-04)"},
      {"wi not unit", d2h, h + "0,0,0.5,0.6,0,0.8\n",
       "in.csv:2: wi is not a unit vector (|wi|^2 - 1 = -7.5e-01)"},
      {"below horizon", d2h, h + ok + "0.6,0,-0.8,0,0,1\n",
       "in.csv:3: wi is below the horizon (wi_z < 0): wi_z = -0.8"},
      {"wo below horizon", d2h, h + "0,0,1,0.6,0,-0.8\n",
       "in.csv:2: wo is below the horizon (wo_z < 0): wo_z = -0.8"},
      {"blank line inside", d2h, h + ok + "\n" + ok,
       "in.csv:3: empty line inside the data (blank lines are allowed only at the end)"},
      {"empty file", d2h, "", "in.csv: the input is empty (expected a header row)"},
      {"no header", d2h, ok + ok,
       "in.csv:1: header does not match: expected 'wi_x,wi_y,wi_z,wo_x,wo_y,wo_z', found "
       "'0,0,1,0.6,0,0.8'; the first line looks like data: the input needs a header row"},
      {"header of another form", d2h, "theta_h,phi_h,theta_d,phi_d\n0.1,0,0.1,0\n",
       "in.csv:1: header does not match: expected 'wi_x,wi_y,wi_z,wo_x,wo_y,wo_z', found "
       "'theta_h,phi_h,theta_d,phi_d'; these are the columns of '--from halfdiff'"},
      {"isotropic header without --isotropic",
       {"convert", "--from", "ortho", "--to", "dirs", "-i", "in.csv"},
       "hbar,kbar,dphi\n",
       "in.csv:1: header does not match: expected 'hbar,phi_h,kbar,phi_k', found "
       "'hbar,kbar,dphi'; these are the columns of '--from ortho --isotropic'"},
      {"4D header with --isotropic",
       {"convert", "--from", "ortho", "--to", "dirs", "--isotropic", "-i", "in.csv"},
       "hbar,phi_h,kbar,phi_k\n",
       "in.csv:1: header does not match: expected 'hbar,kbar,dphi', found "
       "'hbar,phi_h,kbar,phi_k'; these are the columns of '--from ortho' (without --isotropic)"},
      {"columns reordered", d2h, "wi_x,wi_y,wi_z,wo_y,wo_x,wo_z\n" + ok,
       "in.csv:1: header does not match: expected 'wi_x,wi_y,wi_z,wo_x,wo_y,wo_z', found "
       "'wi_x,wi_y,wi_z,wo_y,wo_x,wo_z'"},
      {"nan in a parameterization",
       {"convert", "--from", "halfdiff", "--to", "dirs", "-i", "in.csv"},
       "theta_h,phi_h,theta_d,phi_d\n0.1,0,0.1,0\n0.1,NaN,0.1,0\n",
       "in.csv:3: column phi_h: 'NaN' is not a finite number"},
      {"unterminated quote", d2h, h + "0,0,1,\"0.6,0,0.8\n", "in.csv:2: unterminated quoted field"},
  };
  for (const BadInput& c : cases) {
    SCOPED_TRACE(c.name);
    put(path("in.csv"), c.input);
    const Result r = run(c.args);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err, "halfback convert: error: " + c.message + "\n");
    EXPECT_EQ(r.out, "");  // nothing on stdout
  }
}

TEST_F(CliTest, StdinIsNamedInMessages) {
  std::string input = kDirsHeader;  // appended apart: GCC 12's -Warray-bounds on string + literal
  input += "1,0,0,0,1,0.5\n";
  const Result r = run({"convert", "--from", "dirs", "--to", "ortho"}, input);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err,
            "halfback convert: error: <stdin>:2: wo is not a unit vector (|wo|^2 - 1 = 2.5e-01)\n");
}

TEST_F(CliTest, SkipInvalidWritesValidZeroRows) {
  const std::string in = std::string(kDirsHeader) +
                         "0,0,1,0.6,0,0.8\n"     // 2 ok
                         "0,0,1,0.6,0,0.8002\n"  // 3 not unit
                         "0,0,1,0.6,nan,0.8\n"   // 4 nan
                         "0,0,1,0.6,0\n"         // 5 wrong count
                         "0,0,1,x,0,0.8\n"       // 6 not a number
                         "0.6,0,-0.8,0,0,1\n"    // 7 below the horizon
                         "0,0,1,0,0,1\n";        // 8 ok
  const Result r =
      run({"convert", "--from", "dirs", "--to", "halfdiff", "--jacobian", "--skip-invalid"}, in);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err,
            "halfback convert: warning: 5 invalid input rows written with valid = 0; the first: "
            "<stdin>:3: wo is not a unit vector (|wo|^2 - 1 = 3.2e-04)\n");
  const CsvTable t = parse(r.out);
  ASSERT_EQ(t.header, header_of(column_names({space_of<HalfDiff>, false}), {"valid", "jacobian"}));
  ASSERT_EQ(t.rows(), 7u);
  EXPECT_EQ(t.columns[4], (std::vector<double>{1, 0, 0, 0, 0, 0, 1}));
  for (std::size_t row = 1; row <= 5; ++row)
    for (std::size_t c : {0u, 1u, 2u, 3u, 5u}) EXPECT_TRUE(std::isnan(t.columns[c][row]));
  EXPECT_TRUE(std::isfinite(t.columns[0][0]));
  EXPECT_TRUE(std::isfinite(t.columns[0][6]));

  // A parameterization input: a NaN row becomes a valid = 0 row, like an out-of-domain one.
  const Result p = run({"convert", "--from", "hybrid", "--to", "dirs", "--skip-invalid"},
                       "hbar,phi_h,k,phi_k\n0.3,0,0.3,0\nnan,0,0.3,0\n0.9,0,0.9,0\n");
  ASSERT_EQ(p.status, 0) << p.err;
  EXPECT_EQ(p.err,
            "halfback convert: warning: 1 invalid input row written with valid = 0; the first: "
            "<stdin>:3: column hbar: 'nan' is not a finite number\n");
  EXPECT_EQ(parse(p.out).columns[6], (std::vector<double>{1, 0, 0}));
}

TEST_F(CliTest, MissingInputFile) {
  const Result r = run({"convert", "--from", "dirs", "--to", "hybrid", "-i", "missing.csv"});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err,
            "halfback convert: error: cannot read 'missing.csv': No such file or directory\n");
  EXPECT_EQ(r.out, "");
}

TEST_F(CliTest, UnwritableOutput) {
  put(path("in.csv"), std::string(kDirsHeader) + "0,0,1,0.6,0,0.8\n");
  put(path("file"), "x");
  Result r =
      run({"convert", "--from", "dirs", "--to", "hybrid", "-i", "in.csv", "-o", "nodir/out.csv"});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err,
            "halfback convert: error: cannot write 'nodir/out.csv': No such file or directory\n");
  r = run({"convert", "--from", "dirs", "--to", "hybrid", "-i", "in.csv", "-o", "file/out.csv"});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "halfback convert: error: cannot write 'file/out.csv': Not a directory\n");
  r = run({"convert", "--from", "dirs", "--to", "hybrid", "-i", "in.csv", "-o", "."});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "halfback convert: error: cannot write '.': Is a directory\n");
  if (geteuid() != 0) {  // root ignores directory permissions
    fs::create_directory(path("ro"));
    fs::permissions(path("ro"), fs::perms::owner_read | fs::perms::owner_exec);
    r = run({"convert", "--from", "dirs", "--to", "hybrid", "-i", "in.csv", "-o", "ro/out.csv"});
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err, "halfback convert: error: cannot write 'ro/out.csv': Permission denied\n");
  }
  EXPECT_EQ(entries(), (std::vector<std::string>{"file", "in.csv"}));
}

TEST_F(CliTest, ExistingOutputIsKeptWhenTheInputIsBad) {
  put(path("out.csv"), "precious\n");
  const std::vector<std::string> bad_inputs = {
      std::string(kDirsHeader) + "0,0,1,0.6,0,0.8\n0,0,1,0.6,0,0.9\n",  // not unit (line 3)
      std::string(kDirsHeader) + "0,0,1,0.6\n",                         // column count
      "theta_h,phi_h,theta_d,phi_d\n",                                  // header
      "",                                                               // empty
  };
  for (const auto& bad : bad_inputs) {
    put(path("in.csv"), bad);
    const Result r =
        run({"convert", "--from", "dirs", "--to", "hybrid", "-i", "in.csv", "-o", "out.csv"});
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(slurp(path("out.csv")), "precious\n");
    EXPECT_EQ(entries(), (std::vector<std::string>{"in.csv", "out.csv"}));
  }
  // A missing input and a usage error leave it too.
  EXPECT_EQ(run({"convert", "--from", "dirs", "--to", "hybrid", "-i", "nope.csv", "-o", "out.csv"})
                .status,
            1);
  EXPECT_EQ(
      run({"convert", "--from", "dirs", "--to", "dirs", "--isotropic", "-o", "out.csv"}).status, 2);
  EXPECT_EQ(slurp(path("out.csv")), "precious\n");
  EXPECT_EQ(entries(), (std::vector<std::string>{"in.csv", "out.csv"}));

  // A good input replaces it.
  put(path("in.csv"), std::string(kDirsHeader) + "0,0,1,0,0,1\n");
  const Result r =
      run({"convert", "--from", "dirs", "--to", "hybrid", "-i", "in.csv", "-o", "out.csv"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(path("out.csv")), "hbar,phi_h,k,phi_k\n0,0,0,0\n");
}

// ---------------------------------------------------------------------------------------------
// The BRDF commands: models, eval, info, export-merl, resample
// ---------------------------------------------------------------------------------------------

TEST_F(CliTest, ModelsListsEveryModelWithItsParameters) {
  const Result r = run({"models"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* s : {"lambert", "ggx", "beckmann", "abc", "sheen", "test", "albedo", "alpha_x",
                        "default 0.2, in [0.001, 10]", "one of F | S | G",
                        "roughness along t (default: alpha, in [0.001, 10])",
                        "red channel (default: albedo, in [0, 1])"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
  // No sentinel shown as a bound: the only negative bounds are Lafortune's Cxy, whose range is
  // [-1, 1] indeed, and Bagher et al.'s Fresnel rows and shadowing onset (published F0, F1 down to
  // -1, theta0 to -0.66).
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    const std::string_view l = line;
    if (l.find("-1") == l.npos && l.find("-3") == l.npos) continue;
    const bool signed_param =
        l.find("Cxy") != l.npos || l.find("BBM's eta") != l.npos || l.find("theta0") != l.npos;
    EXPECT_TRUE(signed_param) << "a sentinel is shown as a bound: " << l;
  }
}

// docs/reliability/cli.md: a value below a parameter's range is an error, not "not given".
TEST_F(CliTest, ModelParametersOutOfRangeAreErrors) {
  const std::string in = std::string(kDirsHeader) + "0,0,1,0,0,1\n";
  for (const char* spec :
       {"lambert:albedo_r=-0.3", "ggx:f0_r=-0.5", "ggx:alpha_x=-0.5", "ggx:alpha_y=0.0001"}) {
    const Result r = run({"eval", "--brdf", spec}, in);
    EXPECT_NE(r.status, 0) << spec << " was accepted:\n" << r.out;
    const std::string name(spec + std::string(spec).find(':') + 1);
    EXPECT_NE(r.err.find(name + " is outside ["), std::string::npos) << r.err;
  }
}

// Lambert is ρ = albedo/π; GGX at normal incidence and normal view is D(0) F0 G / (4 cos²) with
// D(0) = 1/(π α²) and G = 1 (Smith at normal incidence): values computed here.
TEST_F(CliTest, EvalGivesClosedFormValuesAndZeroBelowTheHorizon) {
  const std::string input = std::string(kDirsHeader) +
                            "0,0,1,0,0,1\n"
                            "0.6,0,0.8,-0.6,0,0.8\n"
                            "0,0,1,0.6,0,-0.8\n";
  Result r = run({"eval", "--brdf", "lambert:albedo=0.5"}, input);
  ASSERT_EQ(r.status, 0) << r.err;
  CsvTable t = parse(r.out);
  ASSERT_EQ(t.header, (std::vector<std::string>{"r", "g", "b"}));
  ASSERT_EQ(t.rows(), 3u);
  for (int c = 0; c < 3; ++c) {
    EXPECT_DOUBLE_EQ(t.columns[c][0], 0.5 / kPi);
    EXPECT_DOUBLE_EQ(t.columns[c][1], 0.5 / kPi);
    EXPECT_EQ(t.columns[c][2], 0.0);
  }
  r = run({"eval", "--brdf", "ggx:alpha=0.3,f0=0.9", "-i", "in.csv", "-o", "out.csv"});
  EXPECT_NE(r.status, 0);  // no such input file
  put(path("in.csv"), std::string(kDirsHeader) + "0,0,1,0,0,1\n");
  r = run({"eval", "--brdf", "ggx:alpha=0.3,f0=0.9", "-i", "in.csv", "-o", "out.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  t = parse(slurp(path("out.csv")));
  EXPECT_NEAR(t.columns[0][0], 0.9 / (kPi * 0.09) / 4, 1e-12);
}

// docs/reliability/numerics.md: eval takes a direction within the unit tolerance as
// `convert` does, put onto the unit sphere (accept_pair): a grazing mirror pair with |ωi| = 1 +
// 4e-7 gives the ρ of the unit pair (GGX α = 0.001: 6.55e12, not the 2.48e6 of the tilted half
// vector), and sheen's value at a pair off unit length by −4e-7 is that of the unit pair.
TEST_F(CliTest, EvalNormalizesNearUnitDirectionsAsConvertDoes) {
  const double t = 89 * kPi / 180, s = std::sin(t), c = std::cos(t);
  for (const auto& [spec, scale] :
       {std::pair{"ggx:alpha=0.001", 1 + 4e-7}, std::pair{"sheen:alpha=0.3", 1 - 4e-7}}) {
    const std::array<double, 6> near{s * scale, 0, c * scale, -s, 0, c};
    const Result got =
        run({"eval", "--brdf", spec}, std::string(kDirsHeader) + fmt_row(near) + "\n");
    ASSERT_EQ(got.status, 0) << got.err;
    const double norm = std::sqrt(near[0] * near[0] + near[2] * near[2]);
    const Rgb unit = load_brdf(spec)->eval({{near[0] / norm, 0, near[2] / norm}, {-s, 0, c}});
    const double value = parse(got.out).columns[1][0];
    EXPECT_NEAR(value, unit.g, 1e-9 * std::abs(unit.g) + 1e-12) << spec;
  }
}

TEST_F(CliTest, EvalBadInput) {
  Result r = run({"eval", "--brdf", "lambert"}, std::string(kDirsHeader) + "0,0,1,0,0.5,0.5\n");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("<stdin>:2: wo is not a unit vector"), std::string::npos) << r.err;
  r = run({"eval", "--brdf", "lambert"}, "a,b\n1,2\n");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("header does not match"), std::string::npos) << r.err;
  r = run({"eval", "--brdf", "glossy:alpha=2"}, std::string(kDirsHeader));
  EXPECT_EQ(r.status, 2);  // a spec that names nothing: the command line's (class H)
  EXPECT_NE(r.err.find("'glossy:alpha=2' is neither an existing file nor a known BRDF model"),
            std::string::npos)
      << r.err;
  r = run({"eval", "--brdf", "ggx:alpha=-1"}, std::string(kDirsHeader));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("alpha"), std::string::npos) << r.err;
  put(path("out.csv"), "keep me\n");
  r = run({"eval", "--brdf", "lambert", "-o", "out.csv"}, std::string(kDirsHeader) + "1,2,3\n");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(slurp(path("out.csv")), "keep me\n");
  EXPECT_EQ(entries(), (std::vector<std::string>{"out.csv"}));
}

TEST_F(CliTest, InfoOfAModelAndOfAMerlFileItWrote) {
  Result r = run({"info", "lambert:albedo=0.25"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("isotropic:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("albedo at θi = 60°:    0.25, 0.25, 0.25"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0.0795775"), std::string::npos) << r.out;  // max ρ = 0.25/π

  r = run({"export-merl", "--brdf", "ggx:alpha=0.3,f0=0.5", "-o", "ggx.binary"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(fs::file_size(path("ggx.binary")), 34992012u);
  r = run({"info", "ggx.binary"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* s :
       {"merl:ggx", "MERL .binary", "unmeasured bins:", "sha256:", "not one of the 100 published"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
  // The file evaluates like the model at a bin centre away from any bin edge.
  const double th = std::pow(40.5 / 90, 2) * kPi / 2, td = 30.5 / 90 * kPi / 2,
               pd = 60.5 / 180 * kPi;
  std::array<double, 6> d{};
  ASSERT_TRUE(convert_one<double>({space_of<HalfDiff>, true}, {Space::dirs, false},
                                  std::array<double, 3>{th, td, pd}, d));
  const std::string input = std::string(kDirsHeader) + fmt_row(d) + "\n";
  const Result a = run({"eval", "--brdf", "ggx.binary"}, input);
  const Result b = run({"eval", "--brdf", "ggx:alpha=0.3,f0=0.5"}, input);
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(b.status, 0) << b.err;
  const CsvTable ta = parse(a.out), tb = parse(b.out);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(ta.columns[c][0], tb.columns[c][0], 1e-9 * tb.columns[c][0]);
}

// The shared data folder (../shared/data/SUB from HALFBACK_SHARED_DIR, which CTest sets), or ""
// when it is absent (the test then skips, or fails under CI=true).
fs::path shared_data(const std::string& sub) {
  const char* dir = std::getenv("HALFBACK_SHARED_DIR");
  const fs::path p = fs::path(dir && *dir ? dir : HALFBACK_SOURCE_DIR "/../shared") / "data" / sub;
  std::error_code ec;
  return fs::exists(p, ec) ? p : fs::path{};
}

TEST_F(CliTest, InfoAndEvalOfAnEmbeddedNeuralBrdf) {
  Result r = run({"info", "embedded:pink-felt"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* s : {"nbrdf:pink-felt", "Keras HDF5", "6-21-21-3", "675 float32",
                        "source:", "embedded:pink-felt", "albedo at θi = 60°:"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
  // Below the horizon: 0; above: positive, finite values.
  r = run({"eval", "--brdf", "embedded:pink-felt"},
          std::string(kDirsHeader) + "0.6,0,0.8,-0.6,0,0.8\n0,0,1,0.6,0,-0.8\n");
  ASSERT_EQ(r.status, 0) << r.err;
  const CsvTable t = parse(r.out);
  ASSERT_EQ(t.rows(), 2u);
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(t.columns[c][0], 0.0);
    EXPECT_LT(t.columns[c][0], 10.0);
    EXPECT_EQ(t.columns[c][1], 0.0);
  }
}

TEST_F(CliTest, EvalOfTheH5AndNpyFormsOfANeuralBrdfAgree) {
  const fs::path dir = shared_data("nbrdf/merl_nbrdf");
  if (dir.empty()) {
    const char* ci = std::getenv("CI");
    if (ci && std::string(ci) == "true") FAIL() << "../shared/data/nbrdf is missing under CI";
    GTEST_SKIP() << "../shared/data/nbrdf not found (set HALFBACK_SHARED_DIR)";
  }
  const std::string input = dirs_csv(well_conditioned_pairs(50, 5));
  const Result a = run({"eval", "--brdf", (dir / "blue-acrylic.h5").string()}, input);
  const Result b = run({"eval", "--brdf", (dir / "npy").string()}, input);
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_EQ(a.out, b.out);
  EXPECT_EQ(parse(a.out).rows(), 50u);
  const Result info = run({"info", (dir / "npy").string()});
  ASSERT_EQ(info.status, 0) << info.err;
  EXPECT_NE(info.out.find("NumPy .npy files"), std::string::npos) << info.out;
  // A folder that is not the NumPy form is an error naming it.
  const Result bad = run({"info", dir.string()});
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("NumPy form of a neural BRDF"), std::string::npos) << bad.err;
}

// docs/reliability/readers.md: unmeasured MERL bins are missing, never a negative ρ;
// the albedo is the mean over the measured directions, with the fraction measured shown.
TEST_F(CliTest, UnmeasuredMerlBinsAreMissingInEvalAndInfo) {
  Result r = run({"export-merl", "--brdf", "ggx:alpha=0.3,f0=0.5", "-o", "ggx.binary"});
  ASSERT_EQ(r.status, 0) << r.err;
  const double deg = kPi / 180;
  const std::array<double, 6> grazing{
      std::sin(89.9 * deg), 0, std::cos(89.9 * deg), 0, std::sin(80 * deg), std::cos(80 * deg)};
  // Every bin a valid pair can be looked up in is written: the grazing pair's bin is unmeasured
  // only where a measurement left it so (marked -1 here).
  r = run({"eval", "--brdf", "ggx.binary"}, std::string(kDirsHeader) + fmt_row(grazing) + "\n");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.find("nan"), std::string::npos) << r.out;
  std::string unmeasured_bin = slurp(path("ggx.binary"));
  const merl::BinIndex b = merl::bin_of(
      DirPair<double>{{grazing[0], grazing[1], grazing[2]}, {grazing[3], grazing[4], grazing[5]}});
  for (std::size_t c = 0; c < 3; ++c) {
    const double mark = -1;
    std::memcpy(unmeasured_bin.data() + merl::kHeaderBytes +
                    8 * (c * merl::kBins + merl::bin(b.theta_h, b.theta_d, b.phi_d)),
                &mark, 8);
  }
  put(path("bin.binary"), unmeasured_bin);
  r = run({"eval", "--brdf", "bin.binary"}, std::string(kDirsHeader) + fmt_row(grazing) + "\n");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("nan,nan,nan"), std::string::npos) << r.out;  // was -0.000667
  EXPECT_EQ(r.out.find(",-"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("\n-"), std::string::npos) << r.out;

  // The albedo of each incidence: a number >= 0; at 80° part of the hemisphere is unmeasured.
  auto albedo_line = [](const std::string& out, const std::string& angle) {
    const std::size_t at = out.find("albedo at θi = " + angle + "°:");
    return at == std::string::npos ? std::string() : out.substr(at, out.find('\n', at) - at);
  };
  r = run({"info", "ggx.binary"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const std::string angle : {"0", "30", "60", "80"}) {
    const std::string line = albedo_line(r.out, angle);
    ASSERT_FALSE(line.empty()) << r.out;
    const double red = std::stod(line.substr(line.find(':') + 1));
    EXPECT_GT(red, 0.0) << line;
    EXPECT_LT(red, 1.0) << line;
  }
  // The same file with every bin of θh index >= 45 unmeasured (a partial measurement).
  std::string holes = slurp(path("ggx.binary"));
  const double unmeasured = -1;
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t i = merl::bin(45, 0, 0); i < merl::kBins; ++i)
      std::memcpy(holes.data() + merl::kHeaderBytes + 8 * (c * merl::kBins + i), &unmeasured, 8);
  put(path("holes.binary"), holes);
  r = run({"info", "holes.binary"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const std::string angle : {"0", "80"}) {
    const std::string line = albedo_line(r.out, angle);
    EXPECT_NE(line.find("mean over the measured"), std::string::npos) << r.out;
    EXPECT_GT(std::stod(line.substr(line.find(':') + 1)), 0.0) << line;
  }

  // A file with no measured bin: no albedo at all (it was -0.0105), and no negative value.
  std::string bytes(merl::kFileBytes, '\0');
  const std::int32_t dims[3] = {90, 90, 180};
  std::memcpy(bytes.data(), dims, sizeof dims);
  for (std::size_t i = 0; i < 3 * merl::kBins; ++i) {
    std::memcpy(bytes.data() + merl::kHeaderBytes + 8 * i, &unmeasured, 8);
  }
  put(path("empty.binary"), bytes);
  r = run({"info", "empty.binary"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(albedo_line(r.out, "0").find("undefined: no ωo at this incidence was measured"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("-0.0"), std::string::npos) << r.out;
}

// `halfback nbrdf train` (docs/neural.md): the .h5 + .json it writes are a BRDF the other
// commands read; what it cannot train on or write is an error that writes nothing.
TEST_F(CliTest, NbrdfTrainWritesANetworkTheCommandsRead) {
  Result r = run({"nbrdf", "train", "--brdf", "ggx:alpha=0.3", "--samples", "3000", "--epochs", "2",
                  "--hidden", "8,8", "-o", "g.h5"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("a 6-8-8-3 network of ggx"), std::string::npos) << r.out;
  EXPECT_EQ(r.err, "");  // no progress: stderr is not a terminal
  EXPECT_EQ(entries(), (std::vector<std::string>{"g.h5", "g.json"}));
  EXPECT_NE(slurp(path("g.json")).find(R"("input":"sztrajman-halfdiff")"), std::string::npos);
  r = run({"info", "g.h5"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("6-8-8-3"), std::string::npos) << r.out;
  r = run({"eval", "--brdf", "g.h5"}, "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,1,0.6,0,0.8\n");
  ASSERT_EQ(r.status, 0) << r.err;
  // A network of the isotropic coordinates of halfdiff.
  r = run({"nbrdf", "train", "--brdf", "ggx:alpha=0.3", "--samples", "2000", "--epochs", "1",
           "--param", "halfdiff", "-o", "hd.h5"});
  ASSERT_EQ(r.status, 0) << r.err;
  r = run({"info", "hd.h5"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("the isotropic coordinates of halfdiff (theta_h, theta_d, phi_d)"),
            std::string::npos)
      << r.out;
  // The same seed and options give the same bytes, whatever the thread count.
  r = run({"nbrdf", "train", "--brdf", "ggx:alpha=0.3", "--samples", "3000", "--epochs", "2",
           "--hidden", "8,8", "--threads", "1", "-o", "again.h5"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(path("again.h5")), slurp(path("g.h5")));
}

TEST_F(CliTest, NbrdfTrainBadInputWritesNothing) {
  auto expect_error = [&](const std::vector<std::string>& args, int status,
                          const std::string& message) {
    std::vector<std::string> full{"nbrdf", "train"};
    full.insert(full.end(), args.begin(), args.end());
    for (const std::string option : {"--samples", "--epochs"})  // small unless given
      if (std::find(args.begin(), args.end(), option) == args.end())
        full.insert(full.end(), {option, option == "--samples" ? "2000" : "1"});
    const Result r = run(full);
    EXPECT_EQ(r.status, status) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
  };
  put(path("keep.h5"), "kept\n");
  // A BRDF that is 0 everywhere, or NaN where sampled (a MERL file without a measured bin).
  expect_error({"--brdf", "lambert:albedo=0", "-o", "keep.h5"}, 1, "is 0 at all");
  std::string bytes(merl::kFileBytes, '\0');
  const std::int32_t dims[3] = {90, 90, 180};
  std::memcpy(bytes.data(), dims, sizeof dims);
  const double unmeasured = -1;
  for (std::size_t i = 0; i < 3 * merl::kBins; ++i)
    std::memcpy(bytes.data() + merl::kHeaderBytes + 8 * i, &unmeasured, 8);
  put(path("empty.binary"), bytes);
  expect_error({"--brdf", "empty.binary", "-o", "keep.h5"}, 1, "is NaN at θh = ");
  expect_error({"--brdf", "ggx:alpha_x=0.1,alpha_y=0.4", "-o", "keep.h5"}, 1, "is anisotropic");
  // Sizes out of range.
  expect_error({"--brdf", "lambert", "--hidden", "21,0", "-o", "keep.h5"}, 2, "--hidden");
  expect_error({"--brdf", "lambert", "--hidden", "65", "-o", "keep.h5"}, 2, "expected 1 to 64");
  expect_error({"--brdf", "lambert", "--samples", "0", "-o", "keep.h5"}, 2, "--samples: 0");
  expect_error({"--brdf", "lambert", "--epochs", "0", "-o", "keep.h5"}, 2, "--epochs: 0");
  expect_error({"--brdf", "lambert", "--batch", "0", "-o", "keep.h5"}, 2, "--batch: 0");
  expect_error({"--brdf", "lambert", "--param", "nonesuch", "-o", "keep.h5"}, 2,
               "--param 'nonesuch'");
  expect_error({"--brdf", "lambert", "--loss", "l2", "-o", "keep.h5"}, 2, "--loss 'l2'");
  // Outputs naming an input: the weights, or the .json written beside them.
  ASSERT_EQ(run({"nbrdf", "train", "--brdf", "lambert", "--samples", "500", "--epochs", "1", "-o",
                 "net.h5"})
                .status,
            0);
  const std::string net = slurp(path("net.h5"));
  expect_error({"--brdf", "net.h5", "-o", "net.h5"}, 2, "net.h5");
  ASSERT_EQ(run({"factor", "--brdf", "lambert", "--param", "halfdiff", "--rank", "1", "--counts",
                 "4,4,4", "-o", "l.json"})
                .status,
            0);
  const std::string factored = slurp(path("l.json"));
  expect_error({"--brdf", "l.json", "-o", "l.h5"}, 2, "l.json");
  expect_error({"--brdf", "lambert", "-o", "x.json"}, 2, "name the weights file NAME.h5");
  expect_error({"--brdf", "lambert", "-o", "missing/x.h5"}, 1, "cannot write");
  EXPECT_EQ(slurp(path("keep.h5")), "kept\n");
  EXPECT_EQ(slurp(path("net.h5")), net);
  EXPECT_EQ(slurp(path("l.json")), factored);
  EXPECT_EQ(entries(),
            (std::vector<std::string>{"empty.binary", "keep.h5", "l.json", "net.h5", "net.json"}));
}

// docs/reliability/cli.md: a file term in a sum ('ggx:alpha=0.2+./x.binary') is a
// term, loaded as a file (it was read as part of alpha's value: "not a finite number").
TEST_F(CliTest, FileTermsInSums) {
  ASSERT_EQ(run({"export-merl", "--brdf", "lambert:albedo=0.2", "-o", "x.binary"}).status, 0);
  const std::string pair = std::string(kDirsHeader) + "0,0,1,0,0,1\n";
  const Result sum = run({"eval", "--brdf", "ggx:alpha=0.2+./x.binary"}, pair);
  ASSERT_EQ(sum.status, 0) << sum.err;
  const Result a = run({"eval", "--brdf", "ggx:alpha=0.2"}, pair);
  const Result b = run({"eval", "--brdf", "./x.binary"}, pair);
  const double expected = parse(a.out).columns[1][0] + parse(b.out).columns[1][0];
  EXPECT_NEAR(parse(sum.out).columns[1][0], expected, 1e-12 * expected);
  const Result missing = run({"info", "ggx:alpha=0.2+./none.bsdf"});
  EXPECT_NE(missing.status, 0);
  EXPECT_EQ(missing.err.find("not a finite number"), std::string::npos) << missing.err;
  EXPECT_NE(missing.err.find("none.bsdf"), std::string::npos) << missing.err;
}

TEST_F(CliTest, ExportMerlBadInputKeepsTheOutput) {
  put(path("x.binary"), "old");
  Result r = run({"export-merl", "--brdf", "nope", "-o", "x.binary"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(slurp(path("x.binary")), "old");
  r = run({"export-merl", "--brdf", "lambert", "-o", "missing/x.binary"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("cannot write"), std::string::npos) << r.err;
  r = run({"info", "x.binary"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("x.binary"), std::string::npos) << r.err;
  EXPECT_EQ(entries(), (std::vector<std::string>{"x.binary"}));
  // docs/reliability/readers.md: an anisotropic BRDF is refused (its φh = 0 slice
  // was written silently), as export-rgl refuses it; the old file stays.
  r = run({"export-merl", "--brdf", "ggx:alpha_x=0.1,alpha_y=0.4", "-o", "x.binary"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("is anisotropic: a MERL file holds an isotropic BRDF only"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(slurp(path("x.binary")), "old");
}

TEST_F(CliTest, ExportRglWritesAFileTheReaderReads) {
  Result r = run({"export-rgl", "--brdf", "ggx:alpha=0.3,f0=0.5", "-o", "ggx.bsdf", "--theta-i",
                  "6", "--resolution", "16", "--vndf-resolution", "64"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("ggx.bsdf written (rgb variant, 6 incidence elevations, 16x16"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("incidence slice"), std::string::npos) << r.err;  // no terminal here
  r = run({"info", "ggx.bsdf"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* s : {"RGL tensor_file", "6 θi × 1 φi", "16 × 16 samples", "2 × 64",
                        "exported by halfback export-rgl from 'ggx:alpha=0.3,f0=0.5'"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
  r = run({"export-rgl", "--brdf", "lambert", "-o", "l.bsdf", "-q", "--description", "grey"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  r = run({"info", "l.bsdf"});
  EXPECT_NE(r.out.find("material:              grey"), std::string::npos) << r.out;
}

TEST_F(CliTest, ExportRglSpectralVariant) {
  Result r = run({"export-rgl", "--brdf", "ggx:alpha=0.3,f0_r=0.9,f0_g=0.5,f0_b=0.2", "-o",
                  "s.bsdf", "--variant", "spectral", "--theta-i", "4", "--resolution", "8",
                  "--vndf-resolution", "32"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("s.bsdf written (spectral variant"), std::string::npos) << r.err;
  const TensorFile tf = read_tensor_file(path("s.bsdf"));
  EXPECT_EQ(tf.find("rgb"), nullptr);
  ASSERT_NE(tf.find("spectra"), nullptr);
  EXPECT_EQ(tf.find("spectra")->shape, (std::vector<std::uint64_t>{1, 4, 95, 8, 8}));
  r = run({"info", "s.bsdf"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("spectral variant (95 wavelengths, integrated to RGB)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("spectra upsampled from RGB"), std::string::npos) << r.out;
}

TEST_F(CliTest, ExportRglBadInputKeepsTheOutput) {
  put(path("x.bsdf"), "old");
  struct Case {
    std::vector<std::string> args;
    int status;
    const char* message;
  };
  const Case cases[] = {
      {{"--brdf", "ggx:alpha_x=0.1,alpha_y=0.3"}, 1, "anisotropic"},
      {{"--brdf", "lambert:albedo=0"}, 1, "zero in every backscattering direction"},
      {{"--brdf", "nope"}, 2, "nope"},
      {{"--brdf", "lambert", "--theta-i", "1"}, 2, "--theta-i"},
      {{"--brdf", "lambert", "--resolution", "1"}, 2, "--resolution"},
      {{"--brdf", "lambert", "--vndf-resolution", "x"}, 2, "--vndf-resolution"},
      {{"--brdf", "lambert", "--variant", "xyz"}, 2, "--variant"},
      {{"--brdf", "lambert", "--incidences", "even"}, 2, "--incidences"},
      {{"--brdf", "lambert", "--tabulation", "hat"}, 2, "--tabulation"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args{"export-rgl", "-o", "x.bsdf"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const Result r = run(args);
    EXPECT_EQ(r.status, c.status) << c.message << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_EQ(slurp(path("x.bsdf")), "old");
  }
  const Result r = run({"export-rgl", "--brdf", "lambert", "-o", "-"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(entries(), (std::vector<std::string>{"x.bsdf"}));
}

TEST_F(CliTest, ResampleWritesEachFormatAndRejectsBadGrids) {
  for (const char* f : {"t.exr", "t.npz", "t.npy"}) {
    const Result r = run({"resample", "--brdf", "test:S", "--param", "hybrid", "--kind", "slice",
                          "--azimuth", "45", "--size", "16,8", "-o", f});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("128 grid points"), std::string::npos) << r.err;
    EXPECT_GT(fs::file_size(path(f)), 16u * 8 * 3 * 4);
  }
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const Case cases[] = {
      {{"--param", "dirs"}, "expected a parameterization"},
      {{"--size", "16,0"}, "'0' is not a positive whole number"},
      {{"--size", "4,4"}, "has 3 axes, got 2 sample counts"},
      {{"--azimuth", "30"}, "needs --kind slice"},
      {{"--range", "theta_h=0:1"}, "no axis 'theta_h' (its axes: hbar, k, dphi)"},
      {{"--range", "k=1:0"}, "lo <= hi"},
      {{"--range", "k=0:x"}, "'x' is not a number"},
      {{"--range", "k"}, "expected NAME=LO:HI"},
      {{"--kind", "cube"}, "cube"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args{"resample", "--brdf", "lambert", "-o", "bad.npz"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const Result r = run(args);
    EXPECT_EQ(r.status, 2) << c.message << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
  }
  Result r = run({"resample", "--brdf", "lambert", "-o", "t.csv"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find(".exr, .npz or .npy"), std::string::npos) << r.err;
  EXPECT_EQ(entries(), (std::vector<std::string>{"t.exr", "t.npy", "t.npz"}));
}

// docs/reliability/numerics.md: one rule for azimuths, wrap into [0, 360): -90 and 630 are 270
// (the table was all NaN before); NaN is an error naming --azimuth; an all-NaN table is a warning.
TEST_F(CliTest, ResampleWrapsTheSliceAzimuth) {
  std::map<std::string, std::string> tables;
  for (const char* az : {"270", "-90", "630"}) {
    const std::string out = std::string("a") + az + ".npy";
    const Result r = run({"resample", "--brdf", "ggx:alpha=0.3", "--param", "hybrid", "--kind",
                          "slice", "--azimuth", az, "--size", "12", "-o", out});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("144 grid points"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("(0 inside"), std::string::npos) << az << ": " << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
    tables[az] = slurp(path(out));
  }
  EXPECT_EQ(tables["-90"], tables["270"]);
  EXPECT_EQ(tables["630"], tables["270"]);
  for (const char* az : {"nan", "inf", "-inf"}) {
    const Result r = run({"resample", "--brdf", "lambert", "--kind", "slice", "--azimuth", az,
                          "--size", "4", "-o", "n.npy"});
    EXPECT_EQ(r.status, 2) << az;
    EXPECT_NE(r.err.find("--azimuth: '"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(az == std::string("nan") ? "is not a number" : "is not a finite"),
              std::string::npos)
        << r.err;
  }
  const Result r = run({"resample", "--brdf", "lambert", "--kind", "slice", "--size", "4",
                        "--range", "k=1.5:2", "-o", "outside.npy"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("(0 inside the domain)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("halfback resample: warning: no grid point is inside the domain"),
            std::string::npos)
      << r.err;
}

// docs/reliability/numerics.md: an image that overflows the float range is refused, not written
// as +Inf.
TEST_F(CliTest, RenderRefusesAnImageThatIsNotFinite) {
  Result r = run({"render", "--brdf", "lambert", "--env", "constant:1e30", "--env-exposure", "64",
                  "--width", "8", "--height", "8", "--spp", "2", "-q", "-o", "over.exr"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("64 of 64 pixels are infinite or NaN"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--env-exposure"), std::string::npos) << r.err;
  EXPECT_EQ(entries(), std::vector<std::string>{});
  r = run({"render", "--brdf", "lambert", "--env", "constant:1e30", "--width", "8", "--height", "8",
           "--spp", "2", "-q", "-o", "bright.exr"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(entries(), std::vector<std::string>{"bright.exr"});
}

// ---------------------------------------------------------------------------------------------
// Outputs that are not regular files (docs/reliability/cli.md) and signals
// ---------------------------------------------------------------------------------------------

using test::FifoReader;

bool is_char_device(const fs::path& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 && S_ISCHR(st.st_mode);
}

// `-o /dev/null` must leave /dev/null a character device (as root the rename destroyed it). The
// real /dev/null is tried only after a private copy of it (mknod, root only) came through
// intact, so that a regression cannot destroy it.
TEST_F(CliTest, OutputToADeviceWritesItAndKeepsIt) {
  const std::string in = std::string(kDirsHeader) + "0,0,1,0.6,0,0.8\n";
  const std::vector<std::string> convert{"convert", "--from", "dirs", "--to", "hybrid", "-o"};
  const auto to = [&](const std::string& out) {
    std::vector<std::string> args = convert;
    args.push_back(out);
    return run(args, in);
  };
  if (::mknod(path("null").c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0) {
    const Result r = to("null");
    EXPECT_EQ(r.status, 0) << r.err;
    ASSERT_TRUE(is_char_device(path("null"))) << "the device node was replaced by a file";
    EXPECT_EQ(entries(), std::vector<std::string>{"null"});
  }
  ASSERT_TRUE(is_char_device("/dev/null"));
  Result r = to("/dev/null");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(is_char_device("/dev/null"));
  // /dev/stdout is standard output as it is (here a file the test opened), not a file to replace.
  r = to("/dev/stdout");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.rfind("hbar,phi_h,k,phi_k\n", 0), 0u) << r.out;
}

TEST_F(CliTest, OutputToAFifoIsWrittenToItsReader) {
  ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0600), 0);
  FifoReader reader(path("fifo"));
  const Result r = run({"export-merl", "--brdf", "lambert", "-o", "fifo"});
  const std::string received = reader.finish();
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(received.size(), 12u + 3u * 8u * 90u * 90u * 180u);  // a whole MERL file
  struct stat st {};
  ASSERT_EQ(::stat(path("fifo").c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_EQ(entries(), std::vector<std::string>{"fifo"});
}

TEST_F(CliTest, ReadOnlyOutputIsRefusedLikeCp) {
  const std::string in = std::string(kDirsHeader) + "0,0,1,0.6,0,0.8\n";
  put(path("out.csv"), "precious\n");
  fs::permissions(path("out.csv"), fs::perms::owner_read | fs::perms::group_read);
  Result r = run({"convert", "--from", "dirs", "--to", "hybrid", "-o", "out.csv"}, in);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err,
            "halfback convert: error: cannot write 'out.csv' (it is read-only, mode 0440; make it "
            "writable or remove it): Permission denied\n");
  r = run({"export-merl", "--brdf", "lambert", "-o", "out.csv"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("read-only"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(path("out.csv")), "precious\n");
  EXPECT_EQ(entries(), std::vector<std::string>{"out.csv"});
}

// Ctrl-C, SIGTERM and SIGHUP remove the hidden temporary beside the output, and the tool dies of
// the signal. `convert` creates its output's temporary before reading its input, so a standard
// input that never ends holds it open for as long as the test needs.
TEST_F(CliTest, SignalsRemoveTheTemporaryFiles) {
  for (const int sig : {SIGTERM, SIGINT, SIGHUP}) {
    int input[2];
    ASSERT_EQ(::pipe(input), 0);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, input[0], 0);
    posix_spawn_file_actions_addclose(&actions, input[1]);
    posix_spawn_file_actions_addopen(&actions, 2, path("err").c_str(), O_WRONLY | O_CREAT, 0644);
    const std::string out = path("out.csv").string();
    std::vector<std::string> args{HALFBACK_CLI_PATH, "convert", "--from", "dirs", "--to",
                                  "hybrid",          "-o",      out};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    // The tool keeps a signal its parent ignores ignored (a shell's background jobs inherit
    // SIGINT ignored): the child starts with the default disposition of the signal under test.
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    sigset_t defaults;
    sigemptyset(&defaults);
    sigaddset(&defaults, sig);
    posix_spawnattr_setsigdefault(&attributes, &defaults);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF);
    pid_t pid = 0;
    ASSERT_EQ(posix_spawn(&pid, HALFBACK_CLI_PATH, &actions, &attributes, argv.data(), environ), 0);
    posix_spawnattr_destroy(&attributes);
    posix_spawn_file_actions_destroy(&actions);
    ::close(input[0]);
    const std::string header(kDirsHeader);
    ASSERT_EQ(::write(input[1], header.data(), header.size()), ssize_t(header.size()));
    const auto has_temporary = [&] {
      for (const auto& e : fs::directory_iterator(dir_.path()))
        if (e.path().filename().string().starts_with(".out.csv.tmp")) return true;
      return false;
    };
    for (int i = 0; i < 1000 && !has_temporary(); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    EXPECT_TRUE(has_temporary()) << "no temporary file to remove";
    ::kill(pid, sig);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ::close(input[1]);
    EXPECT_TRUE(WIFSIGNALED(status)) << "signal " << sig << ": status " << status;
    if (WIFSIGNALED(status)) {
      EXPECT_EQ(WTERMSIG(status), sig);
    }
    EXPECT_EQ(entries(), std::vector<std::string>{"err"}) << "signal " << sig;
    fs::remove(path("err"));
  }
}

// One rule for every command that writes (docs/reliability/cli.md, "Files and outputs"): an
// output that names an input of the same command, by its name, through a symbolic link, or as
// the file written beside it (plan's sidecar), is refused before any work (status 2), the input
// left byte-identical and no temporary left. Inputs are BRDF files (a factored model, read by
// content whatever its name), CSV files, a plan and its pilot, and a file inside a study's or a
// figure's output folder.
TEST_F(CliTest, OutputThatNamesAnInputIsRefusedBeforeAnyWork) {
  ASSERT_EQ(run({"factor", "--brdf", "lambert", "--rank", "1", "--counts", "4,4,4", "-o", "f.json"})
                .status,
            0);
  put(path("d.csv"), std::string(kDirsHeader) + "0,0,1,0.6,0,0.8\n");
  ASSERT_EQ(run({"plan", "--budget", "300", "-o", "p.csv"}).status, 0);
  ASSERT_EQ(run({"plan", "--design", "sequential", "--budget", "500", "-o", "pilot.csv"}).status,
            0);
  const auto values = [&](const std::string& plan, const std::string& out) {
    std::string text = "row,value\n";
    for (std::size_t k = 0; k < parse(slurp(path(plan))).rows(); ++k)
      text += std::to_string(k) + ",0.1\n";
    put(path(out), text);
  };
  values("p.csv", "lab.csv");
  values("pilot.csv", "pv.csv");
  for (const char* link : {"f.binary", "f.bsdf", "f.npy", "f.png", "g.h5"})
    fs::create_symlink("f.json", path(link));
  fs::create_symlink("lab.csv", path("lab.binary"));
  fs::create_directories(path("st"));
  fs::create_directories(path("figs"));
  fs::copy_file(path("f.json"), path("st/azimuthal.csv"));
  fs::copy_file(path("f.json"), path("figs/m.png"));
  struct Case {
    std::vector<std::string> args;
    std::vector<std::string> inputs;  // left byte-identical
  };
  const std::vector<Case> cases = {
      {{"fit", "--brdf", "f.json", "--model", "lambert", "--samples", "100", "-o", "f.json"},
       {"f.json"}},
      {{"fit", "--brdf", "f.json", "--model", "lambert", "--samples", "100", "-o", "x.json",
        "--emit", "pbrt-v4:f.json"},
       {"f.json"}},
      {{"factor", "--brdf", "f.json", "--counts", "4,4,4", "-o", "f.json"}, {"f.json"}},
      {{"plan", "--pilot", "pilot.json", "--pilot-measurements", "pv.csv", "-o", "pilot.csv"},
       {"pilot.csv", "pilot.json"}},
      {{"plan", "--pilot", "pilot.json", "--pilot-measurements", "pv.csv", "-o", "pv.csv"},
       {"pv.csv"}},
      {{"reconstruct", "--plan", "p.json", "--measurements", "lab.csv", "-o", "lab.binary"},
       {"lab.csv"}},
      {{"export-merl", "--brdf", "f.json", "-o", "f.binary"}, {"f.json"}},
      {{"export-rgl", "--brdf", "f.json", "--theta-i", "2", "--resolution", "2",
        "--vndf-resolution", "2", "-o", "f.bsdf"},
       {"f.json"}},
      {{"resample", "--brdf", "f.json", "--size", "4", "-o", "f.npy"}, {"f.json"}},
      {{"convert", "--from", "dirs", "--to", "hybrid", "-i", "d.csv", "-o", "d.csv"}, {"d.csv"}},
      {{"eval", "--brdf", "lambert", "-i", "d.csv", "-o", "d.csv"}, {"d.csv"}},
      {{"eval", "--brdf", "f.json", "-i", "d.csv", "-o", "f.json"}, {"f.json"}},
      {{"render", "--brdf", "f.json", "--width", "8", "--height", "8", "--spp", "1", "-o", "f.png"},
       {"f.json"}},
      {{"figure", "slices", "--brdf", "lambert+f.json", "--out", "f.png"}, {"f.json"}},
      {{"figure", "material", "--brdf", "f.json", "--render-size", "16", "--spp", "1", "--out",
        "f.png"},
       {"f.json"}},
      {{"figure", "hemisphere", "--param", "hybrid,dupuy-jakob:f.json", "--out", "f.png"},
       {"f.json"}},
      {{"study", "st/azimuthal.csv", "--quick", "--no-gonio", "-o", "st"}, {"st/azimuthal.csv"}},
      {{"figure", "paper", "--material", "figs/m.png", "--formats", "png", "--render-size", "16",
        "--spp", "1", "--out", "figs"},
       {"figs/m.png"}},
      // The weights (g.h5, a link to the input), then the description beside them (f.json).
      {{"nbrdf", "train", "--brdf", "f.json", "--hidden", "2", "--samples", "1000", "--epochs", "1",
        "-o", "g.h5"},
       {"f.json"}},
      {{"nbrdf", "train", "--brdf", "f.json", "--hidden", "2", "--samples", "1000", "--epochs", "1",
        "-o", "f.weights"},
       {"f.json"}},
      {{"compare", "f.json", "lambert", "--samples", "100", "--json", "f.json"}, {"f.json"}},
      {{"compare", "lambert", "f.json", "--samples", "100", "-o", "f.png"}, {"f.json"}},
  };
  std::vector<std::vector<std::string>> lines;
  for (const Case& c : cases) lines.push_back(c.args);
  expect_every_output_written(lines);  // every command that writes, each of its outputs
  for (const Case& c : cases) {
    std::map<std::string, std::string> before;
    for (const std::string& f : c.inputs) before[f] = slurp(path(f));
    const Result r = run(c.args);
    std::string line;
    for (const std::string& a : c.args) line += " " + a;
    EXPECT_EQ(r.status, 2) << line << "\n" << r.err;
    EXPECT_NE(r.err.find("never replaces an input"), std::string::npos) << line << "\n" << r.err;
    for (const std::string& f : c.inputs) EXPECT_EQ(slurp(path(f)), before[f]) << line << ": " << f;
    for (const auto& e : fs::recursive_directory_iterator(dir_.path()))
      EXPECT_FALSE(e.path().filename().string().starts_with(".")) << line << ": " << e.path();
  }
}

// The command lines of the two tests below: every command that writes, through each of its outputs
// (expect_every_output_written), with inputs in the test's folder and outputs under `at` (a
// folder and '/', or ""). Each output is larger than 1 KiB, the smallest `ulimit -f`; fit's
// --emit case writes its JSON (600 bytes) outside `at`, so that the failing write is the emit's.
struct WriteCase {
  std::vector<std::string> args;
  std::vector<std::string> outputs;  // each holds "old" before, and after
};

std::vector<WriteCase> write_cases(const std::string& at) {
  const auto o = [&](const std::string& name) { return at + name; };
  return {
      {{"convert", "--from", "dirs", "--to", "hybrid", "-i", "pairs.csv", "-o", o("c.csv")},
       {o("c.csv")}},
      {{"eval", "--brdf", "lambert", "-i", "pairs.csv", "-o", o("e.csv")}, {o("e.csv")}},
      {{"factor", "--brdf", "lambert", "--counts", "16,16,16", "-o", o("f.json")}, {o("f.json")}},
      {{"plan", "--budget", "300", "-o", o("q.csv")}, {o("q.csv"), o("q.json")}},
      {{"reconstruct", "--plan", "p.json", "--measurements", "lab.csv", "-o", o("m.binary")},
       {o("m.binary")}},
      {{"export-merl", "--brdf", "lambert", "-o", o("x.binary")}, {o("x.binary")}},
      {{"export-rgl", "--brdf", "lambert", "--theta-i", "2", "--resolution", "8",
        "--vndf-resolution", "8", "-o", o("x.bsdf")},
       {o("x.bsdf")}},
      {{"resample", "--brdf", "lambert", "--size", "16", "-o", o("x.npy")}, {o("x.npy")}},
      {{"render", "--brdf", "lambert", "--width", "16", "--height", "16", "--spp", "1", "-o",
        o("x.exr")},
       {o("x.exr")}},
      {{"figure", "slices", "--brdf", "lambert", "--out", o("x.png")}, {o("x.png")}},
      {{"figure", "hemisphere", "--param", "hybrid", "--elevations", "0", "--scale", "0.5", "--out",
        o("h.png")},
       {o("h.png")}},
      {{"figure", "material", "--brdf", "lambert", "--render-size", "16", "--spp", "1", "--out",
        o("m.png")},
       {o("m.png")}},
      {{"figure", "paper", "--no-materials", "--formats", "png", "--out", o("figs")},
       {o("figs/fig1-hemisphere.png")}},
      {{"study", "--quick", "--no-gonio", "--no-sampling", "--no-fit", "--test-pairs", "1000", "-o",
        o("st"), "lambert"},
       {o("st/report.md")}},
      // Three lobes: 1.7 KB of JSON.
      {{"fit", "--brdf", "ggx:alpha=0.3", "--model", "lambert+ggx+ggx", "--samples", "200", "-o",
        o("fit.json")},
       {o("fit.json")}},
      {{"fit", "--brdf", "lambert", "--model", "lambert", "--samples", "100", "-o", "fe.json",
        "--emit", "blender:" + o("b.py")},
       {"fe.json", o("b.py")}},
      {{"compare", "lambert", "ggx:alpha=0.3", "--samples", "200", "--test-pairs", "100",
        "--albedo-samples", "4", "--json", o("c.json")},
       {o("c.json")}},
      {{"compare", "lambert", "ggx:alpha=0.3", "--samples", "200", "--test-pairs", "100",
        "--albedo-samples", "4", "-o", o("c.png")},
       {o("c.png")}},
      // A tiny training (0.04 s): 9.8 KB of weights and 1.4 KB of description.
      {{"nbrdf", "train", "--brdf", "lambert", "--hidden", "2", "--samples", "1000", "--epochs",
        "1", "--batch", "100", "-o", o("n.h5")},
       {o("n.h5"), o("n.json")}},
  };
}

std::vector<std::vector<std::string>> command_lines(const std::vector<WriteCase>& cases) {
  std::vector<std::vector<std::string>> lines;
  for (const WriteCase& c : cases) lines.push_back(c.args);
  return lines;
}

void CliTest::write_case_inputs() {
  put(path("pairs.csv"), dirs_csv(well_conditioned_pairs(200, 7)));
  ASSERT_EQ(run({"plan", "--budget", "300", "-o", "p.csv"}).status, 0);
  std::string lab = "row,value\n";
  for (std::size_t k = 0; k < parse(slurp(path("p.csv"))).rows(); ++k)
    lab += std::to_string(k) + ",0.1\n";
  put(path("lab.csv"), lab);
}

void CliTest::expect_failed_write_left_old_files(const std::string& line, const Result& r,
                                                 const std::vector<std::string>& outputs,
                                                 const std::string& message) {
  EXPECT_EQ(r.status, 1) << line << "\n" << r.err;
  EXPECT_NE(r.err.find(message), std::string::npos) << line << "\n" << r.err;
  for (const std::string& f : outputs) EXPECT_EQ(slurp(path(f)), "old\n") << line << ": " << f;
  for (const auto& e : fs::recursive_directory_iterator(dir_.path()))
    EXPECT_FALSE(e.path().filename().string().starts_with(".")) << line << ": " << e.path();
}

std::string joined(const std::vector<std::string>& args) {
  std::string line;
  for (const std::string& a : args) line += " " + a;
  return line;
}

// Past the file size limit (`ulimit -f`), every command that writes fails with a message naming
// the limit (status 1), the old file kept and no temporary left: SIGXFSZ is ignored, so that the
// write fails with EFBIG, as a full disk fails with ENOSPC (the tool died of SIGXFSZ, status 153,
// with no message and the temporary left).
TEST_F(CliTest, FileSizeLimitLeavesTheOldFileAndNoTemporary) {
  write_case_inputs();
  if (HasFatalFailure()) return;
  const std::vector<WriteCase> cases = write_cases("");
  expect_every_output_written(command_lines(cases));
  for (const char* folder : {"st", "figs"}) fs::create_directories(path(folder));
  for (const WriteCase& c : cases) {
    for (const std::string& f : c.outputs) put(path(f), "old\n");
    file_limit_kib_ = 1;
    const Result r = run(c.args);
    file_limit_kib_ = 0;
    expect_failed_write_left_old_files(joined(c.args), r, c.outputs, "file size limit");
  }
}

// A full file system (ENOSPC) fails the same way for every command that writes: the old file
// kept, no temporary, a message. The test mounts a 64 KiB tmpfs and fills it before each command
// (the old files are in it), which needs the privilege to mount (CI runs as root; skipped
// without it).
TEST_F(CliTest, FullDiskLeavesTheOldFileAndNoTemporary) {
  write_case_inputs();
  if (HasFatalFailure()) return;
  const fs::path full = path("full");
  fs::create_directories(full);
  if (::mount("tmpfs", full.c_str(), "tmpfs", 0, "size=64k") != 0)
    GTEST_SKIP() << "cannot mount a tmpfs: " << std::strerror(errno);
  struct Unmount {
    fs::path at;
    ~Unmount() { EXPECT_EQ(::umount2(at.c_str(), MNT_DETACH), 0) << std::strerror(errno); }
  } unmount{full};
  const std::vector<WriteCase> cases = write_cases("full/");
  expect_every_output_written(command_lines(cases));
  for (const WriteCase& c : cases) {
    for (const auto& e : fs::directory_iterator(full)) fs::remove_all(e.path());
    for (const std::string& f : c.outputs) {
      fs::create_directories(path(f).parent_path());
      put(path(f), "old\n");
    }
    {  // fill the file system: every further write fails with ENOSPC
      std::ofstream filler(full / "filler", std::ios::binary);
      const std::string block(4096, 'x');
      for (int k = 0; k < 64 && filler.write(block.data(), block.size()); ++k) filler.flush();
    }
    const Result r = run(c.args);
    expect_failed_write_left_old_files(joined(c.args), r, c.outputs, "the file system is full");
  }
}

// ---------------------------------------------------------------------------------------------
// halfback figure
// ---------------------------------------------------------------------------------------------

TEST_F(CliTest, FigurePaperWritesEveryFigure) {
  const Result r = run({"figure", "paper", "--out", "figs", "--formats", "png", "--material",
                        "lambert:albedo=0.4", "--render-size", "16", "--spp", "2"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"fig1-hemisphere.png", "fig1-hemisphere-mirror.png",
                        "fig1-hemisphere-back.png", "fig2-slices.png", "fig3-lambert.png"}) {
    EXPECT_TRUE(fs::is_regular_file(path("figs") / f)) << f;
    EXPECT_NE(r.out.find(f), std::string::npos) << r.out;
  }
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(path("figs"))) n += e.is_regular_file();
  EXPECT_EQ(n, 5u);
}

TEST_F(CliTest, FigurePaperTakesTheMerlFilesOfAFolder) {
  fs::create_directories(path("merl"));
  Result r = run({"export-merl", "--brdf", "lambert:albedo=0.2", "-o", "merl/b.binary"});
  ASSERT_EQ(r.status, 0) << r.err;
  put(path("merl/notes.txt"), "not a MERL file\n");
  r = run({"figure", "paper", "--out", "figs", "--formats", "png", "--merl-dir", "merl",
           "--render-size", "16", "--spp", "1"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(path("figs") / "fig3-merl-b.png")) << r.out;
  EXPECT_FALSE(fs::exists(path("figs") / "fig4-felt.png"));
  r = run({"figure", "paper", "--out", "figs2", "--merl-dir", "figs"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no MERL .binary file in it"), std::string::npos) << r.err;
}

TEST_F(CliTest, FigureBadInputLeavesNothing) {
  Result r = run({"figure", "paper", "--out", "figs", "--material", "nope"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("'nope' is neither an existing file nor a known BRDF model"),
            std::string::npos)
      << r.err;
  r = run({"figure", "paper", "--out", "figs", "--env", "default,missing.hdr"});
  EXPECT_EQ(r.status, 2);  // a spec that names nothing, as in `halfback render` (class H)
  EXPECT_NE(r.err.find("'missing.hdr': neither a built-in"), std::string::npos) << r.err;
  r = run({"figure", "material", "--brdf", "lambert", "--azimuths", "", "-o", "m.png"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--azimuths: an empty value"), std::string::npos) << r.err;
  r = run({"figure", "material", "--brdf", "lambert", "-o", "missing/m.png"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("cannot write"), std::string::npos) << r.err;
  r = run({"figure", "paper", "--out", "figs", "--no-materials", "--material", "lambert"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(entries(), std::vector<std::string>{});
}

// docs/reliability/cli.md: each message names the option or file, the problem and what
// is accepted, and the exit status says whose fault it is (2 the command line, 1 the data).
TEST_F(CliTest, MessagesNameTheProblemAndExitCodesAgree) {
  struct Case {
    std::vector<std::string> args;
    int status;
    std::vector<std::string> parts;
  };
  put(path("pairs.csv"), std::string(kDirsHeader) + "0,0,1,0,0,1\n");
  const Case cases[] = {
      {{"figure", "bogus"},
       2,
       {"halfback figure: error: 'bogus' is not a figure subcommand (the subcommands are: "
        "hemisphere, slices, paper, material)"}},
      {{"figure"}, 2, {"a subcommand is required (one of: hemisphere, slices"}},
      {{"eval", "--brdf", "+ggx", "-i", "pairs.csv"},
       2,
       {"'+ggx': a sum has an empty term (a sum is SPEC+SPEC+..."}},
      {{"render", "--brdf", "ggx", "--env", "missing.hdr", "-o", "r.exr"},
       2,
       {"--env 'missing.hdr'", "neither a built-in (sky, studio, sunset)"}},
      {{"figure", "material", "--brdf", "ggx", "--env", "missing.hdr", "-o", "m.png"},
       2,
       {"--env 'missing.hdr'", "nor an existing file"}},
      {{"render", "--brdf", "ggx", "--env", "constant:1,x", "-o", "r.exr"},
       2,
       {"--env 'constant:1,x'", "'x' is not a number"}},
      {{"figure", "material", "--brdf", "ggx", "--env", "constant:0.5,0.2", "-o", "m.png"},
       2,
       {"--env 'constant:0.5,0.2'", "expected constant:V or constant:R,G,B"}},
  };
  for (const Case& c : cases) {
    const Result r = run(c.args);
    EXPECT_EQ(r.status, c.status) << c.args[0] << " " << c.args[1] << ": " << r.err;
    for (const std::string& part : c.parts) EXPECT_NE(r.err.find(part), std::string::npos) << r.err;
  }
  // 901 elevations: refused from the figure's layout, before any sampling.
  std::string many = "0";
  for (int i = 1; i <= 900; ++i) (many += ',') += std::to_string(i * 0.1);
  Result r = run({"figure", "hemisphere", "--elevations", many, "-o", "h.png"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("fewer elevations (901 given)"), std::string::npos) << r.err;
  // constant:R,G,B keeps its commas in a list of environments.
  r = run({"figure", "material", "--brdf", "lambert", "--env", "constant:0.5,0.2,0.1,studio",
           "--render-size", "16", "--spp", "1", "-o", "m.png"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(entries(), std::vector<std::string>({"m.png", "pairs.csv"}));
}

// ---------------------------------------------------------------------------------------------
// halfback study
// ---------------------------------------------------------------------------------------------

TEST_F(CliTest, StudyWritesItsCsvFilesAndReport) {
  // --quick, lighter still: the test runs under the sanitizers too.
  // The paper's four parameterizations (the others are the same code path, and the test runs
  // under the sanitizers too).
  const Result r =
      run({"study", "--quick", "--params", "halfdiff,ortho,hybrid,spherical", "--test-pairs",
           "5000", "--env", "sky", "--image-size", "32", "--image-spp", "4", "-o", "st", "test:S",
           "test:G", "ggx:alpha_x=0.2,alpha_y=0.5,f0=0.9", "embedded:acrylic_felt_green"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string az = slurp(path("st") / "azimuthal.csv");
  EXPECT_EQ(az.substr(0, az.find('\n')), "brdf,parameterization,error,dims");
  // S = 1 − ‖h̄‖ = 1 − sin θh cos θd has no azimuthal dependence in halfdiff, ortho and hybrid;
  // G = 1 − cos θi cos θo none in spherical, some in the others.
  auto error_of = [&](const std::string& key) {
    const std::size_t at = az.find(key + ",");
    if (at == std::string::npos) return -1.0;
    return std::stod(az.substr(at + key.size() + 1));
  };
  for (const char* key : {"test:S,halfdiff", "test:S,ortho", "test:S,hybrid", "test:G,spherical"}) {
    EXPECT_GE(error_of(key), 0) << key << "\n" << az;
    EXPECT_LT(error_of(key), 1e-12) << key << "\n" << az;
  }
  for (const char* key : {"test:S,spherical", "test:G,halfdiff", "test:G,ortho", "test:G,hybrid"})
    EXPECT_GT(error_of(key), 1e-3) << key << "\n" << az;
  // The anisotropic model also has its 4D rows.
  EXPECT_NE(az.find("\"ggx:alpha_x=0.2,alpha_y=0.5,f0=0.9\",hybrid,"), std::string::npos) << az;
  EXPECT_NE(az.find(",4\n"), std::string::npos) << az;
  const std::string sep = slurp(path("st") / "separability.csv");
  EXPECT_EQ(sep.substr(0, sep.find('\n')), "brdf,parameterization,rank,error,dims");
  EXPECT_NE(sep.find("test:S,hybrid,8,"), std::string::npos);

  // The gonio-reflectometer: the smooth G is reconstructed better from 10^4 measurements than
  // from 10^3, in every parameterization and design (the sequential one too); S, affine in ‖h̄‖,
  // exactly by the regular design in ortho and hybrid.
  const std::vector<std::vector<std::string>> gonio = csv_rows(slurp(path("st") / "gonio.csv"));
  ASSERT_FALSE(gonio.empty());
  EXPECT_EQ(gonio[0], (std::vector<std::string>{"brdf", "parameterization", "design", "samples",
                                                "error", "dims", "budget", "spacing"}));
  std::map<std::string, std::map<std::string, double>> g_error;  // param/design -> budget -> e
  int four_d = 0, s_exact = 0;
  std::map<std::string, int>
      spacings;  // the other designs (docs/study.md, "Designs"): rows of each spacing
  for (std::size_t i = 1; i < gonio.size(); ++i) {
    ASSERT_EQ(gonio[i].size(), 8u);
    ++spacings[gonio[i][7]];
    if (gonio[i][7] != "own") continue;  // the checks below are those of the own design
    if (gonio[i][0] == "test:G")
      g_error[gonio[i][1] + "/" + gonio[i][2]][gonio[i][6]] = std::stod(gonio[i][4]);
    if (gonio[i][0] == "test:S" && gonio[i][2] == "regular" &&
        (gonio[i][1] == "ortho" || gonio[i][1] == "hybrid")) {
      EXPECT_LT(std::stod(gonio[i][4]), 1e-12) << gonio[i][1];
      ++s_exact;
    }
    four_d += gonio[i][5] == "4";
  }
  EXPECT_EQ(s_exact, 4);
  EXPECT_EQ(g_error.size(), 12u);  // 4 parameterizations x regular, stratified, sequential
  for (const auto& [key, e] : g_error) {
    ASSERT_EQ(e.size(), 2u) << key;
    EXPECT_LT(e.at("10000"), 0.7 * e.at("1000")) << key;
    EXPECT_LT(e.at("10000"), 0.05) << key;
  }
  EXPECT_EQ(four_d, 16);
  // angle, merl and learned rows (learned from the three other BRDFs), in the regular layout:
  // for each BRDF, 4 parameterizations x 2 budgets each (the copies of own included).
  for (const char* spacing : {"angle", "merl", "learned"})
    EXPECT_EQ(spacings[spacing], 4 * 4 * 2) << spacing;
  // Measured data too: the felt's reconstruction improves with the budget.
  std::map<std::string, double> felt;
  for (const auto& row : gonio)
    if (row[0] == "embedded:acrylic_felt_green" && row[2] == "regular" && row[7] == "own")
      felt[row[1] + row[6]] = std::stod(row[4]);
  ASSERT_EQ(felt.size(), 8u);
  for (const char* p : {"halfdiff", "ortho", "hybrid", "spherical"})
    EXPECT_LT(felt[std::string(p) + "10000"], felt[std::string(p) + "1000"])
        << p;  // the anisotropic GGX: 4 parameterizations x 2 designs x 2 budgets
  const std::vector<std::vector<std::string>> image = csv_rows(slurp(path("st") / "image.csv"));
  ASSERT_GT(image.size(), 1u);
  EXPECT_EQ(image[0][5], "relative_rmse");
  EXPECT_EQ(image[0].back(), "ssim");
  for (std::size_t i = 1; i < image.size(); ++i)
    if (image[i][0] == "test:S") {
      EXPECT_LT(std::stod(image[i][5]), 0.05) << image[i][1];
    }

  const std::string report = slurp(path("st") / "report.md");
  for (const char* h :
       {"## 1. Azimuthal dependence", "## 2. Separability", "## 3. Virtual gonio-reflectometer",
        "## 3b. Designs", "## 4. Image-space error"})
    EXPECT_NE(report.find(h), std::string::npos) << h;
  // A new user's rough edges (docs/reliability/cli.md): a quick run says so, and stdout has the
  // report's summary and where the whole report is, not the whole report.
  EXPECT_NE(report.find("**A quick run**"), std::string::npos);
  EXPECT_NE(r.out.find("## Summary"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("## 1. Azimuthal dependence"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(the whole report: st/report.md)"), std::string::npos) << r.out;
  EXPECT_NE(slurp(path("st") / "report.html").find("src=\"data:image/png;base64,"),
            std::string::npos);
  for (const char* f :
       {"azimuthal.png", "azimuthal.svg", "separability.png", "separability.svg", "gonio.png",
        "gonio.svg", "gonio4d.png", "image.png", "budget.csv", "designs.png"})
    EXPECT_GT(fs::file_size(path("st") / f), 100u) << f;
}

TEST_F(CliTest, StudyParamsChooseTheColumns) {
  // --params: the parameterizations and their order, in the tables, the report and the settings.
  Result r =
      run({"study", "--quick", "--no-gonio", "--params", "hybrid,halfdiff", "-o", "st", "lambert"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<std::vector<std::string>> az = csv_rows(slurp(path("st") / "azimuthal.csv"));
  ASSERT_EQ(az.size(), 3u);
  EXPECT_EQ(az[1][1], "hybrid");
  EXPECT_EQ(az[2][1], "halfdiff");
  EXPECT_NE(slurp(path("st") / "report.md").find("| BRDF | hybrid | halfdiff |\n|---|---|---|"),
            std::string::npos);
  EXPECT_EQ(slurp(path("st") / "parts" / "settings.txt")
                .rfind("parameterizations = hybrid,halfdiff\n", 0),
            0u);
  // --resume with other parameterizations is refused, as any other setting.
  r = run({"study", "--quick", "--no-gonio", "--resume", "-o", "st", "lambert"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("was run with other settings"), std::string::npos) << r.err;
  r = run({"study", "--params", "hybrid,nope", "lambert"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("'nope' is not a parameterization"), std::string::npos) << r.err;
}

// Dupuy & Jakob's parameterization with a parameter: converted by name both ways (the ordered
// pair back), refused with the family's message when its BRDF names nothing, the study's
// per-material placeholder refused outside the study, and studied per material: every BRDF has a
// row under the placeholder's name (a glossy model, an anisotropic one and a test function; a BRDF
// whose NDF cannot be recovered: MaterialSpaces.EveryBrdfGetsAWarp),
// and --resume takes the parts back.
TEST_F(CliTest, DupuyJakobByNameAndPerMaterialInTheStudy) {
  const std::string pairs =
      "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0.3,0.1,0.9486832980505138,-0.2,0.4,0.8944271909999159\n";
  Result r = run({"convert", "--from", "dirs", "--to", "dupuy-jakob:ggx:alpha=0.3"}, pairs);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.rfind("theta_i,phi_i,s1,s2\n", 0), 0u) << r.out;
  const Result back =
      run({"convert", "--from", "dupuy-jakob:ggx:alpha=0.3", "--to", "dirs"}, r.out);
  ASSERT_EQ(back.status, 0) << back.err;
  const std::vector<std::vector<std::string>> rows = csv_rows(back.out);
  ASSERT_EQ(rows.size(), 2u);
  const double expected[6] = {0.3, 0.1, 0.9486832980505138, -0.2, 0.4, 0.8944271909999159};
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(std::stod(rows[1][std::size_t(k)]), expected[k], 1e-9);
  r = run({"convert", "--from", "dirs", "--to", "dupuy-jakob:nope"}, pairs);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("'dupuy-jakob:nope': 'nope' is neither"), std::string::npos) << r.err;
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"convert", "--from", "dirs", "--to", "dupuy-jakob:per-material"},
        {"resample", "--brdf", "lambert", "--param", "dupuy-jakob:per-material", "-o", "r.npy"},
        {"figure", "slices", "--param", "dupuy-jakob:per-material", "--out", "s.png"}}) {
    r = run(args, pairs);
    EXPECT_EQ(r.status, 2) << args[0];
    EXPECT_NE(r.err.find("for `halfback study --params` only"), std::string::npos) << r.err;
  }
  r = run({"resample", "--brdf", "lambert", "--param", "dupuy-jakob:nope", "-o", "r.npy"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("'dupuy-jakob:nope': 'nope' is neither"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("r.npy")));
  EXPECT_FALSE(fs::exists(path("s.png")));

  const std::vector<std::string> study = {"study",
                                          "--quick",
                                          "--no-images",
                                          "--params",
                                          "halfdiff,dupuy-jakob:per-material",
                                          "-o",
                                          "st",
                                          "ggx:alpha=0.2",
                                          "ggx:alpha_x=0.1,alpha_y=0.4",
                                          "test:S"};
  r = run(study);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<std::vector<std::string>> gonio = csv_rows(slurp(path("st") / "gonio.csv"));
  std::set<std::string> studied;
  for (const auto& row : gonio)
    if (row.size() > 1 && row[1] == "dupuy-jakob:per-material") studied.insert(row[0]);
  EXPECT_EQ(studied.size(), 3u);
  std::vector<std::string> resume = study;
  resume.insert(resume.begin() + 1, "--resume");
  r = run(resume);
  EXPECT_EQ(r.status, 0) << r.err;
}

// Nielsen et al.'s design in a study: rows of halfdiff at each count, the BRDF that is a member
// left out of its basis; its database in the settings (another database: --resume refused);
// halfdiff required.
TEST_F(CliTest, StudyWithNielsensDatabase) {
  const std::vector<std::string> study = {
      "study",
      "--quick",
      "--no-images",
      "--no-sampling",
      "--no-fit",
      "--params",
      "halfdiff",
      "--designs",
      "own",
      "--nielsen-counts",
      "1,5",
      "--test-pairs",
      "5000",
      "--nielsen-database",
      "lambert:albedo_r=0.8,albedo_g=0.5,albedo_b=0.2",
      "--nielsen-database",
      "lambert:albedo=0.1+ggx:alpha=0.1,f0=0.9",
      "--nielsen-database",
      "lambert:albedo_r=0.4,albedo_g=0.45,albedo_b=0.3+ggx:alpha=0.3",
      "-o",
      "st",
      "lambert:albedo=0.1+ggx:alpha=0.1,f0=0.9",
      "ggx:alpha=0.2"};
  Result r = run(study);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("Nielsen's database of 3 BRDFs"), std::string::npos) << r.err;
  std::map<std::string, std::map<std::string, double>> nielsen;  // brdf -> n -> error
  for (const auto& row : csv_rows(slurp(path("st") / "gonio.csv")))
    if (row.size() == 8 && row[2] == "nielsen") nielsen[row[0]][row[6]] = std::stod(row[4]);
  ASSERT_EQ(nielsen.size(), 2u);
  for (const auto& [brdf, e] : nielsen) {
    ASSERT_EQ(e.size(), 2u) << brdf;
    EXPECT_GT(e.at("5"), 1e-3) << brdf;  // the member is left out: not exact
  }
  EXPECT_NE(slurp(path("st") / "parts" / "settings.txt").find("nielsen_from = 3 members, "),
            std::string::npos);
  EXPECT_NE(slurp(path("st") / "report.md").find("Nielsen et al. 2015's minimal sampling"),
            std::string::npos);
  std::vector<std::string> other = study;
  other[14] = "lambert:albedo=0.7";  // another first member
  other.insert(other.begin() + 1, "--resume");
  r = run(other);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("other settings"), std::string::npos) << r.err;
  for (const char* counts : {"5,1", "0,2", "x"}) {
    r = run({"study", "--quick", "--params", "halfdiff", "--nielsen-database", "lambert",
             "--nielsen-counts", counts, "-o", "s4", "lambert"});
    EXPECT_EQ(r.status, 2) << counts << ": " << r.err;
    EXPECT_NE(r.err.find("--nielsen-budgets"), std::string::npos) << counts << ": " << r.err;
  }
  r = run({"study", "--quick", "--params", "hybrid", "--nielsen-database", "lambert", "-o", "s2",
           "lambert"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("add halfdiff to --params"), std::string::npos) << r.err;
  r = run({"study", "--quick", "--params", "halfdiff", "--nielsen-database",
           "ggx:alpha_x=0.1,alpha_y=0.4", "--nielsen-database", "lambert", "-o", "s3", "lambert"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("not isotropic"), std::string::npos) << r.err;
}

TEST_F(CliTest, StudyBadInput) {
  Result r = run({"study", "-o", "st", "nope"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("'nope' is neither"), std::string::npos) << r.err;
  r = run({"study", "--space", "sqrt", "lambert"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--error-space 'sqrt': expected linear, log, cbrt, nielsen or low"),
            std::string::npos)
      << r.err;
  r = run({"study", "--designs", "own,uniform", "lambert"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--spacings: 'uniform' is not a spacing"), std::string::npos) << r.err;
  fs::create_directories(path("empty"));
  r = run({"study", "-o", "st", "empty"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no MERL, RGL, ALTA or neural BRDF file"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("st")));
  r = run({"study", "--budgets", "1000,100", "lambert"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("ascending"), std::string::npos) << r.err;
  r = run({"study", "--budgets", "1000,3000", "--image-budget", "5", "lambert"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("image budget 5"), std::string::npos) << r.err;
  r = run({"study", "--max-theta", "0", "lambert"});
  EXPECT_EQ(r.status, 2);
  r = run({"study", "--env", "nowhere.hdr", "lambert"});
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("nowhere.hdr"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("study")));
}

// --metrics runs the metrics named (those that can be turned off; azimuthal and separability
// always run), and the settings, files and report follow; a metric's options are its flags.
TEST_F(CliTest, StudyMetricsChooseTheMetrics) {
  Result r = run({"study", "--quick", "--metrics", "fit", "--params", "halfdiff", "--test-pairs",
                  "1000", "--fit-samples", "1000", "-q", "-o", "st", "lambert"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* file : {"azimuthal.csv", "separability.csv", "fit.csv"})
    EXPECT_TRUE(fs::exists(path("st") / file)) << file;
  for (const char* file : {"gonio.csv", "image.csv", "sampling.csv"})
    EXPECT_FALSE(fs::exists(path("st") / file)) << file;
  const std::string settings = slurp(path("st") / "parts" / "settings.txt");
  EXPECT_NE(settings.find("\nbudgets = \n"), std::string::npos) << settings;
  EXPECT_NE(settings.find("\nsampler_kib = \n"), std::string::npos) << settings;
  EXPECT_NE(settings.find("\nfit_samples = 1000\n"), std::string::npos) << settings;
  const std::string report = slurp(path("st") / "report.md");
  EXPECT_NE(report.find("## Fitting from measurements"), std::string::npos);
  EXPECT_EQ(report.find("## Importance sampling"), std::string::npos);
  r = run({"study", "--metrics", "fit,nosuch", "lambert"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("'nosuch' is not a metric (azimuthal, separability, gonio"),
            std::string::npos)
      << r.err;
  r = run({"study", "--fit-budgets", "1000,100", "lambert"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--fit-budgets: the values must be ascending"), std::string::npos) << r.err;
  r = run({"study", "--sampler-kib", "64,x", "lambert"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--sampler-kib: 'x' is not a table size"), std::string::npos) << r.err;
}

// The options of the small studies below: a few seconds each, under the sanitizers too.
std::vector<std::string> tiny_study(const std::string& out, std::vector<std::string> specs) {
  // Four parameterizations, one of them without SIMD kernels (its descriptors' path).
  std::vector<std::string> a{
      "study",        "--quick", "--params",     "halfdiff,hybrid,stereographic,spherical",
      "--test-pairs", "3000",    "--budgets",    "300,1000",
      "--env",        "sky",     "--image-size", "16",
      "--image-spp",  "2",       "-o",           out};
  a.insert(a.end(), specs.begin(), specs.end());
  return a;
}

// Sets the value of an option of a command line (the element after the option's name).
void set_option(std::vector<std::string>& args, const std::string& option, const std::string& v) {
  const auto it = std::find(args.begin(), args.end(), option);
  ASSERT_TRUE(it != args.end() && it + 1 != args.end()) << option;
  *(it + 1) = v;
}

const std::vector<std::string> kTinyPanel{"lambert", "ggx:alpha=0.3", "test:S",
                                          "embedded:acrylic_felt_green"};

std::vector<std::string> study_csvs(const fs::path& dir) {
  std::vector<std::string> t;
  for (const char* f :
       {"azimuthal.csv", "separability.csv", "gonio.csv", "budget.csv", "image.csv"})
    t.push_back(slurp(dir / f));
  return t;
}

// Killed outright (SIGKILL: no clean-up at all) after its first finished BRDF, a run continued
// with --resume writes the same CSV files as a run that was never interrupted; the BRDFs finished
// before the kill are not studied again.
TEST_F(CliTest, StudyResumeAfterAKillGivesTheSameTables) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "whole studies take minutes under AddressSanitizer; the study code runs "
                  "under it in StudyWritesItsCsvFilesAndReport, this orchestration in release";
#endif
  ASSERT_EQ(run(tiny_study("whole", kTinyPanel)).status, 0);
  const auto parts = [&] {
    std::size_t n = 0;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(path("cut") / "parts", ec))
      n += e.path().extension() == ".part";
    return n;
  };
  std::vector<std::string> args = tiny_study("cut", kTinyPanel);
  args.insert(args.begin(), HALFBACK_CLI_PATH);
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 2, path("err").c_str(), O_WRONLY | O_CREAT, 0644);
  const fs::path cwd = fs::current_path();
  fs::current_path(dir_.path());
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, HALFBACK_CLI_PATH, &actions, nullptr, argv.data(), environ);
  fs::current_path(cwd);
  posix_spawn_file_actions_destroy(&actions);
  ASSERT_EQ(rc, 0);
  for (int i = 0; i < 60000 && parts() < 1; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ::kill(pid, SIGKILL);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  const std::size_t kept = parts();
  ASSERT_GE(kept, 1u);
  ASSERT_LT(kept, kTinyPanel.size()) << "the run ended before the kill: nothing to resume";
  EXPECT_FALSE(fs::exists(path("cut") / "report.md"));

  std::vector<std::string> resume = tiny_study("cut", kTinyPanel);
  resume.insert(resume.begin() + 1, "--resume");
  const Result r = run(resume);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("kept from the earlier run"), std::string::npos) << r.err;
  EXPECT_EQ(study_csvs(path("cut")), study_csvs(path("whole")));

  // Other settings cannot resume the run: a usage error, the results untouched.
  std::vector<std::string> other = tiny_study("cut", kTinyPanel);
  set_option(other, "--test-pairs", "4000");
  other.insert(other.begin() + 1, "--resume");
  const Result bad = run(other);
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("other settings"), std::string::npos) << bad.err;
  EXPECT_EQ(parts(), kTinyPanel.size());
  // Nor can another set of BRDFs: the learned design of each would come from other profiles.
  std::vector<std::string> fewer = tiny_study("cut", {kTinyPanel[0], kTinyPanel[1]});
  fewer.insert(fewer.begin() + 1, "--resume");
  const Result bad_set = run(fewer);
  EXPECT_EQ(bad_set.status, 2);
  EXPECT_NE(bad_set.err.find("other settings"), std::string::npos) << bad_set.err;
  EXPECT_EQ(parts(), kTinyPanel.size());
}

// Two runs over halves of the BRDFs, merged, write the tables of one run over all of them.
// The learned design makes a BRDF's results depend on the other BRDFs of the run: runs over
// halves merge into the whole run only without it (with it, their merge is refused).
TEST_F(CliTest, StudyMergeOfTwoRunsIsOneRun) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "whole studies take minutes under AddressSanitizer; the study code runs "
                  "under it in StudyWritesItsCsvFilesAndReport, this orchestration in release";
#endif
  const auto no_learned = [](std::vector<std::string> a) {
    a.insert(a.begin() + 1, {"--designs", "own,angle,merl"});
    return a;
  };
  ASSERT_EQ(run(no_learned(tiny_study("whole", kTinyPanel))).status, 0);
  ASSERT_EQ(run(no_learned(tiny_study("a", {kTinyPanel[0], kTinyPanel[1]}))).status, 0);
  ASSERT_EQ(run(no_learned(tiny_study("b", {kTinyPanel[2], kTinyPanel[3]}))).status, 0);
  Result r = run({"study", "--merge", "a", "b", "-o", "merged"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(study_csvs(path("merged")), study_csvs(path("whole")));
  const std::string report = slurp(path("merged") / "report.md");
  EXPECT_NE(report.find("## 4. Image-space error"), std::string::npos);
  EXPECT_TRUE(fs::exists(path("merged") / "renderings.png"));
  r = run({"study", "--merge", "a", "b", "-o", "quiet", "--quiet"});  // nothing on stdout
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "");
  r = run({"study", "--merge", "a", "b", "-o", "full", "--full-report"});  // all of it
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.substr(0, report.size()), report);

  // A BRDF in two of the runs, a directory that is not a study, different settings, BRDFs
  // given with --merge: each a clear error, and nothing written.
  r = run({"study", "--merge", "a", "whole", "-o", "m2"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("'lambert' is in both"), std::string::npos) << r.err;
  r = run({"study", "--merge", "a", "nowhere", "-o", "m2"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("'nowhere': not the output of a study"), std::string::npos) << r.err;
  std::vector<std::string> other = no_learned(tiny_study("c", {"test:G"}));
  set_option(other, "--test-pairs", "4000");
  ASSERT_EQ(run(other).status, 0);
  r = run({"study", "--merge", "a", "c", "-o", "m2"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("different settings"), std::string::npos) << r.err;
  ASSERT_EQ(run(tiny_study("la", {kTinyPanel[0], kTinyPanel[1]})).status, 0);
  ASSERT_EQ(run(tiny_study("lb", {kTinyPanel[2], kTinyPanel[3]})).status, 0);
  r = run({"study", "--merge", "la", "lb", "-o", "m2"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("learned designs come from different sets of BRDFs"), std::string::npos)
      << r.err;
  r = run({"study", "lambert", "--merge", "a", "-o", "m2"});
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(fs::exists(path("m2")));
}

// ---------------------------------------------------------------------------------------------
// Bounded work and streaming (docs/reliability/cli.md)
// ---------------------------------------------------------------------------------------------

TEST_F(CliTest, RenderLimitsAreStated) {
  Result r =
      run({"render", "--brdf", "lambert", "--width", "16384", "--height", "16384", "-o", "a.exr"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("16384 x 16384 = 268435456 pixels is above the limit of 16777216 pixels"),
            std::string::npos)
      << r.err;
  r = run({"render", "--brdf", "lambert", "--spp", "20000000", "-o", "a.exr"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("16777216"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("a.exr")));
}

// Measured in the command's CPU time (GNU time), which other jobs on the machine do not stretch:
// a first pass of 2048 x 2048 samples of a sum of twelve lobes costs many seconds of CPU on one
// thread; the 0.2 s budget ends it (plus start-up and the environment's tables).
TEST_F(CliTest, RenderTimeBudgetEndsALargeFirstPass) {
  std::string twelve_lobes = "ggx:alpha=0.2";
  for (int i = 0; i < 11; ++i) twelve_lobes += "+ggx:alpha=0.2";
  double cpu = 0;
  const Result r = run({"render", "--brdf", twelve_lobes, "--width", "2048", "--height", "2048",
                        "--threads", "1", "--time-budget", "0.2", "-q", "-o", "a.exr"},
                       "", nullptr, &cpu);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("the time budget of 0.2 s ran out before every pixel had one sample"),
            std::string::npos)
      << r.err;
  // Start-up and the environment's tables cost ~1 s of CPU in release and ~2 s under
  // AddressSanitizer, where the full pass also costs several times its release 7.5 s.
#if defined(__SANITIZE_ADDRESS__)
  constexpr double kBound = 6.0;
#else
  constexpr double kBound = 2.0;
#endif
  EXPECT_LT(cpu, kBound);
  EXPECT_FALSE(fs::exists(path("a.exr")));
}

TEST_F(CliTest, StudyLimitsAreStated) {
  Result r = run({"study", "--budgets", "2000000000", "lambert"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("the sample budget 2000000000 is above the maximum of 10000000"),
            std::string::npos)
      << r.err;
  r = run({"study", "--budgets-4d", "1000,20000000", "lambert"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("above the maximum of 10000000"), std::string::npos) << r.err;
  r = run({"study", "--test-pairs", "2000000000", "lambert"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("10000000"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("study")));
}

TEST_F(CliTest, ResampleGridLimitIsStatedInBytes) {
  const Result r = run({"resample", "--brdf", "lambert", "--param", "hybrid", "--kind", "full",
                        "--size", "91", "-o", "t.npz"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("more than the maximum of 2^26 = 67108864"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1.7 GB"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("t.npz")));
}

// Pairs of ordinary directions, n rows of dirs CSV, from a cheap generator.
std::string many_pairs_csv(std::size_t n) {
  std::string text = kDirsHeader;
  text.reserve(n * 120);
  for (std::size_t i = 0; i < n; ++i) {
    const double a = 0.001 * double(i % 6283), b = 0.3 + 0.5 * double(i % 97) / 97;
    const double s = std::sqrt(1 - b * b);
    text += fmt_row({s * std::cos(a), s * std::sin(a), b, -s * std::sin(a), s * std::cos(a), b});
    text += '\n';
  }
  return text;
}

// convert reads, converts and writes blocks of 65536 rows: the output of several blocks is the
// library's conversion of the whole input, byte for byte.
TEST_F(CliTest, ConvertStreamsBlocksByteIdentically) {
  constexpr std::size_t n = 150000;
  const std::string input = many_pairs_csv(n);
  const Result r = run({"convert", "--from", "dirs", "--to", "hybrid", "--jacobian"}, input);
  ASSERT_EQ(r.status, 0) << r.err;
  const CsvTable in = read_csv(input, "in");
  std::vector<ConstColumn<double>> in_cols;
  for (const auto& c : in.columns) in_cols.push_back({c.data(), 1});
  std::vector<std::vector<double>> out(5, std::vector<double>(n));
  std::vector<Column<double>> out_cols;
  for (int c = 0; c < 4; ++c) out_cols.push_back({out[c].data(), 1});
  ConvertOutput<double> conv;
  conv.columns = out_cols;
  conv.jacobian = {out[4].data(), 1};
  convert<double>({Space::dirs, false}, {space_of<Hybrid>, false}, in_cols, n, conv);
  const std::vector<std::span<const double>> cols(out.begin(), out.end());
  EXPECT_TRUE(r.out ==
              to_csv(header_of(column_names({space_of<Hybrid>, false}), {"jacobian"}), cols))
      << "the streamed output differs from the whole-input conversion";
}

// A bad row in a later block still fails the command and leaves no output file; with
// --skip-invalid it is counted and named like a bad row of the first block.
TEST_F(CliTest, ConvertStreamingKeepsTheErrorBehaviour) {
  std::string input = many_pairs_csv(140000);
  const std::size_t line = 140000;  // row 139999 (0-based 139998): in the third block
  std::size_t pos = 0;
  for (std::size_t l = 1; l < line; ++l) pos = input.find('\n', pos) + 1;
  input.replace(pos, input.find('\n', pos) - pos, "0,0,1,0,0,2");
  put(path("in.csv"), input);
  put(path("out.csv"), "kept\n");
  Result r = run({"convert", "--from", "dirs", "--to", "ortho", "-i", "in.csv", "-o", "out.csv"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("in.csv:140000: wo is not a unit vector"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(path("out.csv")), "kept\n");
  r = run({"convert", "--from", "dirs", "--to", "ortho", "--skip-invalid", "-i", "in.csv"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("1 invalid input row written with valid = 0; the first: in.csv:140000:"),
            std::string::npos)
      << r.err;
  const CsvTable t = parse(r.out);
  ASSERT_EQ(t.rows(), 140000u);
  EXPECT_EQ(t.columns[4][line - 2], 0.0);
  EXPECT_TRUE(std::isnan(t.columns[0][line - 2]));
  EXPECT_EQ(t.columns[4][line - 3], 1.0);
}

// Memory does not grow with the input: 400000 rows (48 MB of text) were held whole before, with
// their columns and output (well over 100 MB resident); a block at a time needs a few MB.
TEST_F(CliTest, ConvertAndEvalRunInBoundedMemory) {
#if defined(__SANITIZE_ADDRESS__)
  // ASan's shadow memory and quarantine put the tool at 140-170 MB whatever it holds: the release
  // build's run of this test is the one that measures.
  GTEST_SKIP() << "resident memory is not meaningful under AddressSanitizer";
#endif
  if (access(kTimePath, X_OK) != 0) GTEST_SKIP() << kTimePath << " is needed to measure memory";
  const std::string input = many_pairs_csv(400000);
  long rss_kb = 0;
  Result r = run({"convert", "--from", "dirs", "--to", "hybrid"}, input, &rss_kb);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 400001);
  EXPECT_LT(rss_kb, 48 * 1024) << "convert: peak resident memory " << rss_kb << " kB";
  r = run({"eval", "--brdf", "lambert"}, input, &rss_kb);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 400001);
  EXPECT_LT(rss_kb, 48 * 1024) << "eval: peak resident memory " << rss_kb << " kB";
}

// `halfback view` fails before serving on a bad command line or BRDF (the server itself is
// tested by src/view/api_test.cpp and tests/browser/view_test.py).
TEST_F(CliTest, ViewRefusesBadOptionsBeforeServing) {
  Result r = run({"view", "--port", "70000"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--port: expected 0 ... 65535"), std::string::npos) << r.err;
  r = run({"view", "ggx:alpha=-1", "--port", "0"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("'ggx:alpha=-1'"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  r = run({"view", "--root", "/nonexistent/halfback-root", "--port", "0"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--root '/nonexistent/halfback-root': not a readable directory"),
            std::string::npos)
      << r.err;
}

// A second server on a port that is taken fails at once with status 1 (a runtime error), naming
// the address, the port and the reason (here the port is held by a plain listening socket, so
// that the command cannot serve even where it would share the port).
TEST_F(CliTest, ViewOnATakenPortFailsNamingThePort) {
  const int held = ::socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(held, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t size = sizeof a;
  ASSERT_EQ(::bind(held, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  ASSERT_EQ(::listen(held, 1), 0);
  ASSERT_EQ(::getsockname(held, reinterpret_cast<sockaddr*>(&a), &size), 0);
  const std::string port = std::to_string(ntohs(a.sin_port));
  const Result r = run({"view", "lambert", "--port", port});
  ::close(held);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("cannot listen on 127.0.0.1:" + port + ": Address already in use"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.out, "");
}

// The command lines of a text that fit or render a MERL file named merl.binary: docs' lines
// "$ halfback ..." (`prompt`), or every line of the text beginning with "halfback " (after
// spaces), each joined with the lines its trailing '\' continues.
std::vector<std::string> merl_examples(const std::string& text, bool prompt) {
  std::vector<std::string> commands;
  std::istringstream in(text);
  std::string command;
  bool continued = false;
  for (std::string line; std::getline(in, line);) {
    const std::size_t b = line.find_first_not_of(' ');
    line = b == std::string::npos ? "" : line.substr(b);
    if (!continued) {
      if (prompt ? !line.starts_with("$ halfback ") : !line.starts_with("halfback ")) continue;
      command = prompt ? line.substr(2) : line;
    } else {
      command += " " + line;
    }
    continued = !command.empty() && command.back() == '\\';
    if (continued) {
      command.pop_back();
      continue;
    }
    std::string normal;  // spaces as one
    std::istringstream words(command);
    for (std::string w; words >> w;) normal += (normal.empty() ? "" : " ") + w;
    if (normal.find("merl.binary") != std::string::npos) commands.push_back(normal);
  }
  return commands;
}

// The docs' examples that fit and render a MERL file run as written on a file that export-merl
// made: docs/cli.md's "$ halfback ... merl.binary" lines (a render of the fit's printed spec,
// `render --brdf "$(halfback fit --brdf merl.binary ...)"`, and a fit with --emit),
// docs/fit.md's, and `halfback fit --help`'s example, read from them (a changed example is run
// as changed; one removed fails the count), run by the shell with `halfback` on the PATH. Each
// exits 0 with no warning and writes the files it names. On the file written before every bin a
// valid pair is looked up in had a value, the fit failed ("not finite ... at 100 of 20000
// samples"), the render warned of NaN samples, and the pipeline ended with "--brdf: an empty
// value".
TEST_F(CliTest, DocsMerlExamplesRunAsWritten) {
  std::vector<std::string> commands;
  const auto add = [&](const std::vector<std::string>& found, const char* where,
                       std::size_t expected) {
    EXPECT_GE(found.size(), expected) << where << ": the examples with merl.binary are gone";
    for (const std::string& c : found)
      if (std::ranges::find(commands, c) == commands.end()) commands.push_back(c);
  };
  add(merl_examples(slurp(HALFBACK_SOURCE_DIR "/docs/cli.md"), true), "docs/cli.md", 2);
  add(merl_examples(slurp(HALFBACK_SOURCE_DIR "/docs/fit.md"), false), "docs/fit.md", 1);
  const Result help = run({"fit", "--help"});
  ASSERT_EQ(help.status, 0);
  add(merl_examples(help.out, false), "halfback fit --help", 1);
  ASSERT_TRUE(std::ranges::any_of(commands, [](const std::string& c) {
    return c.find("\"$(halfback fit") != std::string::npos;
  })) << "no render of a fit's spec among the examples";
  // A diffuse and a glossy lobe, tabulated: grazing bins hold values (ggx near its mirror).
  Result r = run(
      {"export-merl", "--brdf", "lambert:albedo=0.3+ggx:alpha=0.2,f0=0.5", "-o", "merl.binary"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string bin = fs::path(HALFBACK_CLI_PATH).parent_path().string();
  for (const std::string& command : commands) {
    std::vector<std::string> named;  // the files the command writes: -o FILE, --emit T:FILE
    std::istringstream words(command);
    for (std::string w, previous; words >> w; previous = w) {
      while (!w.empty() && (w.back() == ')' || w.back() == '"')) w.pop_back();  // "$(... -o F)"
      if (previous == "-o") named.push_back(w);
      if (previous == "--emit") named.push_back(w.substr(w.find(':') + 1));
    }
    ASSERT_FALSE(named.empty()) << command;
    for (const std::string& f : named) fs::remove(path(f));
    const test::Spawned s = test::spawn_and_wait(
        dir_.path(), {"/bin/bash", "-c", "PATH=\"" + bin + ":$PATH\"; set -o pipefail; " + command},
        "/dev/null", path(".out"), path(".err"));
    const std::string err = slurp(path(".err"));
    EXPECT_EQ(s.status, 0) << command << "\n" << err;
    EXPECT_EQ(err.find("warning"), std::string::npos) << command << "\n" << err;
    for (const std::string& f : named)
      EXPECT_GT(fs::exists(path(f)) ? fs::file_size(path(f)) : 0, 0u) << command << ": " << f;
  }
}

// `halfback fit`: the spec it prints is the fitted model, which `info` and `eval` read back, and
// which reproduces the BRDF it was fitted to (a Lambert + GGX sum with colours, recovered).
TEST_F(CliTest, FitPrintsASpecThatEveryCommandReadsBack) {
  const std::string truth =
      "lambert:albedo_r=0.6,albedo_g=0.2,albedo_b=0.1+ggx:alpha=0.08,f0_r=0.95,f0_g=0.7,f0_b=0.4";
  Result r = run({"fit", "--brdf", truth, "--model", "lambert+ggx", "--samples", "2000",
                  "--threads", "1", "-o", "fit.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_FALSE(r.out.empty());
  const std::string spec = r.out.substr(0, r.out.find('\n'));
  EXPECT_EQ(r.out, spec + "\n");
  const std::string json = slurp(path("fit.json"));
  for (const std::string& part :
       {"\"spec\":\"" + spec + "\"", "\"name\":\"ngan\""s, "\"layout\":\"halfdiff-halton\""s,
        "\"count\":2000"s, "\"name\":\"f0_b\""s, "\"iterations\":"s, "\"seconds\":"s})
    EXPECT_NE(json.find(part), std::string::npos) << part << " not in " << json;
  EXPECT_EQ(run({"info", spec}).status, 0);
  const std::string input = std::string(kDirsHeader) + "0,0,1,0,0,1\n0.6,0,0.8,-0.48,0.36,0.8\n";
  const CsvTable want = parse(run({"eval", "--brdf", truth}, input).out);
  r = run({"eval", "--brdf", spec}, input);
  ASSERT_EQ(r.status, 0) << r.err;
  const CsvTable got = parse(r.out);
  ASSERT_EQ(got.rows(), 2u);
  for (int c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < 2; ++i)
      EXPECT_NEAR(got.columns[c][i], want.columns[c][i], 1e-4 * want.columns[c][i]);
}

// `halfback fit` says what the fit could and could not do (docs/fit.md): a dead lobe (a Lambert
// term fitted to a GGX lobe ends at albedo 0) is flagged in the JSON and warned of on stderr; a
// parameter without effect (f0 under η > 0) is not "fitted"; a lobe that can be anisotropic is
// fitted on the turned layout.
TEST_F(CliTest, FitReportsDeadLobesInertParametersAndTheTurnedLayout) {
  Result r = run({"fit", "--brdf", "ggx:alpha=0.2,f0=0.5", "--model", "lambert+ggx", "--samples",
                  "1000", "--threads", "1", "-o", "dead.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: term 1 of 2 (lambert) is a dead lobe"), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("term 2 of 2"), std::string::npos) << r.err;
  std::string json = slurp(path("dead.json"));
  const std::size_t ggx = json.find("{\"model\":\"ggx\""), dead = json.find("\"dead\":true"),
                    alive = json.find("\"dead\":false");
  EXPECT_NE(json.find("\"albedo_share\":"), std::string::npos) << json;
  EXPECT_NE(json.find("\"loss_without\":"), std::string::npos) << json;
  EXPECT_TRUE(dead < ggx && ggx < alive && alive != std::string::npos) << json;
  r = run({"fit", "--brdf", "ggx:alpha=0.2,f0=0.5", "--model", "ggx:eta=1.5", "--samples", "500",
           "-o", "eta.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  json = slurp(path("eta.json"));
  const nlohmann::json params = nlohmann::json::parse(json)["terms"][0]["parameters"];
  const auto at = std::find_if(params.begin(), params.end(),
                               [](const nlohmann::json& p) { return p["name"] == "f0_r"; });
  ASSERT_NE(at, params.end()) << json;
  const nlohmann::json& f0_r = *at;
  EXPECT_EQ(f0_r["value"].get<double>(), 0.04) << json;  // ((1.5 - 1) / (1.5 + 1))², to the bit
  EXPECT_EQ(f0_r["unit"], "1") << json;
  EXPECT_EQ(f0_r["fitted"], false) << json;
  r = run({"fit", "--brdf", "ggx:alpha=0.2,f0=0.5", "--model", "ggx:alpha_x=0.1", "--samples",
           "500", "-o", "aniso.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(path("aniso.json")).find("\"layout\":\"halfdiff-halton-turned\""),
            std::string::npos);
}

// Bad models, losses and --brdf specs are usage errors (2, as in every command); a target the fit
// cannot use is a data error (1); none leaves a file, and an existing output is kept.
TEST_F(CliTest, FitBadInputLeavesNoOutput) {
  put(path("old.json"), "old");
  struct Case {
    std::vector<std::string> args;
    int status;
    std::string words;
  };
  const std::vector<Case> cases{
      {{"--brdf", "ggx", "--model", "phong"}, 2, "phong"},
      {{"--brdf", "ggx", "--model", "ggx:roughness=1"}, 2, "roughness"},
      {{"--brdf", "ggx", "--model", "ggx", "--loss", "l2"}, 2, "--loss 'l2'"},
      {{"--brdf", "nosuchmodel:x=1", "--model", "ggx"}, 2, "nosuchmodel"},
      {{"--brdf", "ggx", "--model", "ggx:alpha=0.1,f0=0.5"}, 2, "nothing to fit"},
      {{"--brdf", "lambert:albedo=0", "--model", "ggx"}, 1, "zero at all"},
      {{"--brdf", "ggx:alpha_x=0.1,alpha_y=0.4", "--model", "ggx"}, 1, "anisotropic"},
  };
  for (const Case& c : cases) {
    for (const char* out : {"new.json", "old.json"}) {
      std::vector<std::string> args{"fit", "--samples", "200", "-o", out};
      args.insert(args.end(), c.args.begin(), c.args.end());
      const Result r = run(args);
      EXPECT_EQ(r.status, c.status) << c.words << ": " << r.err;
      EXPECT_NE(r.err.find(c.words), std::string::npos) << r.err;
      EXPECT_TRUE(r.out.empty()) << r.out;
    }
  }
  EXPECT_EQ(entries(), std::vector<std::string>{"old.json"});
  EXPECT_EQ(slurp(path("old.json")), "old");
}

// `--emit TARGET:FILE`: the fit as the renderers' own materials, beside the JSON (docs/fit.md,
// "Renderer-ready output"); the emitted values are the fitted spec's.
TEST_F(CliTest, FitEmitWritesTheRenderersMaterials) {
  Result r = run({"fit", "--brdf", "lambert:albedo_r=0.6,albedo_g=0.25,albedo_b=0.125", "--model",
                  "lambert", "--samples", "500", "--threads", "1", "-o", "fit.json", "--emit",
                  "mitsuba3:bsdf.xml", "--emit", "pbrt-v4:material.pbrt"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(entries(), (std::vector<std::string>{"bsdf.xml", "fit.json", "material.pbrt"}));
  const std::string spec = r.out.substr(0, r.out.find('\n'));
  const std::string xml = slurp(path("bsdf.xml")), pbrt = slurp(path("material.pbrt"));
  EXPECT_NE(xml.find("halfback fit: " + spec + "\n"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<bsdf id=\"halfback_fit\" type=\"diffuse\">"), std::string::npos) << xml;
  EXPECT_NE(pbrt.find("MakeNamedMaterial \"halfback_fit\"\n    \"string type\" \"diffuse\""),
            std::string::npos)
      << pbrt;
  EXPECT_NE(r.err.find("mitsuba3 material 'halfback_fit' written to bsdf.xml"), std::string::npos)
      << r.err;
  // The albedo fitted, as the spec prints it, is the reflectance written.
  const std::size_t at = spec.find("albedo_r=") + 9;
  const std::string red = spec.substr(at, spec.find(',', at) - at);
  EXPECT_NE(xml.find("<rgb name=\"reflectance\" value=\"" + red + ", "), std::string::npos) << xml;
  EXPECT_NE(pbrt.find("\"rgb reflectance\" [ " + red + " "), std::string::npos) << pbrt;

  r = run({"fit", "--brdf", "ggx:alpha=0.2,f0=0.9", "--model", "ggx", "--samples", "500",
           "--threads", "1", "-o", "ggx.json", "--emit", "pbrt-v4:ggx.pbrt"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(path("ggx.pbrt")).find("\"string type\" \"conductor\""), std::string::npos);
}

// A model the renderer has no material for, an unknown target or a malformed --emit: usage
// errors (2) before the fit; a fitted value the renderer cannot take, a target the fit cannot use
// or an unwritable destination: 1. Nothing is written, and existing files are kept.
TEST_F(CliTest, FitEmitRefusesWhatTheRendererLacksAndLeavesNoFile) {
  put(path("old.json"), "old");
  put(path("old.xml"), "old xml");
  struct Case {
    std::vector<std::string> args;
    int status;
    std::string words;
  };
  const std::string brdf = "ggx:alpha=0.2,f0=0.9";
  const std::vector<Case> cases{
      {{"--brdf", brdf, "--model", "ward", "--emit", "pbrt-v4:E"}, 2, "halfback export-rgl"},
      {{"--brdf", brdf, "--model", "lambert+ggx", "--emit", "pbrt-v4:E"}, 2, "no plain sum"},
      {{"--brdf", brdf, "--model", "beckmann", "--emit", "pbrt-v4:E"}, 2, "Trowbridge-Reitz"},
      {{"--brdf", brdf, "--model", "sheen", "--emit", "mitsuba3:E"}, 2, "no 'sheen' lobe"},
      {{"--brdf", brdf, "--model", "ggx", "--emit", "cycles:E"}, 2, "unknown target 'cycles'"},
      {{"--brdf", brdf, "--model", "beckmann", "--emit", "blender:E"}, 2, "GGX distribution only"},
      {{"--brdf", brdf, "--model", "ggx", "--emit", "mitsuba3"}, 2, "TARGET:FILE"},
      {{"--brdf", brdf, "--model", "ggx", "--emit", "mitsuba3:-"}, 2, "writes to a file"},
      {{"--brdf", brdf, "--model", "ggx", "--emit", "mitsuba3:J"}, 2, "the file of -o"},
      {{"--brdf", brdf, "--model", "ggx", "--emit", "mitsuba3:E", "--emit", "pbrt-v4:E"},
       2,
       "another --emit"},
      {{"--brdf", "lambert:albedo=0", "--model", "ggx", "--emit", "mitsuba3:E"}, 1, "zero at all"},
      {{"--brdf", "lambert:albedo=1", "--model", "lambert:albedo=1+ggx", "--emit", "mitsuba3:E"},
       1,
       "an albedo of 1"},
      {{"--brdf", brdf, "--model", "ggx", "--emit", "mitsuba3:no/such/dir/E"}, 1, "cannot"},
  };
  for (const Case& c : cases) {
    for (const auto& [json, emitted] :
         {std::pair{"new.json", "new.xml"}, {"old.json", "old.xml"}}) {
      std::vector<std::string> args{"fit", "--samples", "200", "--threads", "1", "-o", json};
      for (std::string a : c.args) {
        for (const auto& [from, to] : {std::pair{"E", emitted}, {"J", json}})
          if (const std::size_t at = a.rfind(from); at != std::string::npos && at + 1 == a.size())
            a.replace(at, 1, to);
        args.push_back(a);
      }
      const Result r = run(args);
      EXPECT_EQ(r.status, c.status) << c.words << ": " << r.err;
      EXPECT_NE(r.err.find(c.words), std::string::npos) << r.err;
      EXPECT_TRUE(r.out.empty()) << r.out;
    }
  }
  EXPECT_EQ(entries(), (std::vector<std::string>{"old.json", "old.xml"}));
  EXPECT_EQ(slurp(path("old.json")), "old");
  EXPECT_EQ(slurp(path("old.xml")), "old xml");
}

}  // namespace
}  // namespace halfback

namespace halfback {
namespace {

// A float32 .npy array (format 1.0) of the given shape.
void put_npy(const fs::path& p, const std::string& shape, const std::vector<float>& values) {
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': " + shape + ", }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string bytes("\x93NUMPY\x01\x00", 8);
  bytes += char(header.size() & 0xff);
  bytes += char(header.size() >> 8);
  bytes += header;
  bytes.append(reinterpret_cast<const char*>(values.data()), 4 * values.size());
  put(p, bytes);
}

// docs/reliability/readers.md: a BRDF whose ρ is above the bound on a
// BRDF's value is refused by every command, naming the file and the bound: a neural BRDF whose
// last bias is 100 (ρ = 1.65e38 everywhere: `info` printed it, `export-rgl` wrote a file its own
// reader refused, `render` blamed --env-exposure) and an ALTA sample of 1e308 (`max ρ: inf`).
TEST_F(CliTest, BrdfAboveTheBoundIsRefusedByEveryCommand) {
  put_npy(path("hot_fc1.npy"), "(6, 2)", std::vector<float>(12, 0.1f));
  put_npy(path("hot_b1.npy"), "(2,)", {0, 0});
  put_npy(path("hot_fc2.npy"), "(2, 3)", std::vector<float>(6, 0.1f));
  put_npy(path("hot_b2.npy"), "(3,)", {100, 100, 100});
  const std::string why = "above the bound of 1e+10 sr⁻¹ on a BRDF's value";
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"info", "hot_fc1.npy"},
        {"render", "--brdf", "hot_fc1.npy", "-o", "hot.png", "--width", "8", "--height", "8"},
        {"export-rgl", "--brdf", "hot_fc1.npy", "-o", "hot.bsdf"},
        {"export-merl", "--brdf", "hot_fc1.npy", "-o", "hot.binary"}}) {
    const Result r = run(args);
    EXPECT_EQ(r.status, 1) << args[0] << ": " << r.err;
    EXPECT_NE(r.err.find("hot_fc1.npy: network: ρ = 1.65"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("exposure"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(path("hot.png")) || fs::exists(path("hot.bsdf")) ||
               fs::exists(path("hot.binary")));
  put(path("hot.dat"),
      "#DIM 3 1\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT INV_STERADIAN\n"
      "0.5 0 0 1\n0.5 0.1 0 1e308\n0.5 0 0.1 1\n");
  const Result r = run({"info", "hot.dat"});
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.err.find("hot.dat: line 5: the sample's value gives ρ = 1e+308 sr⁻¹, " + why),
            std::string::npos)
      << r.err;
}

// docs/reliability/readers.md: `info` on a small RGL file extended to 1.5 GB by
// truncate -s (sparse) read it whole (3.1 GB of memory, 25 s) and accepted it; it is refused with
// both byte counts, within 100 MB of resident memory.
TEST_F(CliTest, SparseExtensionOfAFileIsRefusedInLittleMemory) {
  const fs::path small = HALFBACK_SOURCE_DIR "/data/rgl/acrylic_felt_green_rgb.bsdf";
  fs::copy_file(small, path("big.bsdf"));
  fs::permissions(path("big.bsdf"), fs::perms::owner_write, fs::perm_options::add);
  fs::resize_file(path("big.bsdf"), 1'500'000'000);
  long rss_kb = 0;
  const Result r = run({"info", "big.bsdf"}, "", &rss_kb);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("big.bsdf: file size: the header declares " +
                       std::to_string(fs::file_size(small)) +
                       " bytes (the end of its last field), the file has 1500000000 bytes"),
            std::string::npos)
      << r.err;
  EXPECT_GT(rss_kb, 0);  // measured
  EXPECT_LT(rss_kb, 100 * 1024) << rss_kb << " KB";
  fs::remove(path("big.bsdf"));
}

}  // namespace
}  // namespace halfback
