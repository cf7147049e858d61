// convert() for forms whose parameterization is outside KernelParams (registered at run time):
// blocks of rows through the descriptors' row maps (ParamDescriptor::forward_rows, ...), with the
// built-in side, if any, through the scalar reference (convert_row). Slower than the SIMD tables,
// the same semantics (masks, NaN rows, the measure).
#pragma once

#include <cstddef>
#include <span>

#include "halfback/core/batch.hpp"

namespace halfback::detail {

template <class T>
void convert_registered(Form from, Form to, std::span<const ConstColumn<T>> in, std::size_t n,
                        const ConvertOutput<T>& out, const BatchOptions& options);

}  // namespace halfback::detail
