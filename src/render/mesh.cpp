#include "halfback/render/mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "halfback/core/parallel.hpp"
#include "halfback/util/format_error.hpp"

namespace halfback::render {

namespace {

using V3 = Vec3<double>;
constexpr double kHalfHeight = 1.25;  // renderer.cpp's orthographic view

V3 sub(const V3& a, const V3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
double dot(const V3& a, const V3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
V3 normalize(const V3& v) {
  const double l = std::sqrt(dot(v, v));
  return l > 0 ? V3{v.x / l, v.y / l, v.z / l} : V3{0, 0, 1};
}

// renderer.cpp's shading frame: t along the parallels (normalize(+y × n)), b = n × t.
struct Frame {
  V3 t, b, n;
  V3 to_local(const V3& w) const { return {dot(w, t), dot(w, b), dot(w, n)}; }
  V3 to_world(const V3& w) const {
    return {w.x * t.x + w.y * b.x + w.z * n.x, w.x * t.y + w.y * b.y + w.z * n.y,
            w.x * t.z + w.y * b.z + w.z * n.z};
  }
};
Frame shading_frame(const V3& n) {
  V3 t{n.z, 0, -n.x};
  const double l = std::sqrt(t.x * t.x + t.z * t.z);
  t = l > 1e-12 ? V3{t.x / l, 0, t.z / l} : V3{1, 0, 0};
  return {t, cross(n, t), n};
}

// --- OBJ ------------------------------------------------------------------------------------

std::string_view next_token(std::string_view& s) {
  std::size_t a = 0;
  while (a < s.size() && (s[a] == ' ' || s[a] == '\t' || s[a] == '\r')) ++a;
  std::size_t b = a;
  while (b < s.size() && s[b] != ' ' && s[b] != '\t' && s[b] != '\r') ++b;
  const std::string_view token = s.substr(a, b - a);
  s.remove_prefix(b);
  return token;
}

double obj_number(std::string_view token, const std::string& name, std::size_t line) {
  double x = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), x);
  if (token.empty() || ec != std::errc() || ptr != token.data() + token.size() || !std::isfinite(x))
    throw FormatError(name, fmt::format("line {}", line),
                      fmt::format("'{}' is not a finite number", token.substr(0, 32)));
  return x;
}

// A 1-based (or negative, relative) OBJ index into a list of `count`, as a 0-based one.
std::uint32_t obj_index(std::string_view token, std::size_t count, const std::string& name,
                        std::size_t line, const char* what) {
  long long i = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), i);
  if (token.empty() || ec != std::errc() || ptr != token.data() + token.size())
    throw FormatError(name, fmt::format("line {}", line),
                      fmt::format("'{}' is not a {} index", token.substr(0, 32), what));
  const long long n = (long long)count;
  const long long k = i > 0 ? i - 1 : n + i;
  if (i == 0 || k < 0 || k >= n)
    throw FormatError(
        name, fmt::format("line {}", line),
        fmt::format("{} index {} is outside 1…{} (the {}s read so far)", what, i, n, what));
  return std::uint32_t(k);
}

}  // namespace

