#include "command.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <new>
#include <stdexcept>
#include <system_error>

#include <unistd.h>

#include "halfback/core/space.hpp"
#include "halfback/formats/adaptive_param.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::cli {

void warn(std::string_view command, std::string_view message) {
  fmt::print(stderr, "halfback {}: warning: {}\n", command, message);
}

std::unique_ptr<CsvStreamReader> open_csv_input(const std::string& path) {
  if (path == "-") return std::make_unique<CsvStreamReader>(STDIN_FILENO, "<stdin>");
  return std::make_unique<CsvStreamReader>(path);
}

Output::Output(const std::string& path) {
  if (path != "-") file_ = std::make_unique<AtomicFile>(path);
}

void Output::write(std::string_view data) {
  if (file_) {
    file_->write(data);
    return;
  }
  if (std::fwrite(data.data(), 1, data.size(), stdout) != data.size())
    throw std::system_error(errno, std::generic_category(), "cannot write to standard output");
}

void Output::commit() {
  if (file_) {
    file_->commit();
    return;
  }
  if (std::fflush(stdout) != 0)
    throw std::system_error(errno, std::generic_category(), "cannot write to standard output");
}

void check_writable(const std::string& path) {
  AtomicFile probe(path);
  probe.discard();
}

namespace {

namespace fs = std::filesystem;

// An option's value as given on the command line: the option's name and the text.
struct OptionValue {
  std::string option, value;
  bool folder = false;  // an output folder (an option of type DIR: study -o, figure paper --out)
};

bool is_output_option(const CLI::Option& o) {
  const auto& l = o.get_lnames();
  const auto& s = o.get_snames();
  return std::ranges::find(l, "output") != l.end() || std::ranges::find(l, "out") != l.end() ||
         std::ranges::find(l, "json") != l.end() || std::ranges::find(s, "o") != s.end();
}

bool is_emit_option(const CLI::Option& o) {
  return std::ranges::find(o.get_lnames(), "emit") != o.get_lnames().end();
}

// The texts in a value that may name a file: the value, its items split at ',' and '+', and
// what follows each ':' of an item.
std::vector<std::string> possible_paths(const std::string& value) {
  std::vector<std::string> paths{value};
  std::size_t start = 0;
  while (start <= value.size()) {
    const std::size_t end = std::min(value.find_first_of(",+", start), value.size());
    const std::string item = value.substr(start, end - start);
    paths.push_back(item);
    for (std::size_t colon = item.find(':'); colon != std::string::npos;
         colon = item.find(':', colon + 1))
      paths.push_back(item.substr(colon + 1));
    start = end + 1;
  }
  return paths;
}

// Whether `file` is a regular file inside the folder `dir` (at any depth) of a kind the
// commands write into their output folders.
bool written_kind_inside(const fs::path& dir, const fs::path& file) {
  static const char* const kinds[] = {".csv", ".md",  ".html", ".png",     ".svg",
                                      ".pdf", ".exr", ".part", ".profile", ".txt"};
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return false;
  const std::string ext = file.extension().string();
  if (std::ranges::none_of(kinds, [&](const char* k) { return ext == k; })) return false;
  const fs::path d = fs::weakly_canonical(dir, ec), f = fs::weakly_canonical(file, ec);
  if (ec) return false;
  const auto [d_end, f_at] = std::mismatch(d.begin(), d.end(), f.begin(), f.end());
  return d_end == d.end() && f_at != f.end();
}

// UsageError when `out` would replace (or, a folder, overwrite a file in) the input `in`.
void refuse_output_over_input(const OptionValue& out, const OptionValue& in) {
  std::error_code ec;
  const fs::file_status st = fs::status(out.value, ec);
  for (const std::string& candidate : possible_paths(in.value)) {
    if (candidate.empty() || candidate == "-") continue;
    const bool same = fs::is_regular_file(st) && fs::equivalent(out.value, candidate, ec) && !ec;
    if (same)
      throw UsageError(fmt::format(
          "{} '{}' is the file of {} '{}': an output never replaces an input of the same "
          "command; write it elsewhere",
          out.option, out.value, in.option, in.value));
    if (out.folder && fs::is_directory(st) && written_kind_inside(out.value, candidate))
      throw UsageError(fmt::format(
          "{} '{}' is a folder that holds the input {} '{}', a file of a kind the command "
          "writes there: an output never replaces an input of the same command; move the input "
          "or write elsewhere",
          out.option, out.value, in.option, candidate));
  }
}

}  // namespace

