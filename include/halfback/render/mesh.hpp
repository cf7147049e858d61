// A triangle mesh (read from Wavefront OBJ text) rendered with any BRDF, as the explorer's lit
// mesh view shows it (docs/view.md, "Lit mesh"): under one distant light, evaluated, or under an
// environment, estimated by multiple importance sampling of the BRDF and the environment.
//
// Scene and camera: those of renderer.hpp's orthographic sphere (+y up, the camera on +z looking
// along −z, the image spanning [−1.25, 1.25] vertically), the mesh centred on its bounding box and
// scaled so that its farthest vertex is at distance 1, then turned by `yaw` about +y and `pitch`
// about +x. The shading frame at a point of (interpolated) normal n is renderer.hpp's. Direct
// lighting only, without visibility: a point is lit by every direction above its own horizon, so
// a convex mesh is rendered exactly and a concave one without its shadows.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/render/envmap.hpp"
#include "halfback/render/image.hpp"

namespace halfback::render {

// Bounds of a mesh read from OBJ text.
inline constexpr std::size_t kMaxMeshVertices = 1u << 21;   // 2 M positions (and normals)
inline constexpr std::size_t kMaxMeshTriangles = 1u << 22;  // 4 M triangles after fans

struct Mesh {
  std::vector<Vec3<double>> positions;
  // One unit normal per position: the OBJ's `vn` where every corner of a position names the same
  // one, else the area-weighted mean of its triangles' normals.
  std::vector<Vec3<double>> normals;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // indices into positions, counter-clockwise
};

// Reads OBJ text: `v x y z`, `vn x y z`, `f a b c ...` (corners `v`, `v/vt`, `v//vn` or `v/vt/vn`,
// 1-based, negative counts back from the last; a polygon is split into a fan), other statements
// ignored. Throws FormatError naming `name` and the line for a malformed number or corner, an
// index out of range, a face of fewer than 3 corners, more than the bounds above, or no face.
Mesh parse_obj(std::string_view text, const std::string& name);

struct MeshSettings {
  int width = 256, height = 256;
  int supersample = 2;  // k × k fixed positions per pixel (k in 1…4)
  double yaw_deg = 0, pitch_deg = 0;
  int spp = 4;             // environment: samples per position (each one of the BRDF and one of
                           // the environment, weighted by the balance heuristic)
  std::uint64_t seed = 1;  // environment: the image is a function of the seed
  int threads = 0;
  // Polled before each row of pixels is shaded and every 4096 triangles of the rasterization
  // (may be empty): once it answers true the render stops and throws MeshRenderCancelled.
  std::function<bool()> cancelled;
};

// A mesh render that MeshSettings::cancelled stopped before its image was complete.
class MeshRenderCancelled : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The mesh under a distant light of irradiance 1 from the unit direction `light` in camera space
// (renderer.hpp's render_point_light): each pixel the mean over its positions of
// ρ(ωi, ωo) cos θi, 0 where the light or the camera is below the surface, and the background 0.
// Throws std::invalid_argument for bad settings or light, MeshRenderCancelled when cancelled.
Image render_mesh_point_light(const Brdf& brdf, const Mesh& mesh, const Vec3<double>& light,
                              const MeshSettings& settings);
// The mesh under an environment (its own world frame, renderer.hpp's): each pixel the mean over
// its positions of an estimate of the reflected radiance from settings.spp samples of the BRDF's
// sampler (Brdf::sample, its pdf) and as many of the environment's, combined by the balance
// heuristic; the background 0 (the page draws its own). Passes of other seeds are independent
// estimates: their mean converges to the radiance. Throws as render_mesh_point_light.
Image render_mesh_environment(const Brdf& brdf, const EnvMap& env, const Mesh& mesh,
                              const MeshSettings& settings);

// Which pixels the mesh covers, at the pixels' centres (1) or not (0): row 0 at the top.
std::vector<std::uint8_t> mesh_coverage(const Mesh& mesh, const MeshSettings& settings);

}  // namespace halfback::render
