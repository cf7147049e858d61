#include "command.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
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
  if (ec == std::errc() && end == text.data() + text.size() && std::isfinite(v)) return "";
  return fmt::format("'{}' is not a finite number", value);
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
    const std::string type = option->get_type_name();
    option->check(CLI::Validator(
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
  } catch (const std::exception& e) {
    message = fmt::format("'{}': {}", name, e.what());
    return std::nullopt;
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
