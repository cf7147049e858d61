// The OBJ reader and the mesh renderer (render/mesh.hpp): a fine sphere mesh against the analytic
// sphere of render_point_light, the white furnace under a constant environment, and the reader's
// refusals.
#include "halfback/render/mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "halfback/loader/load.hpp"
#include "halfback/render/renderer.hpp"
#include "halfback/util/format_error.hpp"

namespace halfback::render {
namespace {

// A latitude-longitude sphere of radius 1 with its exact normals, faces counter-clockwise from
// outside (quads, which the reader splits).
std::string sphere_obj(int nu, int nv) {
  std::string s;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double v = std::numbers::pi * j / nv, u = 2 * std::numbers::pi * i / nu;
      const double x = std::sin(v) * std::cos(u), y = std::cos(v), z = std::sin(v) * std::sin(u);
      s += "v " + std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) + "\n";
      s += "vn " + std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) + "\n";
    }
  const auto at = [&](int j, int i) { return std::to_string(1 + j * nu + (i % nu)); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const std::string a = at(j, i), b = at(j, i + 1), c = at(j + 1, i + 1), d = at(j + 1, i);
      // y up, u turning from +x to +z: (a, b, c, d) faces outwards.
      s +=
          "f " + a + "//" + a + " " + b + "//" + b + " " + c + "//" + c + " " + d + "//" + d + "\n";
    }
  return s;
}

TEST(Mesh, ReadsVerticesNormalsAndFans) {
  const Mesh m = parse_obj(
      "# a square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 -1//1\n", "sq");
  ASSERT_EQ(m.positions.size(), 4u);
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.triangles[1][2], 3u);  // -1: the last vertex
  for (const auto& n : m.normals) EXPECT_DOUBLE_EQ(n.z, 1.0);
  // Without vn: the faces' normal (counter-clockwise: +z).
  const Mesh t = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "t");
  EXPECT_NEAR(t.normals[0].z, 1.0, 1e-12);
}

