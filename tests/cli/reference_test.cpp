// Tests of the command reference (the binary at HALFBACK_CLI_PATH): every built-in
// parameterization and loss is named wherever a list of them is printed (the help texts, the man
// page, docs/cli.md), and the generated reference (`halfback --help-reference`) covers every
// command and option of the help texts. That the committed docs are the generated text is the
// test cli_reference_matches_docs (scripts/cli_reference.py --check).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/core/space.hpp"
#include "halfback/fit/fit.hpp"
#include "support/spawn.hpp"
#include "support/test_support.hpp"

// A named namespace: the test files are compiled as one unity translation unit.
namespace halfback::reference_cli_test {

namespace fs = std::filesystem;

struct Outcome {
  int status = -1;
  std::string out, err;
};

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// `name` in `text` as a word of its own: not inside a longer name ("halfdiff" in
// "stereo-halfdiff", "ortho" in "orthographic").
bool names(std::string_view text, std::string_view name) {
  const auto part_of_name = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_';
  };
  for (std::size_t at = text.find(name); at != std::string_view::npos;
       at = text.find(name, at + 1)) {
    const bool before = at > 0 && part_of_name(text[at - 1]);
    const std::size_t end = at + name.size();
    // A name may end a sentence or a list ("hybrid." "hybrid,"): '-' after it continues it.
    const bool after = end < text.size() && part_of_name(text[end]);
    if (!before && !after) return true;
  }
  return false;
}

std::vector<std::string> builtin_parameterizations() {
  std::vector<std::string> v;
  for (Space s : kBuiltinSpaces) v.emplace_back(name_of(s));
  return v;
}

std::vector<std::string> losses() {
  std::vector<std::string> v;
  for (fit::Loss l : fit::kLosses) v.emplace_back(fit::name_of(l));
  return v;
}

// The names of `all` that `text` lacks.
std::vector<std::string> missing(std::string_view text, const std::vector<std::string>& all) {
  std::vector<std::string> m;
  for (const std::string& n : all)
    if (!names(text, n)) m.push_back(n);
  return m;
}

