#include "halfback/view/api.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <new>
#include <optional>
#include <random>
#include <stdexcept>

#include "catalog.hpp"
#include "halfback/util/format_error.hpp"
#include "handlers.hpp"
#include "json.hpp"
#include "web_assets.hpp"

namespace halfback::view {

const std::string* Request::param(std::string_view key) const {
  for (const auto& [k, v] : query)
    if (k == key) return &v;
  return nullptr;
}

const std::string* Request::header(std::string_view name) const {
  const auto it = headers.find(std::string(name));
  return it == headers.end() ? nullptr : &it->second;
}

std::string random_token() {
  std::random_device device;
  std::string token;
  for (int i = 0; i < 4; ++i) token += fmt::format("{:08x}", std::uint32_t(device()));
  return token;
}

namespace {

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::string decode_component(std::string_view s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    char c = s[i];
    if (c == '+') {
      c = ' ';
    } else if (c == '%') {
      const int hi = i + 2 < s.size() ? hex_digit(s[i + 1]) : -1;
      const int lo = i + 2 < s.size() ? hex_digit(s[i + 2]) : -1;
      if (hi < 0 || lo < 0) throw std::invalid_argument("malformed percent escape in the query");
      c = char(hi * 16 + lo);
      i += 2;
    }
    if (c == '\0') throw std::invalid_argument("NUL byte in the query");
    out += c;
  }
  return out;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> parse_query(std::string_view query) {
  std::vector<std::pair<std::string, std::string>> out;
  std::size_t start = 0;
  while (start <= query.size()) {
    std::size_t amp = query.find('&', start);
    if (amp == std::string_view::npos) amp = query.size();
    const std::string_view part = query.substr(start, amp - start);
    if (!part.empty()) {
      const std::size_t eq = part.find('=');
      out.emplace_back(decode_component(part.substr(0, eq)),
                       eq == std::string_view::npos ? "" : decode_component(part.substr(eq + 1)));
    }
    start = amp + 1;
  }
  return out;
}

struct Api::State {
  ApiConfig config;
  Catalog catalog;
  std::atomic<int> fits_running = 0;
  std::atomic<bool> stopping = false;
  explicit State(ApiConfig c)
      : config(std::move(c)), catalog(config.specs, config.roots, config.given) {}
};

Api::Api(ApiConfig config) : state_(std::make_unique<State>(std::move(config))) {}
Api::~Api() = default;

void Api::set_port(int port) {
  state_->config.port = port;
}
void Api::stop() {
  state_->stopping = true;
}

const ApiConfig& Api::config() const {
  return state_->config;
}

void Api::load_specs() const {
  for (std::size_t i = 0; i < state_->config.specs.size(); ++i) {
    try {
      state_->catalog.brdf("arg:" + std::to_string(i));
    } catch (const std::invalid_argument& e) {  // the spec names nothing: a usage error
      throw std::invalid_argument(fmt::format("'{}': {}", state_->config.specs[i], e.what()));
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("'{}': {}", state_->config.specs[i], e.what()));
    }
  }
}

namespace {

Response error(int status, std::string_view message) {
  Response r;
  r.status = status;
  Json body;
  body["error"] = message;
  r.body = json_text(std::move(body));
  return r;
}

// Equal strings, in a time that does not depend on where they differ.
bool same_secret(std::string_view a, std::string_view b) {
  if (a.size() != b.size() || a.empty()) return false;  // the length is no secret
  unsigned diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= unsigned(a[i] ^ b[i]);
  return diff == 0;
}

bool is_ip_literal(std::string_view name) {
  if (name.size() > 2 && name.front() == '[' && name.back() == ']') {
    return std::all_of(name.begin() + 1, name.end() - 1, [](char c) {
      return std::isxdigit((unsigned char)c) || c == ':' || c == '.';
    });
  }
  int dots = 0;
  for (const char c : name) {
    if (c == '.')
      ++dots;
    else if (!std::isdigit((unsigned char)c))
      return false;
  }
  return dots == 3;
}

// Whether a Host header value ("name:port") names this server: the port it is bound to, and a
// name no DNS-rebinding page can have (an IP literal, localhost, or the --host given).
bool accepted_host(std::string_view value, const ApiConfig& c) {
  const std::size_t colon = value.rfind(':');
  if (colon == std::string_view::npos || value.substr(colon + 1) != std::to_string(c.port))
    return false;
  const std::string_view name = value.substr(0, colon);
  if (name.empty()) return false;
  const std::string bound = c.host.find(':') != std::string::npos ? "[" + c.host + "]" : c.host;
  return name == "localhost" || name == bound || is_ip_literal(name);
}

std::string cookie_name(const ApiConfig& c) {
  return fmt::format("halfback_token_{}", c.port);
}

// The token of the request: token= in the query, else the page's cookie.
std::string request_token(const Request& r, const ApiConfig& c) {
  if (const std::string* t = r.param("token")) return *t;
  const std::string* cookies = r.header("cookie");
  if (!cookies) return {};
  const std::string prefix = cookie_name(c) + "=";
  std::string_view s = *cookies;
  while (!s.empty()) {
    const std::size_t semi = s.find(';');
    std::string_view item = s.substr(0, semi);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    if (item.substr(0, prefix.size()) == prefix) return std::string(item.substr(prefix.size()));
    if (semi == std::string_view::npos) break;
    s.remove_prefix(semi + 1);
  }
  return {};
}

// The refusal of a request that is not for this server, or nothing.
std::optional<Response> refusal(const Request& r, const ApiConfig& c) {
  if (r.method != "GET" && r.method != "HEAD") {
    Response res =
        error(405, fmt::format("method {} is not allowed (GET only)", r.method.substr(0, 16)));
    res.headers.emplace_back("Allow", "GET, HEAD");
    return res;
  }
  const std::string* host = r.header("host");
  if (!host || !accepted_host(*host, c))
    return error(403, fmt::format("Host '{}' is not this server (expected 127.0.0.1:{} or "
                                  "localhost:{})",
                                  host ? host->substr(0, 128) : "", c.port, c.port));
  if (const std::string* origin = r.header("origin")) {
    const bool own = origin->substr(0, 7) == "http://" && accepted_host(origin->substr(7), c);
    if (!own)
      return error(403,
                   fmt::format("cross-origin request from '{}' refused", origin->substr(0, 128)));
  }
  if (!same_secret(request_token(r, c), c.token))
    return error(403, "missing or wrong token: open the URL that `halfback view` printed");
  return std::nullopt;
}

std::string_view content_type_of(std::string_view name) {
  const auto ends = [&](std::string_view e) {
    return name.size() >= e.size() && name.substr(name.size() - e.size()) == e;
  };
  if (ends(".html")) return "text/html; charset=utf-8";
  if (ends(".js")) return "text/javascript; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  if (ends(".svg")) return "image/svg+xml";
  return "application/octet-stream";
}

std::optional<Response> asset(std::string_view name) {
  for (const WebAsset& a : web_assets()) {
    if (a.name != name) continue;
    Response r;
    r.content_type = std::string(content_type_of(name));
    r.body.assign(reinterpret_cast<const char*>(a.bytes.data()), a.bytes.size());
    return r;
  }
  return std::nullopt;
}

Response route(const Catalog& catalog, const Request& r, const ApiConfig& c,
               std::atomic<int>& fits_running, const std::atomic<bool>& stopping) {
  const std::string& p = r.path;
  const Budget budget(c.compute_seconds, r.abandoned, stopping);
  if (p == "/" || p == "/index.html") {
    Response res = *asset("index.html");
    if (r.param("token"))  // later loads (the modules, a reload) carry the cookie instead
      res.headers.emplace_back(
          "Set-Cookie", cookie_name(c) + "=" + c.token + "; Path=/; HttpOnly; SameSite=Strict");
    return res;
  }
  if (p.rfind("/static/", 0) == 0)
    if (auto a = asset(std::string_view(p).substr(8))) return *a;
  if (p == "/api/info") return info_response(catalog);
  if (p == "/api/brdf") return brdf_response(catalog, r);
  if (p == "/api/slices") return slices_response(catalog, r, c.threads, budget);
  if (p == "/api/hemisphere") return hemisphere_response(catalog, r, c.threads, budget);
  if (p == "/api/polar") return polar_response(catalog, r);
  if (p == "/api/albedo") return albedo_response(catalog, r, c.threads, budget);
  if (p == "/api/point") return point_response(catalog, r);
  if (p == "/api/render") return render_response(catalog, r, c.threads, budget);
  if (p == "/api/pointlight") return point_light_response(catalog, r, c.threads, budget);
  if (p == "/api/mesh") return mesh_response(catalog, r, c.threads, budget);
  if (p == "/api/fit") return fit_response(catalog, r, c.threads, fits_running, budget);
  return error(404, fmt::format("no such resource '{}'", p.substr(0, 128)));
}

}  // namespace

Response Api::handle(const Request& request) const {
  const ApiConfig& c = state_->config;
  Response res;
  try {
    std::size_t target = request.path.size();
    for (const auto& [k, v] : request.query) target += k.size() + v.size() + 2;
    if (target > kMaxTargetBytes)
      res = error(414, fmt::format("request target longer than {} bytes", kMaxTargetBytes));
    else if (auto refused = refusal(request, c))
      res = std::move(*refused);
    else if (state_->stopping)
      res = error(503, "the server is stopping");
    else
      res = route(state_->catalog, request, c, state_->fits_running, state_->stopping);
  } catch (const RequestError& e) {
    res = error(e.status(), e.what());
  } catch (const FormatError& e) {
    res = error(400, e.what());
  } catch (const std::invalid_argument& e) {
    res = error(400, e.what());
  } catch (const std::out_of_range& e) {
    res = error(400, e.what());
  } catch (const std::bad_alloc&) {
    res = error(503, "out of memory for this request");
  } catch (const std::exception& e) {
    res = error(500, e.what());
  }
  // The token travels in the page's URL: it must not leak through a Referer, nor be cached.
  res.headers.emplace_back("Referrer-Policy", "no-referrer");
  res.headers.emplace_back("Cache-Control", "no-store");
  res.headers.emplace_back("X-Content-Type-Options", "nosniff");
  res.headers.emplace_back("Content-Security-Policy",
                           "default-src 'self'; img-src 'self' data: blob:; "
                           "connect-src 'self'; frame-ancestors 'none'");
  return res;
}

Response Api::handle_target(std::string method, std::string_view target, const RawHeaders& headers,
                            std::function<bool()> abandoned) const {
  Request request;
  request.method = std::move(method);
  request.abandoned = std::move(abandoned);
  for (const auto& [name, value] : headers) {
    std::string lower = name;
    std::ranges::transform(lower, lower.begin(),
                           [](unsigned char c) { return char(std::tolower(c)); });
    const bool checked = lower == "host" || lower == "origin" || lower == "cookie";
    if (!request.headers.emplace(lower, value).second && checked)
      return error(400, fmt::format("the {} header is given more than once", lower));
  }
  const std::size_t mark = target.find('?');
  request.path = std::string(target.substr(0, mark));
  if (target.size() > kMaxTargetBytes) {
    request.path = std::string(kMaxTargetBytes + 1, '/');  // refused by handle() with a 414
  } else if (mark != std::string_view::npos) {
    try {
      request.query = parse_query(target.substr(mark + 1));
    } catch (const std::invalid_argument& e) {
      return error(400, e.what());
    }
  }
  return handle(request);
}

}  // namespace halfback::view
