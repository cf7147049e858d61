// In-register transposes between rows of D values (D = 4 or 6) and D column vectors, for the
// kernel tables whose vectors are one or two 128-bit lanes (SSE2, AVX2). Each lane of a column
// holds its own group of rows (4 floats or 2 doubles; lane 1 the group after lane 0's), so the
// transpose is one small transpose per lane, of in-lane unpacks and shuffles; the loads put
// 128-bit pieces of the rows into their lanes, and the stores put the lanes back in row order.
//
// Include this only from a batch_kernels_<isa>.cpp translation unit, after batch_kernels.hpp;
// its `Ops` (the vector operations of one instruction set, defined in that unit) provides:
//   F, Dv: the float and double vectors (of one or two 128-bit lanes);
//   load(p, lane_stride): the 128 bits at p in lane 0, at p + lane_stride in lane 1;
//   store(v, n, lo, hi): v[0, n) (n even) as their lanes, lanes 0 in order from lo, lanes 1 from
//   hi; unpacklo, unpackhi, and shuffle<Imm> (shufps, or shufpd with Imm's two bits), lane by lane.
// Everything has internal linkage (the one-definition-rule hazard of batch_kernels.hpp).
#pragma once

#include <immintrin.h>

#include <cstddef>

#include "batch_kernels.hpp"

