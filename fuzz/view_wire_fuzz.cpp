// libFuzzer target for the socket side of `halfback view` (see fuzz/run.sh): the input is what a
// client sends on one connection, bytes as they are (request lines, headers, repeated ones,
// several requests in a row), cut into pieces at each "~~\n" that are written one at a time with a
// pause between them (a client trickling its request, cut anywhere). The pieces go through a
// socket pair to Server::serve_connection: httplib's parser, the stream with the request head's
// deadline, and the Api. The client then closes its side, so no input waits for a deadline (and a
// computation sees its client leave: the abandonment is fuzzed too).
// The server's answer must begin with a status line of a status in [100, 600), or be empty.
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>
#include <thread>

#include "halfback/view/api.hpp"
#include "halfback/view/server.hpp"

using namespace halfback::view;

namespace {

// One server, bound to 127.0.0.1 (any port) and never listening: its connections come from the
// fuzzer. The Api's port is set back to 8765, the port of the seeds' Host headers.
Server& server() {
  static Server* instance = [] {
    ApiConfig c;
    c.token = "t";
    c.specs = {"ggx:alpha=0.3", "lambert"};
    c.threads = 1;
    static Api api(c);
    auto* s = new Server(api, 1);
    s->bind("127.0.0.1", 0);
    api.set_port(8765);
    return s;
  }();
  return *instance;
}

// Writes the input's pieces to `fd`, 200 µs apart, then ends the sending side.
void send_pieces(int fd, std::string_view input) {
  constexpr std::string_view kCut = "~~\n";
  while (!input.empty()) {
    const std::size_t cut = input.find(kCut);
    const std::string_view piece = input.substr(0, cut);
    for (std::size_t sent = 0; sent < piece.size();) {
      const ssize_t n = ::send(fd, piece.data() + sent, piece.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) return;
      sent += std::size_t(n);
    }
    input = cut == std::string_view::npos ? std::string_view{} : input.substr(cut + kCut.size());
    if (!input.empty()) std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  ::shutdown(fd, SHUT_WR);
}

// Whether `answer` is empty or begins with "HTTP/1.1 NNN " with NNN in [100, 600).
bool begins_with_a_status(const std::string& answer) {
  if (answer.empty()) return true;
  if (answer.size() < 13 || answer.compare(0, 9, "HTTP/1.1 ") != 0 || answer[12] != ' ')
    return false;
  const int status = std::atoi(answer.substr(9, 3).c_str());
  return status >= 100 && status < 600;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  // A sphere render's cost grows with size × spp: the defaults exercise the same code.
  if (input.find("render") != std::string_view::npos &&
      (input.find("size") != std::string_view::npos || input.find("spp") != std::string_view::npos))
    return 0;
  Server& s = server();
  int fds[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM, 0, fds) != 0) std::abort();
  std::thread serving([&s, fd = fds[1]] { s.serve_connection(fd); });  // closes fds[1]
  send_pieces(fds[0], input);
  std::string answer;
  char buf[65536];
  // Read to the end (a signal of libFuzzer's interrupting a read is no end: had the reading
  // stopped there, the server would have dropped the connection only at its write deadline).
  for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0 || (n < 0 && errno == EINTR);)
    if (n > 0) answer.append(buf, std::size_t(n));
  serving.join();
  ::close(fds[0]);
  if (!begins_with_a_status(answer)) std::abort();
  return 0;
}
