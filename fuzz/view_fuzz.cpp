// libFuzzer target for the request handler of `halfback view` (see fuzz/run.sh). The input is a
// request as text: the first line the target ("/api/slices?brdf=...&token=t"), optionally
// preceded by a method ("POST /x"), then "name: value" header lines. A valid Host header comes
// first (the input may replace it), so that the fuzzer reaches the endpoints behind the checks.
// Every response must be a status in [200, 600) with a body; a 4xx must be JSON.
#include <cstdint>
#include <cstdlib>
#include <map>
#include <string>
#include <string_view>

#include "halfback/view/api.hpp"

using namespace halfback::view;

namespace {

const Api& api() {
  static const Api* instance = [] {
    ApiConfig c;
    c.token = "t";
    c.port = 8765;
    c.specs = {"ggx:alpha=0.3", "lambert"};
    c.threads = 1;
    return new Api(c);
  }();
  return *instance;
}

std::string_view next_line(std::string_view& s) {
  const std::size_t nl = s.find('\n');
  const std::string_view line = s.substr(0, nl);
  s = nl == std::string_view::npos ? std::string_view{} : s.substr(nl + 1);
  return line;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view input(reinterpret_cast<const char*>(data), size);
  std::string_view target = next_line(input);
  std::string method = "GET";
  if (const std::size_t sp = target.find(' '); sp != std::string_view::npos && sp < 8) {
    method = std::string(target.substr(0, sp));
    target.remove_prefix(sp + 1);
  }
  // A sphere render's cost grows with size × spp (up to 512² × 64 samples): the fuzzer keeps to
  // the default size and samples, which exercise the same code.
  if (target.find("render") != std::string_view::npos &&
      (target.find("size") != std::string_view::npos ||
       target.find("spp") != std::string_view::npos))
    return 0;
  Api::RawHeaders headers{{"host", "127.0.0.1:8765"}};
  while (!input.empty()) {
    const std::string_view line = next_line(input);
    const std::size_t colon = line.find(':');
    if (colon == std::string_view::npos) continue;
    std::string_view value = line.substr(colon + 1);
    while (!value.empty() && value.front() == ' ') value.remove_prefix(1);
    headers.emplace_back(line.substr(0, colon), value);  // repeated ones too (a 400)
  }
  const Response r = api().handle_target(method, target, headers);
  if (r.status < 200 || r.status >= 600) std::abort();
  if (r.status >= 400 && r.status < 500 && (r.body.empty() || r.body.front() != '{')) std::abort();
  return 0;
}
