// A parameterization defined here, in a test, and registered at run time: it gets the batch
// conversions, resampling, figure axes and slices, and a tabulated sampler without any other file
// knowing it (docs/architecture.md: a parameterization in a test). Its own maps are checked like
// the built-in ones: round trips, the Jacobian (1 in these coordinates: dω = d(cos θ) dφ) and the
// domain.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "halfback/brdf/resample.hpp"
#include "halfback/core/batch.hpp"
#include "halfback/core/space.hpp"
#include "halfback/figure/coordinates.hpp"
#include "halfback/figure/slices.hpp"
#include "halfback/models/analytic.hpp"
#include "halfback/render/brdf_sampler.hpp"

namespace halfback {
namespace {

// (cos θi, φi, cos θo, φo): spherical with the elevations as cosines. Written only for scalar
// lanes (float, double), as a user's parameterization would be.
struct CosineSpherical {
  static constexpr std::string_view name = "test-cosine-spherical";
  static constexpr std::string_view summary = "(cos θi, φi, cos θo, φo), a test fixture";
  static constexpr Axis kCosI{"cos_theta_i", "cos θ_i", AxisKind::length, 0, 1, 0.1};
  static constexpr Axis kCosO{"cos_theta_o", "cos θ_o", AxisKind::length, 0, 1, 0.1};
  static constexpr std::array<Axis, 4> axes{kCosI, azimuth_axis("phi_i", "φ_i"), kCosO,
                                            azimuth_axis("phi_o", "φ_o")};
  static constexpr std::array<Axis, 3> iso_axes{kCosI, kCosO, azimuth_axis("dphi", "φ_o − φ_i")};
  using SamplerChart = SphericalChart;

