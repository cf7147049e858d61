// The only file that includes httplib.h (a large header): everything else works on
// halfback::view::Request and Response.
#include "halfback/view/server.hpp"

#include <fmt/format.h>
#include <httplib.h>
#include <malloc.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <semaphore>
#include <stdexcept>
#include <string_view>
#include <thread>

#include "json.hpp"

namespace halfback::view {

namespace {

// A thread for each connection, up to kMaxThreads at once (more wait their turn): a client
// that trickles its request's header lines holds only its own connection's thread, where with a
// pool of --workers threads twenty such clients stalled every request for 30 s; and it holds it
// for kRequestHeadSeconds at most (HttpServer::serve). The work of the requests is bounded apart
// (Server::Impl::handling: --workers at once).
class ConnectionQueue : public httplib::TaskQueue {
 public:
  static constexpr std::size_t kMaxThreads = 256;

  void enqueue(std::function<void()> fn) override {
    std::lock_guard lock(mutex_);
    if (active_ < kMaxThreads)
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

// Why host:port cannot be bound, in the system's words (httplib reports only that it failed):
// the reason of a bind of a socket of our own, with the same options.
std::string bind_failure(const std::string& host, int port) {
  const std::string where = fmt::format("cannot listen on {}:{}", host, port);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  if (const int e = ::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found))
    return fmt::format("{}: {}", where, ::gai_strerror(e));
  int error = 0;
  const int sock = ::socket(found->ai_family, found->ai_socktype, found->ai_protocol);
  if (sock < 0) {
    error = errno;
  } else {
    exclusive_socket_options(sock);
    if (::bind(sock, found->ai_addr, found->ai_addrlen) != 0) error = errno;
    ::close(sock);
  }
  ::freeaddrinfo(found);
  std::string reason = error != 0 ? std::strerror(error) : "it could not be bound";
  if (error == EADDRINUSE)
    reason +=
        " (another server has this port: stop it, or choose another with --port; "
        "--port 0 takes any free one)";
  return fmt::format("{}: {}", where, reason);
}

}  // namespace

// Named, not anonymous: Server::Impl holds an HttpServer.
namespace http_detail {

using Clock = std::chrono::steady_clock;

// Milliseconds from now to `t` (0 if past), for poll().
int milliseconds_until(Clock::time_point t) {
  const auto ms = std::chrono::ceil<std::chrono::milliseconds>(t - Clock::now()).count();
  return int(std::clamp<long long>(ms, 0, 1 << 30));
}

// Whether `sock` has data (or an end) to read before `t` (a signal does not end the wait).
// Whether `sock` has `events` (POLLIN, POLLOUT) before `t`.
bool ready_before(socket_t sock, short events, Clock::time_point t) {
  pollfd p{sock, events, 0};
  int ready = 0;
  do ready = ::poll(&p, 1, milliseconds_until(t));
  while (ready < 0 && errno == EINTR);
  return ready > 0;
}
bool readable_before(socket_t sock, Clock::time_point t) {
  return ready_before(sock, POLLIN, t);
}

// The numeric address and port of a socket's peer (`peer`) or its own end.
void socket_address(socket_t sock, bool peer, std::string& ip, int& port) {
  sockaddr_storage a{};
  socklen_t size = sizeof a;
  auto* sa = reinterpret_cast<sockaddr*>(&a);
  char host[NI_MAXHOST] = "", service[NI_MAXSERV] = "0";
  if ((peer ? ::getpeername(sock, sa, &size) : ::getsockname(sock, sa, &size)) != 0 ||
      ::getnameinfo(sa, size, host, sizeof host, service, sizeof service,
                    NI_NUMERICHOST | NI_NUMERICSERV) != 0)
    host[0] = '\0';
  ip = host;
  port = std::atoi(service);
}

// The stream of one connection, for all its requests (httplib's own is per request, and loses
// the bytes of a pipelined request). While a request head is being read (set_head_deadline()
// until head_done()), every read ends at that deadline, however the bytes trickle: httplib's
// own stream only bounds the wait of each read, which a client sending a line a second extends
// forever. Past the deadline the stream swallows what httplib writes (its 400), and the server
// answers 408 itself. Likewise a response is written within kResponseWriteSeconds of its first
// byte, without blocking on a full socket: a client that stops reading (or reads a byte now and
// then) loses its connection instead of holding a worker in send() for ever.
class ConnectionStream : public httplib::Stream {
 public:
  ConnectionStream(socket_t sock, std::chrono::microseconds read_timeout,
                   std::chrono::microseconds write_timeout)
      : sock_(sock), read_timeout_(read_timeout), write_timeout_(write_timeout) {}

