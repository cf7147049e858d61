// Per-pixel sample sequences for the renderer: 2D points from a scrambled, shuffled Sobol (0,2)
// sequence, one independent scramble per pixel and per pair of dimensions ("padding"), after
// Burley 2020, "Practical Hash-based Owen Scrambling"; or independent uniform numbers. Both are
// pure functions of (seed, pixel, sample index, dimension pair), so an image does not depend on
// the number of threads or on how the work was split.
//
// PixelPair is the same sequence for the renderer's inner loop: the hashes that depend only on the
// seed, the pixel and the dimension are computed once per pixel, not once per sample, and the
// second Sobol dimension comes from byte tables; it returns sample_2d's numbers bit for bit.
#pragma once

#include <array>
#include <cstdint>

namespace halfback::render::detail {

inline std::uint64_t mix64(std::uint64_t x) {  // splitmix64's finalizer
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return x;
}

inline std::uint32_t hash32(std::uint64_t a, std::uint64_t b, std::uint64_t c) {
  return std::uint32_t(mix64(mix64(mix64(a) ^ b) ^ c) >> 32);
}

constexpr std::uint32_t reverse_bits(std::uint32_t x) {
  x = __builtin_bswap32(x);  // the bytes, then the bits within each byte
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  return ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
}

// A hash that only lets a bit depend on the bits below it (Laine and Karras 2011), applied to the
// reversed bits: a nested uniform (Owen) scramble of a 32-bit fraction.
inline std::uint32_t owen_scramble(std::uint32_t x, std::uint32_t seed) {
  x = reverse_bits(x);
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return reverse_bits(x);
}

// The first two dimensions of Sobol's sequence: van der Corput, and the dimension with the
// primitive polynomial x + 1 (direction numbers v_k = v_{k-1} ^ (v_{k-1} >> 1)).
inline std::uint32_t sobol_dim0(std::uint32_t i) {
  return reverse_bits(i);
}
constexpr std::uint32_t sobol_dim1(std::uint32_t i) {
  std::uint32_t v = 1u << 31, r = 0;
  for (; i; i >>= 1, v ^= v >> 1)
    if (i & 1) r ^= v;
  return r;
}

inline double to_unit(std::uint32_t x) {
  return double(x) * 0x1p-32;  // in [0, 1)
}

enum class SequenceKind { sobol, random };

// The key of dimension pair `dim`: every bit of the seed matters (a shift would drop the top
// ones), and dimensions differ.
inline std::uint64_t dimension_key(std::uint64_t seed, std::uint32_t dim) {
  return mix64(seed ^ mix64(std::uint64_t(dim) + 0x9e3779b97f4a7c15ull));
}

// Point `index` of the 2D sequence `dim` (a dimension pair) of one pixel.
inline void sample_2d(SequenceKind kind, std::uint64_t seed, std::uint64_t pixel,
                      std::uint32_t index, std::uint32_t dim, double& u1, double& u2) {
  const std::uint64_t key = dimension_key(seed, dim);
  if (kind == SequenceKind::random) {
    const std::uint64_t h = mix64(mix64(mix64(key) ^ pixel) ^ index);
    u1 = double(h >> 11) * 0x1p-53;
    u2 = double(mix64(h) >> 11) * 0x1p-53;
    return;
  }
  const std::uint32_t shuffled = owen_scramble(index, hash32(key, pixel, 0x5bd1e995));
  u1 = to_unit(owen_scramble(sobol_dim0(shuffled), hash32(key, pixel, 0x68e31da4)));
  u2 = to_unit(owen_scramble(sobol_dim1(shuffled), hash32(key, pixel, 0xb5297a4d)));
}

// The Laine-Karras hash of owen_scramble, on bits already reversed.
inline std::uint32_t laine_karras(std::uint32_t x, std::uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

// reverse_bits(sobol_dim1(x)) as the XOR of four byte tables (the map is linear over GF(2)).
struct SobolDim1Tables {
  std::array<std::array<std::uint32_t, 256>, 4> t{};
  constexpr SobolDim1Tables() {
    for (int b = 0; b < 4; ++b)
      for (std::uint32_t v = 0; v < 256; ++v) t[b][v] = reverse_bits(sobol_dim1(v << (8 * b)));
  }
  std::uint32_t operator()(std::uint32_t x) const {
    return t[0][x & 255] ^ t[1][(x >> 8) & 255] ^ t[2][(x >> 16) & 255] ^ t[3][x >> 24];
  }
};
inline constexpr SobolDim1Tables kSobolDim1Reversed{};

// One dimension pair of one pixel: point(index) == sample_2d(kind, seed, pixel, index, dim).
class PixelPair {
 public:
  PixelPair() = default;
  // `key` = dimension_key(seed, dim).
  PixelPair(SequenceKind kind, std::uint64_t key, std::uint64_t pixel) : kind_(kind) {
    if (kind == SequenceKind::random) {
      key_ = mix64(mix64(key) ^ pixel);
      return;
    }
    shuffle_ = hash32(key, pixel, 0x5bd1e995);
    scramble0_ = hash32(key, pixel, 0x68e31da4);
    scramble1_ = hash32(key, pixel, 0xb5297a4d);
  }
  void point(std::uint32_t index, double& u1, double& u2) const {
    point(index, reverse_bits(index), u1, u2);
  }
  // The same with reversed = reverse_bits(index), which the pairs of one sample share.
  void point(std::uint32_t index, std::uint32_t reversed, double& u1, double& u2) const {
    if (kind_ == SequenceKind::random) {
      const std::uint64_t h = mix64(key_ ^ index);
      u1 = double(h >> 11) * 0x1p-53;
      u2 = double(mix64(h) >> 11) * 0x1p-53;
      return;
    }
    // owen_scramble(x, s) = reverse(laine_karras(reverse(x), s)) and sobol_dim0 = reverse, so
    // the shuffled index, reversed, feeds both dimensions' hashes directly.
    const std::uint32_t shuffled = reverse_bits(laine_karras(reversed, shuffle_));
    u1 = to_unit(reverse_bits(laine_karras(shuffled, scramble0_)));
    u2 = to_unit(reverse_bits(laine_karras(kSobolDim1Reversed(shuffled), scramble1_)));
  }

 private:
  SequenceKind kind_ = SequenceKind::sobol;
  std::uint64_t key_ = 0;
  std::uint32_t shuffle_ = 0, scramble0_ = 0, scramble1_ = 0;
};

}  // namespace halfback::render::detail