  template <class T>
  static Tuple4<T> angles(const Tuple4<T>& q) {
    return {std::acos(q[0]), q[1], std::acos(q[2]), q[3]};
  }
  template <class T>
  static Tuple4<T> cosines(const Tuple4<T>& a) {
    return {std::cos(a[0]), a[1], std::cos(a[2]), a[3]};
  }
  template <class T>
  static Tuple4<T> forward(const DirPair<T>& p) {
    const Tuple4<T> s = Spherical::forward(p);
    return {p.wi.z, s[1], p.wo.z, s[3]};
  }
  template <class T>
  static Solved<T> inverse_raw(const Tuple4<T>& q) {
    Solved<T> r = Spherical::inverse_raw(angles(q));
    r.in_domain = r.in_domain && q[0] >= 0 && q[0] <= 1 && q[2] >= 0 && q[2] <= 1;
    return r;
  }
  template <class T>
  static T jacobian(const Tuple4<T>&) {
    return T(1);
  }
  template <class T>
  static Tuple3<T> forward_iso(const DirPair<T>& p) {
    return {p.wi.z, p.wo.z, Spherical::forward_iso(p)[2]};
  }
  template <class T>
  static Tuple4<T> lift_iso(const Tuple3<T>& q) {
    return {q[0], T(0), q[1], q[2]};
  }
  template <class T>
  static Solved<T> inverse_iso_raw(const Tuple3<T>& q) {
    Solved<T> r = Spherical::inverse_iso_raw(Tuple3<T>{std::acos(q[0]), std::acos(q[1]), q[2]});
    r.in_domain = r.in_domain && q[0] >= 0 && q[0] <= 1 && q[1] >= 0 && q[1] <= 1;
    return r;
  }
  template <class T>
  static Tuple4<T> reciprocal(const Tuple4<T>& q) {
    return {q[2], q[3], q[0], q[1]};
  }
  template <class T>
  static Tuple4<T> mirror(const Tuple4<T>& q) {
    return cosines(Spherical::mirror(angles(q)));
  }
  template <class T>
  static Tuple3<T> reciprocal_iso(const Tuple3<T>& q) {
    return {q[1], q[0], Spherical::reciprocal_iso(q)[2]};
  }
  template <class T>
  static Tuple3<T> mirror_iso(const Tuple3<T>& q) {
    return {q[0], q[1], Spherical::mirror_iso(q)[2]};
  }
};
static_assert(Parameterization<CosineSpherical>);

// Uniform pairs in solid angle.
std::vector<DirPair<double>> random_pairs(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  auto w = [&] {
    const double z = u(rng), phi = 2 * std::numbers::pi * u(rng), r = std::sqrt(1 - z * z);
    return Vec3<double>{r * std::cos(phi), r * std::sin(phi), z};
  };
  std::vector<DirPair<double>> pairs(n);
  for (auto& p : pairs) p = {w(), w()};
  return pairs;
}

Space toy_space() {
  static const Space s = register_parameterization<CosineSpherical>();
  return s;
}

TEST(RegisteredParam, IsNamedListedAndDescribed) {
  const Space s = toy_space();
  EXPECT_FALSE(s.has_kernels());
  EXPECT_EQ(name_of(s), "test-cosine-spherical");
  EXPECT_EQ(space_from_name("test-cosine-spherical"), s);
  const std::vector<Space> all = parameterizations();
  EXPECT_EQ(all.back(), s);
  EXPECT_NE(space_names().find("test-cosine-spherical"), std::string::npos);
  const auto cols = column_names({s, true});
  EXPECT_EQ(std::vector<std::string_view>(cols.begin(), cols.end()),
            (std::vector<std::string_view>{"cos_theta_i", "cos_theta_o", "dphi"}));
  EXPECT_THROW(register_parameterization<Spherical>(), std::invalid_argument);  // a built-in name
}

template <class T>
void check_conversions() {
  const Space s = toy_space();
  const std::vector<DirPair<double>> pairs = random_pairs(5000, 11);
  const std::size_t n = pairs.size();
  for (bool iso : {false, true}) {
    SCOPED_TRACE(iso ? "isotropic" : "4D");
    const Form form{s, iso};
    const std::size_t d = dimension(form);
    std::vector<T> dirs(6 * n), q(d * n), back(6 * n), jac(n);
    for (std::size_t i = 0; i < n; ++i) {
      const auto& p = pairs[i];
      const double v[6] = {p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z};
      for (int c = 0; c < 6; ++c) dirs[6 * i + std::size_t(c)] = T(v[c]);
    }
    auto rows = [](T* data, std::size_t dim) {
      std::vector<Column<T>> c(dim);
      for (std::size_t k = 0; k < dim; ++k) c[k] = {data + k, std::ptrdiff_t(dim)};
      return c;
    };
    auto crows = [](const T* data, std::size_t dim) {
      std::vector<ConstColumn<T>> c(dim);
      for (std::size_t k = 0; k < dim; ++k) c[k] = {data + k, std::ptrdiff_t(dim)};
      return c;
    };
    std::vector<std::uint8_t> valid(n);
    const auto qc = rows(q.data(), d);
    convert<T>({Space::dirs}, form, crows(dirs.data(), 6), n, {qc, {jac.data(), 1}, valid.data()});
    const auto bc = rows(back.data(), 6);
    convert<T>(form, {Space::dirs}, crows(q.data(), d), n, {bc, {}, nullptr});
    const double tol = std::is_same_v<T, float> ? 2e-3 : 1e-7;  // acos near θ = 0
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(valid[i], 1);
      EXPECT_NEAR(double(q[d * i]), pairs[i].wi.z, 1e-6);  // cos θi
      EXPECT_NEAR(double(jac[i]), iso ? 2 * std::numbers::pi : 1.0, 1e-6);
      // 4D: the same pair; isotropic: the same pair up to a rotation about n.
      const DirPair<double> b{
          {double(back[6 * i]), double(back[6 * i + 1]), double(back[6 * i + 2])},
          {double(back[6 * i + 3]), double(back[6 * i + 4]), double(back[6 * i + 5])}};
      EXPECT_NEAR(b.wi.z, pairs[i].wi.z, tol);
      EXPECT_NEAR(b.wo.z, pairs[i].wo.z, tol);
      EXPECT_NEAR(detail::dot(b.wi, b.wo), detail::dot(pairs[i].wi, pairs[i].wo), tol);
      if (!iso) {
        EXPECT_NEAR(b.wi.x, pairs[i].wi.x, tol);
      }
    }
  }
  // Outside the domain: NaN and a zero mask.
  const T bad[4] = {T(1.5), T(0), T(0.5), T(0)};
  T out[6];
  EXPECT_FALSE(convert_one<T>({s, false}, {Space::dirs}, bad, out));
  EXPECT_TRUE(std::isnan(out[0]));
}

TEST(RegisteredParam, ConvertsBothWaysWithItsMeasure) {
  check_conversions<double>();
  check_conversions<float>();
}

TEST(RegisteredParam, ResamplesOnItsOwnAxes) {
  const GridSpec g = default_grid(toy_space(), GridKind::isotropic, {6, 6, 8});
  EXPECT_EQ(g.axes[0].name, "cos_theta_i");
  EXPECT_EQ(g.axes[2].hi, 2 * std::numbers::pi);
  const auto lambert = std::make_shared<models::Lambert>(Rgb{0.5, 0.5, 0.5});
  const ResampledTable t = resample(*lambert, g, {1});
  EXPECT_EQ(t.valid_count(), g.points());  // the box is the domain
  for (std::size_t k = 0; k < g.points(); ++k)
    EXPECT_NEAR(t.rgb[3 * k], 0.5 / std::numbers::pi, 1e-12);
}

TEST(RegisteredParam, FiguresLabelItsAxesAndSampleItsSlices) {
  const auto coords = figure::iso_coordinates(toy_space());
  EXPECT_EQ(coords[0].label, "cos θ_i");
  EXPECT_FALSE(coords[0].angle);
  EXPECT_EQ(figure::relative_azimuth_label(toy_space()), "φ_o − φ_i");
  const figure::SliceSample s =
      figure::sample_slice(toy_space(), 1.0, figure::Grid::pixel_centres(16, 16, 0, 1, 0, 1), 1);
  for (std::size_t k = 0; k < s.valid.size(); ++k) {
    ASSERT_EQ(s.valid[k], 1);
    EXPECT_NEAR(s.pairs[k].wi.z, s.grid.x(k % 16), 1e-12);
  }
}

TEST(RegisteredParam, TabulatedSamplerUsesItsChart) {
  models::MicrofacetParams p;
  p.alpha_x = p.alpha_y = 0.3;
  const models::Microfacet ggx(p);
  render::TabulationOptions o;
  o.param = toy_space();
  o.radial = 16;
  o.azimuthal = 32;
  o.theta_slices = 8;
  const render::TabulatedSampler t(ggx, o);
  EXPECT_NE(t.describe_sampling().find("test-cosine-spherical"), std::string::npos);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  const Vec3<double> wo{0.5, 0, std::sqrt(0.75)};
  int drawn = 0;
  for (int k = 0; k < 2000; ++k) {
    const BrdfSample x = t.sample(wo, u(rng), u(rng));
    if (!(x.pdf > 0)) continue;
    ++drawn;
    EXPECT_NEAR(x.pdf, t.pdf(wo, x.wi), 1e-9 * x.pdf);
  }
  EXPECT_GT(drawn, 1500);
}

}  // namespace
}  // namespace halfback
