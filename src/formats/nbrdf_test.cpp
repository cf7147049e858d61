// Neural BRDFs: the input encoding, the evaluation against hand-computed networks, the .npy and
// Keras .h5 readers and their errors, batch vs single evaluation, no allocation in eval(), and the
// direction convention, decided against the RGL reader on the 12 RGL materials in ../shared.
#include "halfback/formats/nbrdf.hpp"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <limits>
#include <new>
#include <numbers>
#include <random>

#include "halfback/formats/rgl.hpp"
#include "support/every_isa.hpp"
#include "support/test_support.hpp"

// Counts the allocations of this thread (for the no-allocation test of eval()).
namespace {
thread_local std::size_t g_allocations = 0;
}
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
// GCC cannot see that these pair with the malloc above (a known false positive).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
#pragma GCC diagnostic pop

namespace halfback {
namespace {

using test::TempDir;
constexpr double kPi = std::numbers::pi;

Vec3<double> dir(double theta, double phi) {
  return test::direction(theta, phi);
}

// ωo and its mirror image about n (ωi = (−x, −y, z)): h is exactly n, and d = ωo.
DirPair<double> mirror_pair(const Vec3<double>& wo) {
  return {{-wo.x, -wo.y, wo.z}, wo};
}

double dot(const Vec3<double>& a, const Vec3<double>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

DirPair<double> rotate_about_n(const DirPair<double>& p, double alpha) {
  const double c = std::cos(alpha), s = std::sin(alpha);
  auto r = [&](const Vec3<double>& v) {
    return Vec3<double>{c * v.x - s * v.y, s * v.x + c * v.y, v.z};
  };
  return {r(p.wi), r(p.wo)};
}

// Pairs uniform on the hemisphere, every third one with ωi at grazing (z < 1e-3) and every
// fifth with ωo = ωi (θh = θi, d = n).
std::vector<DirPair<double>> random_pairs(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<DirPair<double>> pairs(n);
  for (std::size_t i = 0; i < n; ++i) {
    pairs[i] = {test::uniform_hemisphere(rng), test::uniform_hemisphere(rng)};
    if (i % 3 == 0) pairs[i].wi = dir(kPi / 2 - 1e-3 * double(i % 7) / 7, 0.1 * double(i));
    if (i % 5 == 0) pairs[i].wo = pairs[i].wi;
  }
  return pairs;
}

// ---------------------------------------------------------------------------------------------
// A tiny network whose outputs the tests compute by hand: 6 -> 2 (ReLU) -> 3, then exp(y) - 1.
//   h0 = relu(x0 + 0.5 x3 + x5 - 0.5),  h1 = relu(0.25 - x2)
//   y  = (h0 + 2 h1,  0.5 h0 + 0.1,  -h0 + h1 + 0.2)
// ---------------------------------------------------------------------------------------------
NbrdfNetwork tiny_network() {
  NbrdfNetwork net;
  net.source = "tiny";
  net.form = "test";
  net.layers.push_back({6,
                        2,
                        {1, 0,    //
                         0, 0,    //
                         0, -1,   //
                         0.5, 0,  //
                         0, 0,    //
                         1, 0},
                        {-0.5f, 0.25f}});
  net.layers.push_back({2, 3, {1, 0.5f, -1, 2, 0, 1}, {0, 0.1f, 0.2f}});
  return net;
}

std::array<double, 3> tiny_expected(const std::array<double, 6>& x) {
  const double h0 = std::max(x[0] + 0.5 * x[3] + x[5] - 0.5, 0.0);
  const double h1 = std::max(0.25 - x[2], 0.0);
  const double y[3] = {h0 + 2 * h1, 0.5 * h0 + 0.1, -h0 + h1 + 0.2};
  return {std::max(std::exp(y[0]) - 1, 0.0), std::max(std::exp(y[1]) - 1, 0.0),
          std::max(std::exp(y[2]) - 1, 0.0)};
}

void expect_rgb_near(const Rgb& got, const std::array<double, 3>& want, double rel) {
  EXPECT_NEAR(got.r, want[0], rel * std::max(1.0, std::abs(want[0])));
  EXPECT_NEAR(got.g, want[1], rel * std::max(1.0, std::abs(want[1])));
  EXPECT_NEAR(got.b, want[2], rel * std::max(1.0, std::abs(want[2])));
}

TEST(NbrdfEncode, HalfVectorAtNormalGivesDifferenceEqualToWo) {
  const double a = kPi / 3, b = 0.4;
  const auto x = nbrdf::encode(mirror_pair(dir(a, b)));
  // d = ωo itself, with its sign of y: a mirrored convention (dy → −dy) would fail here.
  const std::array<double, 6> want{
      0, 0, 1, std::sin(a) * std::cos(b), std::sin(a) * std::sin(b), std::cos(a)};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(x[i], want[i], 1e-15) << i;
}

TEST(NbrdfEncode, EqualDirectionsGiveTheHalfVectorAndDAlongN) {
  const double t = 1.2;
  const auto x = nbrdf::encode({dir(t, 0.7), dir(t, 0.7)});
  const std::array<double, 6> want{std::sin(t), 0, std::cos(t), 0, 0, 1};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(x[i], want[i], 1e-15) << i;
}

TEST(NbrdfEncode, DIsUnitAtAngleThetaDAndInvariantUnderRotationAboutN) {
  std::mt19937_64 rng(7);
  for (int i = 0; i < 1000; ++i) {
    const DirPair<double> p{test::uniform_hemisphere(rng), test::uniform_hemisphere(rng)};
    const auto x = nbrdf::encode(p);
    const double d_norm = std::sqrt(x[3] * x[3] + x[4] * x[4] + x[5] * x[5]);
    EXPECT_NEAR(d_norm, 1, 1e-12);
    // cos θd = h·ωo, and in the half-vector frame h is n, so dz = cos θd.
    Vec3<double> h{p.wi.x + p.wo.x, p.wi.y + p.wo.y, p.wi.z + p.wo.z};
    const double hn = std::sqrt(dot(h, h));
    EXPECT_NEAR(x[5], dot(h, p.wo) / hn, 1e-12);
    EXPECT_NEAR(x[2], h.z / hn, 1e-12);
    const auto y = nbrdf::encode(rotate_about_n(p, 1.3));
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(x[k], y[k], 1e-12) << k;
  }
}

TEST(NbrdfEval, TinyNetworkMatchesHandComputedOutputs) {
  const NbrdfBrdf brdf(tiny_network(), "tiny");
  const double a = kPi / 3, t = 80 * kPi / 180;
  // h = n, d = (0, 0, 1): y = (0.5, 0.35, -0.3).
  expect_rgb_near(brdf.eval({dir(0, 0), dir(0, 0)}), {std::exp(0.5) - 1, std::exp(0.35) - 1, 0.0},
                  1e-6);
  // h = n, d = ωo = (sin a, 0, cos a): the convention d = ωo (not ωi, which gives dx = -sin a).
  expect_rgb_near(brdf.eval(mirror_pair(dir(a, 0))),
                  tiny_expected({0, 0, 1, std::sin(a), 0, std::cos(a)}), 1e-6);
  // Both hidden units active: ωi = ωo at θ = 80°.
  expect_rgb_near(brdf.eval({dir(t, 2.0), dir(t, 2.0)}),
                  tiny_expected({std::sin(t), 0, std::cos(t), 0, 0, 1}), 1e-6);
  const Rgb swapped = brdf.eval(mirror_pair({-std::sin(a), 0, std::cos(a)}));
  // The swapped convention (d = ωi) would give a clearly different value.
  EXPECT_GT(std::abs(swapped.r - tiny_expected({0, 0, 1, std::sin(a), 0, std::cos(a)})[0]), 0.1);
}

TEST(NbrdfEval, BelowHorizonIsZeroAndNanIsNan) {
  const NbrdfBrdf brdf(tiny_network(), "tiny");
  EXPECT_EQ(brdf.eval({dir(0.3, 0), {0.1, 0, -0.5}}), (Rgb{0, 0, 0}));
  EXPECT_TRUE(std::isnan(brdf.eval({{std::nan(""), 0, 1}, dir(0.2, 1)}).g));
  // ωo = −ωi at grazing: h is taken as n, a finite value.
  const Rgb grazing = brdf.eval({{1, 0, 0}, {-1, 0, 0}});
  EXPECT_TRUE(std::isfinite(grazing.r) && std::isfinite(grazing.g) && std::isfinite(grazing.b));
}

// The block kernel in the version of every instruction set (isa_versions.hpp: what HALFBACK_ISA
// runs) against the one-pair path, within FMA rounding.
TEST(NbrdfEval, BatchMatchesSinglePairEvaluation) {
  const NbrdfBrdf brdf(tiny_network(), "tiny");
  std::vector<DirPair<double>> pairs = random_pairs(10007, 3);
  pairs[5] = {{std::nan(""), 0, 1}, dir(0.2, 1)};
  pairs[6] = {dir(0.2, 1), {0.3, 0, -0.2}};
  std::vector<Rgb> batch(pairs.size());
  test::under_every_isa([&](SimdIsa) {
    brdf.eval_batch(pairs, batch);
    std::size_t compared = 0;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const Rgb one = brdf.eval(pairs[i]);
      if (std::isnan(one.r)) {
        EXPECT_TRUE(std::isnan(batch[i].r)) << i;
        continue;
      }
      expect_rgb_near(batch[i], {one.r, one.g, one.b}, 1e-6);
      ++compared;
    }
    EXPECT_GT(compared, 10000u);
  });
  EXPECT_THROW(brdf.eval_batch(pairs, std::span<Rgb>(batch).first(3)), std::invalid_argument);
}

TEST(NbrdfEval, SinglePairEvaluationDoesNotAllocate) {
  const NbrdfBrdf brdf(tiny_network(), "tiny");
  const DirPair<double> pair{dir(0.4, 0.1), dir(0.9, 2.5)};
  const std::size_t before = g_allocations;
  double sum = 0;
  for (int i = 0; i < 100; ++i) sum += brdf.eval(pair).g;
  EXPECT_EQ(g_allocations, before);
  EXPECT_GT(sum, 0);
  // The counter does count: a vector allocates.
  std::vector<int> v(10);
  EXPECT_GT(g_allocations, before);
}

TEST(NbrdfNetworkCheck, RejectsWrongShapesAndNonFiniteWeights) {
  auto rejects = [](NbrdfNetwork net, const std::string& part) {
    EXPECT_FORMAT_ERROR(NbrdfBrdf(std::move(net), "x"), std::string("tiny"), part);
  };
  NbrdfNetwork net = tiny_network();
  net.layers[0].kernel[3] = std::numeric_limits<float>::quiet_NaN();
  rejects(net, "NaN or infinite");
  net = tiny_network();
  net.layers[1].bias[1] = std::numeric_limits<float>::infinity();
  rejects(net, "NaN or infinite");
  net = tiny_network();
  net.layers[0].inputs = 5;
  net.layers[0].kernel.resize(10);
  rejects(net, "5 inputs, expected 6");
  net = tiny_network();
  net.layers[1] = {2, 4, std::vector<float>(8, 0.f), std::vector<float>(4, 0.f)};
  rejects(net, "must give 3");
  net = tiny_network();
  net.layers.clear();
  rejects(net, "0 dense layers");
}

// ---------------------------------------------------------------------------------------------
// .npy
// ---------------------------------------------------------------------------------------------
std::string npy(const std::string& shape, const std::vector<float>& values,
                const std::string& descr = "<f4", const std::string& order = "False") {
  std::string header =
      "{'descr': '" + descr + "', 'fortran_order': " + order + ", 'shape': " + shape + ", }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string out("\x93NUMPY\x01\x00", 8);
  out += char(header.size() & 0xff);
  out += char(header.size() >> 8);
  out += header;
  out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
  return out;
}

NpyArray parse(const std::string& bytes) {
  return parse_npy_float32({reinterpret_cast<const std::byte*>(bytes.data()), bytes.size()},
                           "a.npy");
}

void write_npy_network(const std::filesystem::path& dir, const std::string& stem,
                       const NbrdfNetwork& net) {
  for (std::size_t l = 0; l < net.layers.size(); ++l) {
    const NbrdfLayer& layer = net.layers[l];
    const std::string k =
        npy("(" + std::to_string(layer.inputs) + ", " + std::to_string(layer.outputs) + ")",
            layer.kernel);
    const std::string b = npy("(" + std::to_string(layer.outputs) + ",)", layer.bias);
    test::write_bytes(dir / (stem + "_fc" + std::to_string(l + 1) + ".npy"), k.data(), k.size());
    test::write_bytes(dir / (stem + "_b" + std::to_string(l + 1) + ".npy"), b.data(), b.size());
  }
}

TEST(Npy, ParsesShapeAndValues) {
  const NpyArray a = parse(npy("(2, 3)", {1, 2, 3, 4, 5, 6.5f}));
  EXPECT_EQ(a.shape, (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(a.values, (std::vector<float>{1, 2, 3, 4, 5, 6.5f}));
  EXPECT_EQ(parse(npy("(3,)", {1, 2, 3})).shape, (std::vector<std::size_t>{3}));
}

TEST(Npy, RejectsOtherDtypesOrdersAndSizes) {
  EXPECT_FORMAT_ERROR(parse(npy("(2,)", {1, 2}, "<f8")), "a.npy", "dtype", "'<f8'");
  EXPECT_FORMAT_ERROR(parse(npy("(2,)", {1, 2}, ">f4")), "dtype", "'>f4'");
  EXPECT_FORMAT_ERROR(parse(npy("(2, 1)", {1, 2}, "<f4", "True")), "fortran_order");
  EXPECT_FORMAT_ERROR(parse(npy("(3,)", {1, 2})), "file size", "declares 140 bytes",
                      "has 136 bytes", "truncated");
  EXPECT_FORMAT_ERROR(parse(npy("(1,)", {1, 2})), "file size", "declares 132 bytes",
                      "has 136 bytes", "4 bytes of trailing data");
  EXPECT_FORMAT_ERROR(parse(npy("(4000000000, 4000000000)", {1})), "shape");
  EXPECT_FORMAT_ERROR(parse("\x93NUMPZ\x01\x00\x00\x00"), "not a NumPy");
  std::string cut = npy("(2,)", {1, 2});
  EXPECT_FORMAT_ERROR(parse(cut.substr(0, 40)), "header", "past the end");
  std::string bad = npy("(2,)", {1, 2});
  bad.replace(bad.find("'shape'"), 7, "'shapz'");
  EXPECT_FORMAT_ERROR(parse(bad), "npy header", "'shapz'");
}

TEST(NbrdfNpy, ReadsTheSixFileFormByFileOrFolder) {
  TempDir tmp;
  write_npy_network(tmp.path(), "tiny", tiny_network());
  for (const auto& path : {tmp / "tiny_fc1.npy", tmp.path()}) {
    const auto brdf = load_nbrdf(path);
    EXPECT_EQ(brdf->name(), "nbrdf:tiny");
    EXPECT_EQ(brdf->architecture(), "6-2-3");
    EXPECT_EQ(brdf->parameter_count(), 12u + 2 + 6 + 3);
    const double a = kPi / 3;
    expect_rgb_near(brdf->eval(mirror_pair(dir(a, 0.4))),
                    tiny_expected({0, 0, 1, std::sin(a) * std::cos(0.4),
                                   std::sin(a) * std::sin(0.4), std::cos(a)}),
                    1e-6);
  }
}

TEST(NbrdfNpy, MissingFilesAndMismatchedShapesAreNamed) {
  TempDir tmp;
  write_npy_network(tmp.path(), "m", tiny_network());
  std::filesystem::remove(tmp / "m_b2.npy");
  EXPECT_FORMAT_ERROR(load_nbrdf(tmp.path()), "m_b2.npy", "missing");
  const std::string b = npy("(5,)", {1, 2, 3, 4, 5});
  test::write_bytes(tmp / "m_b2.npy", b.data(), b.size());
  EXPECT_FORMAT_ERROR(load_nbrdf(tmp.path()), "m_b2.npy", "5 values for a kernel of 3 outputs");
  const std::string k = npy("(2, 3)", {1, 2, 3, 4, 5, 6}, "<f8");
  test::write_bytes(tmp / "m_fc2.npy", k.data(), k.size());
  EXPECT_FORMAT_ERROR(load_nbrdf(tmp.path()), "m_fc2.npy", "dtype");
  write_npy_network(tmp.path(), "n", tiny_network());
  EXPECT_FORMAT_ERROR(load_nbrdf(tmp.path()), "2 *_fc1.npy files");
  NbrdfNetwork nan = tiny_network();
  nan.layers[1].kernel[2] = std::numeric_limits<float>::quiet_NaN();
  TempDir other;
  write_npy_network(other.path(), "nan", nan);
  EXPECT_FORMAT_ERROR(load_nbrdf(other.path()), "nan_fc1.npy", "layer 2", "NaN");
}

// ---------------------------------------------------------------------------------------------
// Keras .h5, written by the test with the HDF5 C API
// ---------------------------------------------------------------------------------------------
struct KerasFileOptions {
  bool lambda_layer = true;    // the trailing weightless output layer
  bool double_kernel = false;  // layer 1's kernel as float64
  std::string omit_dataset;    // e.g. "dense_2/bias:0"
};

void write_string_attribute(hid_t loc, const char* name, const std::vector<std::string>& items) {
  std::size_t width = 1;
  for (const auto& s : items) width = std::max(width, s.size());
  std::string buffer(items.size() * width, '\0');
  for (std::size_t i = 0; i < items.size(); ++i)
    buffer.replace(i * width, items[i].size(), items[i]);
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, width);
  const hsize_t n = items.size();
  const hid_t space = H5Screate_simple(1, &n, nullptr);
  const hid_t attr = H5Acreate2(loc, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attr, type, buffer.data());
  H5Aclose(attr), H5Sclose(space), H5Tclose(type);
}

void write_dataset(hid_t group, const std::string& path, const std::vector<hsize_t>& dims,
                   const std::vector<float>& values, bool as_double) {
  const hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(lcpl, 1);
  const hid_t space = H5Screate_simple(int(dims.size()), dims.data(), nullptr);
  const hid_t type = as_double ? H5T_IEEE_F64LE : H5T_IEEE_F32LE;
  const hid_t data = H5Dcreate2(group, path.c_str(), type, space, lcpl, H5P_DEFAULT, H5P_DEFAULT);
  H5Dwrite(data, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
  H5Dclose(data), H5Sclose(space), H5Pclose(lcpl);
}

void write_keras_h5(const std::filesystem::path& path, const NbrdfNetwork& net,
                    const KerasFileOptions& options = {}) {
  const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  std::vector<std::string> names;
  for (std::size_t l = 0; l < net.layers.size(); ++l)
    names.push_back("dense_" + std::to_string(l + 1));
  if (options.lambda_layer) names.push_back("lambda_1");
  write_string_attribute(file, "layer_names", names);
  for (std::size_t l = 0; l < names.size(); ++l) {
    const hid_t group = H5Gcreate2(file, names[l].c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (l < net.layers.size()) {
      const NbrdfLayer& layer = net.layers[l];
      const std::string k = names[l] + "/kernel:0", b = names[l] + "/bias:0";
      write_string_attribute(group, "weight_names", {k, b});
      if (options.omit_dataset != k)
        write_dataset(group, k, {layer.inputs, layer.outputs}, layer.kernel,
                      options.double_kernel && l == 0);
      if (options.omit_dataset != b) write_dataset(group, b, {layer.outputs}, layer.bias, false);
    } else {
      write_string_attribute(group, "weight_names", {});
    }
    H5Gclose(group);
  }
  H5Fclose(file);
}

TEST(NbrdfH5, ReadsAKerasWeightsFileWrittenByHdf5) {
  TempDir tmp;
  write_keras_h5(tmp / "tiny.h5", tiny_network());
  const auto brdf = load_nbrdf(tmp / "tiny.h5");
  EXPECT_EQ(brdf->name(), "nbrdf:tiny");
  EXPECT_EQ(brdf->network().form, "Keras HDF5");
  const double t = 80 * kPi / 180;
  expect_rgb_near(brdf->eval({dir(t, 2.0), dir(t, 2.0)}),
                  tiny_expected({std::sin(t), 0, std::cos(t), 0, 0, 1}), 1e-6);
  // The same from a file image in memory.
  std::ifstream in(tmp / "tiny.h5", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const NbrdfNetwork net =
      parse_nbrdf_h5({reinterpret_cast<const std::byte*>(bytes.data()), bytes.size()}, "mem");
  EXPECT_EQ(net.layers[1].kernel, tiny_network().layers[1].kernel);
}

TEST(NbrdfH5, BadFilesGiveErrorsNamingTheProblem) {
  TempDir tmp;
  KerasFileOptions options;
  options.omit_dataset = "dense_2/bias:0";
  write_keras_h5(tmp / "a.h5", tiny_network(), options);
  EXPECT_FORMAT_ERROR(read_nbrdf_h5(tmp / "a.h5"), "a.h5", "dense_2/bias:0", "missing");
  options = {};
  options.double_kernel = true;
  write_keras_h5(tmp / "b.h5", tiny_network(), options);
  EXPECT_FORMAT_ERROR(read_nbrdf_h5(tmp / "b.h5"), "b.h5", "dense_1/kernel:0", "float32");
  options = {};
  options.lambda_layer = false;
  write_keras_h5(tmp / "c.h5", tiny_network(), options);
  EXPECT_FORMAT_ERROR(read_nbrdf_h5(tmp / "c.h5"), "c.h5", "last layer has weights");
  NbrdfNetwork wide = tiny_network();
  wide.layers[0] = {5, 2, std::vector<float>(10, 0.1f), {0, 0}};
  write_keras_h5(tmp / "d.h5", wide);
  EXPECT_FORMAT_ERROR(load_nbrdf(tmp / "d.h5"), "d.h5", "5 inputs, expected 6");
  NbrdfNetwork inf = tiny_network();
  inf.layers[0].bias[0] = std::numeric_limits<float>::infinity();
  write_keras_h5(tmp / "e.h5", inf);
  EXPECT_FORMAT_ERROR(load_nbrdf(tmp / "e.h5"), "e.h5", "NaN or infinite");
  const std::string text = "not hdf5 at all";
  test::write_bytes(tmp / "f.h5", text.data(), text.size());
  EXPECT_FORMAT_ERROR(read_nbrdf_h5(tmp / "f.h5"), "f.h5", "not an HDF5 file");
  // Truncated: the first half of a valid file.
  std::ifstream in(tmp / "e.h5", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  test::write_bytes(tmp / "g.h5", bytes.data(), bytes.size() / 2);
  EXPECT_FORMAT_ERROR(read_nbrdf_h5(tmp / "g.h5"), "g.h5");
  EXPECT_FORMAT_ERROR(
      parse_nbrdf_h5({reinterpret_cast<const std::byte*>(bytes.data()), bytes.size() / 2}, "mem"),
      "mem");
}

// A corrupt address in the root group's symbol-table entry (byte 135 of a file written by
// Debian's HDF5: the high byte of the scratch pad's B-tree address) makes libhdf5 ask malloc for
// 0x5800...: an error naming the file, not a crash (the fuzzer's find; ASan lets malloc return
// null as a release build's does, see CMakePresets.json).
TEST(NbrdfH5, AbsurdAddressInTheRootEntryIsAnError) {
  TempDir tmp;
  write_keras_h5(tmp / "a.h5", tiny_network());
  std::ifstream in(tmp / "a.h5", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  ASSERT_GT(bytes.size(), 136u);
  ASSERT_EQ(bytes[135], 0) << "the superblock's layout changed: find the entry again";
  bytes[135] = 0x58;
  EXPECT_FORMAT_ERROR(
      parse_nbrdf_h5({reinterpret_cast<const std::byte*>(bytes.data()), bytes.size()}, "mem"),
      "mem");
}

// docs/reliability/readers.md, "A reader reads what the file's header declares, and nothing more":
// an HDF5 file ends at the end of file address of its superblock, a .npy file after the data its
// header declares; anything after is refused with both byte counts, unread (a file extended to a
// gigabyte by truncate -s).
TEST(NbrdfTrailingData, RefusedWithBothCounts) {
  TempDir tmp;
  write_keras_h5(tmp / "t.h5", tiny_network());
  const std::string bytes = test::read_file(tmp / "t.h5");
  const std::string more = bytes + "junk";
  test::write_bytes(tmp / "j.h5", more.data(), more.size());
  EXPECT_FORMAT_ERROR(read_nbrdf_h5(tmp / "j.h5"), std::string("j.h5: file size"),
                      "declares " + std::to_string(bytes.size()) + " bytes",
                      std::string("4 bytes of trailing data"));
  EXPECT_FORMAT_ERROR(
      parse_nbrdf_h5({reinterpret_cast<const std::byte*>(more.data()), more.size()}, "mem"), "mem",
      "4 bytes of trailing data");
  std::filesystem::resize_file(tmp / "j.h5", std::uintmax_t(1) << 30);
  EXPECT_FORMAT_ERROR(load_nbrdf(tmp / "j.h5"), "j.h5", "has 1073741824 bytes", "trailing data");

  write_npy_network(tmp.path(), "n", tiny_network());
  std::filesystem::resize_file(tmp / "n_b2.npy", std::uintmax_t(1) << 30);
  EXPECT_FORMAT_ERROR(load_nbrdf(tmp / "n_fc1.npy"), "n_b2.npy", "declares 140 bytes",
                      "has 1073741824 bytes", "trailing data");
}

// docs/reliability/readers.md, "One bound on a BRDF's value": a network whose outputs are absurd (a
// last bias of 100: ρ = e¹⁰⁰ − 1, 1.65e38 sr⁻¹ in float, everywhere) is refused at load, naming the
// file; its ρ is checked on the probe set when interval arithmetic through the layers cannot prove
// it bounded everywhere.
TEST(NbrdfBound, DivergingNetworkIsRefusedAtLoad) {
  TempDir tmp;
  NbrdfNetwork net = tiny_network();
  {
    const NbrdfBrdf tiny(net, "tiny");  // y ≤ 2.6 on the inputs' box: proven
    const auto facts = tiny.facts();
    EXPECT_NE(facts.back().value.find("everywhere (interval arithmetic"), std::string::npos)
        << facts.back().value;
  }
  net.layers[1].bias = {100, 100, 100};
  write_npy_network(tmp.path(), "hot", net);
  EXPECT_FORMAT_ERROR(load_nbrdf(tmp.path()), "hot_fc1.npy", "network",
                      "above the bound of 1e+10 sr⁻¹ on a BRDF's value", "last layer");
  write_keras_h5(tmp / "hot.h5", net);
  EXPECT_FORMAT_ERROR(load_nbrdf(tmp / "hot.h5"), "hot.h5", "network", "above the bound");
  // y = 16 (sin θh + cos θh) ≤ 16√2 = 22.6, ρ ≤ 6.6e9: within the bound, but interval arithmetic,
  // which takes sin θh and cos θh as independent, gives y ≤ 32, ρ ≤ 7.9e13: checked on the probe.
  net.layers = {{6, 2, std::vector<float>(12, 0.0f), {0, 0}},
                {2, 3, {1, 0, 0, 0, 0, 0}, {0, 0, 0}}};
  net.layers[0].kernel[0] = net.layers[0].kernel[4] = 16;  // x0 and x2 → h0
  const NbrdfBrdf loose(net, "loose");
  EXPECT_NE(loose.facts().back().value.find("on the probe set"), std::string::npos)
      << loose.facts().back().value;
}

// ---------------------------------------------------------------------------------------------
// The published networks (../shared/data/nbrdf)
// ---------------------------------------------------------------------------------------------
TEST(NbrdfShared, H5AndNpyFormsOfBlueAcrylicAreTheSameNetwork) {
  HALFBACK_REQUIRE_SHARED(dir, "nbrdf/merl_nbrdf");
  const auto h5 = load_nbrdf(dir / "blue-acrylic.h5");
  const auto npy = load_nbrdf(dir / "npy");
  EXPECT_EQ(h5->architecture(), "6-21-21-3");
  EXPECT_EQ(h5->parameter_count(), 675u);
  ASSERT_EQ(h5->network().layers.size(), npy->network().layers.size());
  for (std::size_t l = 0; l < 3; ++l) {
    EXPECT_EQ(h5->network().layers[l].kernel, npy->network().layers[l].kernel);
    EXPECT_EQ(h5->network().layers[l].bias, npy->network().layers[l].bias);
  }
}

// Luminance agreement of a network with the RGL file it was trained on, over pairs with both
// directions at z > 0.1: the median of 2|a − b| / (a + b). `transform` maps the pair the network
// is evaluated at (the identity, or a wrong convention).
template <class Transform>
double median_relative_difference(const Brdf& rgl, const Brdf& net, Transform transform) {
  std::mt19937_64 rng(2021);
  std::vector<DirPair<double>> pairs;
  while (pairs.size() < 4000) {
    const DirPair<double> p{test::uniform_hemisphere(rng), test::uniform_hemisphere(rng)};
    if (p.wi.z > 0.1 && p.wo.z > 0.1) pairs.push_back(p);
  }
  std::vector<double> diffs;
  for (const auto& p : pairs) {
    const double a = rgl.eval(p).luminance(), b = net.eval(transform(p)).luminance();
    if (a + b > 0) diffs.push_back(2 * std::abs(a - b) / (a + b));
  }
  std::nth_element(diffs.begin(), diffs.begin() + diffs.size() / 2, diffs.end());
  return diffs[diffs.size() / 2];
}

// The agreement measured with the convention d = ωo (docs/formats.md, "Neural BRDFs"), as the
// median relative luminance difference of median_relative_difference(); the bound is 10% above
// it. Every material's swapped convention (d = ωi) measures above its bound (by 14% for the
// closest, irid_flake_paint2 and cc_ibiza_sunset, 2x to 7.6x for most), so the test fails if
// the convention is swapped; a mirrored one (dy → −dy) is pinned by NbrdfEncode instead, the RGL
// data being symmetric about the plane of incidence.
struct Agreement {
  const char* material;
  double median;
};
constexpr Agreement kAgreement[] = {
    {"acrylic_felt_green_rgb", 0.0271}, {"aurora_white_rgb", 0.0330},
    {"cardboard_rgb", 0.0433},          {"cc_ibiza_sunset_rgb", 0.3068},
    {"chm_mint_rgb", 0.1969},           {"colodur_azure_4e_rgb", 0.0233},
    {"ilm_l3_37_metallic_rgb", 0.2132}, {"irid_flake_paint2_rgb", 0.2022},
    {"leaf_maple_rgb", 0.0219},         {"paper_white_rgb", 0.0104},
    {"satin_rosaline_rgb", 0.0240},     {"vch_golden_yellow_rgb", 0.0917},
};

TEST(NbrdfShared, DirectionConventionAgreesWithTheRglReader) {
  HALFBACK_REQUIRE_SHARED(rgl_dir, "rgl");
  HALFBACK_REQUIRE_SHARED(net_dir, "nbrdf/rgl-isotropic_nbrdf");
  auto identity = [](const DirPair<double>& p) { return p; };
  auto swapped = [](const DirPair<double>& p) { return DirPair<double>{p.wo, p.wi}; };
  double total_right = 0, total_swapped = 0;
  for (const Agreement& a : kAgreement) {
    const auto rgl = load_rgl(rgl_dir / (std::string(a.material) + ".bsdf"));
    const auto net = load_nbrdf(net_dir / (std::string(a.material) + ".h5"));
    const double right = median_relative_difference(*rgl, *net, identity);
    const double swap = median_relative_difference(*rgl, *net, swapped);
    EXPECT_LT(right, 1.1 * a.median) << a.material;
    EXPECT_GT(right, 0.9 * a.median) << a.material << " (agrees better than measured: update)";
    EXPECT_GT(swap, 1.1 * a.median) << a.material << ": the swapped convention fits as well";
    total_right += right, total_swapped += swap;
  }
  EXPECT_GT(total_swapped, 1.5 * total_right);
}

// ---------------------------------------------------------------------------------------------
// The writer: the authors' pair of files, read back by this reader
// ---------------------------------------------------------------------------------------------
TEST(NbrdfWrite, WritesWhatTheReaderReadsBack) {
  TempDir tmp;
  write_nbrdf(tmp / "w.h5", tiny_network(), {{"trained_from", "a test"}});
  const auto brdf = load_nbrdf(tmp / "w.h5");
  EXPECT_EQ(brdf->name(), "nbrdf:w");
  ASSERT_EQ(brdf->network().layers.size(), 2u);
  for (std::size_t l = 0; l < 2; ++l) {
    EXPECT_EQ(brdf->network().layers[l].kernel, tiny_network().layers[l].kernel);
    EXPECT_EQ(brdf->network().layers[l].bias, tiny_network().layers[l].bias);
  }
  const std::string json = test::read_file(tmp / "w.json");
  for (const char* part : {R"("class_name":"Sequential")", R"("units":2,"activation":"relu")",
                           R"("units":3,"activation":"linear")", R"("function":"exp_minus_one")",
                           R"("input":"sztrajman-halfdiff","trained_from":"a test")"})
    EXPECT_NE(json.find(part), std::string::npos) << part << " not in " << json;
  // Written again over both: replaced, nothing else left in the folder.
  write_nbrdf(tmp / "w.h5", tiny_network());
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(tmp.path())) ++files;
  EXPECT_EQ(files, 2u);
}

// A network of three inputs, the isotropic coordinates of a parameterization named in the file.
NbrdfNetwork tiny_param_network(const std::string& input) {
  NbrdfNetwork net = tiny_network();
  net.input = input;
  net.layers[0].inputs = 3;
  net.layers[0].kernel.resize(3 * 2);  // rows x0, x1, x2 of tiny_network's kernel
  return net;
}

TEST(NbrdfWrite, NetworkOfAParameterizationsCoordinatesReadsBack) {
  TempDir tmp;
  write_nbrdf(tmp / "h.h5", tiny_param_network("halfdiff"));
  const auto brdf = load_nbrdf(tmp / "h.h5");
  EXPECT_EQ(brdf->network().input, "halfdiff");
  EXPECT_EQ(brdf->architecture(), "3-2-3");
  // tiny_network on x = (θh, θd, φd): hidden h0 = relu(x0 − 0.5), h1 = relu(0.25 − x2), then
  // y = (h0 + 2 h1, 0.5 h0 + 0.1, −h0 + h1 + 0.2) (its kernel's first three rows).
  const DirPair<double> pair{{0.3, 0.1, std::sqrt(1 - 0.1)}, {-0.2, 0.4, std::sqrt(1 - 0.2)}};
  const auto q = space_from_name("halfdiff")->param().forward_iso(pair);
  const double h0 = std::max(double(float(q[0])) - 0.5, 0.0);
  const double h1 = std::max(0.25 - double(float(q[2])), 0.0);
  expect_rgb_near(
      brdf->eval(pair),
      {std::max(std::expm1(h0 + 2 * h1), 0.0), std::max(std::expm1(0.5 * h0 + 0.1), 0.0),
       std::max(std::expm1(-h0 + h1 + 0.2), 0.0)},
      1e-6);
  std::vector<Rgb> batch(1);
  brdf->eval_batch(std::span(&pair, 1), batch);
  EXPECT_EQ(batch[0], brdf->eval(pair));
  const auto facts = brdf->facts();
  EXPECT_NE(facts[4].value.find("isotropic coordinates of halfdiff (theta_h, theta_d, phi_d)"),
            std::string::npos)
      << facts[4].value;
}

TEST(NbrdfWrite, ReaderRefusesAnInputItCannotEvaluate) {
  TempDir tmp;
  // Names that are no built-in parameterization: write_nbrdf refuses them as the reader does.
  for (const std::string input : {"nonesuch", "dupuy-jakob:ggx", "dirs"})
    EXPECT_FORMAT_ERROR(write_nbrdf(tmp / "n.h5", tiny_param_network(input)),
                        std::string("halfback_input"), "'" + input + "'");
  // A file whose attribute names another input (rewritten with the HDF5 C API): the reader
  // refuses it.
  write_nbrdf(tmp / "r.h5", tiny_param_network("halfdiff"));
  {
    const hid_t file = H5Fopen((tmp / "r.h5").c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(file, 0);
    H5Adelete(file, "halfback_input");
    write_string_attribute(file, "halfback_input", {"nonesuch"});
    H5Fclose(file);
  }
  EXPECT_FORMAT_ERROR(load_nbrdf(tmp / "r.h5"), "r.h5", "halfback_input", "'nonesuch'",
                      "this reader evaluates Sztrajman et al.'s input");
  std::filesystem::remove(tmp / "r.h5");
  std::filesystem::remove(tmp / "r.json");
  // A parameterization's name on a network of Sztrajman's 6 inputs.
  NbrdfNetwork six = tiny_network();
  six.input = "hybrid";
  EXPECT_FORMAT_ERROR(write_nbrdf(tmp / "s.h5", six), "layer 1",
                      "expected 3 (the isotropic coordinates of hybrid)");
  EXPECT_TRUE(std::filesystem::is_empty(tmp.path()));
}

TEST(NbrdfWrite, RefusesWhatItCannotWriteAndWritesNothing) {
  TempDir tmp;
  NbrdfNetwork nan = tiny_network();
  nan.layers[1].bias[0] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(write_nbrdf(tmp / "n.h5", nan), FormatError);
  EXPECT_THROW(write_nbrdf(tmp / "j.json", tiny_network()), std::invalid_argument);
  EXPECT_TRUE(std::filesystem::is_empty(tmp.path()));
}

}  // namespace
}  // namespace halfback
