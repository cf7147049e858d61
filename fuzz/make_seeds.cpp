// Writes small valid inputs for the fuzzers into DIR/{merl,rgl,alta,npy,envmap,factored}/ (see
// fuzz/run.sh): a synthetic RGL material with tiny grids (RGB and spectral), ALTA files, MERL
// headers, .npy arrays, environment maps (Radiance and OpenEXR); and of each, a copy with trailing
// data and one extended by zeros, as `truncate -s` extends a file (class C of
// docs/reliability/readers.md: every reader ends where its header says, and a text reader
// refuses a NUL byte).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

#include "halfback/brdf/rho_bound.hpp"
#include "halfback/formats/factored.hpp"
#include "halfback/formats/rgl.hpp"
#include "halfback/render/image.hpp"

using namespace halfback;
namespace fs = std::filesystem;

namespace {

template <class T>
std::vector<std::byte> le(const std::vector<T>& v) {  // the fuzzers run on little-endian hosts
  std::vector<std::byte> b(v.size() * sizeof(T));
  if (!v.empty()) std::memcpy(b.data(), v.data(), b.size());
  return b;
}

void write(const fs::path& p, const void* data, std::size_t n) {
  std::ofstream(p, std::ios::binary)
      .write(static_cast<const char*>(data), static_cast<std::streamsize>(n));
  // The same followed by trailing data, and extended by zeros (a sparse extension, shortened to
  // what the fuzzers' -max_len lets through).
  std::string junk(static_cast<const char*>(data), n);
  const fs::path stem = p.parent_path() / p.stem();
  std::ofstream(stem.string() + "-trailing" + p.extension().string(), std::ios::binary)
      << junk << "junk";
  std::ofstream(stem.string() + "-zeros" + p.extension().string(), std::ios::binary)
      << junk << std::string(2048, '\0');
}

// `spectral`: the spectral variant, `wavelengths` and `spectra` (3 wavelengths) instead of `rgb`.
std::vector<std::byte> rgl_material(std::size_t n_theta, std::size_t w, std::size_t r,
                                    std::vector<float> phi_i, bool spectral = false) {
  std::vector<float> theta(n_theta);
  for (std::size_t i = 0; i < n_theta; ++i) theta[i] = float(1.5 * double(i) / double(n_theta));
  const std::size_t np = phi_i.size(), slices = np * n_theta;
  std::vector<float> vndf, lum, rgb;
  for (std::size_t s = 0; s < slices; ++s) {
    for (std::size_t k = 0; k < w * w; ++k) vndf.push_back(float(1 + (k * 7 + s) % 5));
    for (std::size_t k = 0; k < r * r; ++k) lum.push_back(1.0f);
    for (std::size_t k = 0; k < 3 * r * r; ++k) rgb.push_back(float(0.1 * double(k % 7)));
  }
  const std::string desc = "seed";
  std::vector<std::byte> d(desc.size());
  std::memcpy(d.data(), desc.data(), desc.size());
  std::vector<TensorFieldData> fields{
      {"description", TensorDtype::uint8, {desc.size()}, d},
      {"phi_i", TensorDtype::float32, {np}, le(phi_i)},
      {"theta_i", TensorDtype::float32, {n_theta}, le(theta)},
      {"sigma", TensorDtype::float32, {2, w}, le(std::vector<float>(2 * w, 0.8f))},
      {"ndf", TensorDtype::float32, {2, w}, le(std::vector<float>(2 * w, 0.5f))},
      {"vndf", TensorDtype::float32, {np, n_theta, w, w}, le(vndf)},
      {"luminance", TensorDtype::float32, {np, n_theta, r, r}, le(lum)},
      {"rgb", TensorDtype::float32, {np, n_theta, 3, r, r}, le(rgb)},
      {"jacobian", TensorDtype::uint8, {1}, {std::byte{1}}},
  };
  if (spectral) {  // the same numbers, read as 3 wavelengths
    fields[7] = {"wavelengths", TensorDtype::float32, {3}, le(std::vector<float>{400, 550, 700})};
    fields.insert(fields.begin() + 8,
                  {"spectra", TensorDtype::float32, {np, n_theta, 3, r, r}, le(rgb)});
  }
  return serialize_tensor_file(fields);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_fuzz_seeds DIR\n";
    return 2;
  }
  const fs::path dir = argv[1];
  for (const char* sub : {"merl", "rgl", "alta", "npy", "envmap", "factored"})
    fs::create_directories(dir / sub);