  // Whether the next request's first byte arrives before `t` (or is already buffered).
  bool request_arrives_before(Clock::time_point t) const {
    return offset_ < size_ || readable_before(sock_, t);
  }
  void set_head_deadline(Clock::time_point t) {
    head_deadline_ = t;
    in_head_ = true;
  }
  void head_done() { in_head_ = false; }
  bool head_too_late() const { return too_late_; }
  // The next write begins a response (its deadline starts then).
  void response_done() { writing_ = false; }

  bool is_readable() const override { return offset_ < size_ || readable_before(sock_, limit()); }
  bool is_writable() const override {
    const Clock::time_point t = Clock::now() + write_timeout_;
    return ready_before(sock_, POLLOUT, writing_ ? std::min(t, write_deadline_) : t);
  }

  ssize_t read(char* ptr, std::size_t size) override {
    if (offset_ == size_ && !fill()) return -1;
    if (offset_ == size_) return 0;  // the peer closed
    const std::size_t n = std::min(size, size_ - offset_);
    std::memcpy(ptr, buffer_.data() + offset_, n);
    offset_ += n;
    return ssize_t(n);
  }

  ssize_t write(const char* ptr, std::size_t size) override {
    if (too_late_) return ssize_t(size);  // the 408 replaces httplib's answer
    if (!writing_) {
      writing_ = true;
      write_deadline_ = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(kResponseWriteSeconds));
    }
    if (!is_writable()) return -1;
    // What the socket takes now (httplib writes the rest in further calls).
    ssize_t n;
    do n = ::send(sock_, ptr, size, MSG_NOSIGNAL | MSG_DONTWAIT);
    while (n < 0 && errno == EINTR);
    return n < 0 && errno == EAGAIN ? 0 : n;
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    socket_address(sock_, true, ip, port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    socket_address(sock_, false, ip, port);
  }
  socket_t socket() const override { return sock_; }

 private:
  // The time a read may wait until: the read timeout, and the head's deadline while in a head.
  Clock::time_point limit() const {
    const Clock::time_point t = Clock::now() + read_timeout_;
    return in_head_ ? std::min(t, head_deadline_) : t;
  }
  // Reads what the socket has into the empty buffer: false on a timeout or an error (a timeout
  // past the head's deadline marks the stream too late), true with size_ == 0 at the peer's end.
  bool fill() {
    offset_ = size_ = 0;
    if (!readable_before(sock_, limit())) {
      too_late_ = in_head_ && Clock::now() >= head_deadline_;
      return false;
    }
    const ssize_t n = ::recv(sock_, buffer_.data(), buffer_.size(), 0);
    if (n < 0) return false;
    size_ = std::size_t(n);
    return true;
  }

