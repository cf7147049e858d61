// Batch conversion between any two coordinate forms: the hot path.
//
// Data is a set of columns, one per coordinate, each a pointer and a stride in elements: stride 1
// is structure-of-arrays (the fast layout), stride = dimension is a row-major array of tuples such
// as a NumPy (N, 6) array. Internally rows are processed in tiles that are gathered into SoA
// scratch, converted with SIMD kernels (the same formulas as param.hpp) and scattered back, on
// several threads for large batches. See docs/performance.md for the measurements behind this.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "halfback/core/space.hpp"

namespace halfback {

template <class T>
struct ConstColumn {
  const T* data = nullptr;
  std::ptrdiff_t stride = 1;
};

template <class T>
struct Column {
  T* data = nullptr;
  std::ptrdiff_t stride = 1;
};

template <class T>
struct ConvertOutput {
  std::span<const Column<T>> columns;  // dimension(to) columns
  // Optional: J with dωi dωo = J d(params), for the parameterization `to`, or `from` when `to` is
  // dirs (for isotropic forms, the measure of the 3 coordinates: see jacobian_iso()).
  Column<T> jacobian{};
  // Optional: 1 where the input row is valid (a checked direction pair, or a tuple inside the
  // parameterization's domain), 0 elsewhere; invalid rows get NaN in every output column.
  std::uint8_t* valid = nullptr;
};

struct BatchOptions {
  int threads = 0;  // as in core/parallel.hpp: 0 all cores, 1 the calling thread, n at most n
};

// Converts n rows from `from` to `to`. Throws std::invalid_argument when the column counts do not
// match the forms. Dirs input is checked like check_pair() (in the precision of T).
template <class T>
void convert(Form from, Form to, std::span<const ConstColumn<T>> in, std::size_t n,
             const ConvertOutput<T>& out, const BatchOptions& options = {});

extern template void convert<float>(Form, Form, std::span<const ConstColumn<float>>, std::size_t,
                                    const ConvertOutput<float>&, const BatchOptions&);
extern template void convert<double>(Form, Form, std::span<const ConstColumn<double>>, std::size_t,
                                     const ConvertOutput<double>&, const BatchOptions&);

// Single row through the same code path, for callers that hold one tuple (values in, values out).
// Returns whether the input was valid. `jacobian` may be null.
template <class T>
bool convert_one(Form from, Form to, std::span<const T> in, std::span<T> out,
                 T* jacobian = nullptr);

}  // namespace halfback