namespace halfback::detail {
namespace {

template <class Ops, class S, int D>
struct LaneRows;

// 2 rows of doubles a lane; piece p of a row is its columns 2p and 2p + 1.
template <class Ops, int D>
struct LaneRows<Ops, double, D> {
  using V = typename Ops::Dv;
  static constexpr std::ptrdiff_t kLaneStride = 2 * D;
  static void load(const double* rows, V* columns) {
    for (int p = 0; p < D / 2; ++p) {
      const V first = Ops::load(rows + 2 * p, kLaneStride);       // rows 0 (and 2)
      const V second = Ops::load(rows + D + 2 * p, kLaneStride);  // rows 1 (and 3)
      columns[2 * p] = Ops::unpacklo(first, second);
      columns[2 * p + 1] = Ops::unpackhi(first, second);
    }
  }
  static void store(const V* columns, double* rows) {
    V piece[D];  // the pieces of row 0 (and 2), then of row 1 (and 3)
    for (int p = 0; p < D / 2; ++p) {
      piece[p] = Ops::unpacklo(columns[2 * p], columns[2 * p + 1]);
      piece[D / 2 + p] = Ops::unpackhi(columns[2 * p], columns[2 * p + 1]);
    }
    Ops::store(piece, D, rows, rows + kLaneStride);
  }
};

// The 64-bit pieces 0 of a and b of each lane, and pieces 1 (floats seen as doubles).
template <class Ops>
typename Ops::F pieces_lo(typename Ops::F a, typename Ops::F b) {
  return Ops::as_f(Ops::unpacklo(Ops::as_d(a), Ops::as_d(b)));
}
template <class Ops>
typename Ops::F pieces_hi(typename Ops::F a, typename Ops::F b) {
  return Ops::as_f(Ops::unpackhi(Ops::as_d(a), Ops::as_d(b)));
}
// [piece Imm & 1 of a, piece Imm >> 1 of b] in each lane.
template <class Ops, int Imm>
typename Ops::F pieces(typename Ops::F a, typename Ops::F b) {
  return Ops::as_f(Ops::template shuffle<Imm>(Ops::as_d(a), Ops::as_d(b)));
}

// 4 rows of 4 floats a lane: a 4 x 4 transpose in each lane.
template <class Ops>
struct LaneRows<Ops, float, 4> {
  using V = typename Ops::F;
  static void load(const float* rows, V* columns) {
    V r[4];  // row j (and j + 4)
    for (int j = 0; j < 4; ++j) r[j] = Ops::load(rows + 4 * j, 16);
    const V r01lo = Ops::unpacklo(r[0], r[1]);  // r0c0 r1c0 r0c1 r1c1
    const V r01hi = Ops::unpackhi(r[0], r[1]);  // r0c2 r1c2 r0c3 r1c3
    const V r23lo = Ops::unpacklo(r[2], r[3]);
    const V r23hi = Ops::unpackhi(r[2], r[3]);
    columns[0] = pieces_lo<Ops>(r01lo, r23lo);
    columns[1] = pieces_hi<Ops>(r01lo, r23lo);
    columns[2] = pieces_lo<Ops>(r01hi, r23hi);
    columns[3] = pieces_hi<Ops>(r01hi, r23hi);
  }
  static void store(const V* columns, float* rows) {
    const V c01lo = Ops::unpacklo(columns[0], columns[1]);  // r0c0 r0c1 r1c0 r1c1
    const V c01hi = Ops::unpackhi(columns[0], columns[1]);  // r2c0 r2c1 r3c0 r3c1
    const V c23lo = Ops::unpacklo(columns[2], columns[3]);
    const V c23hi = Ops::unpackhi(columns[2], columns[3]);
    const V r[4] = {pieces_lo<Ops>(c01lo, c23lo), pieces_hi<Ops>(c01lo, c23lo),
                    pieces_lo<Ops>(c01hi, c23hi), pieces_hi<Ops>(c01hi, c23hi)};
    Ops::store(r, 4, rows, rows + 16);
  }
};

// 4 rows of 6 floats a lane, as 64-bit pieces (piece k: columns 2k, 2k + 1). Two rows are three
// 128-bit quarters, x = [pieces 0, 1 of the first], y = [piece 2 of the first, 0 of the second],
// z = [pieces 1, 2 of the second]; one shufpd each sorts them into piece k of both rows, and one
// shufps makes the columns of the two row pairs of a lane.
template <class Ops>
struct LaneRows<Ops, float, 6> {
  using V = typename Ops::F;
  static void load(const float* rows, V* columns) {
    V piece[2][3];  // [row pair i][k]: piece k of rows 2i and 2i + 1 (and + 4)
    for (int i = 0; i < 2; ++i) {
      const V x = Ops::load(rows + 12 * i, 24), y = Ops::load(rows + 12 * i + 4, 24),
              z = Ops::load(rows + 12 * i + 8, 24);
      piece[i][0] = pieces<Ops, 0b10>(x, y);
      piece[i][1] = pieces<Ops, 0b01>(x, z);
      piece[i][2] = pieces<Ops, 0b10>(y, z);
    }
    for (int k = 0; k < 3; ++k) {
      columns[2 * k] = Ops::template shuffle<_MM_SHUFFLE(2, 0, 2, 0)>(piece[0][k], piece[1][k]);
      columns[2 * k + 1] = Ops::template shuffle<_MM_SHUFFLE(3, 1, 3, 1)>(piece[0][k], piece[1][k]);
    }
  }
  static void store(const V* columns, float* rows) {
    V piece[2][3];
    for (int k = 0; k < 3; ++k) {
      piece[0][k] = Ops::unpacklo(columns[2 * k], columns[2 * k + 1]);  // rows 0, 1 (4, 5)
      piece[1][k] = Ops::unpackhi(columns[2 * k], columns[2 * k + 1]);  // rows 2, 3 (6, 7)
    }
    V q[6];  // the quarters x, y, z of row pair 0, then of row pair 1
    for (int i = 0; i < 2; ++i) {
      q[3 * i] = pieces_lo<Ops>(piece[i][0], piece[i][1]);
      q[3 * i + 1] = pieces<Ops, 0b10>(piece[i][2], piece[i][0]);
      q[3 * i + 2] = pieces_hi<Ops>(piece[i][1], piece[i][2]);
    }
    Ops::store(q, 6, rows, rows + 24);
  }
};

}  // namespace
}  // namespace halfback::detail
