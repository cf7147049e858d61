// The Markdown-to-HTML step of the study's report (report.hpp: markdown_to_html): the subset
// of Markdown the report writes, as one standalone page with its images embedded.
#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

#include "halfback/study/report.hpp"
#include "halfback/util/text_encoding.hpp"

namespace halfback::study {

namespace {

// `code` and **bold**, the rest escaped.
std::string inline_html(std::string_view s) {
  std::string out;
  bool code = false, bold = false;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '`') {
      out += code ? "</code>" : "<code>";
      code = !code;
    } else if (!code && s.substr(i, 2) == "**") {
      out += bold ? "</strong>" : "<strong>";
      bold = !bold;
      ++i;
    } else if (!code && s[i] == '\\' && i + 1 < s.size() && s[i + 1] == '|') {
      out += '|';
      ++i;
    } else {
      out += escape_xml(s.substr(i, 1));
    }
  }
  if (code) out += "</code>";
  if (bold) out += "</strong>";
  return out;
}

std::vector<std::string> table_cells(std::string_view line) {
  std::vector<std::string> cells;
  std::string cur;
  for (std::size_t i = 1; i < line.size(); ++i) {
    if (line[i] == '\\' && i + 1 < line.size() && line[i + 1] == '|') {
      cur += "\\|";
      ++i;
    } else if (line[i] == '|') {
      cells.push_back(cur);
      cur.clear();
    } else {
      cur += line[i];
    }
  }
  for (std::string& c : cells) {
    const auto a = c.find_first_not_of(' '), b = c.find_last_not_of(' ');
    c = a == std::string::npos ? "" : c.substr(a, b - a + 1);
  }
  return cells;
}

}  // namespace

std::string markdown_to_html(std::string_view markdown, const std::filesystem::path& image_dir,
                             std::string_view title) {
  std::vector<std::string> lines;
  {
    std::istringstream in{std::string(markdown)};
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  std::string html = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n"
      "<style>body{{font-family:sans-serif;max-width:72em;margin:2em auto;padding:0 1em;"
      "line-height:1.4}}table{{border-collapse:collapse;font-size:90%;margin:1em 0}}"
      "td,th{{border:1px solid #ccc;padding:2px 6px;text-align:right}}td:first-child{{text-align:"
      "left}}img{{max-width:100%}}code{{background:#f4f4f4}}</style>\n</head>\n<body>\n",
      escape_xml(title));
  std::string paragraph;
  auto flush = [&] {
    if (!paragraph.empty()) html += "<p>" + inline_html(paragraph) + "</p>\n";
    paragraph.clear();
  };
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& l = lines[i];
    if (l.empty()) {
      flush();
    } else if (l[0] == '#') {
      flush();
      const std::size_t level = std::min<std::size_t>(l.find_first_not_of('#'), 6);
      html += fmt::format("<h{0}>{1}</h{0}>\n", level,
                          inline_html(l.substr(std::min(l.size(), level + 1))));
    } else if (l.rfind("![", 0) == 0 && l.find("](") != std::string::npos && l.back() == ')') {
      flush();
      const std::size_t mid = l.find("](");
      const std::string alt = l.substr(2, mid - 2), src = l.substr(mid + 2, l.size() - mid - 3);
      std::ifstream f(image_dir / src, std::ios::binary);
      const std::string data((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
      if (!f.good() && data.empty())
        html += fmt::format("<p><a href=\"{}\">{}</a></p>\n", escape_xml(src), escape_xml(alt));
      else
        html += fmt::format("<p><img alt=\"{}\" src=\"data:image/png;base64,{}\"></p>\n",
                            escape_xml(alt), base64_encode(data));
    } else if (l[0] == '|') {
      flush();
      html += "<table>\n";
      bool header = true;
      for (; i < lines.size() && !lines[i].empty() && lines[i][0] == '|'; ++i) {
        if (lines[i].rfind("|---", 0) == 0) continue;
        html += "<tr>";
        for (const std::string& c : table_cells(lines[i]))
          html += fmt::format("<{0}>{1}</{0}>", header ? "th" : "td", inline_html(c));
        html += "</tr>\n";
        header = false;
      }
      --i;
      html += "</table>\n";
    } else if (l.rfind("* ", 0) == 0) {
      flush();
      html += "<ul>\n";
      for (; i < lines.size() && lines[i].rfind("* ", 0) == 0; ++i)
        html += "<li>" + inline_html(lines[i].substr(2)) + "</li>\n";
      --i;
      html += "</ul>\n";
    } else {
      paragraph += (paragraph.empty() ? "" : " ") + l;
    }
  }
  flush();
  return html + "</body>\n</html>\n";
}

}  // namespace halfback::study
