// HalfDiff's forward map against an independent long double reference at every scale of
// ωi + ωo: the kernel computes D = 2 rxy len d = 8‖h̄‖ ‖h‖ d (docs/math.md §2.2) and rescales by
// powers of two where that would underflow (ĥ within ~1e-145 rad of n, or h ≈ 0).
// The pairs below are built so that the sums are exactly tiny: ωi + ωo = (t1 + t2, 0, z1 + z2).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/batch_engine.hpp"
#include "halfback/core/batch.hpp"
#include "halfback/core/param.hpp"
#include "support/test_util.hpp"

namespace halfback {
namespace {

using LD = long double;
constexpr LD kTwoPiL = 6.283185307179586476925286766559L;

// The azimuth convention of param.hpp: in [0, 2π), 0 for the zero vector.
LD azimuth(LD y, LD x) {
  if (x == 0 && y == 0) return 0;
  const LD a = std::atan2(y, x);
  return a < 0 ? a + kTwoPiL : a;
}

struct Reference {
  std::array<LD, 4> q;
  LD theta_h_condition;  // 1, or where the clamp acts (or nearly), |d| / ‖(dx, dz)‖
};

// The textbook map in long double (whose exponent range makes every square here normal), on the
// same symmetric d = (R k)_xy + ‖h‖ n and the same clamp of θh as the kernel.
template <class T>
Reference reference(const DirPair<T>& p) {
  const LD sx = LD(p.wi.x) + p.wo.x, sy = LD(p.wi.y) + p.wo.y, sz = LD(p.wi.z) + p.wo.z;
  const LD kx = (LD(p.wi.x) - p.wo.x) / 2, ky = (LD(p.wi.y) - p.wo.y) / 2,
           kz = (LD(p.wi.z) - p.wo.z) / 2;
  const LD rxy = std::hypot(sx, sy), len = std::hypot(rxy, sz);
  const LD cx = rxy == 0 ? 1 : sx / rxy, cy = rxy == 0 ? 0 : sy / rxy;
  const LD a = cx * kx + cy * ky, b = cx * ky - cy * kx;
  LD dx = a, dy = b, dz = 0, theta_h = 0;  // h = 0: ĥ := n
  if (len > 0) {
    dx = (sz * a - rxy * kz) / len;
    dz = len / 2;
    theta_h = std::atan2(rxy, sz);
  }
  // The bound of the clamp is the angle of (|dx|, dz), which the inputs' rounding (ε |d|) moves
  // by ε |d| / ‖(dx, dz)‖.
  const LD bound = std::atan2(dz, std::abs(dx)), xz = std::hypot(dx, dz);
  const LD d = std::hypot(xz, dy);
  const LD condition = bound < theta_h + 1e-6L ? std::max(LD(1), d / xz) : LD(1);
  return {{std::min(theta_h, bound), azimuth(sy, sx), std::atan2(std::hypot(dx, dy), dz),
           azimuth(dy, dx)},
          condition};
}

LD angle_distance(LD a, LD b) {
  const LD d = std::abs(a - b);
  return std::min(d, kTwoPiL - d);
}

// Pairs whose sums are exactly tiny: ωi = (t1, y, z1), ωo = (t2, -y, z2), y = √(1 - z1²), with
// t1, t2, z1, z2 zero or 10^-e for e up to the smallest subnormal, in the four axis-aligned poses
// (x and y swapped, signs flipped), each direction unit to rounding.
template <class T>
std::vector<DirPair<T>> tiny_sum_pairs(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const double max_e = -std::log10(double(std::numeric_limits<T>::denorm_min()));
  auto tiny = [&](double min_e) {
    const double v = u(rng);
    if (v < 0.1) return 0.0;
    const double t = std::pow(10.0, -(min_e + (max_e - min_e) * u(rng)));
    return v < 0.55 ? t : -t;
  };
  std::vector<DirPair<T>> pairs;
  for (std::size_t i = 0; i < n; ++i) {
    const double t1 = tiny(9), t2 = u(rng) < 0.3 ? -t1 * (1 + 1e-3 * u(rng)) : tiny(9);
    const double z1 = u(rng) < 0.3 ? u(rng) : std::abs(tiny(9));
    const double z2 = z1 < 1e-9 && u(rng) < 0.7 ? std::abs(tiny(9)) : z1;
    const T y = T(std::sqrt((1 - z1) * (1 + z1)));
    Vec3<T> wi{T(t1), y, T(z1)}, wo{T(t2), -y, T(z2)};
    if (i % 2) {
      std::swap(wi.x, wi.y);
      std::swap(wo.x, wo.y);
    }
    if (i % 4 >= 2) {
      wi = {-wi.x, -wi.y, wi.z};
      wo = {-wo.x, -wo.y, wo.z};
    }
    pairs.push_back({wi, wo});
  }
  return pairs;
}

template <class T>
std::vector<DirPair<T>> test_pairs() {
  auto pairs = tiny_sum_pairs<T>(20000, 2026);
  for (const auto& p : test::random_pairs(20000, 1203)) pairs.push_back(test::cast_pair<T>(p));
  for (const auto& p : test::edge_pairs()) pairs.push_back(test::cast_pair<T>(p));
  return pairs;
}

// Every angle within 8ε of the reference; φd within 8ε / sin θd, and a clamped θh within 8ε times
// the bound's condition: their conditioning.
template <class T>
void expect_near_reference(const std::vector<DirPair<T>>& pairs,
                           const std::vector<std::array<T, 4>>& got, const std::string& label) {
  const LD eps = std::numeric_limits<T>::epsilon(), tol = 8 * eps;
  int failures = 0;
  LD worst = 0;
  for (std::size_t i = 0; i < pairs.size() && failures < 5; ++i) {
    const auto [ref, condition] = reference(pairs[i]);
    const auto& q = got[i];
    const LD sin_d = std::sin(ref[2]);
    const LD err[4] = {angle_distance(q[0], ref[0]) / condition, angle_distance(q[1], ref[1]),
                       angle_distance(q[2], ref[2]), angle_distance(q[3], ref[3]) * sin_d};
    for (int c = 0; c < 4; ++c) {
      worst = std::max(worst, err[c] / eps);
      if (!(err[c] <= tol)) {
        ++failures;
        ADD_FAILURE() << label << " pair " << i << " (" << pairs[i].wi.x << ", " << pairs[i].wi.y
                      << ", " << pairs[i].wi.z << ") (" << pairs[i].wo.x << ", " << pairs[i].wo.y
                      << ", " << pairs[i].wo.z << "): coordinate " << c << " = " << q[c]
                      << ", reference " << double(ref[c]) << " (" << double(err[c] / eps) << " ε)";
      }
    }
  }
  std::printf("  %-24s worst %.2f ε\n", label.c_str(), double(worst));
}

template <class T>
class HalfDiffForward : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(HalfDiffForward, Precisions);

TYPED_TEST(HalfDiffForward, MatchesLongDoubleReferenceAtEveryScale) {
  using T = TypeParam;
  const auto pairs = test_pairs<T>();
  std::vector<std::array<T, 4>> got;
  for (const auto& p : pairs) {
    const Tuple4<T> q = HalfDiff::forward(p);
    got.push_back({q[0], q[1], q[2], q[3]});
  }
  expect_near_reference(pairs, got, "scalar");
}

// The same through the batch engine on every instruction set, whose lanes mix rows that take the
// scaled frame with rows that do not. The engine first puts directions onto the unit sphere, so
// the reference is taken of that normalized pair (convert_one's, bit for bit the engine's).
TYPED_TEST(HalfDiffForward, BatchMatchesLongDoubleReferenceOnEveryInstructionSet) {
  using T = TypeParam;
  const Form dirs{Space::dirs, false}, halfdiff{space_of<HalfDiff>, false};
  const auto raw = test_pairs<T>();
  const std::size_t n = raw.size();
  std::vector<DirPair<T>> pairs;
  std::vector<T> cols(6 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::array<T, 6> in{raw[i].wi.x, raw[i].wi.y, raw[i].wi.z,
                              raw[i].wo.x, raw[i].wo.y, raw[i].wo.z};
    std::array<T, 6> unit;
    ASSERT_TRUE(convert_one<T>(dirs, dirs, in, unit)) << "pair " << i;
    pairs.push_back({{unit[0], unit[1], unit[2]}, {unit[3], unit[4], unit[5]}});
    for (int c = 0; c < 6; ++c) cols[c * n + i] = in[c];
  }
  for (detail::SimdIsa isa : detail::kAllIsas) {
    if (!detail::kernels_for(isa) || !detail::set_batch_isa(isa)) continue;
    std::vector<T> out(4 * n);
    std::vector<std::uint8_t> valid(n);
    std::vector<ConstColumn<T>> in_cols;
    std::vector<Column<T>> out_cols;
    for (int c = 0; c < 6; ++c) in_cols.push_back({cols.data() + c * n, 1});
    for (int c = 0; c < 4; ++c) out_cols.push_back({out.data() + c * n, 1});
    ConvertOutput<T> o{out_cols, {}, valid.data()};
    convert<T>(dirs, halfdiff, in_cols, n, o);
    std::vector<std::array<T, 4>> got(n);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_TRUE(valid[i]) << "pair " << i;
      for (int c = 0; c < 4; ++c) got[i][c] = out[c * n + i];
    }
    expect_near_reference(pairs, got, std::string(detail::kernels_for(isa)->name));
    detail::set_batch_isa(std::nullopt);
  }
}

}  // namespace
}  // namespace halfback
