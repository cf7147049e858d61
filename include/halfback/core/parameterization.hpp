// What a parameterization is (the concept `Parameterization`), the lists of the built-in ones, and
// their run-time form (ParamDescriptor) through which every tool reaches them: the batch engine's
// tables, the run-time names (space.hpp), figure axes, the samplers' charts, the study's rows, the
// explorer and the Python module are all derived from these. Adding a parameterization is its
// header (params/) and one line in KernelParams or PortableParams below, plus its tests
// (docs/architecture.md).
#pragma once

#include <algorithm>
#include <array>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "halfback/core/param_descriptor.hpp"
#include "halfback/core/param_list.hpp"
#include "halfback/core/params/charts.hpp"
#include "halfback/core/params/common.hpp"
#include "halfback/core/params/halfdiff.hpp"
#include "halfback/core/params/halfway_disk.hpp"
#include "halfback/core/params/hybrid.hpp"
#include "halfback/core/params/ortho.hpp"
#include "halfback/core/params/rectified_hybrid.hpp"
#include "halfback/core/params/spherical.hpp"
#include "halfback/core/params/stereographic.hpp"
#include "halfback/core/space.hpp"

namespace halfback {

// The maps of a parameterization on lanes of type T (see params/common.hpp).
template <class P, class T>
concept MapsOnLanes = requires(const DirPair<T>& p, const Tuple4<T>& q, const Tuple3<T>& q3) {
  { P::template forward<T>(p) } -> std::same_as<Tuple4<T>>;
  { P::template inverse_raw<T>(q) } -> std::same_as<Solved<T>>;
  { P::template jacobian<T>(q) } -> std::same_as<T>;
  { P::template forward_iso<T>(p) } -> std::same_as<Tuple3<T>>;
  { P::template lift_iso<T>(q3) } -> std::same_as<Tuple4<T>>;
  { P::template inverse_iso_raw<T>(q3) } -> std::same_as<Solved<T>>;
  { P::template reciprocal<T>(q) } -> std::same_as<Tuple4<T>>;
  { P::template mirror<T>(q) } -> std::same_as<Tuple4<T>>;
  { P::template reciprocal_iso<T>(q3) } -> std::same_as<Tuple3<T>>;
  { P::template mirror_iso<T>(q3) } -> std::same_as<Tuple3<T>>;
};

template <class C>
concept SamplerChartType = requires(const Vec3<double>& w, Vec3<double>& out, double& x) {
  { C::name } -> std::convertible_to<std::string_view>;
  { C::r_max } -> std::convertible_to<double>;
  { C::to_direction(w, 0.0, 0.0, 0.0, out, x) } -> std::same_as<bool>;
  { C::from_direction(w, w, x, x, x) } -> std::same_as<bool>;
};

// A parameterization: its maps on float and double lanes (and on the SIMD packs of the batch
// engine, which instantiates the same templates), a name, a one-line summary, the four axes of
// its 4D form and the three of its isotropic form, and the chart of its tabulated sampler.
template <class P>
concept Parameterization = MapsOnLanes<P, float> && MapsOnLanes<P, double> && requires {
  { P::name } -> std::convertible_to<std::string_view>;
  { P::summary } -> std::convertible_to<std::string_view>;
  { P::axes } -> std::convertible_to<std::array<Axis, 4>>;
  { P::iso_axes } -> std::convertible_to<std::array<Axis, 3>>;
  requires SamplerChartType<typename P::SamplerChart>;
};

// Every built-in parameterization satisfies the concept.
template <class... Ps>
constexpr bool all_parameterizations(ParamList<Ps...>) {
  return (Parameterization<Ps> && ...);
}
static_assert(all_parameterizations(KernelParams{}) && all_parameterizations(PortableParams{}));

// Calls f(P{}) with the built-in parameterization at `index` (< kKernelParamCount).
template <class F>
decltype(auto) visit_kernel_param(std::size_t index, F&& f) {
  return [&]<class... Ps>(ParamList<Ps...>) -> decltype(auto) {
    using R = decltype(f(Spherical{}));
    if constexpr (std::is_void_v<R>) {
      std::size_t i = 0;
      (void)((i++ == index ? (f(Ps{}), true) : false) || ...);
    } else {
      R result{};
      std::size_t i = 0;
      (void)((i++ == index ? (result = f(Ps{}), true) : false) || ...);
      return result;
    }
  }(KernelParams{});
}

// A parameterization may set `static constexpr bool studied_by_default = false` to leave itself out
// of the study's default list (each one adds to a full run's time; docs/study.md).
template <class P>
constexpr bool studied_by_default_of() {
  if constexpr (requires { P::studied_by_default; })
    return P::studied_by_default;
  else
    return true;
}

template <Parameterization P>
class CompiledParam final : public ParamDescriptor {
 public:
  CompiledParam()
      : ParamDescriptor({P::name, P::summary, P::axes, P::iso_axes,
                         chart_of<typename P::SamplerChart>(), studied_by_default_of<P>()}) {}
  Tuple4<double> forward(const DirPair<double>& p) const override { return P::forward(p); }
  Tuple3<double> forward_iso(const DirPair<double>& p) const override { return P::forward_iso(p); }
  Solved<double> inverse(const Tuple4<double>& q) const override { return halfback::inverse<P>(q); }
  Solved<double> inverse_iso(const Tuple3<double>& q) const override {
    return halfback::inverse_iso<P>(q);
  }
  double jacobian(const Tuple4<double>& q) const override { return P::jacobian(q); }
  double jacobian_iso(const Tuple3<double>& q) const override {
    return halfback::jacobian_iso<P>(q);
  }
  Tuple4<double> reciprocal(const Tuple4<double>& q) const override { return P::reciprocal(q); }
  Tuple4<double> mirror(const Tuple4<double>& q) const override { return P::mirror(q); }
  Tuple3<double> reciprocal_iso(const Tuple3<double>& q) const override {
    return P::reciprocal_iso(q);
  }
  Tuple3<double> mirror_iso(const Tuple3<double>& q) const override { return P::mirror_iso(q); }
};

// Registers a C++ parameterization at run time (space.hpp): a test's, a plug-in's.
template <Parameterization P>
Space register_parameterization() {
  return register_parameterization(std::make_shared<CompiledParam<P>>());
}

}  // namespace halfback
