// Tests of the batch engine (batch.cpp): the SIMD/tiled/threaded convert() against the scalar
// reference convert_one() (std math, one row at a time), for every pair of forms, float and
// double, and every instruction set this CPU can run; layouts (strided AoS vs SoA), invalid rows,
// thread counts, sizes; and the xsimd LaneOps mapping itself (batch_simd.hpp).
#include "halfback/core/batch.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/batch_engine.hpp"
#include "core/batch_simd.hpp"
#include "core/row_kernels.hpp"
#include "support/test_util.hpp"

namespace halfback {
namespace {

using detail::SimdIsa;

using test::form_name;

std::vector<Form> all_forms() {
  std::vector<Form> forms{{Space::dirs, false}};
  for (Form f : test::parameterization_forms()) forms.push_back(f);
  return forms;
}

std::string pair_name(Form from, Form to) {
  return form_name(from) + "->" + form_name(to);
}

// The instruction sets to test: every one this build and CPU can run (scalar and sse2 at least
// on x86-64).
std::vector<SimdIsa> available_isas() {
  std::vector<SimdIsa> isas;
  for (SimdIsa isa : detail::kAllIsas)
    if (detail::kernels_for(isa)) isas.push_back(isa);
  return isas;
}

// Forces an instruction set for the lifetime of the guard.
class IsaGuard {
 public:
  explicit IsaGuard(SimdIsa isa) { ok_ = detail::set_batch_isa(isa); }
  ~IsaGuard() { detail::set_batch_isa(std::nullopt); }
  IsaGuard(const IsaGuard&) = delete;
  IsaGuard& operator=(const IsaGuard&) = delete;
  bool ok() const { return ok_; }

 private:
  bool ok_;
};

template <class T>
using Table = std::vector<std::vector<T>>;  // [column][row]

template <class T>
struct Result {
  Table<T> cols;
  std::vector<T> jac;
  std::vector<std::uint8_t> valid;
};

template <class T>
Table<T> make_table(std::size_t dim, std::size_t n) {
  return Table<T>(dim, std::vector<T>(n));
}

// Inputs of form `from` in precision T: the pairs encoded by the scalar path in double, rounded.
template <class T>
Table<T> inputs_for(Form from, const std::vector<DirPair<double>>& pairs) {
  const std::size_t dim = dimension(from);
  Table<T> t = make_table<T>(dim, pairs.size());
  for (std::size_t r = 0; r < pairs.size(); ++r) {
    const auto& p = pairs[r];
    const double v[6] = {p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z};
    double q[6];
    if (from.space == Space::dirs)
      std::copy(v, v + 6, q);
    else
      convert_one<double>({Space::dirs, false}, from, v, std::span<double>(q, dim));
    for (std::size_t c = 0; c < dim; ++c) t[c][r] = static_cast<T>(q[c]);
  }
  return t;
}

// The table as one row-major (N, columns) array: NumPy's default layout.
template <class T>
std::vector<T> row_major(const Table<T>& t) {
  const std::size_t d = t.size(), n = t.empty() ? 0 : t[0].size();
  std::vector<T> rows(n * d);
  for (std::size_t r = 0; r < n; ++r)
    for (std::size_t c = 0; c < d; ++c) rows[r * d + c] = t[c][r];
  return rows;
}

template <class T>
Result<T> run_batch(Form from, Form to, const Table<T>& in, bool jac, int threads = 1) {
  const std::size_t n = in.empty() ? 0 : in[0].size();
  Result<T> r{make_table<T>(dimension(to), n), std::vector<T>(jac ? n : 0),
              std::vector<std::uint8_t>(n, 7)};
  std::vector<ConstColumn<T>> ic;
  for (const auto& c : in) ic.push_back({c.data(), 1});
  std::vector<Column<T>> oc;
  for (auto& c : r.cols) oc.push_back({c.data(), 1});
  ConvertOutput<T> out{oc, jac ? Column<T>{r.jac.data(), 1} : Column<T>{}, r.valid.data()};
  convert<T>(from, to, ic, n, out, {threads});
  return r;
}

template <class T>
Result<T> run_scalar(Form from, Form to, const Table<T>& in) {
  const std::size_t n = in.empty() ? 0 : in[0].size();
  const std::size_t din = dimension(from), dout = dimension(to);
  Result<T> r{make_table<T>(dout, n), std::vector<T>(n), std::vector<std::uint8_t>(n)};
  T a[6], b[6];
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t c = 0; c < din; ++c) a[c] = in[c][i];
    r.valid[i] =
        convert_one<T>(from, to, std::span<const T>(a, din), std::span<T>(b, dout), &r.jac[i]) ? 1
                                                                                               : 0;
    for (std::size_t c = 0; c < dout; ++c) r.cols[c][i] = b[c];
  }
  return r;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  // (memcmp must not see the null data() of empty vectors, e.g. results without a Jacobian.)
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

template <class T>
bool same_bits(const Result<T>& a, const Result<T>& b) {
  if (a.cols.size() != b.cols.size() || a.valid != b.valid || !same_bits(a.jac, b.jac))
    return false;
  for (std::size_t c = 0; c < a.cols.size(); ++c)
    if (!same_bits(a.cols[c], b.cols[c])) return false;
  return true;
}

// ---------------------------------------------------------------------------------------------
// Batch == scalar reference
// ---------------------------------------------------------------------------------------------
//
// The batch kernels evaluate the same param.hpp formulas with the same arithmetic as the scalar
// reference (the kernel TUs are compiled with -ffp-contract=off): only atan2, sin and cos differ,
// batch_simd.hpp's against libm. Measured (BatchLaneOps tests below): the SIMD atan2 is within
// 2.5 ulp of the exact value and xsimd's sin/cos within 1.5 ulp; libm is within 0.5 (double) or
// 1.5 (float) ulp.
// The tolerances, per valid row (ε of the precision T):
//
// - dirs -> P (encode only; the two sides see the same input and the same arithmetic up to the
//   atan2 results): every coordinate within kUlps·ε·max(|x|, 1), azimuths compared on the
//   circle. The error is absolute on the scale of 1 because of at most one cancellation against
//   a quantity of order 1 (Δφ = φo − φi of the isotropic forms).
// - P -> dirs and P -> Q (a decode is involved): a sin or cos one ulp off is amplified by the
//   conditioning of the inverse map, up to √ε for ortho and hybrid at grazing, where
//   z = √(1 − r²), and like ε/‖h̄‖ for the canonical pose of the isotropic forms when h̄ ≈ 0.
//   No two implementations agree in ulps there. The check uses the error model of docs/math.md
//   ("Accuracy") that param_test.cpp verifies for the round trip, bound(p) = ε / max(cond, √ε)
//   with cond = 1 (spherical), ‖h‖ = cos θd (halfdiff), min(zi, zo) (ortho), (zi + zo)/2
//   (hybrid), and for isotropic forms also ‖h̄‖ (the pose's rotation). P -> dirs: the pairs
//   within kPair·bound_P; P -> Q: both outputs decoded by the reference within
//   kPair·(bound_P + bound_Q) (each decode adds one round trip of Q).
// - Jacobian: the batch's J against the reference formula at the same coordinates (the batch's
//   own output, or the input when `to` is dirs), relative error within kUlps·ε·cond_J: 1 for
//   spherical, 1 + 1/cos θd for halfdiff, 1 + 1/zi² + 1/zo² for ortho (zi from √(1 − r²)),
//   1 + 2/√(hz² + c²) for hybrid (hz² + c² from the sincos of the azimuths).
// - The valid flag must match exactly, and invalid rows must be NaN everywhere.
constexpr double kUlps = 8;
constexpr double kPair = 16;

bool is_azimuth_column(Form f, std::size_t c) {
  if (f.space == Space::dirs) return false;
  return f.isotropic ? c == 2 : (c == 1 || c == 3);
}

double distance(Form f, std::size_t c, double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b) ? 0 : INFINITY;
  if (a == b) return 0;  // equal infinities too
  const double d = std::abs(a - b);
  return is_azimuth_column(f, c) ? std::min(d, test::kTwoPiD - d) : d;
}

// Error model of the inverse map of `form` at pair p (docs/math.md, "Accuracy"): the shape of
// the pair is reproduced within ε / max(cond, √ε), cond = 1 (spherical), ‖h‖ = cos θd
// (halfdiff), min(zi, zo) (ortho), (zi + zo)/2 (hybrid); the canonical pose of the isotropic
// forms adds a rotation about n known to ε / ‖h̄‖.
double shape_bound(Form form, const DirPair<double>& p, double eps) {
  double cond = 1;
  switch (form.space.id()) {
    case Space::dirs.id():
    case space_of<Spherical>.id():
      break;
    case space_of<HalfDiff>.id():
      cond = std::sqrt(std::max(0.0, 0.5 * (1 + detail::dot(p.wi, p.wo))));
      break;
    case space_of<Ortho>.id():
      cond = std::min(p.wi.z, p.wo.z);
      break;
    case space_of<Hybrid>.id():
      cond = 0.5 * (p.wi.z + p.wo.z);
      break;
  }
  return eps / std::max(cond, std::sqrt(eps));
}

double pose_bound(Form form, const DirPair<double>& p, double eps) {
  if (!form.isotropic) return 0;
  const double hbar = 0.5 * std::hypot(p.wi.x + p.wo.x, p.wi.y + p.wo.y);
  return hbar == 0 ? 0 : eps / hbar;
}

