// The renderer's per-pixel sequences: PixelPair (hashes hoisted out of the sample loop, byte
// tables for Sobol's second dimension) returns sample_2d's numbers bit for bit, for both kinds.
#include "sequence.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace halfback::render::detail {
namespace {

TEST(Sequence, PixelPairEqualsSample2d) {
  const std::vector<std::uint32_t> indices{
      0, 1, 2, 3, 255, 256, 257, 4095, 65537u, 0x7fffffffu, 0x80000000u, 0xffffffffu};
  for (SequenceKind kind : {SequenceKind::sobol, SequenceKind::random})
    for (std::uint64_t seed : {std::uint64_t(1), std::uint64_t(977), ~std::uint64_t(0)})
      for (std::uint64_t pixel : {std::uint64_t(0), std::uint64_t(12345), std::uint64_t(1) << 40})
        for (std::uint32_t dim = 0; dim < 4; ++dim) {
          const PixelPair pair(kind, dimension_key(seed, dim), pixel);
          auto check = [&](std::uint32_t index) {
            double a1, a2, b1, b2;
            pair.point(index, a1, a2);
            sample_2d(kind, seed, pixel, index, dim, b1, b2);
            ASSERT_EQ(a1, b1) << "index " << index << " dim " << dim;
            ASSERT_EQ(a2, b2) << "index " << index << " dim " << dim;
          };
          for (std::uint32_t i = 0; i < 1024; ++i) check(i);
          for (std::uint32_t i : indices) check(i);
        }
}

TEST(Sequence, SobolTablesAreTheSecondDimension) {
  for (std::uint32_t x : {0u, 1u, 2u, 3u, 0x80u, 0x1234u, 0xdeadbeefu, 0xffffffffu})
    EXPECT_EQ(kSobolDim1Reversed(x), reverse_bits(sobol_dim1(x))) << x;
}

// The first 2^k points of one pixel's scrambled pair are still a (0, 2)-net in base 2: each of
// the 2^k elementary intervals of every shape holds one point (the stratification the scramble
// must keep).
TEST(Sequence, ScrambledPointsStayStratified) {
  const PixelPair pair(SequenceKind::sobol, dimension_key(3, 1), 42);
  constexpr int k = 8, n = 1 << k;
  std::vector<double> u1(n), u2(n);
  for (int i = 0; i < n; ++i) pair.point(std::uint32_t(i), u1[std::size_t(i)], u2[std::size_t(i)]);
  for (int a = 0; a <= k; ++a) {
    std::vector<int> hits(n, 0);
    for (int i = 0; i < n; ++i) {
      const int x = int(u1[std::size_t(i)] * (1 << a)),
                y = int(u2[std::size_t(i)] * (1 << (k - a)));
      ++hits[std::size_t(x * (1 << (k - a)) + y)];
    }
    for (int h : hits) ASSERT_EQ(h, 1) << "intervals of 2^-" << a << " x 2^-" << (k - a);
  }
}

}  // namespace
}  // namespace halfback::render::detail