void refuse_outputs_over_inputs(const CLI::App& app, const std::vector<std::string>& more_outputs) {
  std::vector<OptionValue> outputs, inputs;
  for (const std::string& path : more_outputs) outputs.push_back({"the sidecar of -o", path});
  for (const CLI::Option* o : app.get_options()) {
    const std::string name = o->get_name();
    if (is_output_option(*o)) {
      const bool folder = o->get_type_name().starts_with("DIR");
      if (o->count() > 0)
        for (const std::string& v : o->results()) outputs.push_back({name, v, folder});
      else if (!o->get_default_str().empty())
        outputs.push_back({name, o->get_default_str(), folder});
    } else if (is_emit_option(*o)) {
      for (const std::string& v : o->results())
        if (const std::size_t colon = v.find(':'); colon != std::string::npos)
          outputs.push_back({name + " " + v.substr(0, colon), v.substr(colon + 1)});
    } else if (o->count() > 0) {
      for (const std::string& v : o->results()) inputs.push_back({name, v});
    }
  }
  for (const OptionValue& out : outputs) {
    if (out.value.empty() || out.value == "-") continue;
    for (const OptionValue& in : inputs) refuse_output_over_input(out, in);
  }
}

std::vector<std::string> split_list(const std::string& list, const char* option, const char* what) {
  const auto trimmed = [](std::string_view t) {
    const auto b = t.find_first_not_of(' ');
    if (b == std::string_view::npos) return std::string();
    return std::string(t.substr(b, t.find_last_not_of(' ') - b + 1));
  };
  if (trimmed(list).empty()) throw UsageError(fmt::format("{}: no {} given", option, what));
  std::vector<std::string> items;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    std::string item = trimmed(std::string_view(list).substr(start, comma - start));
    if (item.empty())
      throw UsageError(fmt::format("{} '{}': empty item in the list", option, list));
    items.push_back(std::move(item));
    start = comma + 1;
  }
  return items;
}

std::vector<std::string> environment_list(const std::string& list, const char* option) {
  std::vector<std::string> specs;
  for (std::string& item : split_list(list, option, "environment")) {
    double ignored = 0;
    const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), ignored);
    const bool number = ec == std::errc() && end == item.data() + item.size();
    if (number && !specs.empty() && specs.back().rfind("constant:", 0) == 0)
      specs.back() += "," + item;
    else
      specs.push_back(std::move(item));
  }
  return specs;
}

void rethrow_environment_error(const char* option, const std::string& spec) {
  try {
    throw;
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("{} '{}': {}", option, spec, e.what()));
  }
}

BrdfPtr brdf_argument(const std::string& spec, const char* option) {
  try {
    return load_brdf(spec);
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("{}: {}", option, e.what()));
  }
}

double parse_number(std::string_view text, const std::string& what) {
  double v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v))
    throw UsageError(fmt::format("{}: '{}' is not a number", what, text));
  return v;
}

std::vector<double> number_list(const std::string& list, const char* option, const char* what) {
  std::vector<double> values;
  for (const std::string& item : split_list(list, option, what))
    values.push_back(parse_number(item, option));
  return values;
}

std::vector<std::size_t> count_list(const std::string& list, const char* option, const char* what) {
  std::vector<std::size_t> counts;
  for (const std::string& item : split_list(list, option, what)) {
    std::size_t v = 0;
    const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), v);
    if (ec != std::errc() || end != item.data() + item.size() || v == 0)
      throw UsageError(
          fmt::format("{} '{}': '{}' is not a positive whole number", option, list, item));
    counts.push_back(v);
  }
  return counts;
}