// Functions of a pair that do not depend on its rotation about n.
std::array<double, 4> invariants(const DirPair<double>& p) {
  return {p.wi.z, p.wo.z, detail::dot(p.wi, p.wo), p.wi.x * p.wo.y - p.wi.y * p.wo.x};
}

double max_abs_diff(const std::array<double, 4>& a, const std::array<double, 4>& b) {
  double m = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double d = std::abs(a[i] - b[i]);
    m = std::isnan(d) ? INFINITY : std::max(m, d);
  }
  return m;
}

// Relative error of the jacobian formula of `form` at coordinates q caused by sin/cos results one
// ulp off, in units of ε (see above). The quantities the kernel computes identically on both
// sides (hz², zi², zo² from the same products) are evaluated in the precision T, as the kernel
// does: where they are at rounding level the jacobian has no significant digit.
template <class T>
double jacobian_condition(Form form, const T* q) {
  const T q4[4] = {q[0], form.isotropic ? T(0) : q[1], form.isotropic ? q[1] : q[2],
                   form.isotropic ? q[2] : q[3]};
  switch (form.space.id()) {
    case Space::dirs.id():
    case space_of<Spherical>.id():
      return 1;
    case space_of<HalfDiff>.id():
      return 1 + 1 / std::abs(std::cos(double(q4[2])));
    case space_of<Ortho>.id(): {
      const T hx = q4[0] * std::cos(q4[1]), hy = q4[0] * std::sin(q4[1]);
      const T kx = q4[2] * std::cos(q4[3]), ky = q4[2] * std::sin(q4[3]);
      const T xi = hx + kx, yi = hy + ky, xo = hx - kx, yo = hy - ky;
      const T zi2 = T(1) - (xi * xi + yi * yi), zo2 = T(1) - (xo * xo + yo * yo);
      return 1 + 2 / std::abs(double(zi2)) + 2 / std::abs(double(zo2));
    }
    case space_of<Hybrid>.id(): {
      const T hz2 = T(1) - q4[0] * q4[0] - q4[2] * q4[2];
      const double hz = std::sqrt(std::max(double(hz2), 0.0));
      const double c = double(q4[0]) * std::cos(double(q4[3]) - double(q4[1]));
      return 1 + 4 * std::abs(c) * double(q4[0]) / (hz * hz + c * c);
    }
  }
  return 1;
}

// The reference jacobian formula (scalar, precision T) at coordinates q of `form`.
template <class T>
T reference_jacobian(Form form, const T* q) {
  if (form.space == Space::dirs) return T(1);
  return visit_kernel_param(form.space.kernel_index(), [&](auto p) {
    return detail::jacobian_of<decltype(p), T>(form.isotropic, q);
  });
}

template <class T>
DirPair<double> pair_of(const T* v) {
  return {{double(v[0]), double(v[1]), double(v[2])}, {double(v[3]), double(v[4]), double(v[5])}};
}

// The reference decode of a T tuple of `form` into a pair (the identity for dirs).
template <class T>
bool decode_reference(Form form, const T* q, DirPair<double>& p) {
  T d[6];
  if (form.space == Space::dirs) {
    std::copy(q, q + 6, d);
  } else if (!convert_one<T>(form, {Space::dirs, false}, std::span<const T>(q, dimension(form)),
                             d)) {
    return false;
  }
  p = pair_of(d);
  return true;
}

struct Stats {
  double raw = 0;      // worst difference in ε (of max(|x|, 1) for coordinates, of pairs)
  double raw_jac = 0;  // worst relative jacobian difference, in ε
  double ratio = 0;    // worst difference / tolerance
  std::size_t invalid = 0;
  void merge(const Stats& o) {
    raw = std::max(raw, o.raw);
    raw_jac = std::max(raw_jac, o.raw_jac);
    ratio = std::max(ratio, o.ratio);
    invalid = std::max(invalid, o.invalid);
  }
};

template <class T>
std::string row_text(const Table<T>& in, std::size_t i) {
  std::string s;
  char buf[40];
  for (const auto& c : in) {
    std::snprintf(buf, sizeof buf, " %.9g", static_cast<double>(c[i]));
    s += buf;
  }
  return s;
}

// Compares a batch result with the scalar reference under the tolerances above.
template <class T>
Stats compare(Form from, Form to, const Table<T>& in, const Result<T>& got, const Result<T>& ref,
              bool check_jac, const std::string& label) {
  const double eps = std::numeric_limits<T>::epsilon();
  const std::size_t n = in.empty() ? 0 : in[0].size(), din = dimension(from), dout = dimension(to);
  const Form dirs{Space::dirs, false};
  Stats st;
  int reported = 0;
  auto fail = [&](std::size_t i, const std::string& what) {
    if (reported++ < 5)
      ADD_FAILURE() << label << " row " << i << " (in:" << row_text(in, i) << "): " << what;
  };
  auto check = [&](std::size_t i, const char* what, double err, double tol, double unit) {
    st.raw = std::max(st.raw, err / unit);
    st.ratio = std::max(st.ratio, err / tol);
    if (!(err <= tol)) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "%s differ by %.3g ε (tolerance %.3g ε)", what, err / eps,
                    tol / eps);
      fail(i, buf);
    }
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (got.valid[i] != ref.valid[i]) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "valid flag %d, reference %d", got.valid[i], ref.valid[i]);
      fail(i, buf);
      continue;
    }
    if (!ref.valid[i]) {
      ++st.invalid;
      for (std::size_t c = 0; c < dout; ++c)
        if (!std::isnan(got.cols[c][i])) fail(i, "invalid row with a non-NaN output");
      if (check_jac && !std::isnan(got.jac[i])) fail(i, "invalid row with a non-NaN jacobian");
      continue;
    }
    T x[6], qb[6], qs[6];
    for (std::size_t c = 0; c < din; ++c) x[c] = in[c][i];
    for (std::size_t c = 0; c < dout; ++c) {
      qb[c] = got.cols[c][i];
      qs[c] = ref.cols[c][i];
    }
    if (from.space == Space::dirs) {
      for (std::size_t c = 0; c < dout; ++c) {
        const double unit = eps * std::max(std::abs(double(qs[c])), 1.0);
        check(i, "coordinates", distance(to, c, qb[c], qs[c]), kUlps * unit, unit);
      }
    } else {
      DirPair<double> p;  // the pair the reference decodes from the input
      if (!decode_reference<T>(from, x, p)) {
        fail(i, "reference decode failed");
        continue;
      }
      const double shape = kPair * (shape_bound(from, p, eps) + shape_bound(to, p, eps));
      const double pose = kPair * (pose_bound(from, p, eps) + pose_bound(to, p, eps));
      DirPair<double> pb, ps;
      if (!decode_reference<T>(to, qb, pb) || !decode_reference<T>(to, qs, ps)) {
        fail(i, "an output does not decode");
        continue;
      }
      check(i, "pairs", test::max_abs_diff(pb, ps), shape + pose, eps);
      check(i, "rotation invariants", max_abs_diff(invariants(pb), invariants(ps)), 2 * shape, eps);
    }
    if (check_jac) {
      const Form side = to.space != Space::dirs ? to : from;
      const T* q = to.space != Space::dirs ? qb : x;
      const double jb = got.jac[i], js = reference_jacobian<T>(side, q);
      const double err = distance(dirs, 0, jb, js);
      if (err == 0) continue;
      const double rel_tol = kUlps * eps * jacobian_condition<T>(side, q);
      if (rel_tol >= 1) continue;  // no significant digit (a singular configuration)
      const double unit = eps * std::abs(js);
      const double ratio = err / (rel_tol * std::abs(js));
      st.raw_jac = std::max(st.raw_jac, err / unit);
      st.ratio = std::max(st.ratio, ratio);
      if (!(ratio <= 1)) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "jacobian %.9g vs reference %.9g (%.3g × tolerance)", jb, js,
                      ratio);
        fail(i, buf);
      }
    }
  }
  return st;
}

std::vector<DirPair<double>> test_pairs(std::size_t n_random, std::uint64_t seed) {
  auto pairs = test::random_pairs(n_random, seed);
  const auto edges = test::edge_pairs();
  pairs.insert(pairs.end(), edges.begin(), edges.end());
  // Azimuths just above 0 and just below 2π (the wrap of azimuth()), normal incidence.
  for (double d : {1e-7, 1e-12, 1e-16}) {
    pairs.push_back({test::direction(0.5, -d), test::direction(0.2, test::kTwoPiD - d)});
    pairs.push_back({test::direction(0.5, d), test::direction(0.5, test::kPi + d)});
    pairs.push_back({test::direction(1.0, 0.0), test::direction(0.5, -d)});
  }
  return pairs;
}

template <class T>
class BatchTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
class PrecisionNames {
 public:
  template <class T>
  static std::string GetName(int) {
    return sizeof(T) == 4 ? "float" : "double";
  }
};
TYPED_TEST_SUITE(BatchTest, Precisions, PrecisionNames);

