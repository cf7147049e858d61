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

#include "halfback/core/params/charts.hpp"
#include "halfback/core/params/common.hpp"
#include "halfback/core/params/halfdiff.hpp"
#include "halfback/core/params/halfway_disk.hpp"
#include "halfback/core/params/hybrid.hpp"
#include "halfback/core/params/ortho.hpp"
#include "halfback/core/params/rectified_hybrid.hpp"
#include "halfback/core/params/spherical.hpp"
#include "halfback/core/params/stereographic.hpp"

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

template <Parameterization... Ps>
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

// Calls f(P{}) with the built-in parameterization at `index` (< kKernelParamCount).
template <class F>
decltype(auto) visit_kernel_param(std::size_t index, F&& f) {
  return [&]<class... Ps>(ParamList<Ps...>) -> decltype(auto) {
    using R = decltype(f(Spherical{}));
    if constexpr (std::is_void_v<R>) {
      std::size_t i = 0;
      ((i++ == index ? (f(Ps{}), true) : false) || ...);
    } else {
      R result{};
      std::size_t i = 0;
      ((i++ == index ? (result = f(Ps{}), true) : false) || ...);
      return result;
    }
  }(KernelParams{});
}

// A parameterization at run time: its names and axes, and its maps in double precision, for code
// that picks a parameterization from user input. For a C++ parameterization (CompiledParam) the
// maps are the templates themselves, bit for bit; a run-time one (a Python user's) overrides them.
// The checked forms: inverse() and inverse_iso() give NaN directions outside the valid domain.
class ParamDescriptor {
 public:
  struct Names {
    std::string_view name, summary;
    std::array<Axis, 4> axes;
    std::array<Axis, 3> iso_axes;
    SamplerChart chart;
    // Whether `halfback study` compares it without being asked (--params): see
    // studied_by_default_of below.
    bool studied_by_default = true;
  };
  explicit ParamDescriptor(const Names& names);  // copies every string
  virtual ~ParamDescriptor() = default;
  ParamDescriptor(const ParamDescriptor&) = delete;
  ParamDescriptor& operator=(const ParamDescriptor&) = delete;

  std::string_view name() const { return name_; }
  std::string_view summary() const { return summary_; }
  std::span<const Axis> axes(bool isotropic) const {
    if (isotropic) return iso_axes_;
    return axes_;
  }
  std::span<const std::string_view> columns(bool isotropic) const {
    if (isotropic) return iso_columns_;
    return columns_;
  }
  const SamplerChart& sampler_chart() const { return chart_; }
  bool studied_by_default() const { return studied_by_default_; }

  // Whether the maps may run on several threads at once (a Python callable may not).
  virtual bool concurrent() const { return true; }

  virtual Tuple4<double> forward(const DirPair<double>& pair) const = 0;
  virtual Tuple3<double> forward_iso(const DirPair<double>& pair) const = 0;
  virtual Solved<double> inverse(const Tuple4<double>& q) const = 0;
  virtual Solved<double> inverse_iso(const Tuple3<double>& q) const = 0;
  virtual double jacobian(const Tuple4<double>& q) const = 0;
  virtual double jacobian_iso(const Tuple3<double>& q) const = 0;
  virtual Tuple4<double> reciprocal(const Tuple4<double>& q) const = 0;
  virtual Tuple4<double> mirror(const Tuple4<double>& q) const = 0;
  virtual Tuple3<double> reciprocal_iso(const Tuple3<double>& q) const = 0;
  virtual Tuple3<double> mirror_iso(const Tuple3<double>& q) const = 0;

  // Blocks of m rows, for the batch engine's path of a parameterization outside KernelParams
  // (row-major: `coords` holds m tuples of 4, or 3 when isotropic). The defaults loop over the
  // maps above; a run-time parameterization overrides them to call its vectorized code once.
  virtual void forward_rows(bool isotropic, const DirPair<double>* pairs, std::size_t m,
                            double* coords) const;
  virtual void inverse_rows(bool isotropic, const double* coords, std::size_t m,
                            DirPair<double>* pairs, std::uint8_t* in_domain) const;
  virtual void jacobian_rows(bool isotropic, const double* coords, std::size_t m,
                             double* jacobian) const;

 private:
  std::deque<std::string> strings_;  // owns what the views below point into
  std::string_view name_, summary_;
  std::array<Axis, 4> axes_;
  std::array<Axis, 3> iso_axes_;
  std::array<std::string_view, 4> columns_;
  std::array<std::string_view, 3> iso_columns_;
  SamplerChart chart_;
  bool studied_by_default_;
  std::string_view keep(std::string_view s);
};

template <Parameterization P>
class CompiledParam final : public ParamDescriptor {
 public:
  CompiledParam()
      : ParamDescriptor(
            {P::name, P::summary, P::axes, P::iso_axes, chart_of<typename P::SamplerChart>()}) {}
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

  // The block maps as loops over the inlined templates (no virtual call a row).
  void forward_rows(bool iso, const DirPair<double>* pairs, std::size_t m,
                    double* coords) const override {
    for (std::size_t i = 0; i < m; ++i) {
      if (iso) {
        const Tuple3<double> q = P::forward_iso(pairs[i]);
        std::copy(q.begin(), q.end(), coords + 3 * i);
      } else {
        const Tuple4<double> q = P::forward(pairs[i]);
        std::copy(q.begin(), q.end(), coords + 4 * i);
      }
    }
  }
  void inverse_rows(bool iso, const double* coords, std::size_t m, DirPair<double>* pairs,
                    std::uint8_t* in_domain) const override {
    for (std::size_t i = 0; i < m; ++i) {
      const double* q = coords + (iso ? 3 : 4) * i;
      const Solved<double> s = iso ? halfback::inverse_iso<P>(Tuple3<double>{q[0], q[1], q[2]})
                                   : halfback::inverse<P>(Tuple4<double>{q[0], q[1], q[2], q[3]});
      pairs[i] = s.pair;
      in_domain[i] = s.in_domain ? 1 : 0;
    }
  }
  void jacobian_rows(bool iso, const double* coords, std::size_t m,
                     double* jacobian) const override {
    for (std::size_t i = 0; i < m; ++i) {
      const double* q = coords + (iso ? 3 : 4) * i;
      jacobian[i] = iso ? halfback::jacobian_iso<P>(Tuple3<double>{q[0], q[1], q[2]})
                        : P::jacobian(Tuple4<double>{q[0], q[1], q[2], q[3]});
    }
  }
};

}  // namespace halfback
