// The command reference generated from the commands' own CLI11 definitions (command.hpp,
// command_reference): the man page docs/halfback.1 and the option tables of docs/cli.md. What a
// command's --help says is what these say; scripts/cli_reference.py writes them into docs/, and the
// test cli_reference_matches_docs fails when the committed text differs.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "command.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::cli {

namespace {

// An app's visible subcommands, in the order of its --help.
std::vector<const CLI::App*> visible_subcommands(const CLI::App& app) {
  std::vector<const CLI::App*> subs;
  for (const CLI::App* sub : app.get_subcommands({}))
    if (!sub->get_group().empty() && !sub->get_name().empty()) subs.push_back(sub);
  return subs;
}

// An option's documented parts. Hidden options (an empty group) and the help flag are left out.
struct OptionDoc {
  std::string names;     // "-o, --output" or the positional's name
  std::string value;     // "FILE", "INT in [1 - 16384]" ...; empty for a flag
  std::string fallback;  // the default, as --help shows it; empty when none is stated
  std::string description;
  bool required = false, repeatable = false, positional = false;
};

std::vector<OptionDoc> option_docs(const CLI::App& app) {
  std::vector<OptionDoc> docs;
  const CLI::Option* help = app.get_help_ptr();
  for (const CLI::Option* opt : app.get_options({})) {
    if (opt == help || opt->get_group().empty()) continue;
    OptionDoc d;
    d.positional = !opt->nonpositional();
    if (d.positional) {
      d.names = opt->get_name(true, false);
    } else {
      for (const std::string& s : opt->get_snames()) d.names += (d.names.empty() ? "-" : ", -") + s;
      for (const std::string& l : opt->get_lnames())
        d.names += (d.names.empty() ? "--" : ", --") + l;
    }
    if (!opt->get_option_text().empty()) {
      d.value = opt->get_option_text();
    } else if (opt->get_type_size() != 0) {
      // "INT:INT in [1 - 16384]" (a type, then its validators' descriptions) -> "INT in [1 -
      // 16384]": the type is said once.
      d.value = opt->get_type_name();
      if (const std::size_t colon = d.value.find(':');
          colon != std::string::npos && d.value.compare(colon + 1, colon, d.value, 0, colon) == 0)
        d.value.erase(0, colon + 1);
      d.fallback = opt->get_default_str();
    }
    d.description = opt->get_description();
    d.required = opt->get_required();
    d.repeatable = opt->get_expected_max() >= CLI::detail::expected_max_vector_size &&
                   opt->get_type_size() != 0;
    docs.push_back(std::move(d));
  }
  return docs;
}

// "halfback plan [OPTIONS]"-style usage: the required options with their values, then
// [OPTIONS] when there are others, the positionals, and SUBCOMMAND.
std::string usage(const CLI::App& app, const std::string& path) {
  std::string s = path;
  bool optional = false;
  for (const OptionDoc& d : option_docs(app)) {
    if (d.positional) continue;
    if (!d.required) {
      optional = true;
      continue;
    }
    const std::string first = d.names.substr(0, d.names.find(", "));
    const std::string value = d.value.substr(0, d.value.find_first_of(": "));
    s += " " + first + (value.empty() ? "" : " " + value);
  }
  if (optional) s += " [OPTIONS]";
  for (const OptionDoc& d : option_docs(app)) {
    if (!d.positional) continue;
    const std::string name = d.names + (d.repeatable ? "..." : "");
    s += " " + (d.required ? name : "[" + name + "]");
  }
  if (!visible_subcommands(app).empty()) s += " SUBCOMMAND";
  return s;
}

// Every command and subcommand of `root` under its full name ("halfback figure paper"), in the
// order of --help, a command before its subcommands.
void walk(const CLI::App& app, const std::string& path,
          std::vector<std::pair<std::string, const CLI::App*>>& out) {
  for (const CLI::App* sub : visible_subcommands(app)) {
    const std::string name = path + " " + sub->get_name();
    out.emplace_back(name, sub);
    walk(*sub, name, out);
  }
}

// ---- markdown ----------------------------------------------------------------------------------

// Text inside a table cell: no table, HTML or emphasis syntax.
std::string md_cell(std::string_view text) {
  std::string s;
  for (char c : text) {
    switch (c) {
      case '|':
        s += "\\|";
        break;
      case '<':
        s += "&lt;";
        break;
      case '>':
        s += "&gt;";
        break;
      case '*':
        s += "\\*";
        break;
      case '\\':
        s += "\\\\";
        break;
      case '`':
        s += "'";
        break;
      case '\n':
        s += ' ';
        break;
      default:
        s += c;
    }
  }
  return s;
}

std::string markdown_block(const std::string& name, const CLI::App& app) {
  std::string s = fmt::format("<!-- BEGIN generated: {} -->\n", name);
  s += fmt::format("`{}`: {}\n", usage(app, name), md_cell(app.get_description()));
  const std::vector<OptionDoc> docs = option_docs(app);
  if (!docs.empty()) {
    s += "\n| option | value | default | meaning |\n|---|---|---|---|\n";
    for (const OptionDoc& d : docs) {
      std::string state = d.required ? "required" : md_cell(d.fallback);
      if (d.repeatable) state += state.empty() ? "repeatable" : ", repeatable";
      s += fmt::format("| `{}` | {} | {} | {} |\n", d.names, md_cell(d.value), state,
                       md_cell(d.description));
    }
  }
  const std::vector<const CLI::App*> subs = visible_subcommands(app);
  if (!subs.empty()) {
    s += "\nSubcommands:";
    for (const CLI::App* sub : subs) s += fmt::format(" `{}`", sub->get_name());
    s += ".\n";
  }
  s += fmt::format("<!-- END generated: {} -->\n", name);
  return s;
}

// ---- man ---------------------------------------------------------------------------------------

// roff text: backslashes and hyphens escaped, no line starting with a control character.
std::string roff(std::string_view text) {
  std::string s;
  bool line_start = true;
  for (char c : text) {
    if (line_start && (c == '.' || c == '\'')) s += "\\&";
    line_start = c == '\n';
    if (c == '\\')
      s += "\\e";
    else if (c == '-')
      s += "\\-";
    else
      s += c;
  }
  return s;
}

// A block printed as it is (its columns aligned as in --help).
std::string roff_verbatim(std::string_view text) {
  std::string body = roff(text);
  while (!body.empty() && body.back() == '\n') body.pop_back();
  return ".PP\n.nf\n" + body + "\n.fi\n";
}

std::string man_command(const std::string& name, const CLI::App& app) {
  std::string s = fmt::format(".SS \"{}\"\n", roff(name.substr(std::string("halfback ").size())));
  s += fmt::format(".B {}\n.PP\n{}\n", roff(usage(app, name)), roff(app.get_description()));
  for (const OptionDoc& d : option_docs(app)) {
    std::string head = "\\fB" + roff(d.names) + "\\fR";
    if (!d.value.empty()) head += " \\fI" + roff(d.value) + "\\fR";
    std::string notes;
    if (d.required) notes = "required";
    if (!d.fallback.empty()) notes = "default: " + d.fallback;
    if (d.repeatable) notes += notes.empty() ? "repeatable" : "; repeatable";
    s += fmt::format(".TP\n{}\n{}{}\n", head, roff(d.description),
                     notes.empty() ? "" : " (" + roff(notes) + ")");
  }
  const std::vector<const CLI::App*> subs = visible_subcommands(app);
  if (!subs.empty()) {
    std::string list;
    for (const CLI::App* sub : subs) list += (list.empty() ? "" : ", ") + sub->get_name();
    s += ".PP\nSubcommands: " + roff(list) + ".\n";
  }
  if (!app.get_footer().empty()) s += roff_verbatim(app.get_footer());
  return s;
}

std::string man_page(const CLI::App& root, std::string_view version) {
  std::string s = fmt::format(
      ".\\\" Generated by `halfback --help-reference=man` (scripts/cli_reference.py); do not "
      "edit.\n"
      ".TH HALFBACK 1 \"\" \"halfback {}\" \"User Commands\"\n"
      ".SH NAME\n"
      "halfback \\- BRDF parameterizations: convert, inspect, fit, measure, compare, render and "
      "draw BRDFs\n"
      ".SH SYNOPSIS\n"
      ".B halfback\n"
      ".I COMMAND\n"
      "[\\fIOPTIONS\\fR]\n"
      ".br\n"
      ".B halfback\n"
      ".RB [ \\-\\-help | \\-\\-version ]\n"
      ".SH DESCRIPTION\n",
      roff(version));
  const std::string description = root.get_description();
  s += roff_verbatim(description);
  s += ".SH COMMANDS\n";
  std::vector<std::pair<std::string, const CLI::App*>> all;
  walk(root, "halfback", all);
  for (const auto& [name, app] : all) s += man_command(name, *app);
  std::string embedded;
  for (const std::string& n : embedded_material_names())
    embedded += (embedded.empty() ? "" : ", ") + n;
  s += ".SH BRDF SPECS\n" +
       roff(
           "A file (MERL .binary, RGL .bsdf, ALTA text, a neural BRDF's Keras .h5; recognized by "
           "its content), a neural BRDF's NumPy form (NAME_fc1.npy, or its folder), a model "
           "(ggx:alpha=0.2,f0=0.9, lambert:albedo=0.5; `halfback models` lists them), a sum "
           "(lambert+ggx:alpha=0.1), or embedded:NAME for a material compiled into halfback: " +
           embedded + ".") +
       "\n";
  const std::string footer = root.get_footer();
  if (const std::size_t at = footer.find("Exit status"); at != std::string::npos)
    s += ".SH EXIT STATUS\n" + roff(footer.substr(at)) + "\n";
  s += ".SH SEE ALSO\n" +
       roff(
           "The documentation in docs/ of the source tree: cli.md (conventions and the options of "
           "every command), math.md, formats.md, figures.md, render.md, study.md, fit.md, "
           "acquisition.md, neural.md, view.md.") +
       "\n";
  return s;
}

}  // namespace

std::string command_reference(const CLI::App& root, std::string_view format,
                              std::string_view version) {
  if (format == "man") return man_page(root, version);
  if (format != "markdown")
    throw UsageError("--help-reference: expected man or markdown, not '" + std::string(format) +
                     "'");
  std::string s;
  std::vector<std::pair<std::string, const CLI::App*>> all;
  walk(root, "halfback", all);
  for (const auto& [name, app] : all) s += markdown_block(name, *app);
  return s;
}

}  // namespace halfback::cli