Mesh parse_obj(std::string_view text, const std::string& name) {
  Mesh mesh;
  std::vector<V3> vn;
  // Per position, the `vn` its corners name (-1: none yet, -2: several or none somewhere).
  std::vector<long long> corner_normal;
  std::size_t line_number = 0;
  while (!text.empty()) {
    ++line_number;
    const std::size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos)
      line = line.substr(0, hash);
    const std::string_view keyword = next_token(line);
    if (keyword == "v" || keyword == "vn") {
      V3 p{};
      p.x = obj_number(next_token(line), name, line_number);
      p.y = obj_number(next_token(line), name, line_number);
      p.z = obj_number(next_token(line), name, line_number);
      auto& list = keyword == "v" ? mesh.positions : vn;
      if (list.size() >= kMaxMeshVertices)
        throw FormatError(name, fmt::format("line {}", line_number),
                          fmt::format("more than {} vertices or normals", kMaxMeshVertices));
      list.push_back(p);
      if (keyword == "v") corner_normal.push_back(-1);
    } else if (keyword == "f") {
      std::vector<std::uint32_t> corners;
      for (std::string_view token; !(token = next_token(line)).empty();) {
        const std::size_t slash = token.find('/');
        corners.push_back(
            obj_index(token.substr(0, slash), mesh.positions.size(), name, line_number, "vertex"));
        long long normal = -2;
        if (slash != std::string_view::npos) {
          const std::size_t second = token.find('/', slash + 1);
          if (second != std::string_view::npos && second + 1 < token.size())
            normal = obj_index(token.substr(second + 1), vn.size(), name, line_number, "normal");
        }
        long long& c = corner_normal[corners.back()];
        c = c == -1 ? normal : (c == normal ? c : -2);
        if (corners.size() > 4096)
          throw FormatError(name, fmt::format("line {}", line_number),
                            "a face of more than 4096 corners");
      }
      if (corners.size() < 3)
        throw FormatError(name, fmt::format("line {}", line_number),
                          fmt::format("a face of {} corner(s): at least 3", corners.size()));
      for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
        if (mesh.triangles.size() >= kMaxMeshTriangles)
          throw FormatError(name, fmt::format("line {}", line_number),
                            fmt::format("more than {} triangles", kMaxMeshTriangles));
        mesh.triangles.push_back({corners[0], corners[k], corners[k + 1]});
      }
    }
  }
  if (mesh.triangles.empty()) throw FormatError(name, "faces", "the OBJ text has no face (f)");
  // Normals: the OBJ's where each position has one, else the area-weighted mean of the faces'.
  std::vector<V3> summed(mesh.positions.size(), V3{0, 0, 0});
  for (const auto& t : mesh.triangles) {
    const V3 n = cross(sub(mesh.positions[t[1]], mesh.positions[t[0]]),
                       sub(mesh.positions[t[2]], mesh.positions[t[0]]));  // length: 2 × area
    for (const std::uint32_t i : t)
      summed[i] = {summed[i].x + n.x, summed[i].y + n.y, summed[i].z + n.z};
  }
  mesh.normals.resize(mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    mesh.normals[i] =
        normalize(corner_normal[i] >= 0 ? vn[std::size_t(corner_normal[i])] : summed[i]);
  return mesh;
}

