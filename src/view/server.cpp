// The only file that includes httplib.h (a large header): everything else works on
// halfback::view::Request and Response.
#include "halfback/view/server.hpp"

#include <httplib.h>
#include <malloc.h>
#include <sys/socket.h>

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <semaphore>
#include <stdexcept>
#include <thread>

namespace halfback::view {

namespace {

// A thread for each connection, up to kMaxConnections at once (more wait their turn): a client
// that trickles its request's header lines holds only its own connection's thread, where with a
// pool of --workers threads twenty such clients stalled every request for 30 s. The work of the
// requests is bounded apart (Server::Impl::handling: --workers at once).
class ConnectionQueue : public httplib::TaskQueue {
 public:
  static constexpr std::size_t kMaxConnections = 256;

  void enqueue(std::function<void()> fn) override {
    std::lock_guard lock(mutex_);
    if (active_ < kMaxConnections)
      start_locked(std::move(fn));
    else
      waiting_.push_back(std::move(fn));
  }
  void shutdown() override {  // after the listening loop: the connections end within a timeout
    std::unique_lock lock(mutex_);
    waiting_.clear();
    idle_.wait(lock, [this] { return active_ == 0; });
  }

 private:
  void start_locked(std::function<void()> fn) {
    ++active_;
    std::thread([this, fn = std::move(fn)]() mutable {
      for (;;) {
        fn();
        std::lock_guard lock(mutex_);
        if (waiting_.empty()) {
          --active_;
          idle_.notify_all();
          return;
        }
        fn = std::move(waiting_.front());
        waiting_.pop_front();
      }
    }).detach();
  }

  std::mutex mutex_;
  std::condition_variable idle_;
  std::size_t active_ = 0;
  std::deque<std::function<void()>> waiting_;
};

// The listening socket's options: SO_REUSEADDR (a restart binds while the old connections are in
// TIME_WAIT) and not httplib's SO_REUSEPORT, with which a second `halfback view --port P` bound
// beside the first and answered about half of its requests (with its own token: 403).
void exclusive_socket_options(socket_t sock) {
  const int yes = 1;
  setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
}

}  // namespace

struct Server::Impl {
  Api& api;
  httplib::Server http;
  std::counting_semaphore<> handling;  // requests answered at once: --workers
  Impl(Api& a, int workers) : api(a), handling(workers) {}
};

Server::Server(Api& api, int workers) : impl_(std::make_unique<Impl>(api, std::max(workers, 1))) {
  impl_->http.new_task_queue = [] { return new ConnectionQueue; };
  impl_->http.set_socket_options(exclusive_socket_options);
  impl_->http.set_payload_max_length(1 << 16);  // the API takes no bodies
  // A kept-alive connection holds a worker while it waits, and a browser keeps up to six per
  // host: a short keep-alive frees the workers of idle connections (with httplib's 5 s default,
  // the seventh connection of two tabs waited that long).
  impl_->http.set_keep_alive_timeout(1);
  // A client silent for 2 s between two reads of its request is dropped (httplib's default: 5 s).
  impl_->http.set_read_timeout(2, 0);
  // Without TCP_NODELAY, Nagle's algorithm holds the body's last segment until the client's
  // delayed ACK (up to 40 ms on Linux) — in every response of a slider move.
  impl_->http.set_tcp_nodelay(true);
  impl_->http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    const Response r = [&] {
      impl_->handling.acquire();
      const struct Release {
        std::counting_semaphore<>& s;
        ~Release() { s.release(); }
      } release{impl_->handling};
      return impl_->api.handle_target(req.method, req.target,
                                      Api::RawHeaders(req.headers.begin(), req.headers.end()));
    }();
    res.status = r.status;
    for (const auto& [name, value] : r.headers) res.set_header(name.c_str(), value);
    res.set_content(r.body, r.content_type.c_str());
    return httplib::Server::HandlerResponse::Handled;
  });
}

Server::~Server() = default;

int Server::bind(const std::string& host, int port) {
  const int bound = port == 0 ? impl_->http.bind_to_any_port(host)
                              : (impl_->http.bind_to_port(host, port) ? port : -1);
  if (bound <= 0)
    throw std::runtime_error("cannot listen on " + host + ":" + std::to_string(port) +
                             " (address in use, or not an address of this machine?)");
  impl_->api.set_port(bound);
  return bound;
}

bool Server::run() {
  return impl_->http.listen_after_bind();
}

void Server::stop() {
  impl_->http.stop();
}

bool keep_freed_memory() {
  constexpr int kThreshold = 256 << 20;
  return mallopt(M_MMAP_THRESHOLD, kThreshold) == 1 && mallopt(M_TRIM_THRESHOLD, kThreshold) == 1;
}

bool is_loopback(const std::string& host) {
  return host == "localhost" || host == "::1" || host == "[::1]" || host.rfind("127.", 0) == 0;
}

}  // namespace halfback::view