  // A factored BRDF of rank 2 on a small grid, each factor a ramp.
  FactoredModel factored;
  factored.counts = {3, 2, 4};
  for (auto& terms : factored.channels)
    for (int r = 0; r < 2; ++r)
      terms.push_back({{0.1, 0.2 * r, 0.3}, {1.0, 0.5}, {0.2, 0.4, 0.6, 0.8 * r}});
  write_factored(dir / "factored" / "small.json", factored);
  // At the bound on ρ: max_log = log(1 + kMaxRho) and products far above it (the reader refuses
  // a max_log above; mutations of this one test it).
  FactoredModel at_bound = factored;
  at_bound.max_log = {std::log1p(kMaxRho), std::log1p(kMaxRho), 0};
  for (auto& terms : at_bound.channels)
    for (FactoredTerm& t : terms) t.a = {800, 800, 800};
  write_factored(dir / "factored" / "at_bound.json", at_bound);

  const auto iso = rgl_material(3, 4, 2, {0.0f});
  write(dir / "rgl" / "iso.bsdf", iso.data(), iso.size());
  const auto aniso = rgl_material(2, 3, 2, {-3.14159265f, -1.5707963f, 0.0f});
  write(dir / "rgl" / "aniso.bsdf", aniso.data(), aniso.size());
  const auto spectral = rgl_material(3, 4, 2, {0.0f}, true);
  write(dir / "rgl" / "spectral.bsdf", spectral.data(), spectral.size());

  const std::string alta =
      "#DIM 3 1\n#VS 0\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT "
      "INV_STERADIAN_COSINE_FACTOR\n"
      "0.5 0 0 1\n0.5 0.1 0 2\n0.5 0 0.1 3\n0.5 0.1 0.1 4\n1.0 0 0 1\n1.0 0.2 0 2\n1.0 0 -0.2 3\n";
  write(dir / "alta" / "small.dat", alta.data(), alta.size());
  const std::string alta_vs =
      "#DIM 3 3\n#VS 2\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT INV_STERADIAN\n"
      "0.2 0 0 1 2 3 0.5 1.5\n0.2 1e-1 0 1 2 3 0.5 1.5\n0.2 0 0.1 1 2 3 0.5 1.5\n";
  write(dir / "alta" / "rgb_vs.dat", alta_vs.data(), alta_vs.size());

  // MERL: a valid header followed by a few values.
  std::vector<unsigned char> merl(12 + 64);
  const std::int32_t dims[3] = {90, 90, 180};
  std::memcpy(merl.data(), dims, 12);
  for (std::size_t i = 12; i < merl.size(); ++i) merl[i] = static_cast<unsigned char>(i * 37);
  write(dir / "merl" / "header.bin", merl.data(), merl.size());
  const double pair[6] = {0.3, 0.1, 0.948683, -0.2, 0.4, 0.894427};
  write(dir / "merl" / "pair.bin", pair, sizeof pair);
  // .npy: a 6 × 3 float32 kernel (format 1.0) and a 1-D array.
  auto npy = [](const std::string& shape, std::size_t count) {
    std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': " + shape + ", }";
    while ((10 + header.size() + 1) % 64 != 0) header += ' ';
    header += '\n';
    std::string out("\x93NUMPY\x01\x00", 8);
    out += char(header.size() & 0xff);
    out += char(header.size() >> 8);
    out += header;
    for (std::size_t i = 0; i < count; ++i) {
      const float v = 0.1f * float(i) - 0.5f;
      out.append(reinterpret_cast<const char*>(&v), sizeof v);
    }
    return out;
  };
  const std::string kernel = npy("(6, 3)", 18), bias = npy("(3,)", 3);
  write(dir / "npy" / "kernel.npy", kernel.data(), kernel.size());
  write(dir / "npy" / "bias.npy", bias.data(), bias.size());

  // Environment maps: a flat Radiance file (a width below 8 is never run-length encoded), a
  // run-length encoded one (width 8), and an OpenEXR file.
  auto radiance = [](int w, int h, bool rle) {
    std::string out = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(h) + " +X " +
                      std::to_string(w) + "\n";
    for (int y = 0; y < h; ++y) {
      if (rle) {  // per channel: one run of w equal bytes
        out += std::string{'\x02', '\x02', char(w >> 8), char(w & 0xff)};
        for (const char c : {'\x80', '\x40', '\x20', '\x81'}) out += std::string{char(128 + w), c};
      } else {
        for (int x = 0; x < w; ++x) out += std::string("\x80\x40\x20\x81", 4);
      }
    }
    return out;
  };
  const std::string flat = radiance(4, 2, false), rle = radiance(8, 4, true);
  write(dir / "envmap" / "flat.hdr", flat.data(), flat.size());
  write(dir / "envmap" / "rle.hdr", rle.data(), rle.size());
  const fs::path exr = dir / "envmap" / "map.exr";
  render::write_exr(exr, render::Image{8, 4, std::vector<float>(8 * 4 * 3, 0.5f)});
  std::ifstream in(exr, std::ios::binary);
  const std::string exr_bytes((std::istreambuf_iterator<char>(in)), {});
  write(exr, exr_bytes.data(), exr_bytes.size());
  return 0;
}
