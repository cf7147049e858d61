// The error thrown by the file readers (MERL, RGL, ALTA) and by load_brdf().
//
// Every message names the file, the field (a header entry, a tensor field, a line number, ...)
// and the problem, so that it can be shown to a user as is: what() is "FILE: FIELD: PROBLEM".
#pragma once

#include <stdexcept>
#include <string>

namespace halfback {

class FormatError : public std::runtime_error {
 public:
  FormatError(std::string file, std::string field, std::string problem)
      : std::runtime_error(file + ": " + field + ": " + problem),
        file_(std::move(file)),
        field_(std::move(field)),
        problem_(std::move(problem)) {}

  const std::string& file() const noexcept { return file_; }
  const std::string& field() const noexcept { return field_; }
  const std::string& problem() const noexcept { return problem_; }

 private:
  std::string file_, field_, problem_;
};

}  // namespace halfback
