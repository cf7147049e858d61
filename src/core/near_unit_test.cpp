// docs/reliability/numerics.md, "Every accepted direction pair round-trips": every direction pair
// that the checks accept converts to coordinates that convert back. Accepted directions may be off
// unit length by up to kUnitTolerance and below the horizon by up to kDomainTolerance; the
// conversions put them onto the unit upper hemisphere and clamp the magnitudes ‖h̄‖, ‖k̄‖, ‖k‖ into
// [0, 1] (docs/math.md §6, docs/reliability/numerics.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "core/batch_engine.hpp"
#include "halfback/core/batch.hpp"
#include "support/test_util.hpp"

namespace halfback {
namespace {

constexpr std::size_t kPairs = 100000;

using test::form_name;
using test::parameterization_forms;

// A unit direction at elevation z (>= 0) and azimuth phi.
std::array<double, 3> direction(double z, double phi) {
  const double r = std::sqrt(std::max(0.0, 1 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Grazing-heavy pairs, rows of 6 in T: a fifth uniform, the rest near the horizon (both
// directions grazing, ωi = ωo, the mirror configuration, ωi ≈ ωo), some exactly on it. Most
// directions are moved below the horizon by up to 0.9 kDomainTolerance<T>, and most are scaled off
// unit length by up to 0.8 kUnitTolerance on ‖ω‖²: all still accepted by the checks.
template <class T>
std::vector<T> grazing_pairs(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double two_pi = 2 * std::numbers::pi;
  auto grazing_z = [&] {
    const double v = u(rng);
    return v < 0.2 ? 0.0 : std::pow(10.0, -1 - 15 * u(rng));  // 0, or 1e-16 .. 1e-1
  };
  std::vector<T> rows(6 * n);
  for (std::size_t i = 0; i < n; ++i) {
    std::array<double, 3> wi, wo;
    const double phi = two_pi * u(rng);
    switch (i % 5) {
      case 0:
        wi = direction(u(rng), phi);
        wo = direction(u(rng), two_pi * u(rng));
        break;
      case 1:
        wi = direction(grazing_z(), phi);
        wo = direction(grazing_z(), two_pi * u(rng));
        break;
      case 2:
        wi = wo = direction(grazing_z(), phi);
        break;
      case 3:
        wi = direction(grazing_z(), phi);
        wo = {-wi[0], -wi[1], wi[2]};
        break;
      default:
        wi = direction(grazing_z(), phi);
        wo = direction(grazing_z(), phi + 1e-6 * (u(rng) - 0.5));
        break;
    }
    for (auto* w : {&wi, &wo}) {
      if ((*w)[2] < 1e-3 && u(rng) < 0.2) {  // below the horizon, still unit
        const double z = -0.9 * kDomainTolerance<T> * u(rng);
        const double t = std::sqrt(1 - z * z) / std::hypot((*w)[0], (*w)[1]);
        *w = {(*w)[0] * t, (*w)[1] * t, z};
      }
      if (u(rng) < 0.7) {  // 0.8, not 0.9: rounding to float adds up to 1.2e-7
        const double s = std::sqrt(1 + 0.8 * kUnitTolerance * (2 * u(rng) - 1));
        for (double& c : *w) c *= s;
      }
    }
    for (int c = 0; c < 3; ++c) {
      rows[6 * i + c] = static_cast<T>(wi[c]);
      rows[6 * i + 3 + c] = static_cast<T>(wo[c]);
    }
  }
  return rows;
}

// Row-major columns of an (n, dim) array.
template <class T>
std::vector<ConstColumn<T>> const_columns(const std::vector<T>& rows, std::size_t dim) {
  std::vector<ConstColumn<T>> cols(dim);
  for (std::size_t c = 0; c < dim; ++c) cols[c] = {rows.data() + c, std::ptrdiff_t(dim)};
  return cols;
}
template <class T>
std::vector<Column<T>> columns(std::vector<T>& rows, std::size_t dim) {
  std::vector<Column<T>> cols(dim);
  for (std::size_t c = 0; c < dim; ++c) cols[c] = {rows.data() + c, std::ptrdiff_t(dim)};
  return cols;
}

// Batch conversion of every row; returns how many rows are valid.
template <class T>
std::size_t convert_batch(Form from, Form to, const std::vector<T>& in, std::vector<T>& out) {
  const std::size_t n = in.size() / dimension(from);
  out.assign(n * dimension(to), T(0));
  std::vector<std::uint8_t> valid(n, 0);
  const auto in_cols = const_columns(in, dimension(from));
  const auto out_cols = columns(out, dimension(to));
  ConvertOutput<T> o{out_cols, {}, valid.data()};
  convert<T>(from, to, in_cols, n, o);
  std::size_t count = 0;
  for (std::uint8_t v : valid) count += v;
  return count;
}

template <class T>
void expect_scalar_round_trips(const std::vector<T>& pairs) {
  const Form dirs{Space::dirs, false};
  const std::size_t n = pairs.size() / 6;
  for (Form form : parameterization_forms()) {
    std::size_t bad_forward = 0, bad_back = 0;
    std::array<T, 4> q;
    std::array<T, 6> back;
    for (std::size_t i = 0; i < n; ++i) {
      const std::span<const T> in(pairs.data() + 6 * i, 6);
      const std::span<T> qs(q.data(), dimension(form));
      if (!convert_one<T>(dirs, form, in, qs)) {
        ++bad_forward;
        continue;
      }
      if (!convert_one<T>(form, dirs, qs, back)) ++bad_back;
    }
    EXPECT_EQ(bad_forward, 0u) << form_name(form) << ": accepted pairs rejected";
    EXPECT_EQ(bad_back, 0u) << form_name(form) << ": round trips invalid (of " << n << ")";
  }
}

template <class T>
void expect_batch_round_trips(const std::vector<T>& pairs) {
  const Form dirs{Space::dirs, false};
  const std::size_t n = pairs.size() / 6;
  for (detail::SimdIsa isa : detail::kAllIsas) {
    if (!detail::kernels_for(isa) || !detail::set_batch_isa(isa)) continue;
    const std::string isa_name(detail::kernels_for(isa)->name);
    for (Form form : parameterization_forms()) {
      std::vector<T> q, back;
      EXPECT_EQ(convert_batch(dirs, form, pairs, q), n) << isa_name << " " << form_name(form);
      EXPECT_EQ(convert_batch(form, dirs, q, back), n)
          << isa_name << " " << form_name(form) << ": round trips invalid";
    }
    detail::set_batch_isa(std::nullopt);
  }
}

// The two pairs that once left the valid domain: ‖h̄‖ = 1.0000004 from a direction 4e-7 long, and
// ωi = ωo exactly on the horizon, where ‖h̄‖ rounds to 1 + 2e-16.
TEST(NearUnitDirections, LongAndHorizonPairsConvert) {
  const Form dirs{Space::dirs, false}, ortho{space_of<Ortho>, false};
  const double s = std::sqrt(1 + 8e-7);
  const double x = 0.6 * s, y = 0.8 * s;
  const std::array<double, 6> long_pair{x, y, 0.0, x, y, 0.0};
  std::array<double, 4> q;
  ASSERT_TRUE(convert_one<double>(dirs, ortho, long_pair, q));
  EXPECT_LE(q[0], 1.0);
  std::array<double, 6> back;
  EXPECT_TRUE(convert_one<double>(ortho, dirs, q, back));
  // The accepted pair is converted as the unit pair it stands for.
  std::array<double, 6> dirs_out;
  ASSERT_TRUE(convert_one<double>(dirs, dirs, long_pair, dirs_out));
  EXPECT_NEAR(dirs_out[0] * dirs_out[0] + dirs_out[1] * dirs_out[1], 1.0, 4e-16);

  const double phi = 0.3;
  const std::array<double, 6> horizon{std::cos(phi), std::sin(phi), 0.0,
                                      std::cos(phi), std::sin(phi), 0.0};
  for (Space space : {space_of<Ortho>, space_of<Hybrid>}) {
    std::array<double, 4> h;
    ASSERT_TRUE(convert_one<double>(dirs, {space, false}, horizon, h));
    EXPECT_LE(h[0], 1.0) << name_of(space);
    EXPECT_TRUE(convert_one<double>({space, false}, dirs, h, back)) << name_of(space);
  }
}

// A direction below the horizon within tolerance comes out on it, and unit.
TEST(NearUnitDirections, BelowHorizonOntoIt) {
  const Form dirs{Space::dirs, false};
  const double z = -0.5 * kDomainTolerance<double>;
  const std::array<double, 6> pair{0.0, 1.0, z, 0.6, 0.0, 0.8};
  std::array<double, 6> out;
  ASSERT_TRUE(convert_one<double>(dirs, dirs, pair, out));
  EXPECT_EQ(out[2], 0.0);
  EXPECT_EQ(out[1], 1.0);
  EXPECT_EQ(out[3], 0.6);  // unit to rounding already: kept bit for bit
  EXPECT_EQ(out[5], 0.8);
}

TEST(NearUnitDirections, EveryAcceptedPairRoundTripsScalarDouble) {
  expect_scalar_round_trips(grazing_pairs<double>(kPairs, 12));
}
TEST(NearUnitDirections, EveryAcceptedPairRoundTripsScalarFloat) {
  expect_scalar_round_trips(grazing_pairs<float>(kPairs, 13));
}
TEST(NearUnitDirections, EveryAcceptedPairRoundTripsBatchDouble) {
  expect_batch_round_trips(grazing_pairs<double>(kPairs, 12));
}
TEST(NearUnitDirections, EveryAcceptedPairRoundTripsBatchFloat) {
  expect_batch_round_trips(grazing_pairs<float>(kPairs, 13));
}

}  // namespace
}  // namespace halfback

namespace halfback {
namespace {

// accept_pair, the rule of every entry point that takes directions: check_pair()'s status, an
// accepted pair put onto the unit upper hemisphere (what the conversions use), others untouched.
TEST(AcceptPair, NormalizesAcceptedPairsAndLeavesTheOthers) {
  DirPair<double> p{{0.6 * (1 + 4e-7), 0, 0.8 * (1 + 4e-7)}, {0, 0, 1}};
  EXPECT_EQ(accept_pair(p), PairStatus::ok);
  EXPECT_NEAR(p.wi.x * p.wi.x + p.wi.z * p.wi.z, 1.0, 4e-16);
  DirPair<double> unit{{0.6, 0, 0.8}, {0, 0.28, 0.96}};
  const DirPair<double> before = unit;
  EXPECT_EQ(accept_pair(unit), PairStatus::ok);
  EXPECT_EQ(unit.wi.x, before.wi.x);  // unit to rounding: kept bit for bit
  EXPECT_EQ(unit.wo.z, before.wo.z);
  DirPair<double> grazing{{1, 0, -0.5 * kDomainTolerance<double>},
                          {0, 0, 1}};  // below, within tolerance
  EXPECT_EQ(accept_pair(grazing), PairStatus::ok);
  EXPECT_EQ(grazing.wi.z, 0.0);
  DirPair<double> below{{0.6, 0, -0.8}, {0, 0, 1}};
  EXPECT_EQ(accept_pair(below), PairStatus::wi_below_horizon);
  EXPECT_EQ(below.wi.z, -0.8);
  DirPair<double> off{{0.6, 0, 0.9}, {0, 0, 1}};
  EXPECT_EQ(accept_pair(off), PairStatus::wi_not_unit);
  EXPECT_EQ(off.wi.z, 0.9);
}

}  // namespace
}  // namespace halfback
