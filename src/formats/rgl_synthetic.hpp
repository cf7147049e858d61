// A synthetic RGL material for tests (not part of the library): small grids, callbacks for the
// VNDF and RGB tables.
#pragma once

#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "formats/binary_io.hpp"
#include "halfback/formats/rgl.hpp"

namespace halfback::test {

template <class T>
inline std::vector<std::byte> le_bytes(const std::vector<T>& v) {
  std::vector<std::byte> b(v.size() * sizeof(T));
  for (std::size_t i = 0; i < v.size(); ++i) io_detail::store_le<T>(b.data() + i * sizeof(T), v[i]);
  return b;
}

inline TensorFieldData f32(std::string name, std::vector<std::uint64_t> shape,
                           std::vector<float> v) {
  return {std::move(name), TensorDtype::float32, std::move(shape), le_bytes(v)};
}

// A small isotropic material: n_theta incidence slices, W×W VNDF grids, R×R RGB grids. The
// callbacks give vndf(slice, y, x), luminance(slice, y, x) and rgb(slice, channel, y, x).
struct Synthetic {
  std::vector<float> theta_i{0.0f, 0.5f, 1.0f, 1.5f};
  std::vector<float> phi_i{0.0f};
  std::size_t w = 16, r = 8;
  std::function<float(std::size_t, std::size_t, std::size_t)> vndf = [](auto, auto, auto) {
    return 1.0f;
  };
  std::function<float(std::size_t, std::size_t, std::size_t)> luminance = [](auto, auto, auto) {
    return 1.0f;
  };
  std::function<float(std::size_t, std::size_t, std::size_t, std::size_t)> rgb =
      [](auto, std::size_t c, auto, auto) { return 0.1f * float(c + 1); };
  float ndf = 1.0f, sigma = 1.0f;
  std::uint8_t jacobian = 0;

  std::vector<TensorFieldData> fields() const {
    const std::uint64_t nt = theta_i.size(), np = phi_i.size();
    std::vector<float> vn, lum, col;
    for (std::size_t s = 0; s < np * nt; ++s) {
      for (std::size_t y = 0; y < w; ++y)
        for (std::size_t x = 0; x < w; ++x) vn.push_back(vndf(s, y, x));
      for (std::size_t y = 0; y < r; ++y)
        for (std::size_t x = 0; x < r; ++x) lum.push_back(luminance(s, y, x));
      for (std::size_t c = 0; c < 3; ++c)
        for (std::size_t y = 0; y < r; ++y)
          for (std::size_t x = 0; x < r; ++x) col.push_back(rgb(s, c, y, x));
    }
    const std::string desc = "synthetic";
    std::vector<std::byte> d(desc.size());
    std::memcpy(d.data(), desc.data(), desc.size());
    return {
        {"version", TensorDtype::uint32, {2}, le_bytes(std::vector<std::uint32_t>{1, 0})},
        {"description", TensorDtype::uint8, {desc.size()}, d},
        f32("phi_i", {np}, phi_i),
        f32("theta_i", {nt}, theta_i),
        f32("sigma", {2, w}, std::vector<float>(2 * w, sigma)),
        f32("ndf", {2, w}, std::vector<float>(2 * w, ndf)),
        f32("vndf", {np, nt, w, w}, vn),
        f32("luminance", {np, nt, r, r}, lum),
        f32("rgb", {np, nt, 3, r, r}, col),
        {"jacobian", TensorDtype::uint8, {1}, {std::byte{jacobian}}},
    };
  }
  std::vector<std::byte> bytes() const { return serialize_tensor_file(fields()); }
  RglBrdf brdf() const {
    return RglBrdf(parse_tensor_file(bytes(), "synthetic.bsdf"), "synthetic");
  }
};

}  // namespace halfback::test
