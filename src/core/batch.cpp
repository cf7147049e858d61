#include "halfback/core/batch.hpp"

#include <stdexcept>
#include <string>

#include "row_kernels.hpp"

namespace halfback {

namespace {
void check_shapes(Form from, Form to, std::size_t n_in, std::size_t n_out) {
  if (n_in != dimension(from))
    throw std::invalid_argument("convert: " + std::string(name_of(from.space)) + " needs " +
                                std::to_string(dimension(from)) + " input columns, got " +
                                std::to_string(n_in));
  if (n_out != dimension(to))
    throw std::invalid_argument("convert: " + std::string(name_of(to.space)) + " needs " +
                                std::to_string(dimension(to)) + " output columns, got " +
                                std::to_string(n_out));
  if ((from.space == Space::dirs && from.isotropic) || (to.space == Space::dirs && to.isotropic))
    throw std::invalid_argument("convert: dirs has no isotropic form");
}
}  // namespace

template <class T>
void convert(Form from, Form to, std::span<const ConstColumn<T>> in, std::size_t n,
             const ConvertOutput<T>& out, const BatchOptions& /*options*/) {
  check_shapes(from, to, in.size(), out.columns.size());
  T row_in[detail::kMaxDim], row_out[detail::kMaxDim];
  for (std::size_t r = 0; r < n; ++r) {
    const auto ir = static_cast<std::ptrdiff_t>(r);
    for (std::size_t c = 0; c < in.size(); ++c) row_in[c] = in[c].data[ir * in[c].stride];
    T jac;
    const bool ok =
        detail::convert_row(from, to, row_in, row_out, out.jacobian.data ? &jac : nullptr);
    for (std::size_t c = 0; c < out.columns.size(); ++c)
      out.columns[c].data[ir * out.columns[c].stride] = row_out[c];
    if (out.jacobian.data) out.jacobian.data[ir * out.jacobian.stride] = jac;
    if (out.valid) out.valid[r] = ok ? 1 : 0;
  }
}

template <class T>
bool convert_one(Form from, Form to, std::span<const T> in, std::span<T> out, T* jacobian) {
  check_shapes(from, to, in.size(), out.size());
  return detail::convert_row(from, to, in.data(), out.data(), jacobian);
}

template void convert<float>(Form, Form, std::span<const ConstColumn<float>>, std::size_t,
                             const ConvertOutput<float>&, const BatchOptions&);
template void convert<double>(Form, Form, std::span<const ConstColumn<double>>, std::size_t,
                              const ConvertOutput<double>&, const BatchOptions&);
template bool convert_one<float>(Form, Form, std::span<const float>, std::span<float>, float*);
template bool convert_one<double>(Form, Form, std::span<const double>, std::span<double>,
                                  double*);

}  // namespace halfback
