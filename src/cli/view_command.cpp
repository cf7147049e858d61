// `halfback view`: the interactive explorer in the browser (docs/view.md). Starts the server of
// the view layer on a loopback address, prints the URL with its token, and serves until Ctrl-C
// (SIGINT, SIGTERM or SIGHUP, taken by a thread of its own with sigtimedwait and turned into a
// clean stop of the server).
#include <fmt/format.h>
#include <signal.h>
#include <spawn.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "command.hpp"
#include "halfback/view/api.hpp"
#include "halfback/view/server.hpp"

extern char** environ;

namespace halfback::cli {

namespace {

struct ViewOptions {
  std::vector<std::string> specs;
  std::vector<std::string> roots;
  std::string host = "127.0.0.1";
  int port = 8765;
  bool open = false;
  int threads = 0;
  int workers = 16;
};

// Opens the system browser on `url` (xdg-open, started without a shell; a failure is a warning).
void open_browser(const std::string& url) {
  std::string program = "xdg-open", argument = url;
  char* argv[] = {program.data(), argument.data(), nullptr};
  // The stop signals are blocked in this process (see run_view): not in the browser.
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK);
  pid_t pid = 0;
  if (posix_spawnp(&pid, "xdg-open", nullptr, &attributes, argv, environ) != 0)
    warn("view", "could not start a browser (xdg-open); open the URL by hand");
  posix_spawnattr_destroy(&attributes);
}

// The server stops within this many seconds of a stop signal, whatever it computes.
constexpr int kStopSeconds = 4;

// Waits for SIGINT/SIGTERM/SIGHUP (blocked in every thread of the process) and stops the server,
// or returns when `done` is set. The stop ends every computation that polls its deadline at once;
// if the server still runs kStopSeconds later (a computation that polls none), or another stop
// signal comes, the process ends there (std::_Exit, status 0: the stop that was asked for).
void wait_for_signal(const sigset_t& signals, view::Server& server, const std::atomic<bool>& done) {
  const timespec tick{0, 100'000'000};
  while (!done.load()) {
    if (sigtimedwait(&signals, nullptr, &tick) <= 0) continue;
    fmt::print(stderr, "halfback view: stopping\n");
    server.stop();
    for (int k = 0; k < 10 * kStopSeconds && !done.load(); ++k)
      if (sigtimedwait(&signals, nullptr, &tick) > 0) break;
    if (done.load()) return;
    fmt::print(stderr, "halfback view: a request is still being computed; exiting without it\n");
    std::fflush(nullptr);
    std::_Exit(kExitOk);
  }
}

int run_view(const ViewOptions& o) {
  if (o.port < 0 || o.port > 65535) throw UsageError("--port: expected 0 ... 65535");
  if (o.workers < 1 || o.workers > 64) throw UsageError("--workers: expected 1 ... 64");
  view::ApiConfig config;
  config.token = view::random_token();
  config.host = o.host;
  config.specs = o.specs;
  config.threads = o.threads;
  for (const std::string& r : o.roots) config.roots.emplace_back(r);
  view::keep_freed_memory();
  // Block the stop signals before any thread exists, so that they all inherit the mask: loading
  // the specs starts the parallel loop's threads (a measured file, a neural BRDF), and one of
  // them without the mask took a Ctrl-C by the default action (killed, not a clean stop).
  sigset_t signals;
  sigemptyset(&signals);
  for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&signals, s);
  sigset_t previous;
  pthread_sigmask(SIG_BLOCK, &signals, &previous);
  struct RestoreMask {
    const sigset_t& mask;
    ~RestoreMask() { pthread_sigmask(SIG_SETMASK, &mask, nullptr); }
  } restore{previous};
  view::Api api(std::move(config));  // throws for a --root that is not a directory
  try {
    api.load_specs();  // a bad command-line BRDF fails here, not in the page
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("SPEC: {}", e.what()));
  }
  if (!view::is_loopback(o.host))
    warn("view", fmt::format("--host {} is not a loopback address: anyone who can reach it and "
                             "learns the token can use the server",
                             o.host));

  view::Server server(api, o.workers);
  const int port = server.bind(o.host, o.port);
  const std::string shown = o.host.find(':') != std::string::npos ? "[" + o.host + "]" : o.host;
  const std::string url = fmt::format("http://{}:{}/?token={}", shown, port, api.config().token);
  fmt::print("halfback view: serving on {}\n", url);
  std::fflush(stdout);
  if (o.open) open_browser(url);
  std::atomic<bool> done{false};
  std::thread waiter([&] { wait_for_signal(signals, server, done); });
  const bool ok = server.run();
  done = true;
  waiter.join();
  if (!ok) throw std::runtime_error("the server stopped with an error");
  return kExitOk;
}

}  // namespace

Command register_view(CLI::App& parent) {
  auto o = std::make_shared<ViewOptions>();
  CLI::App* app = parent.add_subcommand(
      "view", "Explore BRDFs in the browser, in every parameterization at once");
  app->add_option("spec", o->specs,
                  "BRDFs to show: files (MERL, RGL, ALTA, neural) or model specs such as "
                  "ggx:alpha=0.2")
      ->type_name("SPEC");
  app->add_option("--root", o->roots,
                  "A directory whose BRDF and environment files the page may open (repeatable); "
                  "nothing outside the roots is ever read")
      ->type_name("DIR");
  app->add_option("--host", o->host, "Address to listen on (default 127.0.0.1, loopback only)");
  app->add_option("--port", o->port, "Port (default 8765; 0: any free port)");
  app->add_flag("--open", o->open, "Open the page in the system browser");
  app->add_option("--threads", o->threads, "Threads per computation (0: all cores)");
  app->add_option("--workers", o->workers,
                  "Requests answered at once (default 16; each connection has a thread of "
                  "its own)");
  app->footer(
      "Prints the URL to open, with a random token that every request must carry; Ctrl-C\n"
      "stops the server. See docs/view.md for the page, the API and the security model.\n"
      "\n"
      "Example:\n"
      "  halfback view ggx:alpha=0.2 embedded:pink-felt --root ~/brdfs --port 0");
  return {app, [o] { return run_view(*o); }};
}

}  // namespace halfback::cli
