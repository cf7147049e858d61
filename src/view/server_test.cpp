// The server on real sockets (127.0.0.1 only, every wait bounded): a port is not shared with a
// second server, and clients that trickle their header lines do not stall the others (issue 35,
// class E).
#include "halfback/view/server.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

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

// The status line of one GET of /api/info (Connection: close), read within `seconds`; "" if none.
std::string get_info(int port, double seconds) {
  const int fd = connect_to(port);
  if (fd < 0) return "";
  const std::string request = "GET /api/info?token=" + kToken +
                              " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
                              "\r\nConnection: close\r\n\r\n";
  (void)!::write(fd, request.data(), request.size());
  std::string answer;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  char buf[4096];
  while (answer.find("\r\n") == std::string::npos) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    pollfd p{fd, POLLIN, 0};
    if (left.count() <= 0 || ::poll(&p, 1, int(left.count())) <= 0) break;
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) break;
    answer.append(buf, std::size_t(n));
  }
  ::close(fd);
  return answer.substr(0, answer.find("\r\n"));
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
  EXPECT_THROW(second.bind("127.0.0.1", first.port), std::runtime_error);
  for (int k = 0; k < 20; ++k) EXPECT_EQ(get_info(first.port, 5), "HTTP/1.1 200 OK") << k;
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

}  // namespace
}  // namespace halfback::view::server_test
