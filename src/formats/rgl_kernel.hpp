// The evaluation's block kernel of RGL materials (private header of src/formats; rgl_kernel.cpp):
// Impl::value() and over_cosine() of a block's rows, step by step across the rows, each step a
// loop that the compiler vectorizes (the cells, the blends, the inverse warp's solve, the shading)
// or a loop of independent loads into columns (the tables' values at the cells, many rows' misses
// in flight), instead of each row's chain of dependent loads, divisions and square roots in turn.
#pragma once

#include <cstddef>

#include "rgl_tables.hpp"
#include "rgl_warp.hpp"

namespace halfback::rgl_kernel {

using rgl_detail::Warp;

inline constexpr std::size_t kRows = rgl_detail::kBlock;

// The tables eval() reads (RglBrdf::Impl), as plain arrays.
struct EvalTables {
  const Warp::Node* node;  // the VNDF warp: slices of vh·vw nodes
  const Warp::Row* row;    // slices of vh rows
  const double* inv_total;
  std::size_t vw, vh;
  const double* rgb;  // slices of rh·rw slots of RgbTable::kSlot
  std::size_t rw, rh;
  const double* ndf;
  std::size_t nw, nh;
  const double* sigma;
  std::size_t sw, sh;
  bool jacobian, clamp_negative;
};

// The rows of a block that take the common path, packed: their table coordinates, slices and ωo
// in, fr out.
struct EvalRows {
  std::size_t n = 0;
  alignas(64) double um_x[kRows], um_y[kRows], uwi_x[kRows], uwi_y[kRows];
  alignas(64) double wo[3][kRows];
  alignas(64) std::size_t slice[4][kRows];
  alignas(64) double weight[4][kRows];
  alignas(64) double fr[3][kRows];
};

// fr of the r.n rows of r (Impl::value() over cos θo), each row of slice_count slices (1, 2
// or 4: Impl::slices() gives every incidence of a material as many): the values of the one-row
// path bit for bit.
void eval_rows(const EvalTables& t, EvalRows& r, int slice_count);

}  // namespace halfback::rgl_kernel
