// `halfback study --help` says each metric option's values as the study resolves them: the help
// of --fit-budgets holds "default X", X being what make_config() gives fit_budgets when it is not
// given, and "--quick Y" when --quick gives another value Y. The words of the option
// (MetricOption::help) repeat none of these values, so that the help cannot drift from them.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "halfback/study/metric.hpp"
#include "halfback/study/parts.hpp"
#include "help_options.hpp"
#include "support/spawn.hpp"
#include "support/test_support.hpp"

// A named namespace: the test files are compiled as one unity translation unit.
namespace halfback::study_help_test {

// The help of each option of a help's "Options:" section, by its first name ("--fit-budgets").
std::map<std::string, std::string> option_help(const std::string& help_text) {
  std::map<std::string, std::string> found;
  for (const test::HelpOption& o : test::help_options(help_text))
    if (!o.names.empty()) found[o.names.front()] = o.text;
  return found;
}

// Whether `text` holds `value` as a whole value: not inside a longer number or list of numbers
// ("64" is not in "1,64" nor in "640").
bool has_value(const std::string& text, const std::string& value) {
  const auto digit = [&](std::size_t i) {
    return i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]));
  };
  const auto joiner = [&](std::size_t i) {
    return i < text.size() && (text[i] == ',' || text[i] == '.');
  };
  for (std::size_t at = text.find(value); at != std::string::npos; at = text.find(value, at + 1)) {
    const std::size_t end = at + value.size();
    const bool before = at > 0 && (digit(at - 1) || (at > 1 && joiner(at - 1) && digit(at - 2)));
    const bool after = digit(end) || (joiner(end) && digit(end + 1));
    if (!before && !after) return true;
  }
  return false;
}

// The configurations make_config() gives without and with --quick, every metric asked for (so that
// the options of those off by default have their values too).
std::pair<study::StudyConfig, study::StudyConfig> configs_with_every_metric() {
  study::StudySettings settings;
  settings.designs = {"own"};
  for (const study::Metric* m : study::study_metrics())
    if (m->switchable()) settings.metrics.emplace_back(m->name());
  study::StudyConfig plain = study::make_config(settings);
  settings.quick = true;
  return {std::move(plain), study::make_config(settings)};
}

// The options of `halfback study --help` (empty when it fails: the callers assert on it).
std::map<std::string, std::string> study_help() {
  test::TempDir dir;
  const test::Captured ran = test::run_captured(dir.path(), {HALFBACK_CLI_PATH, "study", "--help"});
  EXPECT_TRUE(ran.started) << ran.error;
  EXPECT_EQ(ran.status, 0) << ran.err;
  return option_help(ran.out);
}

TEST(StudyHelp, HasValueFindsWholeValuesOnly) {
  EXPECT_TRUE(has_value("(default 64,1024; --quick 64)", "64,1024"));
  EXPECT_TRUE(has_value("default 20.", "20"));
  EXPECT_FALSE(has_value("1 to 640", "64"));
  EXPECT_FALSE(has_value("sizes 64,1024", "64"));
  EXPECT_FALSE(has_value("0.0011", "0.001"));
  EXPECT_FALSE(has_value("widths 1,64", "64"));
}

