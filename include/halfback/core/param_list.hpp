// The lists of the built-in parameterizations (forward declarations only: a translation unit
// that names a space, space_of<HalfDiff>, does not parse the maps), and the compile-time
// utilities over them. The maps: params/; the concept they satisfy: parameterization.hpp.
#pragma once

#include <cstddef>
#include <type_traits>
#include <utility>

namespace halfback {

struct Spherical;
struct HalfDiff;
struct Ortho;
struct Hybrid;
struct RectifiedHybrid;
struct StereoHalfDiff;
struct Stereographic;
struct HalfwayDisk;

template <class... Ps>
struct ParamList {
  static constexpr std::size_t size = sizeof...(Ps);
};

// The built-in parameterizations, in the order of every run-time list (space ids 1, 2, ...).
// KernelParams have SIMD kernels in the batch engine's tables, one instantiation per instruction
// set; PortableParams are converted through their descriptors, in double, a block of rows at a
// time (batch_registered.cpp): each in the SIMD tables would add to every clean build's heaviest
// translation units (docs/performance.md, "Building") for maps that are not on a hot path.
using KernelParams = ParamList<Spherical, HalfDiff, Ortho, Hybrid>;
using PortableParams = ParamList<RectifiedHybrid, StereoHalfDiff, Stereographic, HalfwayDisk>;

inline constexpr std::size_t kKernelParamCount = KernelParams::size;
inline constexpr std::size_t kBuiltinParamCount = KernelParams::size + PortableParams::size;

namespace detail {
template <class P, class List>
struct IndexIn;
template <class P, class... Ps>
struct IndexIn<P, ParamList<Ps...>> {
  static constexpr std::size_t value = [] {
    constexpr bool same[] = {std::is_same_v<P, Ps>...};
    for (std::size_t i = 0; i < sizeof...(Ps); ++i)
      if (same[i]) return i;
    return sizeof...(Ps);
  }();
  static constexpr bool found = value < sizeof...(Ps);
};
}  // namespace detail

// The position of P in KernelParams.
template <class P>
inline constexpr std::size_t kernel_index = detail::IndexIn<P, KernelParams>::value;

// The position of P among the built-in parameterizations: KernelParams, then PortableParams.
template <class P>
inline constexpr std::size_t builtin_index = [] {
  using InKernels = detail::IndexIn<P, KernelParams>;
  using InPortable = detail::IndexIn<P, PortableParams>;
  static_assert(InKernels::found || InPortable::found, "not a built-in parameterization");
  return InKernels::found ? InKernels::value : KernelParams::size + InPortable::value;
}();

// Calls f.template operator()<P, I>() for each P of the list, with I its index.
template <class... Ps, class F>
constexpr void for_each_param(ParamList<Ps...>, F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (f.template operator()<Ps, I>(), ...);
  }
  (std::index_sequence_for<Ps...>{});
}

}  // namespace halfback
