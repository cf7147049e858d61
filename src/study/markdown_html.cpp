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

// The page up to and including <body>: the title and a style for the report's tables.
std::string html_head(std::string_view title) {
  return fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n"
      "<style>body{{font-family:sans-serif;max-width:72em;margin:2em auto;padding:0 1em;"
      "line-height:1.4}}table{{border-collapse:collapse;font-size:90%;margin:1em 0}}"
      "td,th{{border:1px solid #ccc;padding:2px 6px;text-align:right}}td:first-child{{text-align:"
      "left}}img{{max-width:100%}}code{{background:#f4f4f4}}</style>\n</head>\n<body>\n",
      escape_xml(title));
}

// "# Heading" (up to six #).
std::string heading_html(const std::string& line) {
  const std::size_t level = std::min<std::size_t>(line.find_first_not_of('#'), 6);
  return fmt::format("<h{0}>{1}</h{0}>\n", level,
                     inline_html(line.substr(std::min(line.size(), level + 1))));
}

bool is_image_line(const std::string& line) {
  return line.rfind("![", 0) == 0 && line.find("](") != std::string::npos && line.back() == ')';
}

// "![alt](file.png)": the file's bytes as a data: URI, or a link when it cannot be read.
std::string image_html(const std::string& line, const std::filesystem::path& image_dir) {
  const std::size_t mid = line.find("](");
  const std::string alt = line.substr(2, mid - 2),
                    src = line.substr(mid + 2, line.size() - mid - 3);
  std::ifstream f(image_dir / src, std::ios::binary);
  const std::string data((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (!f.good() && data.empty())
    return fmt::format("<p><a href=\"{}\">{}</a></p>\n", escape_xml(src), escape_xml(alt));
  return fmt::format("<p><img alt=\"{}\" src=\"data:image/png;base64,{}\"></p>\n", escape_xml(alt),
                     base64_encode(data));
}

// The run of lines starting at lines[i] for which `in_block` holds; i is left on its last line.
std::vector<std::string> block_at(const std::vector<std::string>& lines, std::size_t& i,
                                  bool (*in_block)(const std::string&)) {
  std::vector<std::string> block;
  for (; i < lines.size() && in_block(lines[i]); ++i) block.push_back(lines[i]);
  --i;
  return block;
}

bool is_table_line(const std::string& line) {
  return !line.empty() && line[0] == '|';
}

// A pipe table: its first row the header, its "|---" rule dropped.
std::string table_html(const std::vector<std::string>& rows) {
  std::string html = "<table>\n";
  bool header = true;
  for (const std::string& row : rows) {
    if (row.rfind("|---", 0) == 0) continue;
    html += "<tr>";
    for (const std::string& c : table_cells(row))
      html += fmt::format("<{0}>{1}</{0}>", header ? "th" : "td", inline_html(c));
    html += "</tr>\n";
    header = false;
  }
  return html + "</table>\n";
}

bool is_list_line(const std::string& line) {
  return line.rfind("* ", 0) == 0;
}

std::string list_html(const std::vector<std::string>& items) {
  std::string html = "<ul>\n";
  for (const std::string& item : items) html += "<li>" + inline_html(item.substr(2)) + "</li>\n";
  return html + "</ul>\n";
}

}  // namespace

std::string markdown_to_html(std::string_view markdown, const std::filesystem::path& image_dir,
                             std::string_view title) {
  std::vector<std::string> lines;
  {
    std::istringstream in{std::string(markdown)};
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  std::string html = html_head(title);
  std::string paragraph;  // the lines of the paragraph being read, joined
  auto flush = [&] {
    if (!paragraph.empty()) html += "<p>" + inline_html(paragraph) + "</p>\n";
    paragraph.clear();
  };
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& l = lines[i];
    const bool block =
        l.empty() || l[0] == '#' || is_image_line(l) || is_table_line(l) || is_list_line(l);
    if (!block) {
      paragraph += (paragraph.empty() ? "" : " ") + l;
      continue;
    }
    flush();
    if (l.empty()) continue;
    if (l[0] == '#')
      html += heading_html(l);
    else if (is_image_line(l))
      html += image_html(l, image_dir);
    else if (is_table_line(l))
      html += table_html(block_at(lines, i, is_table_line));
    else
      html += list_html(block_at(lines, i, is_list_line));
  }
  flush();
  return html + "</body>\n</html>\n";
}

}  // namespace halfback::study
