// One vocabulary across the commands of `halfback` (docs/cli.md, "Option names"): the same idea
// has the same option name in every command. The options are read from the built binary's own
// help (`halfback --help`, then `halfback COMMAND [SUBCOMMAND] --help` for every command it
// lists), so a command or option added later is checked without editing this file. Each idea is
// recognized by what the option says it takes, not by its name:
//   output            -o (or --out/--output)          -> -o,--output (--out an alias)
//   threads           "0: all cores"                  -> --threads
//   parameterization  "parameterization(s)" in help   -> --param (one, type PARAM) or --params
//                                                        (a comma-separated list, PARAM,...)
//   spacing           own, angle, merl                -> --spacing / --spacings
//   design            regular, stratified             -> --design / --designs
//   budget            a count of measurements         -> a name with "budget" ("budgets" for lists)
//   angle             theta, azimuth, elevation, ...  -> degrees, said in the help
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "help_options.hpp"
#include "support/spawn.hpp"
#include "support/test_support.hpp"

// A named namespace: the test files are compiled as one unity translation unit.
namespace halfback::vocabulary_test {

namespace fs = std::filesystem;

struct CliOption {
  std::string command;             // "study", "figure slices"
  std::vector<std::string> names;  // as the help lists them: "-o", "--output", "--out"
  std::string type;                // the word after the names ("PARAM=hybrid", "UINT:UINT", ...)
  std::string text;                // everything after the names: type and description

  // The first long name: the option's name in messages and docs; the others are aliases.
  std::string primary() const {
    for (const std::string& n : names)
      if (n.starts_with("--")) return n;
    return names.empty() ? "" : names.front();
  }
  bool has(const std::string& name) const { return std::ranges::find(names, name) != names.end(); }
  std::string label() const {
    std::string s = "halfback " + command + " ";
    for (std::size_t i = 0; i < names.size(); ++i) s += (i ? "," : "") + names[i];
    return s;
  }
};

class Vocabulary : public testing::Test {
 protected:
  std::string help(const std::string& command) {
    std::vector<std::string> argv{HALFBACK_CLI_PATH};
    std::istringstream words(command);
    for (std::string w; words >> w;) argv.push_back(w);
    argv.push_back("--help");
    const test::Captured ran = test::run_captured(dir_.path(), std::move(argv));
    EXPECT_TRUE(ran.started) << ran.error;
    EXPECT_EQ(ran.status, 0) << command;
    return ran.out;
  }

  // The names listed in a help's "Subcommands:" section.
  static std::vector<std::string> subcommands(const std::string& help_text) {
    std::vector<std::string> names;
    for (const std::string& line : test::section_lines(help_text, "Subcommands:")) {
      std::istringstream words(line);
      std::string name;
      words >> name;
      names.push_back(name);
    }
    return names;
  }

  // The options of a help's "Options:" section (without -h,--help).
  static std::vector<CliOption> options(const std::string& command, const std::string& help_text) {
    std::vector<CliOption> found;
    for (test::HelpOption& h : test::help_options(help_text)) {
      CliOption o;
      o.command = command;
      o.names = std::move(h.names);
      o.text = std::move(h.text);
      o.type = o.text.substr(0, o.text.find(' '));
      if (!o.has("--help")) found.push_back(std::move(o));
    }
    return found;
  }

  // Every option of every command and subcommand, from the help texts.
  std::vector<CliOption> every_option() {
    std::vector<CliOption> all;
    std::vector<std::string> todo = subcommands(help(""));
    EXPECT_GE(todo.size(), 15u) << "the commands of `halfback --help`";
    while (!todo.empty()) {
      const std::string command = todo.back();
      todo.pop_back();
      const std::string text = help(command);
      for (const std::string& sub : subcommands(text)) todo.push_back(command + " " + sub);
      for (CliOption& o : options(command, text)) all.push_back(std::move(o));
    }
    return all;
  }

