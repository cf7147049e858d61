// ParamDescriptor: a parameterization at run time (names, axes, sampler chart, maps in double),
// what a Space leads to (space.hpp). The compile-time side (the concept, CompiledParam):
// parameterization.hpp.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <span>
#include <string>
#include <string_view>

#include "halfback/core/params/charts.hpp"
#include "halfback/core/params/common.hpp"

namespace halfback {

// Wraps the azimuth coordinates (AxisKind::azimuth) of m rows of `axes.size()` coordinates to
// [0, 2π), as the built-in maps' inverses do (params/common.hpp): the batch engine applies it
// before a run-time parameterization's inverse_rows.
void wrap_azimuth_rows(std::span<const Axis> axes, double* coords, std::size_t m);

// The pair mirrored across the vertical plane of h̄ (the xz-plane when h̄ = 0): what a run-time
// parameterization's mirror map does to the pair behind its coordinates.
DirPair<double> mirror_pair(const DirPair<double>& p);

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

}  // namespace halfback