namespace {

std::string finite_number_error(const std::string& value) {
  std::string_view text = value;
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  const bool parsed = ec == std::errc() && end == text.data() + text.size();
  if (parsed && std::isfinite(v)) return "";
  if (parsed && std::isinf(v)) return fmt::format("'{}' is not a finite number", value);
  return fmt::format("'{}' is not a number", value);
}

std::string whole_number_error(const std::string& value, bool allow_negative) {
  std::string_view text = value;
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  const bool negative = !text.empty() && text.front() == '-';
  const std::string_view digits = negative ? text.substr(1) : text;
  const bool all_digits =
      !digits.empty() && std::ranges::all_of(digits, [](char c) { return c >= '0' && c <= '9'; });
  if (!all_digits || (negative && !allow_negative))
    return fmt::format("'{}' is not a whole number{}", value, allow_negative ? "" : " >= 0");
  std::uint64_t magnitude = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), magnitude);
  const std::uint64_t limit =
      allow_negative ? (std::uint64_t{1} << 63) - (negative ? 0 : 1) : ~std::uint64_t{0};
  if (ec != std::errc() || end != digits.data() + digits.size() || magnitude > limit)
    return fmt::format("'{}' is too large (at most {})", value, limit);
  return "";
}

}  // namespace

void harden_options(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    // The value's type, without the descriptions of the option's checks ("FLOAT:FLOAT in [0 -
    // 1e+09]" for a CLI::Range), which hid the type from this rule.
    const std::string full_type = option->get_type_name();
    const std::string type = full_type.substr(0, full_type.find(':'));
    // First of the option's checks (transform() puts it in front), so that "nan" is "not a
    // number" rather than out of the option's range.
    option->transform(CLI::Validator(
        [type](std::string& value) -> std::string {
          if (value.empty()) return "an empty value: give one, or leave the option out";
          if (type == "FLOAT") return finite_number_error(value);
          if (type == "INT") return whole_number_error(value, true);
          if (type == "UINT") return whole_number_error(value, false);
          return "";
        },
        "", "value rule"));
  }
  for (CLI::App* sub : app.get_subcommands({})) harden_options(*sub);
}

CLI::Validator non_negative_integer() {
  return CLI::Validator([](std::string& value) { return whole_number_error(value, false); },
                        "INT >= 0", "non-negative integer");
}

namespace {
// ", or a family's member: dupuy-jakob:BRDF" when families are registered.
std::string family_hint() {
  std::string hint;
  for (const std::string& f : parameterization_families())
    (hint += hint.empty() ? ", or " : ", ") += f;
  return hint;
}
}  // namespace

std::optional<Space> space_or_message(const std::string& name, std::string& message) {
  try {
    const auto s = space_from_name(name);
    if (s && !s->is_dirs() && is_per_material_placeholder(s->param())) {
      message = fmt::format(
          "'{}' is each BRDF's own warp, for `halfback study --params` only: "
          "here, name the BRDF (dupuy-jakob:BRDF)",
          name);
      return std::nullopt;
    }
    return s;
  } catch (const std::invalid_argument& e) {  // a name or a model's value: the command line's
    message = fmt::format("'{}': {}", name, e.what());
    return std::nullopt;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {  // a family member's file that cannot be read or holds bad
    // data: a data error, propagated with the name it came from
    throw std::runtime_error(fmt::format("'{}': {}", name, e.what()));
  }
}

CLI::Validator space_name_validator() {
  return CLI::Validator(
      [](std::string& name) -> std::string {
        std::string message;
        if (space_or_message(name, message)) return {};
        if (!message.empty()) return message;
        return fmt::format("unknown coordinates '{}' (expected one of: {}{})", name, space_names(),
                           family_hint());
      },
      "");
}

CLI::Validator parameterization_validator() {
  return CLI::Validator(
      [](std::string& name) -> std::string {
        std::string message;
        const auto s = space_or_message(name, message);
        if (s && !s->is_dirs()) return {};
        if (!message.empty()) return message;
        return fmt::format("unknown parameterization '{}' (expected one of: {}{})", name,
                           parameterization_names(", "), family_hint());
      },
      "");
}

}  // namespace halfback::cli