  test::TempDir dir_;
};

bool contains(const std::string& text, const std::string& what) {
  return text.find(what) != std::string::npos;
}

bool word_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

// Whether `text` has `word` as a whole word, or with an 's' after it when `plural` (no
// std::regex: GCC 12 warns of an uninitialized std::function inside it under ASan).
bool has_word(const std::string& text, const std::string& word, bool plural = false) {
  for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) {
    if (at > 0 && word_char(text[at - 1])) continue;
    std::size_t end = at + word.size();
    if (plural && end < text.size() && text[end] == 's') ++end;
    if (end == text.size() || !word_char(text[end])) return true;
  }
  return false;
}

// A count (not a FLOAT: a reach in degrees is no budget).
bool count_type(const std::string& type) {
  return type.starts_with("UINT") || type.starts_with("INT") || type == "N" ||
         type.starts_with("N=") || type.starts_with("N,");
}

// Whether the option takes a value: CLI11 prints its type (PARAM, UINT, TEXT:{...}, N, ...) in
// capitals after the names, where a flag's help starts with its description.
bool takes_value(const CliOption& o) {
  std::size_t letters = 0;
  while (letters < o.type.size() && std::isalpha(static_cast<unsigned char>(o.type[letters])))
    ++letters;
  if (letters == 0) return false;
  for (std::size_t k = 0; k < letters; ++k)
    if (!std::isupper(static_cast<unsigned char>(o.type[k]))) return false;
  return true;
}

constexpr std::array<const char*, 7> kAngleWords{"theta", "azimuth", "elevation", "rotation",
                                                 "angle", "zenith",  "tilt"};

// The ideas an option expresses, each with the name the vocabulary gives it (empty: the option
// has it).
struct Finding {
  std::string idea, problem;
};

std::vector<Finding> check(const CliOption& o) {
  std::vector<Finding> f;
  const std::string p = o.primary();
  const bool list = contains(o.text, "comma-separated");
  const auto expect = [&](const std::string& idea, bool ok, const std::string& rule) {
    f.push_back({idea, ok ? "" : o.label() + ": " + rule + " (help: " + o.text + ")"});
  };
  if (o.has("-o") || o.has("--out") || o.has("--output"))
    expect("output", o.has("-o") && p == "--output", "the output is -o,--output");
  if (contains(o.text, "all cores")) expect("threads", p == "--threads", "threads are --threads");
  // (A flag that names parameterizations in its help, as --no-neural does, takes none.)
  if (takes_value(o) &&
      (has_word(o.text, "parameterization", true) || has_word(o.text, "Parameterization", true))) {
    const std::string want = list ? "--params" : "--param";
    const std::string type = list ? "PARAM,..." : "PARAM";
    expect("parameterization", p == want && o.type.starts_with(type),
           "a parameterization is " + want + " " + type + " (--params for a comma-separated list)");
  }
  const bool spacing =
      has_word(o.text, "own") && contains(o.text, "merl") && contains(o.text, "angle");
  if (spacing)
    expect("spacing", p == (list ? "--spacings" : "--spacing"),
           "a spacing of the cells (own, angle, merl, learned) is --spacing (--spacings for a "
           "list)");
  if (!spacing && contains(o.text, "regular") && contains(o.text, "stratified"))
    expect("design", p == (list ? "--designs" : "--design"),
           "a design (regular, stratified, ...) is --design (--designs for a list)");
  if (count_type(o.type) && (contains(o.text, "udget") || contains(o.text, "easurement")))
    expect("budget",
           list ? contains(p, "budgets") : contains(p, "budget") && !contains(p, "budgets"),
           "a count of measurements is a budget: --budget, or --...budgets for a list");
  if (std::any_of(kAngleWords.begin(), kAngleWords.end(),
                  [&](const char* w) { return contains(p, w); }))
    expect("angle", contains(o.text, "degree"), "an angle on the command line is in degrees");
  return f;
}

