// The options of a CLI11 help text, for the tests that read `halfback ... --help`.
#pragma once

#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace halfback::test {

struct HelpOption {
  std::vector<std::string> names;  // as listed in the first column: "-o", "--output", "--out"
  std::string text;                // the rest of its line and its wrapped lines, joined by spaces
};

// The lines of a help's section — those after the line starting with `heading` ("Options:",
// "Subcommands:") up to the first empty or unindented line.
inline std::vector<std::string> section_lines(const std::string& help_text,
                                              std::string_view heading) {
  std::vector<std::string> out;
  std::istringstream lines(help_text);
  bool in_section = false;
  for (std::string line; std::getline(lines, line);) {
    if (!in_section) {
      in_section = line.starts_with(heading);
      continue;
    }
    if (line.empty() || !line.starts_with(" ")) break;
    out.push_back(std::move(line));
  }
  return out;
}

// The options of the help's "Options:" section, in their order (-h,--help included).
inline std::vector<HelpOption> help_options(const std::string& help_text) {
  std::vector<HelpOption> found;
  for (const std::string& line : section_lines(help_text, "Options:")) {
    if (line.starts_with("  -")) {
      HelpOption o;
      const std::size_t end = line.find(' ', 2);
      std::istringstream names(line.substr(2, end - 2));
      for (std::string n; std::getline(names, n, ',');) o.names.push_back(n);
      const std::size_t text = end == std::string::npos ? end : line.find_first_not_of(' ', end);
      if (text != std::string::npos) o.text = line.substr(text);
      found.push_back(std::move(o));
    } else if (!found.empty()) {  // a description on the next line, or continued
      (found.back().text += ' ') += line.substr(line.find_first_not_of(' '));
    }
  }
  return found;
}

}  // namespace halfback::test