TYPED_TEST(BatchTest, MatchesScalarReferenceForEveryPairOfForms) {
  using T = TypeParam;
  const auto pairs = test_pairs(10000, 77);
  const auto isas = available_isas();
  ASSERT_GE(isas.size(), 1u);
  std::printf("  instruction sets:");
  for (SimdIsa isa : isas) std::printf(" %s", std::string(detail::isa_name(isa)).c_str());
  std::printf("\n  %-28s %10s %10s %8s %7s\n", "from -> to", "diff (ε)", "J diff (ε)", "diff/tol",
              "invalid");
  for (Form from : all_forms()) {
    const Table<T> in = inputs_for<T>(from, pairs);
    for (Form to : all_forms()) {
      const Result<T> ref = run_scalar<T>(from, to, in);
      Stats worst;
      for (SimdIsa isa : isas) {
        IsaGuard guard(isa);
        ASSERT_TRUE(guard.ok());
        const std::string label =
            pair_name(from, to) + " [" + std::string(detail::isa_name(isa)) + "]";
        const Result<T> got = run_batch<T>(from, to, in, true);
        worst.merge(compare<T>(from, to, in, got, ref, true, label));
        // Without the jacobian: the same coordinates and flags.
        Result<T> plain = run_batch<T>(from, to, in, false);
        plain.jac = got.jac;
        EXPECT_TRUE(same_bits(plain, got)) << label << ": the jacobian changes the coordinates";
      }
      // The inputs are images of valid pairs: nearly all are valid (rounding a grazing tuple to
      // float may leave the domain; the reference decides, and the batch must agree).
      EXPECT_LE(worst.invalid, pairs.size() / 100) << pair_name(from, to);
      std::printf("  %-28s %10.3g %10.3g %8.3f %7zu\n", pair_name(from, to).c_str(), worst.raw,
                  worst.raw_jac, worst.ratio, worst.invalid);
    }
  }
}