  socket_t sock_;
  std::chrono::microseconds read_timeout_, write_timeout_;
  std::array<char, 4096> buffer_{};
  std::size_t offset_ = 0, size_ = 0;
  Clock::time_point head_deadline_{}, write_deadline_{};
  bool in_head_ = false, too_late_ = false, writing_ = false;
};

// Writes a whole response that closes the connection, with a JSON {"error": message} body (as the
// Api's), then waits briefly for the client's end so that the unread rest of its request does
// not turn the close into a reset that would lose the response.
void answer_and_close(socket_t sock, int status, const char* reason, std::string_view message) {
  Json error;
  error["error"] = message;
  const std::string body = json_text(std::move(error));
  const std::string response = fmt::format(
      "HTTP/1.1 {} {}\r\nContent-Type: application/json\r\nContent-Length: {}\r\n"
      "Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\n{}",
      status, reason, body.size(), body);
  for (std::size_t sent = 0; sent < response.size();) {
    pollfd p{sock, POLLOUT, 0};
    if (::poll(&p, 1, 1000) <= 0) return;
    const ssize_t n = ::send(sock, response.data() + sent, response.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return;
    sent += std::size_t(n);
  }
  ::shutdown(sock, SHUT_WR);
  const Clock::time_point until = Clock::now() + std::chrono::milliseconds(200);
  char drain[4096];
  for (std::size_t total = 0; total < (1 << 16) && readable_before(sock, until);) {
    const ssize_t n = ::recv(sock, drain, sizeof drain, 0);
    if (n <= 0) return;
    total += std::size_t(n);
  }
}

// The open connections, each held by a Slot: at most kMaxConnections at once, keyed by connection
// (every local process shares the address 127.0.0.1, so a bound per address let one of them
// starve the page). A new connection at the bound makes room by closing the one that has waited
// longest for a request head (idle between requests, or trickling one in: it holds a thread and
// no work); when every connection is being answered, the new one is refused. close_all() shuts
// every connection down (their reads and writes end at once) and refuses new ones.
class Connections {
 public:
  class Slot {
   public:
    Slot(Connections& owner, socket_t sock) : owner_(owner), sock_(sock) {
      taken_ = owner_.open(sock);
    }
    ~Slot() {
      if (taken_) owner_.close(sock_);
    }
    Slot(const Slot&) = delete;
    Slot& operator=(const Slot&) = delete;
    bool taken() const { return taken_; }
    // The connection waits for a request head from now (true), or is being answered (false).
    void waiting(bool w) { owner_.set_waiting(sock_, w); }

   private:
    Connections& owner_;
    socket_t sock_;
    bool taken_ = false;
  };

  void close_all() {
    std::lock_guard lock(mutex_);
    closing_ = true;
    for (auto& [sock, c] : open_) {
      ::shutdown(sock, SHUT_RDWR);
      c.closed = true;
    }
  }

 private:
  struct Open {
    bool waiting = true;  // for a request head, since `since`
    Clock::time_point since = Clock::now();
    bool closed = false;  // shut down to make room (its Slot ends soon)
  };

  bool open(socket_t sock) {
    std::lock_guard lock(mutex_);
    if (closing_) return false;
    const auto live =
        std::count_if(open_.begin(), open_.end(), [](const auto& o) { return !o.second.closed; });
    if (std::size_t(live) >= kMaxConnections) {
      auto oldest = open_.end();
      for (auto it = open_.begin(); it != open_.end(); ++it)
        if (it->second.waiting && !it->second.closed &&
            (oldest == open_.end() || it->second.since < oldest->second.since))
          oldest = it;
      if (oldest == open_.end()) return false;
      ::shutdown(oldest->first, SHUT_RDWR);
      oldest->second.closed = true;
    }
    open_[sock] = Open{};
    return true;
  }
  void close(socket_t sock) {
    std::lock_guard lock(mutex_);
    open_.erase(sock);
  }
  void set_waiting(socket_t sock, bool w) {
    std::lock_guard lock(mutex_);
    if (const auto it = open_.find(sock); it != open_.end()) {
      it->second.waiting = w;
      it->second.since = Clock::now();
    }
  }

  std::mutex mutex_;
  std::map<socket_t, Open> open_;
  bool closing_ = false;
};

// The connection the calling thread serves (each connection has a thread of its own), for the
// requests' Request::abandoned.
thread_local socket_t serving_socket = INVALID_SOCKET;

// Whether the peer of `sock` has closed its side (or the connection is gone): its answer is no
// longer wanted. A client that closes only its sending side is taken to have left as well.
bool peer_left(socket_t sock) {
  pollfd p{sock, POLLRDHUP, 0};
  return ::poll(&p, 1, 0) > 0 && (p.revents & (POLLRDHUP | POLLHUP | POLLERR | POLLNVAL)) != 0;
}

// httplib's server with its connection handling replaced (process_and_close_socket, a virtual
// function of httplib::Server that may be overridden although private): the bound on
// connections per client, and the stream whose request heads have a deadline. The requests
// themselves go through httplib's process_request (parsing, routing, writing).
class HttpServer : public httplib::Server {
 public:
  // Widens the bound socket's queue of connections not yet accepted from httplib's 5 (Linux
  // takes a second listen() for that): a burst of more, such as a page's requests with a few
  // other clients, otherwise saw connections dropped by the kernel and set up again 1 to 3 s
  // later.
  void widen_backlog() { ::listen(svr_sock_, ConnectionQueue::kMaxThreads); }
  // Serves a connected socket as an accepted one (Server::serve_connection).
  void serve_accepted(socket_t sock) { process_and_close_socket(sock); }
  // Shuts every connection down and refuses new ones (Server::stop).
  void close_connections() { connections_.close_all(); }

 private:
  bool process_and_close_socket(socket_t sock) override {
    bool ok = false;
    if (Connections::Slot slot(connections_, sock); slot.taken())
      ok = serve(sock, slot);
    else
      answer_and_close(sock, 503, "Service Unavailable",
                       fmt::format("every one of the {} connections is being answered: try again",
                                   kMaxConnections));
    ::shutdown(sock, SHUT_RDWR);
    ::close(sock);
    return ok;
  }

  // The requests of one connection, up to httplib's keep-alive count: each must begin within
  // the keep-alive timeout and have its head read within kRequestHeadSeconds of the wait's start.
  bool serve(socket_t sock, Connections::Slot& slot) {
    using std::chrono::microseconds, std::chrono::seconds;
    serving_socket = sock;
    ConnectionStream stream(sock, seconds(read_timeout_sec_) + microseconds(read_timeout_usec_),
                            seconds(write_timeout_sec_) + microseconds(write_timeout_usec_));
    const auto head_time = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(kRequestHeadSeconds));
    bool ok = false;
    for (std::size_t k = 0; k < keep_alive_max_count_ && svr_sock_ != INVALID_SOCKET; ++k) {
      const Clock::time_point deadline = Clock::now() + head_time;
      if (!stream.request_arrives_before(
              std::min(deadline, Clock::now() + seconds(keep_alive_timeout_sec_))))
        break;  // an idle connection: closed quietly
      stream.set_head_deadline(deadline);
      bool closed = false;
      ok = process_request(stream, k + 1 == keep_alive_max_count_, closed,
                           [&stream, &slot](httplib::Request&) {
                             stream.head_done();
                             slot.waiting(false);
                           });
      stream.response_done();
      slot.waiting(true);
      if (stream.head_too_late()) {
        answer_and_close(sock, 408, "Request Timeout",
                         fmt::format("the request line and headers did not arrive within {} s",
                                     kRequestHeadSeconds));
        return false;
      }
      if (!ok || closed) break;
    }
    return ok;
  }

  Connections connections_;
};

}  // namespace http_detail

struct Server::Impl {
  Api& api;
  http_detail::HttpServer http;
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
      const socket_t sock = http_detail::serving_socket;
      return impl_->api.handle_target(req.method, req.target,
                                      Api::RawHeaders(req.headers.begin(), req.headers.end()),
                                      [sock] { return http_detail::peer_left(sock); });
    }();
    res.status = r.status;
    for (const auto& [name, value] : r.headers) res.set_header(name.c_str(), value);
    // JSON with its charset: Debian's cpp-httplib, built with brotli, compresses an answer whose
    // type is exactly one of its list ("application/json" is, this one is not) for a client
    // that accepts br, at brotli's highest quality — 85 ms of the server's time for the 45 KB
    // of polar curves of three BRDFs, at each step of a drag of ωo, to save nothing on a
    // loopback connection. (The page's files, text/*, are still compressed: once per load.)
    res.set_content(r.body, r.content_type == "application/json" ? "application/json; charset=utf-8"
                                                                 : r.content_type.c_str());
    return httplib::Server::HandlerResponse::Handled;
  });
}

Server::~Server() = default;

int Server::bind(const std::string& host, int port) {
  const int bound = port == 0 ? impl_->http.bind_to_any_port(host)
                              : (impl_->http.bind_to_port(host, port) ? port : -1);
  if (bound <= 0) throw std::runtime_error(bind_failure(host, port));
  impl_->http.widen_backlog();
  impl_->api.set_port(bound);
  return bound;
}

bool Server::run() {
  return impl_->http.listen_after_bind();
}

void Server::stop() {
  impl_->api.stop();  // computations in progress give up
  impl_->http.close_connections();
  impl_->http.stop();
}

void Server::serve_connection(int fd) {
  impl_->http.serve_accepted(fd);
}

bool keep_freed_memory() {
  constexpr int kThreshold = 256 << 20;
  return mallopt(M_MMAP_THRESHOLD, kThreshold) == 1 && mallopt(M_TRIM_THRESHOLD, kThreshold) == 1;
}

bool is_loopback(const std::string& host) {
  return host == "localhost" || host == "::1" || host == "[::1]" || host.rfind("127.", 0) == 0;
}

}  // namespace halfback::view