TEST(Mesh, RefusesMalformedTextNamingTheLine) {
  const auto message = [](const std::string& text) {
    try {
      parse_obj(text, "bad.obj");
    } catch (const FormatError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("v 0 0 0\nv 1 x 0\n").find("line 2"), std::string::npos);
  EXPECT_NE(message("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n").find("vertex index 4"),
            std::string::npos);
  EXPECT_NE(message("v 0 0 0\nv 1 0 0\nf 1 2\n").find("at least 3"), std::string::npos);
  EXPECT_NE(message("v 0 0 0\n").find("no face"), std::string::npos);
  EXPECT_NE(message("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//7 2 3\n").find("normal index 7"),
            std::string::npos);
  EXPECT_NE(message("v 0 0 nan\n").find("finite"), std::string::npos);
}

// The fine sphere mesh under a point light is the analytic sphere of render_point_light, within
// the tessellation's error, wherever both cover the pixel (the silhouette aside).
TEST(Mesh, SphereMeshMatchesTheAnalyticSphere) {
  const Mesh sphere = parse_obj(sphere_obj(192, 96), "sphere");
  const BrdfPtr brdf = load_brdf("lambert:albedo=0.8+ggx:alpha=0.3");
  const Vec3<double> light{0.5, 0.3, std::sqrt(1 - 0.34)};
  MeshSettings ms;
  ms.width = ms.height = 64;
  ms.supersample = 1;
  const Image mesh = render_mesh_point_light(*brdf, sphere, light, ms);
  RenderSettings rs;
  rs.width = rs.height = 64;
  rs.spp = 1;
  const RenderResult ref = render_point_light(*brdf, light, rs);
  // The error of the interpolated normals is O(1e-4) rad: relative to the image's brightest
  // pixel (near the terminator ρ cos θi is small and its relative error large).
  double worst = 0, brightest = 0, compared = 0;
  for (const float v : ref.image.rgb) brightest = std::max(brightest, double(v));
  for (int y = 1; y < 63; ++y)
    for (int x = 1; x < 63; ++x) {
      const double dx = (x + 0.5) / 32 - 1, dy = (y + 0.5) / 32 - 1;
      if (std::hypot(dx, dy) * 1.25 > 0.95) continue;  // away from the silhouette
      for (int c = 0; c < 3; ++c) {
        const std::size_t k = 3 * (std::size_t(y) * 64 + std::size_t(x)) + std::size_t(c);
        worst = std::max(worst, std::abs(double(mesh.rgb[k]) - ref.image.rgb[k]));
        compared += 1;
      }
    }
  EXPECT_GT(compared, 3000);
  EXPECT_GT(brightest, 0.1);
  EXPECT_LT(worst / brightest, 2e-3);  // the flat interpolation of 192 × 96 quads
}

// A white furnace: Lambert of albedo a under a constant environment L reflects a L everywhere;
// the MIS estimator's mean over the covered pixels is that, within its noise.
TEST(Mesh, ConstantEnvironmentGivesTheAlbedo) {
  const Mesh sphere = parse_obj(sphere_obj(48, 24), "sphere");
  const BrdfPtr brdf = load_brdf("lambert:albedo=0.6");
  const EnvMap env = EnvMap::constant(Rgb{1, 1, 1});
  MeshSettings ms;
  ms.width = ms.height = 48;
  ms.spp = 8;
  ms.yaw_deg = 30;
  ms.pitch_deg = 20;
  const Image image = render_mesh_environment(*brdf, env, sphere, ms);
  const auto covered = mesh_coverage(sphere, ms);
  double sum = 0;
  int n = 0;
  for (std::size_t p = 0; p < covered.size(); ++p)
    if (covered[p]) {
      const double dx = (double(p % 48) + 0.5) / 24 - 1, dy = (double(p / 48) + 0.5) / 24 - 1;
      if (std::hypot(dx, dy) * 1.25 > 0.95) continue;  // pixels wholly inside the disk
      sum += image.rgb[3 * p + 1];
      ++n;
    }
  ASSERT_GT(n, 800);
  EXPECT_NEAR(sum / n, 0.6, 0.01);
  // Another seed: another estimate of the same image.
  ms.seed = 2;
  const Image other = render_mesh_environment(*brdf, env, sphere, ms);
  EXPECT_NE(other.rgb, image.rgb);
}

// MeshSettings::cancelled stops a render within it: polled before each row of pixels (and every
// 4096 triangles), the render throws once it answers true, having shaded no row after that; a
// poll that never answers true leaves the image as it is without one.
TEST(Mesh, CancelledStopsTheRenderWithinAnImage) {
  const Mesh sphere = parse_obj(sphere_obj(48, 24), "sphere");
  const BrdfPtr brdf = load_brdf("lambert:albedo=0.6");
  const EnvMap env = EnvMap::constant(Rgb{1, 1, 1});
  MeshSettings ms;
  ms.width = ms.height = 64;
  ms.threads = 1;
  const Image whole = render_mesh_point_light(*brdf, sphere, {0, 0, 1}, ms);
  int polls = 0;
  ms.cancelled = [&polls] { return ++polls > 10; };  // the rasterization's poll, then rows
  try {
    render_mesh_point_light(*brdf, sphere, {0, 0, 1}, ms);
    ADD_FAILURE() << "not cancelled";
  } catch (const MeshRenderCancelled& e) {
    EXPECT_NE(std::string(e.what()).find("of 64 rows"), std::string::npos) << e.what();
  }
  EXPECT_EQ(polls, 11);  // the render stopped at the first poll that said so
  polls = 0;
  EXPECT_THROW(render_mesh_environment(*brdf, env, sphere, ms), MeshRenderCancelled);
  EXPECT_EQ(polls, 11);
  ms.cancelled = [] { return false; };
  EXPECT_EQ(render_mesh_point_light(*brdf, sphere, {0, 0, 1}, ms).rgb, whole.rgb);
  ms.cancelled = [] { return true; };  // at once: in the rasterization
  try {
    render_mesh_point_light(*brdf, sphere, {0, 0, 1}, ms);
    ADD_FAILURE() << "not cancelled";
  } catch (const MeshRenderCancelled& e) {
    EXPECT_NE(std::string(e.what()).find("triangles"), std::string::npos) << e.what();
  }
}

TEST(Mesh, RefusesBadSettings) {
  const Mesh t = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "t");
  const BrdfPtr brdf = load_brdf("lambert");
  MeshSettings s;
  s.supersample = 9;
  EXPECT_THROW(render_mesh_point_light(*brdf, t, {0, 0, 1}, s), std::invalid_argument);
  s.supersample = 1;
  EXPECT_THROW(render_mesh_point_light(*brdf, t, {0, 0, 2}, s), std::invalid_argument);
}

}  // namespace
}  // namespace halfback::render