TEST(StudyHelp, MetricOptionsSayTheValuesTheStudyUses) {
  const auto [plain, quick] = configs_with_every_metric();
  const std::map<std::string, std::string> help = study_help();
  ASSERT_FALSE(help.empty()) << "`halfback study --help` has no options";

  std::size_t checked = 0;
  for (const study::Metric* m : study::study_metrics()) {
    for (const study::MetricOption& o : m->options()) {
      std::string flag = "--" + o.key;
      std::replace(flag.begin(), flag.end(), '_', '-');
      const auto it = help.find(flag);
      ASSERT_NE(it, help.end()) << flag << " is not in `halfback study --help`";
      const std::string& line = it->second;
      const std::string value = plain.option(o.key), quick_value = quick.option(o.key);
      ASSERT_FALSE(value.empty()) << o.key;
      EXPECT_TRUE(line.find("default " + value + ";") != std::string::npos ||
                  line.find("default " + value + ")") != std::string::npos)
          << flag << ": the study's default is " << value << "; the help says: " << line;
      if (quick_value != value) {
        EXPECT_TRUE(line.find("--quick " + quick_value + ";") != std::string::npos ||
                    line.find("--quick " + quick_value + ")") != std::string::npos)
            << flag << ": --quick gives " << quick_value << "; the help says: " << line;
      } else {
        EXPECT_EQ(line.find("--quick"), std::string::npos)
            << flag << ": --quick leaves it at " << value << "; the help says: " << line;
      }
      // The values come from the option's fields only, not from its words.
      EXPECT_EQ(o.help.find("default"), std::string::npos) << flag << ": " << o.help;
      EXPECT_EQ(o.help.find("--quick"), std::string::npos) << flag << ": " << o.help;
      for (const std::string& v : {value, quick_value}) {
        const bool number = std::any_of(v.begin(), v.end(), [](char c) {
          return std::isdigit(static_cast<unsigned char>(c)) != 0;
        });
        if (number) {
          EXPECT_FALSE(has_value(o.help, v)) << flag << " repeats " << v << ": " << o.help;
        }
      }
      ++checked;
    }
  }
  EXPECT_GE(checked, 4u) << "the metrics' options";
}

// The study's own settings say their values as make_config() resolves them, with and without
// --quick (the help had them by hand: "--image-spp (default 16)" never said --quick's 8).
TEST(StudyHelp, SettingsSayTheValuesTheStudyUses) {
  const auto [plain, quick] = configs_with_every_metric();
  const std::map<std::string, std::string> help = study_help();
  ASSERT_FALSE(help.empty()) << "`halfback study --help` has no options";

  const auto list = [](const std::vector<std::size_t>& v) {
    std::string s;
    for (const std::size_t x : v) s += (s.empty() ? "" : ",") + std::to_string(x);
    return s;
  };
  const std::vector<std::array<std::string, 3>> settings_values = {
      {"--budgets", list(plain.budgets), list(quick.budgets)},
      {"--budgets-4d", list(plain.budgets_4d), list(quick.budgets_4d)},
      {"--test-pairs", std::to_string(plain.test_pairs), std::to_string(quick.test_pairs)},
      {"--image-size", std::to_string(plain.image_size), std::to_string(quick.image_size)},
      {"--image-spp", std::to_string(plain.image_spp), std::to_string(quick.image_spp)},
      {"--nielsen-budgets", list(plain.nielsen_counts), list(quick.nielsen_counts)},
      {"--image-budget", std::to_string(plain.image_budget), std::to_string(quick.image_budget)},
  };
  for (const auto& [flag, value, quick_value] : settings_values) {
    const auto it = help.find(flag);
    ASSERT_NE(it, help.end()) << flag << " is not in `halfback study --help`";
    const std::string& line = it->second;
    EXPECT_TRUE(has_value(line, value) && line.find("default " + value) != std::string::npos)
        << flag << ": the study's default is " << value << "; the help says: " << line;
    if (quick_value != value) {
      EXPECT_NE(line.find("--quick " + quick_value), std::string::npos)
          << flag << ": --quick gives " << quick_value << "; the help says: " << line;
    } else {
      EXPECT_EQ(line.find("--quick"), std::string::npos)
          << flag << ": --quick leaves it at " << value << "; the help says: " << line;
    }
  }
  // --quick's own help states its grids.
  const std::string grid = std::to_string(quick.grid.a) + " x " + std::to_string(quick.grid.b) +
                           " x " + std::to_string(quick.grid.phi);
  ASSERT_NE(help.find("--quick"), help.end());
  EXPECT_NE(help.at("--quick").find(grid), std::string::npos) << help.at("--quick");
}

}  // namespace halfback::study_help_test
