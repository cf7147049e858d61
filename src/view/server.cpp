// The only file that includes httplib.h (a large header): everything else works on
// halfback::view::Request and Response.
#include "halfback/view/server.hpp"

#include <httplib.h>
#include <malloc.h>

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace halfback::view {

struct Server::Impl {
  Api& api;
  httplib::Server http;
  explicit Impl(Api& a) : api(a) {}
};

namespace {

std::map<std::string, std::string> lower_case_headers(const httplib::Headers& headers) {
  std::map<std::string, std::string> out;
  for (const auto& [name, value] : headers) {
    std::string lower = name;
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    out.emplace(std::move(lower), value);  // a repeated header keeps its first value
  }
  return out;
}

}  // namespace

Server::Server(Api& api, int workers) : impl_(std::make_unique<Impl>(api)) {
  const std::size_t n = std::size_t(std::max(workers, 1));
  impl_->http.new_task_queue = [n] { return new httplib::ThreadPool(n); };
  impl_->http.set_payload_max_length(1 << 16);  // the API takes no bodies
  // A kept-alive connection holds a worker while it waits, and a browser keeps up to six per
  // host: a short keep-alive frees the workers of idle connections (with httplib's 5 s default,
  // the seventh connection of two tabs waited that long).
  impl_->http.set_keep_alive_timeout(1);
  // Without TCP_NODELAY, Nagle's algorithm holds the body's last segment until the client's
  // delayed ACK (up to 40 ms on Linux) — in every response of a slider move.
  impl_->http.set_tcp_nodelay(true);
  impl_->http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    const Response r =
        impl_->api.handle_target(req.method, req.target, lower_case_headers(req.headers));
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
