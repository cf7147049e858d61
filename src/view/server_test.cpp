// The server on real sockets (127.0.0.1 only, every wait bounded): a port is not shared with a
// second server, clients that trickle their header lines or hold many connections do not stall
// the others, and a computation ends when its client leaves, its deadline passes or the server
// stops.
#include "halfback/view/server.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "halfback/core/space.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::view::server_test {  // (a unity build with api_test.cpp)
namespace {

const std::string kToken = "0123456789abcdef0123456789abcdef";

ApiConfig config() {
  ApiConfig c;
  c.token = kToken;
  c.threads = 1;
  return c;
}

// A connected socket to 127.0.0.1:port, or -1.
int connect_to(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(std::uint16_t(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// What the server writes on `fd` until `stop` is in it (empty: until it closes the connection) or
// `seconds` pass.
std::string read_until(int fd, double seconds, const std::string& stop = "") {
  std::string answer;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  char buf[65536];
  while (stop.empty() || answer.find(stop) == std::string::npos) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    pollfd p{fd, POLLIN, 0};
    if (left.count() <= 0 || ::poll(&p, 1, int(left.count())) <= 0) break;
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) break;
    answer.append(buf, std::size_t(n));
  }
  return answer;
}

// The status line the server writes on `fd` within `seconds` ("" if none, or the connection
// closed without one).
std::string status_line(int fd, double seconds) {
  const std::string answer = read_until(fd, seconds, "\r\n");
  return answer.substr(0, answer.find("\r\n"));
}

// A GET of /api/info with the token, Connection: close, and `extra` header lines.
std::string info_request(int port, const std::string& extra = "") {
  return "GET /api/info?token=" + kToken + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
         "\r\n" + extra + "Connection: close\r\n\r\n";
}

// The status line of one GET of /api/info (Connection: close), read within `seconds`; "" if none.
std::string get_info(int port, double seconds, const std::string& extra = "") {
  const int fd = connect_to(port);
  if (fd < 0) return "";
  const std::string request = info_request(port, extra);
  (void)!::write(fd, request.data(), request.size());
  const std::string status = status_line(fd, seconds);
  ::close(fd);
  return status;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct Running {
  Api api{config()};
  Server server{api, 2};
  int port = server.bind("127.0.0.1", 0);
  std::thread thread{[this] { server.run(); }};
  ~Running() {
    server.stop();
    thread.join();
  }
};

TEST(ViewServer, APortIsNotShared) {
  Running first;
  Api other_api(config());
  Server second(other_api, 2);
  try {
    second.bind("127.0.0.1", first.port);
    ADD_FAILURE() << "a second server bound the port";
  } catch (const std::runtime_error& e) {  // the message names the port and the reason
    const std::string expected =
        "cannot listen on 127.0.0.1:" + std::to_string(first.port) + ": Address already in use";
    EXPECT_EQ(std::string(e.what()).rfind(expected, 0), 0u) << e.what();
  }
  for (int k = 0; k < 20; ++k) EXPECT_EQ(get_info(first.port, 5), "HTTP/1.1 200 OK") << k;
}

// JSON answers are sent as they are, whatever the client accepts: a browser accepts br, and
// httplib compressed "application/json" with brotli at its highest quality (the 45 KB of polar
// curves of three BRDFs took 85 ms, at each step of a drag). Their type names the charset.
TEST(ViewServer, JsonAnswersAreNotCompressed) {
  Running s;
  const int fd = connect_to(s.port);
  ASSERT_GE(fd, 0);
  const std::string request = "GET /api/polar?token=" + kToken +
                              "&brdf=ggx&brdf=lambert&theta_o=40&n=181 HTTP/1.1\r\nHost: "
                              "127.0.0.1:" +
                              std::to_string(s.port) +
                              "\r\nAccept-Encoding: gzip, deflate, br, zstd\r\n"
                              "Connection: close\r\n\r\n";
  (void)!::write(fd, request.data(), request.size());
  const std::string answer = read_until(fd, 10);
  ::close(fd);
  const std::size_t end = answer.find("\r\n\r\n");
  ASSERT_NE(end, std::string::npos) << answer.substr(0, 200);
  std::string head = answer.substr(0, end);
  for (char& c : head) c = char(std::tolower(static_cast<unsigned char>(c)));
  EXPECT_EQ(head.rfind("http/1.1 200 ok", 0), 0u) << head;
  EXPECT_EQ(head.find("content-encoding"), std::string::npos) << head;
  EXPECT_NE(head.find("content-type: application/json; charset=utf-8"), std::string::npos) << head;
  const std::string body = answer.substr(end + 4);
  EXPECT_GT(body.size(), 10000u);
  EXPECT_EQ(body.rfind("{\"angles_deg\":", 0), 0u) << body.substr(0, 64);
  EXPECT_EQ(body.back(), '}');
}

TEST(ViewServer, TricklingClientsDoNotStallTheOthers) {
  Running s;
  // Twenty clients (ten times the workers) that send the start of a request and then a header
  // line now and then, never ending it.
  std::vector<int> slow;
  for (int k = 0; k < 20; ++k) {
    const int fd = connect_to(s.port);
    ASSERT_GE(fd, 0);
    const std::string start = "GET /api/info HTTP/1.1\r\n";
    (void)!::write(fd, start.data(), start.size());
    slow.push_back(fd);
  }
  for (int round = 0; round < 3; ++round) {
    for (const int fd : slow) (void)!::write(fd, "X-A: b\r\n", 8);
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_EQ(get_info(s.port, 5), "HTTP/1.1 200 OK");
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_LT(seconds, 2.0) << "round " << round;
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }
  for (const int fd : slow) ::close(fd);
}

// A client that trickles header lines (one every 250 ms, each well within the read timeout)
// cannot keep its request open: the head has one deadline from the start of the wait, after
// which the server answers 408 and closes.
TEST(ViewServer, ARequestHeadHasADeadlineThatTricklingCannotExtend) {
  Running s;
  const int fd = connect_to(s.port);
  ASSERT_GE(fd, 0);
  const auto t0 = std::chrono::steady_clock::now();
  const std::string start = "GET /api/info?token=" + kToken + " HTTP/1.1\r\n";
  (void)!::write(fd, start.data(), start.size());
  std::string status;
  while (status.empty() && seconds_since(t0) < kRequestHeadSeconds + 4) {
    (void)!::send(fd, "X-A: b\r\n", 8, MSG_NOSIGNAL);
    status = status_line(fd, 0.25);
  }
  const double seconds = seconds_since(t0);
  ::close(fd);
  EXPECT_EQ(status, "HTTP/1.1 408 Request Timeout");
  EXPECT_GT(seconds, kRequestHeadSeconds - 0.5);
  EXPECT_LT(seconds, kRequestHeadSeconds + 1.0);
}

// One local process that holds many connections trickling their request heads (twice the 32
// that once bounded every loopback client together) does not starve the page's requests: each
// is answered 200 at once.
TEST(ViewServer, TricklingConnectionsOfOneProcessDoNotStarveThePage) {
  Running s;
  std::vector<int> slow;
  for (int k = 0; k < 64; ++k) {
    const int fd = connect_to(s.port);
    ASSERT_GE(fd, 0);
    (void)!::write(fd, "GET /api/info HTTP/1.1\r\n", 24);
    slow.push_back(fd);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // every connection counted
  int answered = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int batch = 0; batch < 10; ++batch) {  // 59 requests, 6 at a time, as a page loads
    for (const int fd : slow) (void)!::send(fd, "X-A: b\r\n", 8, MSG_NOSIGNAL);
    std::vector<int> page;
    for (int k = 0; k < 6 && batch * 6 + k < 59; ++k) {
      const int fd = connect_to(s.port);
      ASSERT_GE(fd, 0);
      const std::string request = info_request(s.port);
      (void)!::write(fd, request.data(), request.size());
      page.push_back(fd);
    }
    for (const int fd : page) {
      answered += status_line(fd, 2) == "HTTP/1.1 200 OK";
      ::close(fd);
    }
  }
  EXPECT_EQ(answered, 59);
  EXPECT_LT(seconds_since(t0), 3.0);
  for (const int fd : slow) ::close(fd);
}

// At kMaxConnections open connections, a new one is answered: the connection that has waited
// longest for its request head is closed to make room.
TEST(ViewServer, AtTheBoundTheLongestWaitingConnectionMakesRoom) {
  Running s;
  std::vector<int> held;
  for (std::size_t k = 0; k < kMaxConnections; ++k) {
    const int fd = connect_to(s.port);
    ASSERT_GE(fd, 0);
    (void)!::write(fd, "GET /api/info", 13);  // a request begun, not finished
    held.push_back(fd);
    if (k == 0) std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the oldest
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // every connection counted
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(get_info(s.port, 2), "HTTP/1.1 200 OK");
  EXPECT_LT(seconds_since(t0), 1.0);
  pollfd p{held.front(), POLLIN, 0};  // the oldest was closed (its read ends)
  ASSERT_EQ(::poll(&p, 1, 1000), 1);
  char c;
  EXPECT_EQ(::read(held.front(), &c, 1), 0);
  for (const int fd : held) ::close(fd);
}

// Sends a GET of `target` (with the token and Host) on a new connection; returns the socket.
int send_get(int port, const std::string& target) {
  const int fd = connect_to(port);
  const std::string request = "GET " + target + "&token=" + kToken +
                              " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
                              "\r\nConnection: close\r\n\r\n";
  if (fd >= 0) (void)!::write(fd, request.data(), request.size());
  return fd;
}

// A fit that takes long (four He lobes at the largest size: minutes without a bound).
const std::string kLongFit =
    "/api/fit?brdf=lambert:albedo=0.3%2Bggx:alpha=0.2&model=he%2Bhe%2Bhe%2Bhe&samples=20000";

// A fit whose client leaves is cancelled: the next fit is not refused as "another fit is
// running".
TEST(ViewServer, AFitWhoseClientLeavesIsCancelled) {
  Running s;
  const int fd = send_get(s.port, kLongFit);
  ASSERT_GE(fd, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  ::close(fd);  // the client leaves
  const auto t0 = std::chrono::steady_clock::now();
  std::string status;
  while (seconds_since(t0) < 5) {
    const int quick = send_get(s.port, "/api/fit?brdf=lambert&model=lambert&samples=100");
    status = status_line(quick, 5);
    ::close(quick);
    if (status == "HTTP/1.1 200 OK") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_EQ(status, "HTTP/1.1 200 OK");
  EXPECT_LT(seconds_since(t0), 2.0);
}

// A fit past its deadline is answered 503, saying so.
TEST(ViewServer, AFitPastItsDeadlineIsAnswered503) {
  ApiConfig c = config();
  c.compute_seconds = 0.5;
  Api api(c);
  Server server(api, 2);
  const int port = server.bind("127.0.0.1", 0);
  std::thread thread([&] { server.run(); });
  const auto t0 = std::chrono::steady_clock::now();
  const int fd = send_get(port, kLongFit);
  ASSERT_GE(fd, 0);
  EXPECT_EQ(status_line(fd, 5), "HTTP/1.1 503 Service Unavailable");
  EXPECT_LT(seconds_since(t0), 2.0);
  ::close(fd);
  server.stop();
  thread.join();
}

// stop() ends a server whatever it computes: the fit gives up, the connections close, run()
// returns at once.
TEST(ViewServer, StopEndsALongFitAtOnce) {
  auto s = std::make_unique<Running>();
  const int fd = send_get(s->port, kLongFit);
  ASSERT_GE(fd, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const auto t0 = std::chrono::steady_clock::now();
  s.reset();  // stop() and join the serving thread
  EXPECT_LT(seconds_since(t0), 2.0);
  char buf[256];
  pollfd p{fd, POLLIN, 0};
  EXPECT_EQ(::poll(&p, 1, 1000), 1);  // the connection ended
  (void)!::read(fd, buf, sizeof buf);
  ::close(fd);
}

// A burst of connections (as many as a few pages open) is answered at once: none waits for
// the kernel to set it up again after dropping it from a full queue of unaccepted connections.
TEST(ViewServer, ABurstOfConnectionsIsAnsweredAtOnce) {
  Running s;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<int> burst;
  for (int k = 0; k < 30; ++k) {
    const int fd = connect_to(s.port);
    ASSERT_GE(fd, 0);
    const std::string request = info_request(s.port);
    (void)!::write(fd, request.data(), request.size());
    burst.push_back(fd);
  }
  for (const int fd : burst) {
    EXPECT_EQ(status_line(fd, 3), "HTTP/1.1 200 OK");
    ::close(fd);
  }
  EXPECT_LT(seconds_since(t0), 0.9);
}

// A client that stops reading a large response loses its connection after the write timeout (5 s
// without progress) or kResponseWriteSeconds after the response began, whatever the socket's own
// options: on a socket pair (no SO_SNDTIMEO, as
// the wire fuzzer serves), a send() of the whole response blocked the server's thread for as long
// as the client did not read.
TEST(ViewServer, AClientThatStopsReadingIsDropped) {
  Api api(config());
  Server server(api, 1);
  const int port = server.bind("127.0.0.1", 0);
  int fds[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
  std::atomic<bool> served{false};
  std::thread serving([&] {
    server.serve_connection(fds[1]);
    served = true;
  });
  // Every form's slices of two BRDFs at n = 256: 8 forms × 2 × 3 channels × 256² floats.
  const std::string request =
      "GET /api/slices?token=" + kToken +
      "&brdf=lambert&brdf=ggx:alpha=0.2&n=256 HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
      "\r\nConnection: close\r\n\r\n";
  ASSERT_EQ(::write(fds[0], request.data(), request.size()), ssize_t(request.size()));
  const auto t0 = std::chrono::steady_clock::now();
  // The slices take seconds to compute under ASan on a loaded machine: wait for the write
  // timeout after them, not from the request.
  while (!served && seconds_since(t0) < kResponseWriteSeconds + 60)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_TRUE(served) << "the server still writes to a client that stopped reading";
  EXPECT_GT(seconds_since(t0), 1.0);  // the write timeout (5 s without progress), or the deadline
  std::string answer;
  char buf[65536];
  for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0;) answer.append(buf, std::size_t(n));
  serving.join();
  ::close(fds[0]);
  ASSERT_EQ(answer.rfind("HTTP/1.1 200 OK\r\n", 0), 0u) << answer.substr(0, 80);
  const std::size_t at = answer.find("Content-Length: ");
  ASSERT_NE(at, std::string::npos);
  const std::size_t length = std::stoul(answer.substr(at + 16));
  EXPECT_GT(length, std::size_t(4) << 20);
  EXPECT_LT(answer.size() - answer.find("\r\n\r\n") - 4, length);  // cut short
}

// Two Host or two Origin headers on the wire are refused (httplib keeps both; the Api refuses).
TEST(ViewServer, RepeatedHostOrOriginHeadersAreRefused) {
  Running s;
  const std::string host = "Host: 127.0.0.1:" + std::to_string(s.port) + "\r\n";
  EXPECT_EQ(get_info(s.port, 5, host), "HTTP/1.1 400 Bad Request");
  const std::string origin = "Origin: http://127.0.0.1:" + std::to_string(s.port) + "\r\n";
  EXPECT_EQ(get_info(s.port, 5, origin), "HTTP/1.1 200 OK");
  EXPECT_EQ(get_info(s.port, 5, origin + origin), "HTTP/1.1 400 Bad Request");
}

// A whole response to a GET of `target` (Connection: close), read to the end within `seconds`:
// its head (status line and headers) and its body.
struct Answer {
  std::string head, body;
  std::string status() const { return head.substr(0, head.find("\r\n")); }
  std::string header(const std::string& name) const {
    const std::size_t at = head.find("\r\n" + name + ": ");
    if (at == std::string::npos) return "";
    const std::size_t from = at + name.size() + 4;
    return head.substr(from, head.find("\r\n", from) - from);
  }
};

Answer get_all(int port, const std::string& target, double seconds) {
  const int fd = send_get(port, target);
  std::string all;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  std::vector<char> buf(1 << 16);
  while (fd >= 0) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    pollfd p{fd, POLLIN, 0};
    if (left.count() <= 0 || ::poll(&p, 1, int(left.count())) <= 0) break;
    const ssize_t n = ::read(fd, buf.data(), buf.size());
    if (n <= 0) break;
    all.append(buf.data(), std::size_t(n));
  }
  if (fd >= 0) ::close(fd);
  const std::size_t end = all.find("\r\n\r\n");
  if (end == std::string::npos) return {all, ""};
  return {all.substr(0, end + 2), all.substr(end + 4)};
}

// The explorer's finding on the wire: each distinct dupuy-jakob:BRDF form of a request (in
// forms=, colour= and form=) is answered with its own values, and none is registered: /api/info
// lists the same forms after 30 of them as before, the process's registry is unchanged, and a
// request naming more than kMaxCachedForms is a 413. (Before, each registered a parameterization
// for the life of the process: /api/info grew by one form a request.)
TEST(ViewServer, RequestFormsDoNotAccumulate) {
  register_brdf_parameterization_families();  // as `halfback view` has them
  Running s;
  const std::size_t registered = parameterizations().size();
  const Answer before = get_all(s.port, "/api/info?", 10);
  ASSERT_EQ(before.status(), "HTTP/1.1 200 OK");
  std::string previous;
  for (int k = 0; k < 30; ++k) {
    const std::string form = "dupuy-jakob:ggx:alpha=0." + std::to_string(10 + k);
    const std::string target = k % 3 == 0   ? "/api/slices?brdf=ggx:alpha=0.3&n=8&forms=" + form
                               : k % 3 == 1 ? "/api/hemisphere?n=4&colour=" + form
                                            : "/api/point?iso=1&coords=0.5,0.3,0.7&form=" + form;
    const Answer a = get_all(s.port, target, 10);
    ASSERT_EQ(a.status(), "HTTP/1.1 200 OK") << target << ": " << a.body;
    if (k % 3 == 0) {
      EXPECT_EQ(a.header("X-Halfback-Forms"), form);
      EXPECT_NE(a.body, previous);  // its own form's values, not a cached neighbour's
      previous = a.body;
    }
  }
  EXPECT_EQ(parameterizations().size(), registered);
  EXPECT_EQ(get_all(s.port, "/api/info?", 10).body, before.body);
  std::string many;
  for (std::size_t k = 0; k <= kMaxCachedForms; ++k)
    many += (k ? "," : "") + std::string("dupuy-jakob:ggx:alpha=0.") + std::to_string(k + 1);
  EXPECT_EQ(get_all(s.port, "/api/slices?brdf=lambert&n=2&forms=" + many, 10).status(),
            "HTTP/1.1 413 Payload Too Large");
}

// The explorer's finding on the wire: slices answers stay within kMaxSlicesBytes. Two BRDFs,
// every form, n = 512 in RGB (50 MB before) is a 400 naming the bound, with a small body; the
// page's largest request (the same in luminance) is a 200 whose body, read to its end, has the
// length it declares, within the bound.
TEST(ViewServer, SlicesAnswersStayWithinTheirBound) {
  Running s;
  const Answer big =
      get_all(s.port, "/api/slices?brdf=lambert&brdf=ggx:alpha=0.2&n=512&values=rgb", 30);
  EXPECT_EQ(big.status(), "HTTP/1.1 400 Bad Request");
  EXPECT_NE(big.body.find("above the limit"), std::string::npos) << big.body.substr(0, 200);
  EXPECT_LT(big.body.size(), 1024u);
  const Answer page =
      get_all(s.port, "/api/slices?brdf=lambert&brdf=ggx:alpha=0.2&n=512&values=luminance", 120);
  ASSERT_EQ(page.status(), "HTTP/1.1 200 OK") << page.body.substr(0, 200);
  const std::string length = page.header("Content-Length");
  ASSERT_FALSE(length.empty()) << page.head;
  EXPECT_EQ(std::stoul(length), page.body.size());
  EXPECT_LE(page.body.size(), kMaxSlicesBytes);
  EXPECT_EQ(page.body.size(), 2 * parameterizations().size() * 512 * 512 * sizeof(float));
}

}  // namespace
}  // namespace halfback::view::server_test
