// The HTTP-free core of `halfback view` (docs/view.md): a request (method, path, query, headers)
// goes in, a response (status, content type, body) comes out. The socket adapter (server.hpp)
// only translates; tests and the fuzzer call Api::handle() directly.
//
// Every request is checked before it is routed (docs/view.md, "Security model"):
//   * the token: `token=` in the query, or the cookie `halfback_token` that the page's first
//     load sets (compared in constant time);
//   * the Host header: the bound host:port, or localhost / 127.0.0.1 / [::1] with the port (a
//     DNS-rebinding page has its own name there);
//   * the Origin header, when present: http:// followed by one of the accepted hosts;
//   * the size of the target (path + query).
// Every refusal and every malformed request is a 4xx response with a JSON {"error": message}
// body; handle() never throws.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace halfback {
class Brdf;
}  // namespace halfback

namespace halfback::view {

// Limits of one request (docs/view.md, "Limits").
inline constexpr std::size_t kMaxTargetBytes = 8192;   // path + query
inline constexpr std::size_t kMaxSpecBytes = 1024;     // one BRDF or environment spec
inline constexpr std::size_t kMaxGridSide = 512;       // slice and hemisphere side
inline constexpr std::size_t kMaxPolarSamples = 2001;  // polar plot samples per curve
// The albedo plot: angles θi (from 0° to 89°) and samples per axis of each estimate (n², as
// `halfback info --albedo-samples`): at the limits 181 × 256² ≈ 12 M evaluations a request.
inline constexpr std::size_t kMaxAlbedoAngles = 181, kMaxAlbedoSamples = 256;
// A fit (/api/fit): at most this many sample pairs (about 1 s for an embedded material, 6 starts),
// at most kMaxFitTermSamples terms × samples (a sum's cost grows with its terms), and one fit at a
// time in the server (a second one is answered 503 while the first runs).
inline constexpr std::size_t kMaxFitSamples = 20000;
inline constexpr std::size_t kMaxFitTermSamples = 4 * kMaxFitSamples;
// The deadline of one request's computation (ApiConfig::compute_seconds): a fit, the fields of a
// slices or albedo request and a render give up past it (503), and as soon as their client leaves
// or the server stops (Request::abandoned, Api::stop).
inline constexpr double kComputeSeconds = 60;
inline constexpr int kMaxRenderSide = 512;             // sphere render side
inline constexpr int kMaxRenderSpp = 64;               // samples per pixel of one pass
inline constexpr std::size_t kMaxBrdfsPerRequest = 8;  // brdf= repeated in /api/point
inline constexpr std::size_t kMaxCachedBrdfs = 32;     // loaded BRDFs kept (least recent dropped)
// A /api/slices answer: at most the bytes of 8 RGB fields of 512² (25 MB, 24 MiB): BRDFs × forms
// × n² × channels × 4 above it is a 400 (the page asks as many BRDFs a request as fit
// within it: one request while a slider moves).
inline constexpr std::size_t kMaxSlicesBytes = 8 * 512 * 512 * 3 * sizeof(float);
// The lit mesh view (/api/mesh): a mesh file under a root of at most this many bytes; the mesh
// of the page when it names none.
inline constexpr std::size_t kMaxMeshBytes = 64u << 20;
inline constexpr std::string_view kEmbeddedMesh = "rounded-cube";
// Parameterizations built for requests (dupuy-jakob:BRDF, never registered): at most this many
// kept (least recent dropped), and named by one request.
inline constexpr std::size_t kMaxCachedForms = 4;

struct Request {
  std::string method = "GET";
  std::string path = "/";
  std::vector<std::pair<std::string, std::string>> query;  // decoded, in order (keys may repeat)
  std::map<std::string, std::string> headers;              // names in lower case
  // Whether the answer is no longer wanted (its client left): polled by long computations, which
  // then give up. Empty: wanted until the computation's deadline.
  std::function<bool()> abandoned;

  // The first value of a query key, or nullptr.
  const std::string* param(std::string_view key) const;
  // The header `name` (lower case), or nullptr.
  const std::string* header(std::string_view name) const;
};

struct Response {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;  // extra headers (Set-Cookie, ...)
};

struct ApiConfig {
  std::string token;               // required on every request (empty: refused always)
  std::string host = "127.0.0.1";  // the bound address, as given to --host
  int port = 0;                    // the bound port (after binding port 0)
  std::vector<std::string> specs;  // the BRDFs named on the command line, in order
  // BRDFs given as objects (a Python callable: halfback.view), by index of `specs`: served as
  // arg:N, the spec only naming it (nullptr, or fewer than `specs`: the spec is loaded).
  std::vector<std::shared_ptr<const Brdf>> given;
  std::vector<std::filesystem::path> roots;  // directories whose files may be loaded
  int threads = 0;                           // as in core/parallel.hpp
  double compute_seconds = kComputeSeconds;  // the deadline of one request's computation
};

// A fresh token: 128 random bits (std::random_device) as 32 hexadecimal digits.
std::string random_token();

// Splits "a=1&b=%20x" into decoded pairs ('+' is a space). Throws std::invalid_argument for a
// malformed percent escape or a NUL byte.
std::vector<std::pair<std::string, std::string>> parse_query(std::string_view query);

class Api {
 public:
  explicit Api(ApiConfig config);
  ~Api();
  Api(const Api&) = delete;
  Api& operator=(const Api&) = delete;

  // Sets the port once the server knows it (port 0 picks one when binding).
  void set_port(int port);
  // The server stops: every computation in progress gives up at its next poll, and every request
  // from now on is answered 503. Thread-safe; for Server::stop().
  void stop();
  const ApiConfig& config() const;
  // Loads every BRDF of config().specs (they are then cached). Throws, the message naming the
  // spec: std::invalid_argument for a spec that names nothing or holds a bad value (load_brdf's),
  // std::runtime_error for a file that cannot be read.
  void load_specs() const;

  // The response to a request; never throws (an internal failure is a 500 with a message).
  Response handle(const Request& request) const;
  // The same for a raw request target "/path?query" (the path is taken as it is, the query
  // decoded by parse_query) and the headers as received (names in any case, in order): what the
  // socket adapter and the fuzzer call. A malformed query is a 400; so is a Host, Origin or
  // Cookie header given twice (which one would the checks read?).
  using RawHeaders = std::vector<std::pair<std::string, std::string>>;
  // `abandoned` becomes the Request's.
  Response handle_target(std::string method, std::string_view target, const RawHeaders& headers,
                         std::function<bool()> abandoned = {}) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace halfback::view