TEST_F(Vocabulary, EachIdeaHasOneNameInEveryCommand) {
  const std::vector<CliOption> all = every_option();
  std::map<std::string, std::set<std::string>> names;  // idea -> primary names
  std::map<std::string, std::size_t> count;            // idea -> options
  for (const CliOption& o : all)
    for (const Finding& f : check(o)) {
      EXPECT_EQ(f.problem, "");
      names[f.idea].insert(o.primary());
      ++count[f.idea];
    }
  // Each idea is found where it is known to be (a change of the help's layout that hid the
  // options from this test would make it pass on nothing).
  const std::map<std::string, std::size_t> at_least{
      {"output", 14}, {"threads", 12}, {"parameterization", 8}, {"spacing", 2}, {"design", 1},
      {"budget", 6},  {"angle", 7}};
  for (const auto& [idea, n] : at_least) EXPECT_GE(count[idea], n) << idea;
  for (const auto& [idea, found] : names) {  // what was recognized, for the log
    std::cout << idea << " (" << count[idea] << " options):";
    for (const std::string& n : found) std::cout << " " << n;
    std::cout << "\n";
  }
  // One name per idea: the singular and, for lists, the plural.
  EXPECT_EQ(names["output"], (std::set<std::string>{"--output"}));
  EXPECT_EQ(names["threads"], (std::set<std::string>{"--threads"}));
  EXPECT_EQ(names["parameterization"], (std::set<std::string>{"--param", "--params"}));
  EXPECT_EQ(names["spacing"], (std::set<std::string>{"--spacing", "--spacings"}));
  EXPECT_EQ(names["design"], (std::set<std::string>{"--design"}));
}

// The older names still work, as aliases listed beside the new name in the help.
TEST_F(Vocabulary, OlderNamesAreAliases) {
  const std::vector<CliOption> all = every_option();
  struct Alias {
    std::string command, name, alias;
  };
  const std::vector<Alias> aliases{
      {"render", "--param", "--sampling-param"},
      {"study", "--spacings", "--designs"},
      {"study", "--output", "--out"},
      {"study", "--nielsen-budgets", "--nielsen-counts"},
      {"plan", "--budget", "--count"},
      {"compare", "--output", "--out"},
      {"figure hemisphere", "--params", "--param"},
      {"figure slices", "--params", "--param"},
      {"figure material", "--params", "--param"},
      {"figure slices", "--output", "--out"},
      {"figure paper", "--output", "--out"},
  };
  for (const Alias& a : aliases) {
    const auto o = std::ranges::find_if(
        all, [&](const CliOption& c) { return c.command == a.command && c.primary() == a.name; });
    ASSERT_NE(o, all.end()) << a.command << " " << a.name;
    EXPECT_TRUE(o->has(a.alias)) << o->label() << " lacks its older name " << a.alias;
  }
}

// A script (stderr not a terminal) learns which BRDF sampler `render` used and, with `auto`, why:
// one line, unless -q.
TEST_F(Vocabulary, RenderReportsItsSamplerChoiceToAScript) {
  const fs::path out = dir_ / "out", err = dir_ / "err";
  const auto render = [&](std::vector<std::string> more) {
    std::vector<std::string> argv{
        HALFBACK_CLI_PATH, "render", "--brdf",   "embedded:gold-metallic-paint3",
        "--width",         "16",     "--height", "16",
        "--spp",           "1",      "-o",       "r.png"};
    argv.insert(argv.end(), more.begin(), more.end());
    const test::Spawned s = test::spawn_and_wait(dir_.path(), argv, "/dev/null", out, err);
    EXPECT_EQ(s.status, 0);
    std::ifstream in(err);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  };
  const std::string line = render({});
  EXPECT_TRUE(line.starts_with("halfback render: r.png: 16 x 16, 1 spp, ")) << line;
  EXPECT_EQ(std::count(line.begin(), line.end(), '\n'), 1) << line;
  // A measured material has no sampler of its own: auto measured and chose, and says so.
  EXPECT_TRUE(contains(line, "; BRDF sampler: ")) << line;
  EXPECT_TRUE(contains(line, "(chosen: ")) << line;
  EXPECT_TRUE(contains(line, "threshold") || contains(line, "misses a peak")) << line;
  const std::string table = render({"--brdf-sampling", "table"});
  EXPECT_TRUE(contains(table, "; BRDF sampler: ") && !contains(table, "chosen")) << table;
  EXPECT_EQ(render({"-q"}), "");
}

}  // namespace halfback::vocabulary_test