// P -> Q is decode then encode through the same pair, bit for bit: the engine's composition of
// stages (scratch, masks, tiles) adds nothing.
TYPED_TEST(BatchTest, ParameterToParameterIsDecodeThenEncode) {
  using T = TypeParam;
  const auto pairs = test_pairs(3000, 5);
  const Form dirs{Space::dirs, false};
  for (SimdIsa isa : available_isas()) {
    IsaGuard guard(isa);
    for (Form from : all_forms()) {
      if (from.space == Space::dirs) continue;
      const Table<T> in = inputs_for<T>(from, pairs);
      const Result<T> mid = run_batch<T>(from, dirs, in, false);
      for (Form to : all_forms()) {
        if (to.space == Space::dirs) continue;
        const std::string label =
            pair_name(from, to) + " [" + std::string(detail::isa_name(isa)) + "]";
        const Result<T> direct = run_batch<T>(from, to, in, true);
        const Result<T> composed = run_batch<T>(dirs, to, mid.cols, true);
        std::size_t mismatches = 0;
        for (std::size_t i = 0; i < pairs.size(); ++i) {
          ASSERT_EQ(direct.valid[i], mid.valid[i]) << label << " row " << i;
          if (!direct.valid[i]) continue;
          ASSERT_TRUE(composed.valid[i]) << label << ": decoded pair rejected, row " << i;
          bool same = std::memcmp(&direct.jac[i], &composed.jac[i], sizeof(T)) == 0;
          for (std::size_t c = 0; c < dimension(to); ++c)
            same = same && std::memcmp(&direct.cols[c][i], &composed.cols[c][i], sizeof(T)) == 0;
          if (!same) ++mismatches;
        }
        EXPECT_EQ(mismatches, 0u) << label;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Layouts
// ---------------------------------------------------------------------------------------------

// Row-major (AoS) input and output, strides 6/4/3 (and the jacobian interleaved with the
// outputs), and a mix of strides including a reversed column, give the same bits as SoA.
TYPED_TEST(BatchTest, StridedLayoutsGiveTheSameBitsAsSoa) {
  using T = TypeParam;
  auto pairs = test_pairs(1000, 9);
  pairs.push_back({{0, 0, 2}, {0, 0, 1}});  // an invalid row (dirs input; wi not unit)
  const std::size_t n = pairs.size();
  for (SimdIsa isa : available_isas()) {
    IsaGuard guard(isa);
    for (Form from : all_forms()) {
      const Table<T> in = inputs_for<T>(from, pairs);
      const std::size_t din = dimension(from);
      // AoS input.
      const std::vector<T> aos_in = row_major(in);
      // Mixed input: column 0 reversed in memory (stride -1), column 1 with stride 3, rest SoA.
      std::vector<T> rev(in[0].rbegin(), in[0].rend()), spaced(3 * n);
      for (std::size_t r = 0; r < n; ++r) spaced[3 * r] = in[1][r];
      for (Form to : all_forms()) {
        const std::size_t dout = dimension(to);
        const std::string label =
            pair_name(from, to) + " [" + std::string(detail::isa_name(isa)) + "]";
        const Result<T> soa = run_batch<T>(from, to, in, true);

        std::vector<ConstColumn<T>> ic(din);
        for (std::size_t c = 0; c < din; ++c)
          ic[c] = {aos_in.data() + c, static_cast<std::ptrdiff_t>(din)};
        const std::size_t row = dout + 1;  // outputs then the jacobian, row-major
        std::vector<T> aos_out(n * row);
        std::vector<Column<T>> oc(dout);
        for (std::size_t c = 0; c < dout; ++c)
          oc[c] = {aos_out.data() + c, static_cast<std::ptrdiff_t>(row)};
        std::vector<std::uint8_t> valid(n, 7);
        convert<T>(from, to, ic, n,
                   {oc, {aos_out.data() + dout, static_cast<std::ptrdiff_t>(row)}, valid.data()});
        Result<T> aos{make_table<T>(dout, n), std::vector<T>(n), valid};
        for (std::size_t r = 0; r < n; ++r) {
          for (std::size_t c = 0; c < dout; ++c) aos.cols[c][r] = aos_out[r * row + c];
          aos.jac[r] = aos_out[r * row + dout];
        }
        EXPECT_TRUE(same_bits(aos, soa))
            << label << ": AoS (stride " << din << " -> " << row << ")";

        // Row-major input and output of exactly din and dout values a row (NumPy's C order):
        // the engine's transposing path, over several tiles and a tail (n = 1001).
        std::vector<T> rows_out(n * dout, T(-7));
        for (std::size_t c = 0; c < dout; ++c)
          oc[c] = {rows_out.data() + c, static_cast<std::ptrdiff_t>(dout)};
        std::vector<std::uint8_t> rows_valid(n, 7);
        convert<T>(from, to, ic, n, {oc, {}, rows_valid.data()});
        Result<T> rows{make_table<T>(dout, n), soa.jac, rows_valid};
        for (std::size_t r = 0; r < n; ++r)
          for (std::size_t c = 0; c < dout; ++c) rows.cols[c][r] = rows_out[r * dout + c];
        EXPECT_TRUE(same_bits(rows, soa)) << label << ": rows of " << din << " -> " << dout;
        // The same rows with the Jacobian asked for: the transpose passes instead of the stages.
        std::vector<T> jac_rows_out(n * dout, T(-7));
        for (std::size_t c = 0; c < dout; ++c)
          oc[c] = {jac_rows_out.data() + c, static_cast<std::ptrdiff_t>(dout)};
        Result<T> jac_rows{make_table<T>(dout, n), std::vector<T>(n), std::vector<std::uint8_t>(n)};
        convert<T>(from, to, ic, n, {oc, {jac_rows.jac.data(), 1}, jac_rows.valid.data()});
        for (std::size_t r = 0; r < n; ++r)
          for (std::size_t c = 0; c < dout; ++c) jac_rows.cols[c][r] = jac_rows_out[r * dout + c];
        EXPECT_TRUE(same_bits(jac_rows, soa))
            << label << ": rows of " << din << " -> " << dout << " with the Jacobian";
        if (din == dout) {  // in place: the output overwrites the input array
          std::vector<T> inout(aos_in);
          std::vector<ConstColumn<T>> ip(din);
          for (std::size_t c = 0; c < din; ++c)
            ip[c] = {inout.data() + c, static_cast<std::ptrdiff_t>(din)};
          for (std::size_t c = 0; c < dout; ++c)
            oc[c] = {inout.data() + c, static_cast<std::ptrdiff_t>(dout)};
          convert<T>(from, to, ip, n, {oc, {}, rows_valid.data()});
          EXPECT_TRUE(same_bits(inout, rows_out)) << label << ": in place";
        }

        ic.clear();
        for (std::size_t c = 0; c < din; ++c) ic.push_back({in[c].data(), 1});
        ic[0] = {rev.data() + (n - 1), -1};
        ic[1] = {spaced.data(), 3};
        Result<T> mixed{make_table<T>(dout, n), std::vector<T>(2 * n),
                        std::vector<std::uint8_t>(n)};
        std::vector<T> out0(2 * n);
        oc.clear();
        for (std::size_t c = 0; c < dout; ++c) oc.push_back({mixed.cols[c].data(), 1});
        oc[0] = {out0.data(), 2};
        convert<T>(from, to, ic, n, {oc, {mixed.jac.data(), 2}, mixed.valid.data()});
        for (std::size_t r = 0; r < n; ++r) {
          mixed.cols[0][r] = out0[2 * r];
          mixed.jac[r] = mixed.jac[2 * r];
        }
        mixed.jac.resize(n);
        EXPECT_TRUE(same_bits(mixed, soa)) << label << ": mixed strides";
      }
    }
  }
}

// Forces the outputs' non-temporal stores on or off for the lifetime of the guard.
class StreamingGuard {
 public:
  explicit StreamingGuard(bool on) { detail::set_streaming_stores(on); }
  ~StreamingGuard() { detail::set_streaming_stores(std::nullopt); }
  StreamingGuard(const StreamingGuard&) = delete;
  StreamingGuard& operator=(const StreamingGuard&) = delete;
};

// Row-major inputs and outputs read and written by the stages themselves (fused_rows: every
// instruction set whose table says so), or by the transpose passes: the bits of SoA columns, for
// rows in and out, rows in only, rows out only, with and without non-temporal stores, at sizes
// that leave every kind of tail (less than a vector, a vector and one, a tile and a few).
TYPED_TEST(BatchTest, RowMajorStagesGiveTheSameBitsAsColumns) {
  using T = TypeParam;
  auto all_pairs = test_pairs(1100, 12);
  all_pairs.insert(all_pairs.begin() + 5,
                   DirPair<double>{{0, 0, 2}, {0, 0, 1}});  // invalid (dirs input)
  const std::size_t tile = detail::kTileRows<T>;
  for (std::size_t n : {std::size_t{1}, std::size_t{15}, std::size_t{17}, std::size_t{100},
                        tile + 3, 2 * tile + 9}) {
    const std::vector<DirPair<double>> pairs(all_pairs.begin(), all_pairs.begin() + n);
    for (SimdIsa isa : available_isas()) {
      IsaGuard guard(isa);
      for (Form from : all_forms()) {
        const Table<T> in = inputs_for<T>(from, pairs);
        const std::size_t din = dimension(from);
        const std::vector<T> in_rows = row_major(in);
        for (Form to : all_forms()) {
          const std::size_t dout = dimension(to);
          const std::string label = pair_name(from, to) + " [" +
                                    std::string(detail::isa_name(isa)) + "] n=" + std::to_string(n);
          const Result<T> soa = run_batch<T>(from, to, in, false);
          auto run = [&](bool rows_in, bool rows_out, bool streaming) {
            StreamingGuard s(streaming);
            std::vector<ConstColumn<T>> ic;
            for (std::size_t c = 0; c < din; ++c)
              ic.push_back(rows_in ? ConstColumn<T>{in_rows.data() + c, std::ptrdiff_t(din)}
                                   : ConstColumn<T>{in[c].data(), 1});
            std::vector<T> out_rows(n * dout, T(-5));
            Result<T> r{
                Table<T>(dout, std::vector<T>(n, T(-5))), {}, std::vector<std::uint8_t>(n, 7)};
            std::vector<Column<T>> oc;
            for (std::size_t c = 0; c < dout; ++c)
              oc.push_back(rows_out ? Column<T>{out_rows.data() + c, std::ptrdiff_t(dout)}
                                    : Column<T>{r.cols[c].data(), 1});
            convert<T>(from, to, ic, n, {oc, {}, r.valid.data()});
            if (rows_out)
              for (std::size_t i = 0; i < n; ++i)
                for (std::size_t c = 0; c < dout; ++c) r.cols[c][i] = out_rows[i * dout + c];
            return r;
          };
          for (bool streaming : {false, true}) {
            EXPECT_TRUE(same_bits(run(true, true, streaming), soa)) << label << ": rows -> rows";
            EXPECT_TRUE(same_bits(run(true, false, streaming), soa)) << label << ": rows -> SoA";
            EXPECT_TRUE(same_bits(run(false, true, streaming), soa)) << label << ": SoA -> rows";
          }
        }
      }
    }
  }
}

// Non-temporal output stores (through scratch, for outputs that do not fit in cache) write the
// same bits as plain ones: SoA columns starting off a 16-byte boundary (the copy's unaligned head
// and tail), row-major outputs, in place, strided ones and the Jacobian, over several tiles.
TYPED_TEST(BatchTest, StreamingStoresGiveTheSameBits) {
  using T = TypeParam;
  auto pairs = test_pairs(1500, 21);
  pairs.push_back({{0, 0, 2}, {0, 0, 1}});  // invalid
  const std::size_t n = pairs.size();
  for (SimdIsa isa : available_isas()) {
    IsaGuard guard(isa);
    for (Form from : all_forms()) {
      const Table<T> in = inputs_for<T>(from, pairs);
      const std::size_t din = dimension(from);
      const std::vector<T> in_rows = row_major(in);
      for (Form to : all_forms()) {
        const std::size_t dout = dimension(to);
        const std::string label =
            pair_name(from, to) + " [" + std::string(detail::isa_name(isa)) + "]";
        // SoA outputs one element past an aligned start, the Jacobian with stride 2.
        auto soa_run = [&](bool streaming) {
          StreamingGuard s(streaming);
          std::vector<T> buf(dout * (n + 1) + 2 * n, T(-3));
          std::vector<Column<T>> oc;
          for (std::size_t c = 0; c < dout; ++c) oc.push_back({buf.data() + c * (n + 1) + 1, 1});
          std::vector<ConstColumn<T>> ic;
          for (const auto& c : in) ic.push_back({c.data(), 1});
          std::vector<std::uint8_t> valid(n, 7);
          convert<T>(from, to, ic, n, {oc, {buf.data() + dout * (n + 1), 2}, valid.data()});
          buf.insert(buf.end(), valid.begin(), valid.end());
          return buf;
        };
        EXPECT_TRUE(same_bits(soa_run(true), soa_run(false))) << label << ": SoA";
        auto rows_run = [&](bool streaming, bool in_place) {
          StreamingGuard s(streaming);
          std::vector<T> buf = in_place ? in_rows : std::vector<T>(n * dout, T(-3));
          std::vector<ConstColumn<T>> ic;
          for (std::size_t c = 0; c < din; ++c)
            ic.push_back(
                {(in_place ? buf.data() : in_rows.data()) + c, static_cast<std::ptrdiff_t>(din)});
          std::vector<Column<T>> oc;
          for (std::size_t c = 0; c < dout; ++c)
            oc.push_back({buf.data() + c, static_cast<std::ptrdiff_t>(dout)});
          std::vector<T> jac(n);
          convert<T>(from, to, ic, n, {oc, {jac.data(), 1}, nullptr});
          buf.insert(buf.end(), jac.begin(), jac.end());
          return buf;
        };
        EXPECT_TRUE(same_bits(rows_run(true, false), rows_run(false, false))) << label << ": rows";
        if (din == dout) {
          EXPECT_TRUE(same_bits(rows_run(true, true), rows_run(false, true)))
              << label << ": rows in place";
        }
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Invalid rows
// ---------------------------------------------------------------------------------------------

// Rows the reference rejects, for each input form: not finite, not unit, below the horizon,
// coordinates out of range, and in-range tuples whose directions would be below the horizon.
template <class T>
std::vector<std::vector<T>> invalid_rows(Form from) {
  const T nan = std::numeric_limits<T>::quiet_NaN(), inf = std::numeric_limits<T>::infinity();
  std::vector<std::vector<T>> rows;
  if (from.space == Space::dirs) {
    const std::vector<T> ok{0.6f, 0, 0.8f, 0, -0.28f, 0.96f};
    for (std::size_t c = 0; c < 6; ++c)
      for (T bad : {nan, inf, -inf}) {
        rows.push_back(ok);
        rows.back()[c] = bad;
      }
    rows.push_back({0.6f * 1.001f, 0, 0.8f * 1.001f, 0, -0.28f, 0.96f});  // |ωi|² − 1 = 2e-3
    rows.push_back({0.6f, 0, 0.8f, 0, -0.28f * 0.5f, 0.96f * 0.5f});
    rows.push_back({0, 0, 0, 0, 0, 1});
    rows.push_back({0.6f, 0, -0.8f, 0, 0, 1});          // below the horizon
    rows.push_back({0, 1, 0, 0, 0.9999995f, -0.001f});  // just below
    const T tol = kDomainTolerance<T>;
    rows.push_back({1, 0, T(-2) * tol, 0, 0, 1});  // beyond the horizon tolerance
    return rows;
  }
  const std::size_t dim = dimension(from);
  const bool angular = from.space == space_of<Spherical> || from.space == space_of<HalfDiff>;
  // A valid tuple, and per column its upper limit (π/2 or 1 for magnitudes, 2π excluded).
  std::vector<T> ok =
      from.isotropic ? std::vector<T>{0.3f, 0.4f, 1.0f} : std::vector<T>{0.3f, 1.0f, 0.4f, 2.0f};
  for (std::size_t c = 0; c < dim; ++c) {
    const T upper = is_azimuth_column(from, c) ? T(kTwoPi<T>)
                    : angular                  ? std::nextafter(T(kHalfPi<T>), T(4))
                                               : std::nextafter(T(1), T(2));
    // Azimuths are periodic: only non-finite and absurdly large ones are invalid.
    const std::vector<T> bads =
        is_azimuth_column(from, c)
            ? std::vector<T>{nan, inf, -inf, T(1e30f), T(-7e4f)}
            : std::vector<T>{nan, inf, -inf, T(-0.1f), T(-1e-30f), upper, T(1e30f)};
    for (T bad : bads) {
      rows.push_back(ok);
      rows.back()[c] = bad;
    }
  }
  // In range, outside the domain.
  auto push = [&](std::vector<T> q4) {
    if (from.isotropic) q4 = {q4[0], q4[2], q4[3]};  // φh = 0
    rows.push_back(q4);
  };
  switch (from.space.id()) {
    case space_of<Spherical>.id():
      break;  // its domain is the box
    case space_of<HalfDiff>.id():
      push({1.2f, 0, 1.2f, 0});        // ωi.z = cos 2.4 < 0
      push({1.2f, 0, 1.2f, 3.1416f});  // ωo.z < 0
      break;
    case space_of<Ortho>.id():
      push({0.8f, 0, 0.8f, 0});      // |h̄ + k̄| = 1.6
      push({0.8f, 0, 0.8f, 3.14f});  // |h̄ − k̄| > 1
      push({0.9f, 0, 0.2f, 0.1f});
      break;
    case space_of<Hybrid>.id():
      push({0.8f, 0, 0.8f, 1.0f});  // ‖h̄‖² + ‖k‖² > 1
      push({0.1f, 0, 0.99f, 0});    // k along h̄ with |kz| > hz
      break;
    case Space::dirs.id():
      break;
  }
  return rows;
}

// dirs -> P: the encode stage checks unchecked rows itself (one pass over the input); its bits
// must be those of the check stage followed by the encode stage, as before, on every instruction
// set: valid pairs, pairs off unit length that are rescaled, and invalid ones. (Rescaling twice is
// what convert_row does; on these inputs a second rescale never changed a bit, so a kernel that
// rescaled once would pass too: the test guards the check, the mask and the data path.)
TYPED_TEST(BatchTest, EncodeOfUncheckedRowsIsCheckThenEncode) {
  using T = TypeParam;
  auto pairs = test_pairs(3000, 31);
  const std::size_t valid_rows = pairs.size();
  for (std::size_t r = 0; r < 200; ++r) {  // off unit length: accepted and rescaled, or refused
    DirPair<double> p = pairs[r];
    const double s = 1 + (r % 2 ? 3e-7 : -2e-3) * double(r % 7);
    p.wi = {p.wi.x * s, p.wi.y * s, p.wi.z * s};
    if (r % 3 == 0) p.wo.z = -p.wo.z - 1e-3;  // below the horizon
    pairs.push_back(p);
  }
  pairs.push_back({{std::nan(""), 0, 1}, {0, 0, 1}});
  const Table<T> in = inputs_for<T>({Space::dirs, false}, pairs);
  const std::size_t n = pairs.size();
  const T* in_cols[6];
  for (int c = 0; c < 6; ++c) in_cols[c] = in[c].data();
  for (SimdIsa isa : available_isas()) {
    const auto& k = detail::kernels_for(isa)->template stages<T>();
    Table<T> copy = make_table<T>(6, n);
    std::vector<T> mask_old(n), mask_new(n, detail::kUnchecked<T>);
    T* copy_cols[6];
    for (int c = 0; c < 6; ++c) copy_cols[c] = copy[c].data();
    k.check(in_cols, copy_cols, mask_old.data(), n, {});
    for (Form to : test::parameterization_forms()) {
      SCOPED_TRACE(std::string(detail::isa_name(isa)) + " dirs->" + form_name(to));
      const auto encode = k.encode[to.space.kernel_index()][to.isotropic ? 1 : 0];
      Table<T> out_old = make_table<T>(dimension(to), n), out_new = out_old;
      T *o_old[4], *o_new[4];
      for (std::size_t c = 0; c < dimension(to); ++c) {
        o_old[c] = out_old[c].data();
        o_new[c] = out_new[c].data();
      }
      std::vector<T> m_old = mask_old, m_new(n);
      encode(copy_cols, m_old.data(), m_old.data(), o_old, n, {});
      encode(in_cols, mask_new.data(), m_new.data(), o_new, n, {});
      EXPECT_EQ(m_new, m_old);
      for (std::size_t c = 0; c < dimension(to); ++c)
        EXPECT_EQ(std::memcmp(out_new[c].data(), out_old[c].data(), n * sizeof(T)), 0)
            << "column " << c;
      // The test would prove nothing if every row were valid or every row refused.
      const auto accepted = std::count(m_new.begin(), m_new.end(), T(1));
      EXPECT_GE(accepted, static_cast<std::ptrdiff_t>(valid_rows));
      EXPECT_LT(accepted, static_cast<std::ptrdiff_t>(n));
    }
  }
}

TYPED_TEST(BatchTest, InvalidRowsAreNanWithValidZero) {
  using T = TypeParam;
  const auto pairs = test_pairs(300, 21);
  std::mt19937_64 rng(4);
  for (SimdIsa isa : available_isas()) {
    IsaGuard guard(isa);
    for (Form from : all_forms()) {
      const std::size_t din = dimension(from);
      const Table<T> good = inputs_for<T>(from, pairs);
      const auto bad = invalid_rows<T>(from);
      // Interleave: every invalid row lands at a random place between valid ones, so vectors mix
      // valid and invalid lanes.
      Table<T> in = make_table<T>(din, 0);
      std::vector<int> source;  // -1: invalid, else index in `good`
      std::size_t next_bad = 0, next_good = 0;
      while (next_bad < bad.size() || next_good < pairs.size()) {
        const bool take_bad =
            next_bad < bad.size() && (next_good == pairs.size() || rng() % 3 == 0);
        for (std::size_t c = 0; c < din; ++c)
          in[c].push_back(take_bad ? bad[next_bad][c] : good[c][next_good]);
        source.push_back(take_bad ? -1 : static_cast<int>(next_good));
        take_bad ? ++next_bad : ++next_good;
      }
      for (Form to : all_forms()) {
        const std::string label =
            pair_name(from, to) + " [" + std::string(detail::isa_name(isa)) + "]";
        const Result<T> got = run_batch<T>(from, to, in, true);
        const Result<T> ref = run_scalar<T>(from, to, in);
        const Result<T> alone = run_batch<T>(from, to, good, true);
        for (std::size_t i = 0; i < source.size(); ++i) {
          ASSERT_EQ(got.valid[i], ref.valid[i]) << label << " row" << row_text(in, i);
          if (source[i] < 0) {
            ASSERT_EQ(ref.valid[i], 0) << label << ": test row is valid:" << row_text(in, i);
            for (std::size_t c = 0; c < dimension(to); ++c)
              ASSERT_TRUE(std::isnan(got.cols[c][i])) << label << row_text(in, i);
            ASSERT_TRUE(std::isnan(got.jac[i])) << label << row_text(in, i);
            continue;
          }
          // A valid row's result does not depend on its neighbours in the vector.
          const auto g = static_cast<std::size_t>(source[i]);
          bool same = std::memcmp(&got.jac[i], &alone.jac[g], sizeof(T)) == 0 &&
                      got.valid[i] == alone.valid[g];
          for (std::size_t c = 0; c < dimension(to); ++c)
            same = same && std::memcmp(&got.cols[c][i], &alone.cols[c][g], sizeof(T)) == 0;
          ASSERT_TRUE(same) << label << ": row" << row_text(in, i)
                            << " changes with its neighbours";
        }
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Threads and sizes
// ---------------------------------------------------------------------------------------------

template <class T>
Table<T> big_input(Form from, std::size_t n) {
  const auto pairs = test_pairs(5000, 31);
  const Table<T> base = inputs_for<T>(from, pairs);
  Table<T> t = make_table<T>(base.size(), n);
  for (std::size_t r = 0; r < n; ++r)
    for (std::size_t c = 0; c < base.size(); ++c)
      t[c][r] = r % 1001 == 500 ? std::numeric_limits<T>::quiet_NaN() : base[c][r % pairs.size()];
  return t;
}

const std::pair<Form, Form> kSampleConversions[] = {
    {{Space::dirs, false}, {space_of<HalfDiff>, false}},
    {{space_of<Spherical>, false}, {space_of<Hybrid>, true}},
    {{space_of<Ortho>, false}, {Space::dirs, false}},
    {{space_of<HalfDiff>, true}, {space_of<Spherical>, false}},
};

// The first element of `buffer` on a 64-byte line (a buffer a line longer than it needs).
template <class T>
T* first_line(std::vector<T>& buffer) {
  void* start = buffer.data();
  std::size_t room = buffer.size() * sizeof(T);
  return static_cast<T*>(std::align(64, sizeof(T), start, room));
}

// The engine starts its tiles on a 64-byte line of unit-stride columns that share their offset in
// a line (an aligning head of up to 7 rows, 15 in float, in batches of 16 tiles and more): rows
// are independent, so every placement of the same data gives the same bits, the head or not, the
// columns agreeing or not, columns or rows, on one thread or several.
TYPED_TEST(BatchTest, ColumnOffsetsGiveIdenticalBits) {
  using T = TypeParam;
  const std::size_t n = 16 * detail::kTileRows<T> + 37, lanes_per_line = 64 / sizeof(T);
  for (const auto& [from, to] : kSampleConversions) {
    const Table<T> in = big_input<T>(from, n);
    const Result<T> want = run_batch<T>(from, to, in, true);
    // Every column at `offset` elements past a 64-byte line, inputs at `in_offset`.
    for (std::size_t in_offset : {std::size_t{0}, std::size_t{1}, lanes_per_line - 1})
      for (std::size_t offset :
           {std::size_t{0}, std::size_t{1}, std::size_t{3}, lanes_per_line - 1})
        for (int threads : {1, 2}) {
          const std::size_t din = in.size(), dout = dimension(to), pitch = n + 2 * lanes_per_line;
          std::vector<T> buffer((din + dout + 1) * pitch + lanes_per_line);
          T* const lines = first_line(buffer);  // columns `pitch` apart: whole lines
          std::vector<ConstColumn<T>> ic;
          for (std::size_t c = 0; c < din; ++c) {
            T* col = lines + c * pitch + in_offset;
            std::copy(in[c].begin(), in[c].end(), col);
            ic.push_back({col, 1});
          }
          std::vector<Column<T>> oc;
          for (std::size_t c = 0; c < dout; ++c)
            oc.push_back({lines + (din + c) * pitch + offset, 1});
          T* jac = lines + (din + dout) * pitch + offset;
          std::vector<std::uint8_t> valid(n);
          convert<T>(from, to, ic, n, {oc, {jac, 1}, valid.data()}, {threads});
          Result<T> got{make_table<T>(dout, n), std::vector<T>(jac, jac + n), valid};
          for (std::size_t c = 0; c < dout; ++c)
            std::copy(oc[c].data, oc[c].data + n, got.cols[c].begin());
          EXPECT_TRUE(same_bits(got, want)) << pair_name(from, to) << ", offsets " << in_offset
                                            << "/" << offset << ", " << threads << " threads";
        }
    // Row-major input and output at every offset (no head: rows are not lines), no Jacobian.
    const Result<T> want_rows = run_batch<T>(from, to, in, false);
    for (std::size_t in_offset : {std::size_t{0}, std::size_t{2}, lanes_per_line - 1})
      for (std::size_t offset : {std::size_t{0}, std::size_t{2}, lanes_per_line - 1}) {
        const std::size_t din = in.size(), dout = dimension(to);
        std::vector<T> buffer((din + dout) * n + 4 * lanes_per_line);
        T* const lines = first_line(buffer);
        T* const rows_in = lines + in_offset;
        T* const rows_out = lines + (din * n / lanes_per_line + 2) * lanes_per_line + offset;
        const std::vector<T> packed = row_major(in);
        std::copy(packed.begin(), packed.end(), rows_in);
        std::vector<ConstColumn<T>> ic;
        for (std::size_t c = 0; c < din; ++c)
          ic.push_back({rows_in + c, static_cast<std::ptrdiff_t>(din)});
        std::vector<Column<T>> oc;
        for (std::size_t c = 0; c < dout; ++c)
          oc.push_back({rows_out + c, static_cast<std::ptrdiff_t>(dout)});
        std::vector<std::uint8_t> valid(n);
        convert<T>(from, to, ic, n, {oc, {}, valid.data()}, {1});
        Result<T> got{make_table<T>(dout, n), {}, valid};
        for (std::size_t r = 0; r < n; ++r)
          for (std::size_t c = 0; c < dout; ++c) got.cols[c][r] = rows_out[r * dout + c];
        EXPECT_TRUE(same_bits(got, want_rows))
            << pair_name(from, to) << ", rows at offsets " << in_offset << "/" << offset;
      }
  }
}

TYPED_TEST(BatchTest, ThreadCountsGiveIdenticalBits) {
  using T = TypeParam;
  const std::size_t n = 1000003;
  for (const auto& [from, to] : kSampleConversions) {
    const Table<T> in = big_input<T>(from, n);
    const Result<T> one = run_batch<T>(from, to, in, true, 1);
    for (int threads : {2, 7, 0}) {
      const Result<T> many = run_batch<T>(from, to, in, true, threads);
      EXPECT_TRUE(same_bits(many, one)) << pair_name(from, to) << ", " << threads << " threads";
    }
  }
}

TYPED_TEST(BatchTest, SizesIncludingEmptyAndTails) {
  using T = TypeParam;
  // n = 0 touches nothing, even through null columns.
  {
    std::vector<ConstColumn<T>> ic(6);
    std::vector<Column<T>> oc(4);
    EXPECT_NO_THROW(convert<T>({Space::dirs, false}, {space_of<Ortho>, false}, ic, 0, {oc}));
    T sentinel = T(42);
    std::uint8_t valid = 9;
    std::vector<ConstColumn<T>> ic4(4, ConstColumn<T>{&sentinel, 1});
    std::vector<Column<T>> oc6(6, Column<T>{&sentinel, 1});
    convert<T>({space_of<Hybrid>, false}, {Space::dirs, false}, ic4, 0,
               {oc6, {&sentinel, 1}, &valid});
    EXPECT_EQ(sentinel, T(42));
    EXPECT_EQ(valid, 9);
  }
  // Small sizes (one partial vector) through every pair of forms and instruction set.
  const auto pairs = test_pairs(0, 0);
  for (std::size_t n : {std::size_t{1}, std::size_t{7}}) {
    const std::vector<DirPair<double>> some(pairs.begin() + 40, pairs.begin() + 40 + n);
    for (SimdIsa isa : available_isas()) {
      IsaGuard guard(isa);
      for (Form from : all_forms()) {
        const Table<T> in = inputs_for<T>(from, some);
        for (Form to : all_forms()) {
          const std::string label = pair_name(from, to) + " n=" + std::to_string(n) + " [" +
                                    std::string(detail::isa_name(isa)) + "]";
          compare<T>(from, to, in, run_batch<T>(from, to, in, true), run_scalar<T>(from, to, in),
                     true, label);
        }
      }
    }
  }
  // A large size with a tail, threaded, against the reference.
  for (const auto& [from, to] : kSampleConversions) {
    const Table<T> in = big_input<T>(from, 1000003);
    const Stats s = compare<T>(from, to, in, run_batch<T>(from, to, in, true, 0),
                               run_scalar<T>(from, to, in), true, pair_name(from, to));
    EXPECT_GE(s.invalid, 1000003u / 1001) << pair_name(from, to);
  }
}

TEST(Batch, RejectsWrongShapes) {
  std::vector<ConstColumn<double>> in6(6), in4(4);
  std::vector<Column<double>> out4(4), out3(3), out6(6);
  const Form dirs{Space::dirs, false}, sph{space_of<Spherical>, false};
  EXPECT_THROW(convert<double>(dirs, sph, in4, 1, {out4}), std::invalid_argument);
  EXPECT_THROW(convert<double>(dirs, sph, in6, 1, {out3}), std::invalid_argument);
  EXPECT_THROW(convert<double>(sph, {Space::dirs, true}, in4, 1, {out6}), std::invalid_argument);
  EXPECT_THROW(convert<double>({Space::dirs, true}, sph, in6, 1, {out4}), std::invalid_argument);
}

TEST(Batch, DispatchPicksTheBestAvailableInstructionSet) {
  const auto isas = available_isas();
  ASSERT_FALSE(isas.empty());
  EXPECT_EQ(isas.front(), SimdIsa::scalar);
#if defined(__x86_64__)
  EXPECT_NE(detail::kernels_for(SimdIsa::sse2), nullptr);  // the x86-64 baseline
#endif
  if (std::getenv("HALFBACK_ISA") == nullptr) {
    EXPECT_EQ(detail::active_kernels().isa, isas.back());
    EXPECT_TRUE(simd_isa_request_ignored().empty());
  }
  for (SimdIsa isa : detail::kAllIsas) {
    EXPECT_EQ(detail::isa_from_name(detail::isa_name(isa)), isa);
    const bool available = detail::kernels_for(isa) != nullptr;
    EXPECT_EQ(detail::set_batch_isa(isa), available);
    if (available) {
      EXPECT_EQ(detail::active_kernels().isa, isa);
      EXPECT_EQ(simd_isa(), isa);  // the public query is the engine's choice
      EXPECT_EQ(simd_isa_name(isa), detail::isa_name(isa));
    }
  }
  detail::set_batch_isa(std::nullopt);
  EXPECT_EQ(simd_isa(), detail::active_kernels().isa);
  std::printf("  active: %s\n", std::string(detail::active_kernels().name).c_str());
}

// ---------------------------------------------------------------------------------------------
// The xsimd LaneOps mapping (batch_simd.hpp), on the SSE2 batches this TU can run everywhere
// ---------------------------------------------------------------------------------------------

template <class S>
using Sse2 = xsimd::batch<S, xsimd::sse2>;

template <class S>
std::vector<S> lanes(const Sse2<S>& b) {
  std::vector<S> v(Sse2<S>::size);
  b.store_unaligned(v.data());
  return v;
}

template <class S>
Sse2<S> make(std::initializer_list<S> v) {
  std::vector<S> a(v);
  a.resize(Sse2<S>::size, a.back());
  return Sse2<S>::load_unaligned(a.data());
}

template <class S>
double ulps(S got, long double exact) {
  const S r = static_cast<S>(exact);
  const S up = std::nextafter(std::abs(r), std::numeric_limits<S>::infinity());
  const long double ulp = static_cast<long double>(up) - std::abs(r);
  return static_cast<double>(std::abs(static_cast<long double>(got) - exact) / ulp);
}

// Error of an azimuth in [0, 2π) of (x, y), in ulp of the exact one (atan2l, wrapped). Where that
// rounds to 2π or above, the [0, 2π) azimuth is 0 or the largest value below 2π: 0 error.
template <class S>
double azimuth_error(S got, S y, S x) {
  if (!(got >= 0 && got < kTwoPi<S>) || std::signbit(got)) return 1e30;
  long double exact = atan2l(y, x);
  if (exact < 0) exact += 2 * std::numbers::pi_v<long double>;
  if (static_cast<S>(exact) >= kTwoPi<S>)
    return got == 0 || got == std::nextafter(kTwoPi<S>, S(0)) ? 0 : 1e30;
  return ulps<S>(got, exact);
}

template <class S>
class BatchLaneOps : public ::testing::Test {};
TYPED_TEST_SUITE(BatchLaneOps, Precisions, PrecisionNames);

TYPED_TEST(BatchLaneOps, Atan2SpecialValuesMatchStd) {
  using S = TypeParam;
  using L = LaneOps<Sse2<S>>;
  const S inf = std::numeric_limits<S>::infinity(), nan = std::numeric_limits<S>::quiet_NaN();
  const S ys[] = {0, -S(0), 1, -1, inf, -inf, S(1e-30), nan};
  const S xs[] = {0, -S(0), 1, -1, inf, -inf, S(1e-30), nan};
  for (S y : ys)
    for (S x : xs) {
      const S got = lanes(L::atan2(make<S>({y}), make<S>({x})))[0];
      const S want = std::atan2(y, x);
      if (std::isnan(want)) {
        EXPECT_TRUE(std::isnan(got)) << "atan2(" << y << ", " << x << ")";
      } else {
        EXPECT_LE(ulps<S>(got, want), 2.5) << "atan2(" << y << ", " << x << ")";
        EXPECT_EQ(std::signbit(got), std::signbit(want)) << "atan2(" << y << ", " << x << ")";
      }
    }
}

// Subnormal arguments: the octant tests multiply by tan(π/8), which rounds on the subnormal grid;
// atan2(2^-1074, 0) once took the middle octant with r = 1, 0.018 rad off in float; atan2 now
// scales such arguments up. Also huge ones, which it scales down. Each variant within 3 ulp of
// atan2l on its domain (the narrow ones exclude both arguments tiny, the kernels' choice).
TYPED_TEST(BatchLaneOps, Atan2IsAccurateForSubnormalAndHugeArguments) {
  using S = TypeParam;
  using L = LaneOps<Sse2<S>>;
  const S dm = std::numeric_limits<S>::denorm_min(), mn = std::numeric_limits<S>::min();
  const S mx = std::numeric_limits<S>::max();
  std::vector<S> values;
  for (int m = 0; m <= 24; ++m) values.push_back(S(m) * dm);  // exact multiples
  for (S v : {mn, S(mn / 3), S(1e-3) * mn, S(1), S(1e-5), mx, S(mx / 7)}) values.push_back(v);
  double worst = 0;
  for (S y : values)
    for (S x : values)
      for (S sy : {S(1), S(-1)})
        for (S sx : {S(1), S(-1)}) {
          const S Y = sy * y, X = sx * x;
          if (y == 0 && x == 0) continue;
          const long double want = atan2l(Y, X);
          const auto vy = make<S>({Y}), vx = make<S>({X});
          const std::string at = "(" + std::to_string(double(Y)) + ", " +
                                 std::to_string(double(X)) + ") [" + std::to_string(y / dm) + ", " +
                                 std::to_string(x / dm) + " denorm_min]";
          const double full = ulps<S>(lanes(L::atan2(vy, vx))[0], want);
          EXPECT_LE(full, 3.0) << "atan2" << at;
          worst = std::max(worst, full);
          // The narrow variants' domain: not both below `tiny`, neither beyond 2^1000 (float
          // 2^100).
          if (std::max(y, x) < Atan2Constants<S>::tiny || std::max(y, x) > S(1e20)) continue;
          EXPECT_LE(azimuth_error<S>(lanes(L::azimuth(vy, vx))[0], Y, X), 3.0) << "azimuth" << at;
          if (sy > 0 && sx > 0) {
            EXPECT_LE(ulps<S>(lanes(L::atan2_nonneg(vy, vx))[0], want), 3.0)
                << "atan2_nonneg" << at;
          }
        }
  std::printf("  atan2 at subnormal and huge arguments: worst %.2f ulp\n", worst);
}

// atan2 takes the rare cases (huge magnitudes, 0/0, ∞/∞) on a branch for the whole vector: a
// lane's result must not depend on its neighbours. Each lane of a mixed vector is compared bit
// for bit with the same value in every lane.
TYPED_TEST(BatchLaneOps, Atan2LanesAreIndependent) {
  using S = TypeParam;
  using L = LaneOps<Sse2<S>>;
  constexpr std::size_t W = Sse2<S>::size;
  const S inf = std::numeric_limits<S>::infinity(), nan = std::numeric_limits<S>::quiet_NaN();
  const S big = std::numeric_limits<S>::max() / 3;
  const S vals[] = {0, -S(0), 1, -S(0.3), S(2.5), inf, -inf, big, -big, S(1e-30), nan};
  auto bits = [](S v) {
    return std::bit_cast<std::conditional_t<sizeof(S) == 4, std::uint32_t, std::uint64_t>>(v);
  };
  for (S y0 : vals)
    for (S x0 : vals)
      for (S y1 : vals)
        for (S x1 : vals) {
          std::vector<S> y(W, y1), x(W, x1);
          y[0] = y0;
          x[0] = x0;
          const std::vector<S> mixed =
              lanes(L::atan2(Sse2<S>::load_unaligned(y.data()), Sse2<S>::load_unaligned(x.data())));
          const S alone0 = lanes(L::atan2(make<S>({y0}), make<S>({x0})))[0];
          const S alone1 = lanes(L::atan2(make<S>({y1}), make<S>({x1})))[0];
          ASSERT_EQ(bits(mixed[0]), bits(alone0))
              << y0 << " " << x0 << " beside " << y1 << " " << x1;
          ASSERT_EQ(bits(mixed[1]), bits(alone1))
              << y1 << " " << x1 << " beside " << y0 << " " << x0;
        }
}

// Twin (two vectors as one lane type) gives each half the bits of the single vector.
TYPED_TEST(BatchLaneOps, TwinHalvesAreTheSingleVectors) {
  using S = TypeParam;
  using B = Sse2<S>;
  using L = LaneOps<B>;
  using LT = LaneOps<Twin<B>>;
  const B a = make<S>({S(0.25), -S(3), S(1e-20), 0}), b = make<S>({S(-2), S(0.5), 0, S(40)});
  const B c = make<S>({S(7), S(1e5), S(-0.5), S(2)});
  const Twin<B> ta{a, b}, tb{b, c};
  auto same = [](const B& x, const B& y) {
    const std::vector<S> u = lanes(x), v = lanes(y);
    for (std::size_t k = 0; k < u.size(); ++k)
      if (std::memcmp(&u[k], &v[k], sizeof(S)) != 0) return false;
    return true;
  };
  const Twin<B> t2 = LT::atan2(ta, tb), tq = ta / tb, tf = LT::fma(ta, tb, ta);
  EXPECT_TRUE(same(t2.lo, L::atan2(a, b)) && same(t2.hi, L::atan2(b, c)));
  EXPECT_TRUE(same(tq.lo, a / b) && same(tq.hi, b / c));
  EXPECT_TRUE(same(tf.lo, L::fma(a, b, a)) && same(tf.hi, L::fma(b, c, b)));
  Twin<B> s, co;
  LT::sincos(ta, s, co);
  B s0, c0, s1, c1;
  L::sincos(a, s0, c0);
  L::sincos(b, s1, c1);
  EXPECT_TRUE(same(s.lo, s0) && same(co.lo, c0) && same(s.hi, s1) && same(co.hi, c1));
  const Twin<B> sel = LT::select(ta < tb, ta, tb);
  EXPECT_TRUE(same(sel.lo, L::select(a < b, a, b)) && same(sel.hi, L::select(b < c, b, c)));
}

// atan2_nonneg drops atan2's scaling and rare cases: on its domain it must give the bits of
// atan2, including at the octant boundaries and for -0. azimuth reduces the whole circle at once
// (k π/4 ± at): within 2.5 ulp of the exact azimuth (measured 1.9), in [0, 2π), never -0, and 0 for
// (±0, ±0).
TYPED_TEST(BatchLaneOps, NarrowAtan2sMatchAtan2) {
  using S = TypeParam;
  using L = LaneOps<Sse2<S>>;
  constexpr std::size_t W = Sse2<S>::size;
  const S t8 = Atan2Constants<S>::tan_pi_8;
  std::vector<S> edge = {0,
                         -S(0),
                         1,
                         S(1e-30),
                         std::numeric_limits<S>::min(),
                         std::numeric_limits<S>::denorm_min(),
                         t8,
                         1 / t8,
                         std::nextafter(t8, S(0)),
                         std::nextafter(t8, S(1)),
                         S(0.5),
                         S(2)};
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1, 1);
  auto bits = [](S v) {
    return std::bit_cast<std::conditional_t<sizeof(S) == 4, std::uint32_t, std::uint64_t>>(v);
  };
  double worst = 0;
  auto check = [&](const std::vector<S>& y, const std::vector<S>& x) {
    const auto Y = Sse2<S>::load_unaligned(y.data()), X = Sse2<S>::load_unaligned(x.data());
    const auto azimuth = lanes(L::azimuth(Y, X));
    const auto nonneg = lanes(L::atan2_nonneg(L::abs(Y), L::abs(X)));
    const auto full_abs = lanes(L::atan2(L::abs(Y), L::abs(X)));
    for (std::size_t k = 0; k < W; ++k) {
      const std::string at = "(" + std::to_string(y[k]) + ", " + std::to_string(x[k]) + ")";
      if (y[k] == 0 && x[k] == 0) {
        ASSERT_EQ(bits(azimuth[k]), bits(S(0))) << "azimuth" << at;
        continue;
      }
      const S tiny = Atan2Constants<S>::tiny;
      if (std::abs(y[k]) < tiny && std::abs(x[k]) < tiny) continue;  // outside both domains
      const double error = azimuth_error<S>(azimuth[k], y[k], x[k]);
      ASSERT_LE(error, 2.5) << "azimuth" << at;
      worst = std::max(worst, error);
      ASSERT_EQ(bits(nonneg[k]), bits(full_abs[k]))
          << "atan2_nonneg(|" << y[k] << "|, |" << x[k] << "|)";
    }
  };
  for (S a : edge)
    for (S b : edge)
      for (S sy : {S(1), S(-1)})
        for (S sx : {S(1), S(-1)}) check(std::vector<S>(W, sy * a), std::vector<S>(W, sx * b));
  for (int it = 0; it < 100000; ++it) {
    std::vector<S> y(W), x(W);
    for (std::size_t k = 0; k < W; ++k) {
      y[k] = static_cast<S>(u(rng) * std::pow(10.0, 3 * u(rng)));
      x[k] = static_cast<S>(u(rng) * std::pow(10.0, 3 * u(rng)));
    }
    check(y, x);
  }
  std::printf("  azimuth: worst %.2f ulp\n", worst);
}

// HalfDiff::forward skips the clamp of θh (and its atan2) when no lane can need it. A lane's
// result must be the same whether its vector takes that shortcut or not: each pair alone in a
// vector is compared with the pair beside an invalid (NaN) one, which always evaluates the clamp.
// The pairs are near h = 0 and at grazing, where the clamp acts.
TYPED_TEST(BatchLaneOps, HalfDiffClampShortcutKeepsTheBits) {
  using S = TypeParam;
  using B = Sse2<S>;
  constexpr std::size_t W = B::size;
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(0, 1);
  auto bits = [](S v) {
    return std::bit_cast<std::conditional_t<sizeof(S) == 4, std::uint32_t, std::uint64_t>>(v);
  };
  auto unit = [](double x, double y, double z) {
    const double n = std::sqrt(x * x + y * y + z * z);
    return std::array<S, 3>{S(x / n), S(y / n), S(z / n)};
  };
  const S nan = std::numeric_limits<S>::quiet_NaN();
  int clamped = 0;
  for (int it = 0; it < 50000; ++it) {
    const double phi = 2 * std::numbers::pi * u(rng), tilt = std::pow(10.0, -12 * u(rng));
    const double dphi = (u(rng) - 0.5) * std::pow(10.0, -10 * u(rng));
    const auto wi = unit(std::cos(phi), std::sin(phi), tilt * u(rng));
    const auto wo =
        unit(-std::cos(phi + dphi), -std::sin(phi + dphi), it % 3 ? tilt * u(rng) : u(rng));
    auto vec = [&](std::size_t c, bool poisoned) {
      std::vector<S> v(W, c < 3 ? wi[c] : wo[c - 3]);
      if (poisoned) v[W - 1] = nan;
      return B::load_unaligned(v.data());
    };
    auto forward = [&](bool poisoned) {
      const DirPair<B> p{{vec(0, poisoned), vec(1, poisoned), vec(2, poisoned)},
                         {vec(3, poisoned), vec(4, poisoned), vec(5, poisoned)}};
      return HalfDiff::forward(p);
    };
    const Tuple4<B> alone = forward(false), beside = forward(true);
    for (int c = 0; c < 4; ++c)
      ASSERT_EQ(bits(lanes(alone[c])[0]), bits(lanes(beside[c])[0]))
          << "column " << c << " of (" << wi[0] << ", " << wi[1] << ", " << wi[2] << ") (" << wo[0]
          << ", " << wo[1] << ", " << wo[2] << ")";
    const DirPair<double> pd{{wi[0], wi[1], wi[2]}, {wo[0], wo[1], wo[2]}};
    const double sx = pd.wi.x + pd.wo.x, sy = pd.wi.y + pd.wo.y;
    clamped +=
        HalfDiff::forward(pd)[0] < std::atan2(std::sqrt(sx * sx + sy * sy), pd.wi.z + pd.wo.z);
  }
  EXPECT_GT(clamped, 100) << "the pairs should reach the clamp";
}

TYPED_TEST(BatchLaneOps, MinMaxIgnoreNanLikeFminFmax) {
  using S = TypeParam;
  using L = LaneOps<Sse2<S>>;
  const S nan = std::numeric_limits<S>::quiet_NaN();
  const S vals[] = {nan, 1, -2, 0, -S(0)};
  for (S a : vals)
    for (S b : vals) {
      const S mn = lanes(L::min(make<S>({a}), make<S>({b})))[0];
      const S mx = lanes(L::max(make<S>({a}), make<S>({b})))[0];
      const S fmn = std::fmin(a, b), fmx = std::fmax(a, b);
      EXPECT_TRUE((std::isnan(mn) && std::isnan(fmn)) || mn == fmn) << a << " " << b;
      EXPECT_TRUE((std::isnan(mx) && std::isnan(fmx)) || mx == fmx) << a << " " << b;
    }
}

TYPED_TEST(BatchLaneOps, SincosLanesDoNotDependOnTheirNeighbours) {
  using S = TypeParam;
  using L = LaneOps<Sse2<S>>;
  constexpr std::size_t W = Sse2<S>::size;
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<S> u(0, 7);
  const S odd[] = {S(1e30), std::numeric_limits<S>::quiet_NaN(), S(1e5), S(100),
                   std::numeric_limits<S>::infinity()};
  for (int it = 0; it < 20000; ++it) {
    std::vector<S> a(W), b(W);
    for (auto& v : a) v = u(rng);
    b = a;
    b[W - 1] = odd[it % 5];  // a neighbour that needs another range reduction
    Sse2<S> sa, ca, sb, cb;
    L::sincos(Sse2<S>::load_unaligned(a.data()), sa, ca);
    L::sincos(Sse2<S>::load_unaligned(b.data()), sb, cb);
    const auto vsa = lanes(sa), vca = lanes(ca), vsb = lanes(sb), vcb = lanes(cb);
    for (std::size_t k = 0; k + 1 < W; ++k) {
      ASSERT_EQ(std::memcmp(&vsa[k], &vsb[k], sizeof(S)), 0) << a[k] << " next to " << b[W - 1];
      ASSERT_EQ(std::memcmp(&vca[k], &vcb[k], sizeof(S)), 0) << a[k] << " next to " << b[W - 1];
    }
  }
}

// The accuracy the batch tolerances rely on (see the comment on kUlps).
TYPED_TEST(BatchLaneOps, MathFunctionsAreAccurate) {
  using S = TypeParam;
  using L = LaneOps<Sse2<S>>;
  constexpr std::size_t W = Sse2<S>::size;
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst_atan2 = 0, worst_sin = 0, worst_cos = 0;
  for (int it = 0; it < 200000; ++it) {
    std::vector<S> y(W), x(W), a(W);
    for (std::size_t k = 0; k < W; ++k) {
      y[k] = static_cast<S>(u(rng) * std::pow(10.0, 4 * u(rng)));
      x[k] = static_cast<S>(u(rng) * std::pow(10.0, 4 * u(rng)));
      // [0, 6.4), [0, 1.6) and (-20π, 20π), where the own reduction serves
      a[k] = static_cast<S>(it % 3 == 2 ? u(rng) * 62.8 : (u(rng) + 1) * (it % 3 ? 3.2 : 0.8));
    }
    const auto r =
        lanes(L::atan2(Sse2<S>::load_unaligned(y.data()), Sse2<S>::load_unaligned(x.data())));
    Sse2<S> s, c;
    L::sincos(Sse2<S>::load_unaligned(a.data()), s, c);
    const auto vs = lanes(s), vc = lanes(c);
    for (std::size_t k = 0; k < W; ++k) {
      worst_atan2 = std::max(worst_atan2, ulps<S>(r[k], atan2l(y[k], x[k])));
      worst_sin = std::max(worst_sin, ulps<S>(vs[k], sinl(a[k])));
      worst_cos = std::max(worst_cos, ulps<S>(vc[k], cosl(a[k])));
    }
  }
  std::printf("  SIMD accuracy (ulp): atan2 %.2f, sin %.2f, cos %.2f\n", worst_atan2, worst_sin,
              worst_cos);
  EXPECT_LE(worst_atan2, 3.0);
  EXPECT_LE(worst_sin, 2.0);
  EXPECT_LE(worst_cos, 2.0);
}

}  // namespace
}  // namespace halfback

namespace halfback {
namespace {

// The parameterizations without SIMD kernels (PortableParams) go through the descriptors' row
// maps in blocks: the same bits as convert_one, in both directions, with the measure and the mask,
// on one thread or two.
TYPED_TEST(BatchTest, PortableParameterizationsMatchTheScalarPath) {
  using T = TypeParam;
  auto pairs = test_pairs(20000, 41);
  pairs.push_back({{0, 0, -1}, {0, 0, 1}});  // invalid
  for (Space s : kBuiltinSpaces) {
    if (s.has_kernels()) continue;
    for (const bool iso : {false, true}) {
      const Form form{s, iso};
      SCOPED_TRACE(form_name(form));
      const Table<T> dirs = inputs_for<T>({Space::dirs, false}, pairs);
      const Table<T> coords = inputs_for<T>(form, pairs);
      for (const int threads : {1, 2}) {
        for (const auto& [from, to, in] : {std::tuple{Form{Space::dirs}, form, &dirs},
                                           std::tuple{form, Form{Space::dirs}, &coords}}) {
          const Result<T> b = run_batch<T>(from, to, *in, true, threads);
          const Result<T> r = run_scalar<T>(from, to, *in);
          EXPECT_TRUE(same_bits(b, r)) << name_of(from.space) << " -> " << name_of(to.space);
          EXPECT_EQ(b.valid.back(), 0);
        }
      }
    }
  }
}

}  // namespace
}  // namespace halfback