namespace {

// What the camera sees at each of the k × k positions of each pixel: whether the mesh is there,
// and its interpolated normal (camera space).
struct GBuffer {
  int width = 0, height = 0, k = 1;  // width × height pixels of k × k positions
  std::vector<V3> normal;            // (height·k) × (width·k), row 0 at the top
  std::vector<std::uint8_t> covered;
};

void validate(const MeshSettings& s) {
  if (s.width < 1 || s.height < 1 || s.width > 4096 || s.height > 4096)
    throw std::invalid_argument(
        fmt::format("mesh render: size {} x {} outside 1…4096", s.width, s.height));
  if (s.supersample < 1 || s.supersample > 4)
    throw std::invalid_argument("mesh render: supersample outside 1…4");
  if (s.spp < 1 || s.spp > 1024) throw std::invalid_argument("mesh render: spp outside 1…1024");
  if (!std::isfinite(s.yaw_deg) || !std::isfinite(s.pitch_deg))
    throw std::invalid_argument("mesh render: the mesh's turn must be finite");
}

GBuffer rasterize(const Mesh& mesh, const MeshSettings& s) {
  validate(s);
  if (mesh.positions.empty() || mesh.normals.size() != mesh.positions.size())
    throw std::invalid_argument("mesh render: a mesh without positions or with a normal missing");
  GBuffer g;
  g.width = s.width;
  g.height = s.height;
  g.k = s.supersample;
  const int W = s.width * g.k, H = s.height * g.k;
  g.normal.assign(std::size_t(W) * std::size_t(H), V3{0, 0, 1});
  g.covered.assign(std::size_t(W) * std::size_t(H), 0);
  std::vector<double> depth(std::size_t(W) * std::size_t(H),
                            -std::numeric_limits<double>::infinity());
  // Centre (bounding box) and scale (the farthest vertex at distance 1).
  V3 lo = mesh.positions[0], hi = lo;
  for (const V3& p : mesh.positions) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  const V3 centre{(lo.x + hi.x) / 2, (lo.y + hi.y) / 2, (lo.z + hi.z) / 2};
  double radius = 0;
  for (const V3& p : mesh.positions)
    radius = std::max(radius, std::sqrt(dot(sub(p, centre), sub(p, centre))));
  const double scale = radius > 0 ? 1 / radius : 1;
  const double yaw = s.yaw_deg * std::numbers::pi / 180,
               pitch = s.pitch_deg * std::numbers::pi / 180;
  const double cy = std::cos(yaw), sy = std::sin(yaw), cp = std::cos(pitch), sp = std::sin(pitch);
  const auto turn = [&](const V3& v) {  // yaw about +y, then pitch about +x
    const V3 a{cy * v.x + sy * v.z, v.y, -sy * v.x + cy * v.z};
    return V3{a.x, cp * a.y - sp * a.z, sp * a.y + cp * a.z};
  };
  const double aspect = double(s.width) / s.height;
  std::vector<V3> p(mesh.positions.size()), n(mesh.normals.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const V3 w = turn(sub(mesh.positions[i], centre));
    // Sample-grid coordinates: position (i, j) at its centre (i, j); depth = z (towards the
    // camera).
    p[i] = {((w.x * scale) / (kHalfHeight * aspect) + 1) / 2 * W - 0.5,
            (1 - (w.y * scale) / kHalfHeight) / 2 * H - 0.5, w.z * scale};
    n[i] = turn(mesh.normals[i]);
  }
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    if (i % 4096 == 0 && s.cancelled && s.cancelled())
      throw MeshRenderCancelled(
          fmt::format("mesh render: cancelled after {} of {} triangles", i, mesh.triangles.size()));
    const auto& t = mesh.triangles[i];
    const V3 &a = p[t[0]], &b = p[t[1]], &c = p[t[2]];
    const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (!(std::abs(area) > 1e-300)) continue;
    const int x0 = std::max(0, int(std::ceil(std::min({a.x, b.x, c.x}))));
    const int x1 = std::min(W - 1, int(std::floor(std::max({a.x, b.x, c.x}))));
    const int y0 = std::max(0, int(std::ceil(std::min({a.y, b.y, c.y}))));
    const int y1 = std::min(H - 1, int(std::floor(std::max({a.y, b.y, c.y}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double w0 = ((b.x - x) * (c.y - y) - (b.y - y) * (c.x - x)) / area;
        const double w1 = ((c.x - x) * (a.y - y) - (c.y - y) * (a.x - x)) / area;
        const double w2 = 1 - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        const double z = w0 * a.z + w1 * b.z + w2 * c.z;
        const std::size_t at = std::size_t(y) * std::size_t(W) + std::size_t(x);
        if (z <= depth[at]) continue;
        depth[at] = z;
        const V3 &na = n[t[0]], &nb = n[t[1]], &nc = n[t[2]];
        g.normal[at] =
            normalize({w0 * na.x + w1 * nb.x + w2 * nc.x, w0 * na.y + w1 * nb.y + w2 * nc.y,
                       w0 * na.z + w1 * nb.z + w2 * nc.z});
        g.covered[at] = 1;
      }
  }
  return g;
}

// The pixels of `image`, each the mean over its k × k positions of what `shade_row` adds for a row
// of positions (the row's covered positions, in order) — rows in parallel, `cancelled` (may be
// empty) polled before each row of pixels.
template <class ShadeRow>
Image shade(const GBuffer& g, int threads, const std::function<bool()>& cancelled,
            ShadeRow shade_row) {
  Image image;
  image.width = g.width;
  image.height = g.height;
  image.rgb.assign(3 * std::size_t(g.width) * std::size_t(g.height), 0.0f);
  const int W = g.width * g.k;
  std::atomic<bool> stop{false};
  std::atomic<int> rows{0};
  parallel_for(
      std::size_t(g.height), 1,
      [&](std::size_t begin, std::size_t end) {
        std::vector<Rgb> sum;
        for (std::size_t py = begin; py < end; ++py) {
          if (stop || (cancelled && cancelled())) {
            stop = true;
            return;
          }
          sum.assign(std::size_t(g.width), Rgb{});
          for (int j = 0; j < g.k; ++j) {
            const std::size_t row = (py * std::size_t(g.k) + std::size_t(j)) * std::size_t(W);
            shade_row(row, W, [&](int x, const Rgb& value) { sum[std::size_t(x / g.k)] += value; });
          }
          const double inv = 1.0 / (g.k * g.k);
          for (int px = 0; px < g.width; ++px) {
            float* out = &image.rgb[3 * (py * std::size_t(g.width) + std::size_t(px))];
            out[0] = float(sum[std::size_t(px)].r * inv);
            out[1] = float(sum[std::size_t(px)].g * inv);
            out[2] = float(sum[std::size_t(px)].b * inv);
          }
          ++rows;
        }
      },
      threads);
  if (stop)
    throw MeshRenderCancelled(
        fmt::format("mesh render: cancelled after {} of {} rows", rows.load(), g.height));
  return image;
}

// splitmix64: the environment estimator's numbers, a function of (seed, position, sample).
double uniform(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  return double(z >> 11) * 0x1.0p-53;
}

}  // namespace

std::vector<std::uint8_t> mesh_coverage(const Mesh& mesh, const MeshSettings& settings) {
  MeshSettings s = settings;
  s.supersample = 1;
  return rasterize(mesh, s).covered;
}

Image render_mesh_point_light(const Brdf& brdf, const Mesh& mesh, const Vec3<double>& light,
                              const MeshSettings& settings) {
  const double length = std::sqrt(dot(light, light));
  if (!std::isfinite(length) || std::abs(length - 1) > 1e-6)
    throw std::invalid_argument("mesh render: the light's direction must be a finite unit vector");
  const GBuffer g = rasterize(mesh, settings);
  const V3 wo{0, 0, 1};
  return shade(g, settings.threads, settings.cancelled,
               [&](std::size_t row, int W, const auto& add) {
                 std::vector<DirPair<double>> pairs;
                 std::vector<int> xs;
                 for (int x = 0; x < W; ++x) {
                   if (!g.covered[row + std::size_t(x)]) continue;
                   const Frame f = shading_frame(g.normal[row + std::size_t(x)]);
                   const DirPair<double> pair{f.to_local(light), f.to_local(wo)};
                   if (!(pair.wi.z > 0 && pair.wo.z > 0)) continue;
                   pairs.push_back(pair);
                   xs.push_back(x);
                 }
                 std::vector<Rgb> rho(pairs.size());
                 brdf.eval_batch(pairs, rho);
                 for (std::size_t i = 0; i < pairs.size(); ++i) add(xs[i], rho[i] * pairs[i].wi.z);
               });
}

Image render_mesh_environment(const Brdf& brdf, const EnvMap& env, const Mesh& mesh,
                              const MeshSettings& settings) {
  const GBuffer g = rasterize(mesh, settings);
  const V3 wo{0, 0, 1};
  const int spp = settings.spp;
  return shade(
      g, settings.threads, settings.cancelled, [&](std::size_t row, int W, const auto& add) {
        // Every sample of the row's positions, then one batch of ρ.
        std::vector<DirPair<double>> pairs;
        std::vector<Rgb> weight;  // L × MIS weight / pdf (× 1/spp)
        std::vector<int> xs;
        for (int x = 0; x < W; ++x) {
          const std::size_t at = row + std::size_t(x);
          if (!g.covered[at]) continue;
          const Frame f = shading_frame(g.normal[at]);
          const V3 o = f.to_local(wo);
          if (!(o.z > 0)) continue;
          std::uint64_t state = (settings.seed * 0x2545f4914f6cdd1dull) ^ (std::uint64_t(at) << 1);
          for (int k = 0; k < spp; ++k) {
            // A sample of the BRDF's sampler.
            const BrdfSample b = brdf.sample(o, uniform(state), uniform(state));
            if (b.pdf > 0 && b.wi.z > 0 && std::isfinite(b.pdf)) {
              const EnvMap::Lookup l = env.lookup(f.to_world(b.wi));
              const double w = b.pdf / (b.pdf + l.pdf);
              pairs.push_back({b.wi, o});
              weight.push_back(l.radiance * (w / b.pdf / spp));
              xs.push_back(x);
            }
            // A sample of the environment.
            const EnvMap::Sample e = env.sample(uniform(state), uniform(state));
            if (e.pdf > 0) {
              const V3 i = f.to_local(e.dir);
              if (i.z > 0) {
                const double pb = brdf.pdf(o, i);
                const double w = e.pdf / (e.pdf + pb);
                pairs.push_back({i, o});
                weight.push_back(e.radiance * (w / e.pdf / spp));
                xs.push_back(x);
              }
            }
          }
        }
        std::vector<Rgb> rho(pairs.size());
        brdf.eval_batch(pairs, rho);
        for (std::size_t i = 0; i < pairs.size(); ++i) {
          const Rgb v = rho[i] * pairs[i].wi.z;
          add(xs[i], Rgb{v.r * weight[i].r, v.g * weight[i].g, v.b * weight[i].b});
        }
      });
}

}  // namespace halfback::render
