// The socket side of `halfback view`: an HTTP/1.1 server (Debian's cpp-httplib, included by
// server.cpp alone) that hands every request to an Api and writes its response back.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "halfback/view/api.hpp"

namespace halfback::view {

// Limits of the connections (docs/view.md, "Security model"):
// a request's line and headers arrive within kRequestHeadSeconds of the moment the server starts
// waiting for it (the connection's opening, or the end of the previous response), however they
// trickle in: after it, 408 and the connection closed;
inline constexpr double kRequestHeadSeconds = 4;
// a response is written within kResponseWriteSeconds of its first byte (the largest, 12 MB of
// slices or mesh images, takes milliseconds on loopback, but a headless Chromium on a loaded
// 2-core machine read some in more than 10 s): a client that reads slower is dropped;
inline constexpr double kResponseWriteSeconds = 30;
// at most kMaxConnections connections are open at once, whatever their address: a new one at
// that bound closes the connection that has waited longest for a request head (idle, or
// trickling one in); when every connection is being answered, the new one is answered 503.
inline constexpr std::size_t kMaxConnections = 128;

class Server {
 public:
  // `workers`: threads answering connections (a browser opens up to six per host, and a kept-
  // alive connection holds its thread until it closes); at least 1.
  Server(Api& api, int workers);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds host:port (port 0: any free port), tells the Api the port and returns it. Throws
  // std::runtime_error naming the address when it cannot bind.
  int bind(const std::string& host, int port);
  // Serves until stop() (returns false when the listening loop fails).
  bool run();
  // Stops run() from another thread: every computation in progress gives up (Api::stop), every
  // connection is shut down, and run() returns once their threads end (at once but for a
  // computation that polls no deadline: a single slice, hemisphere or point-light field).
  void stop();
  // Serves one connected socket on the calling thread, as run() serves an accepted connection
  // (its requests, with every limit above), and closes it; after bind(), without run(). For the
  // wire-level fuzzer (fuzz/view_wire_fuzz.cpp).
  void serve_connection(int fd);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Tells the C library to keep freed memory for reuse (mallopt: no mmap for blocks under 256 MB,
// no trimming): a request's buffers (a 256² slice allocates ~8 MB) are then recycled by the next
// instead of being mapped afresh, whose page faults cost more than the computation on a virtual
// machine (docs/performance.md, "Viewer"). For the server process; returns whether it applied.
bool keep_freed_memory();

// Whether `host` is a loopback address (127.0.0.0/8, ::1, localhost).
bool is_loopback(const std::string& host);

}  // namespace halfback::view
