// Running a program from a test: argv[0] a path, started in `dir` with its standard streams
// read from `in` and written to `out` and `err` (files), waited for. For the CLI tests, which
// run the built `halfback` as a user would.
#pragma once

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

namespace halfback::test {

struct Spawned {
  bool started = false;  // false: posix_spawn failed, `error` says why
  std::string error;
  int status = -1;  // the exit status; -1 when a signal ended the program
};

inline Spawned spawn_and_wait(const std::filesystem::path& dir, std::vector<std::string> argv,
                              const std::filesystem::path& in, const std::filesystem::path& out,
                              const std::filesystem::path& err) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, in.c_str(), O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<char*> args;
  for (std::string& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  // The child starts in `dir`: this process's working directory is moved there around the spawn.
  const std::filesystem::path cwd = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
  std::filesystem::current_path(cwd);
  posix_spawn_file_actions_destroy(&actions);
  Spawned s;
  if (rc != 0) {
    s.error = std::strerror(rc);
    return s;
  }
  s.started = true;
  int status = 0;
  waitpid(pid, &status, 0);
  s.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return s;
}

// A program run by run_captured(): how it started and ended, and what it wrote.
struct Captured : Spawned {
  std::string out, err;
};

// Runs argv in `dir` with standard input /dev/null, its standard output and error captured
// through two files in `dir` (removed after).
inline Captured run_captured(const std::filesystem::path& dir, std::vector<std::string> argv) {
  const std::filesystem::path out = dir / ".stdout", err = dir / ".stderr";
  Captured c;
  static_cast<Spawned&>(c) = spawn_and_wait(dir, std::move(argv), "/dev/null", out, err);
  const auto read = [](const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  };
  c.out = read(out);
  c.err = read(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return c;
}

}  // namespace halfback::test
