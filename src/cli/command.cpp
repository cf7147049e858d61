#include "command.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <system_error>

#include "halfback/core/space.hpp"

namespace halfback::cli {

void warn(std::string_view command, std::string_view message) {
  fmt::print(stderr, "halfback {}: warning: {}\n", command, message);
}

InputText read_input(const std::string& path) {
  if (path != "-") return {read_text_file(path), path};
  InputText in{{}, "<stdin>"};
  char buf[1 << 16];
  while (true) {
    const std::size_t n = std::fread(buf, 1, sizeof buf, stdin);
    in.text.append(buf, n);
    if (n < sizeof buf) {
      if (std::ferror(stdin))
        throw std::system_error(errno, std::generic_category(), "cannot read standard input");
      break;
    }
  }
  return in;
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

CLI::Validator space_name_validator() {
  return CLI::Validator(
      [](std::string& name) -> std::string {
        if (space_from_name(name)) return {};
        return fmt::format("unknown coordinates '{}' (expected one of: {})", name, space_names());
      },
      "");
}

}  // namespace halfback::cli