std::size_t named(std::string_view text, const std::vector<std::string>& all) {
  return all.size() - missing(text, all).size();
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

// The man page's text as a reader sees it: roff's escaped hyphens and backslashes undone.
std::string man_text(std::string roff) {
  for (std::size_t at = 0; (at = roff.find("\\-", at)) != std::string::npos;)
    roff.replace(at, 2, "-");
  return roff;
}

class CliReference : public testing::Test {
 protected:
  Outcome run(const std::vector<std::string>& args) const {
    std::vector<std::string> argv{HALFBACK_CLI_PATH};
    argv.insert(argv.end(), args.begin(), args.end());
    const test::Captured ran = test::run_captured(dir_.path(), std::move(argv));
    if (!ran.started) ADD_FAILURE() << "cannot run " << HALFBACK_CLI_PATH << ": " << ran.error;
    return {ran.status, ran.out, ran.err};
  }

  // Every command and subcommand ("convert", "figure paper", ...), from the generated reference's
  // blocks, which the next test checks against `halfback --help`.
  std::vector<std::string> commands() const {
    const Outcome r = run({"--help-reference=markdown"});
    EXPECT_EQ(r.status, 0) << r.err;
    std::vector<std::string> v;
    // (No std::regex: GCC 12 warns of an uninitialized std::function inside it under ASan.)
    const std::string begin = "<!-- BEGIN generated: halfback ", end = " -->";
    for (std::size_t at = r.out.find(begin); at != std::string::npos;
         at = r.out.find(begin, at + 1)) {
      const std::size_t from = at + begin.size(), to = r.out.find(end, from);
      if (to == std::string::npos) break;
      v.push_back(r.out.substr(from, to - from));
    }
    return v;
  }

  std::string help(const std::string& command) const {
    std::vector<std::string> args;
    std::istringstream words(command);
    for (std::string w; words >> w;) args.push_back(w);
    args.push_back("--help");
    const Outcome r = run(args);
    EXPECT_EQ(r.status, 0) << command << ": " << r.err;
    return r.out;
  }

  test::TempDir dir_;
};

TEST_F(CliReference, TheNamesOfTheRegistriesAreOnesTheTestCanFind) {
  // The test below is only as good as `names`: it must tell a name from a longer one.
  EXPECT_TRUE(names("a, halfdiff, b", "halfdiff"));
  EXPECT_TRUE(names("or hybrid.", "hybrid"));
  EXPECT_FALSE(names("stereo-halfdiff", "halfdiff"));
  EXPECT_FALSE(names("orthographic", "ortho"));
  EXPECT_FALSE(names("bbm-ngan", "ngan"));
  EXPECT_GE(builtin_parameterizations().size(), 8u);
  EXPECT_GE(losses().size(), 14u);
}

TEST_F(CliReference, EveryParameterizationAndLossWhereverListsArePrinted) {
  const std::vector<std::string> params = builtin_parameterizations(), loss_names = losses();
  // Where a list must be: the tool's overview, the options that take a parameterization or a
  // loss, the man page and docs/cli.md.
  const std::vector<std::string> param_lists{"",      "convert",           "resample", "render",
                                             "study", "figure hemisphere", "plan"};
  for (const std::string& command : param_lists) {
    const std::string text = command.empty() ? run({"--help"}).out : help(command);
    EXPECT_TRUE(missing(text, params).empty())
        << "halfback " << command << " --help lacks " << joined(missing(text, params));
  }
  for (const std::string command : {"fit", "study"}) {
    const std::string text = help(command);
    EXPECT_TRUE(missing(text, loss_names).empty())
        << "halfback " << command << " --help lacks " << joined(missing(text, loss_names));
  }
  // Any other help that names three of them is a list, and must be whole.
  for (const std::string& command : commands()) {
    const std::string text = help(command);
    if (named(text, params) >= 3) {
      EXPECT_TRUE(missing(text, params).empty())
          << "halfback " << command << " --help lists parameterizations but lacks "
          << joined(missing(text, params));
    }
    if (named(text, loss_names) >= 3) {
      EXPECT_TRUE(missing(text, loss_names).empty())
          << "halfback " << command << " --help lists losses but lacks "
          << joined(missing(text, loss_names));
    }
  }
  const std::string man = man_text(read_all(fs::path(HALFBACK_SOURCE_DIR) / "docs/halfback.1"));
  const std::string cli_md = read_all(fs::path(HALFBACK_SOURCE_DIR) / "docs/cli.md");
  for (const auto& [doc, text] : {std::pair{"docs/halfback.1", &man}, {"docs/cli.md", &cli_md}}) {
    ASSERT_FALSE(text->empty()) << doc;
    EXPECT_TRUE(missing(*text, params).empty())
        << doc << " lacks " << joined(missing(*text, params));
    EXPECT_TRUE(missing(*text, loss_names).empty())
        << doc << " lacks " << joined(missing(*text, loss_names));
  }
}

TEST_F(CliReference, TheReferenceCoversEveryCommandAndOption) {
  const Outcome markdown = run({"--help-reference=markdown"});
  const Outcome man = run({"--help-reference=man"});
  ASSERT_EQ(markdown.status, 0) << markdown.err;
  ASSERT_EQ(man.status, 0) << man.err;
  const std::string man_page = man_text(man.out);
  const std::vector<std::string> all = commands();

  // Every command of `halfback --help`, and every subcommand of theirs, has a block.
  const std::string overview = run({"--help"}).out;
  const std::string listed = overview.substr(overview.find("Subcommands:"));
  std::size_t top_level = 0;
  for (const std::string& c : all) {
    if (c.find(' ') != std::string::npos) continue;
    ++top_level;
    EXPECT_TRUE(names(listed, c)) << c << " is not in halfback --help";
  }
  std::istringstream lines(listed);
  std::size_t in_help = 0;
  for (std::string line; std::getline(lines, line);)
    if (line.starts_with("  ") && line.size() > 2 && line[2] != ' ') ++in_help;
  EXPECT_EQ(top_level, in_help) << "the commands of halfback --help and of the reference differ";
  EXPECT_NE(std::find(all.begin(), all.end(), "figure paper"), all.end());
  EXPECT_NE(std::find(all.begin(), all.end(), "nbrdf train"), all.end());

  // Every option of every command's --help (each name of the first column of its "Options:"
  // lines) is in its markdown block and in its man section.
  for (const std::string& command : all) {
    const std::string name = "halfback " + command;
    const std::size_t from = markdown.out.find("<!-- BEGIN generated: " + name + " -->");
    const std::size_t to = markdown.out.find("<!-- END generated: " + name + " -->");
    ASSERT_TRUE(from != std::string::npos && to != std::string::npos) << name;
    const std::string block = markdown.out.substr(from, to - from);
    const std::size_t man_from = man_page.find(".SS \"" + command + "\"");
    ASSERT_NE(man_from, std::string::npos) << name << " has no section in the man page";
    const std::string section =
        man_page.substr(man_from, man_page.find(".SS \"", man_from + 1) - man_from);
    std::istringstream lines(help(command));
    std::size_t count = 0;
    for (std::string line; std::getline(lines, line);) {
      if (!line.starts_with("  -")) continue;
      std::istringstream first_column(line.substr(2, line.find(' ', 2) - 2));
      for (std::string o; std::getline(first_column, o, ',');) {
        if (o == "-h" || o == "--help") continue;
        ++count;
        EXPECT_TRUE(block.find("`" + o + "`") != std::string::npos ||
                    block.find("`" + o + ", ") != std::string::npos ||
                    block.find(", " + o + "`") != std::string::npos ||
                    block.find(", " + o + ", ") != std::string::npos)  // a middle name
            << name << ": " << o << " is not in its markdown block";
        EXPECT_TRUE(section.find("\\fB" + o) != std::string::npos ||
                    section.find(", " + o) != std::string::npos)
            << name << ": " << o << " is not in its man section";
      }
    }
    if (command != "models" && command != "figure" && command != "nbrdf") {
      EXPECT_GT(count, 0u) << name << ": no option found in its --help";
    }
  }
}

TEST_F(CliReference, AnUnknownFormatIsAUsageError) {
  const Outcome r = run({"--help-reference=html"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty());
  EXPECT_NE(r.err.find("--help-reference: expected man or markdown, not 'html'"), std::string::npos)
      << r.err;
}

}  // namespace halfback::reference_cli_test
