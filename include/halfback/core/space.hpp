// Run-time names for the coordinate spaces, for code that picks a parameterization from user
// input (CLI, Python, file metadata, the explorer). A Space is `dirs` (the 6 Cartesian components
// of the pair) or a parameterization: one of KernelParams (parameterization.hpp), or one
// registered at run time (a test's, or a Python user's). Compile-time code uses the structs of
// params/ directly; space_of<P> names a built-in one.
#pragma once

#include <array>
#include <compare>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/core/param_descriptor.hpp"
#include "halfback/core/param_list.hpp"

namespace halfback {

class Space {
 public:
  static const Space dirs;
  constexpr Space() = default;  // dirs

  // Ids: 0 is dirs, 1 .. kKernelParamCount KernelParams, then PortableParams, then the registered
  // ones.
  static constexpr Space from_id(std::uint16_t id) { return Space(id); }
  constexpr std::uint16_t id() const { return id_; }
  constexpr bool is_dirs() const { return id_ == 0; }
  // Whether the batch engine has SIMD kernels for it (KernelParams).
  constexpr bool has_kernels() const { return id_ >= 1 && id_ <= kKernelParamCount; }
  // The position in KernelParams; only for has_kernels().
  constexpr std::size_t kernel_index() const { return std::size_t(id_) - 1; }

  // The parameterization; throws std::invalid_argument for dirs.
  const ParamDescriptor& param() const;

  friend constexpr bool operator==(Space, Space) = default;
  friend constexpr auto operator<=>(Space, Space) = default;

 private:
  explicit constexpr Space(std::uint16_t id) : id_(id) {}
  std::uint16_t id_ = 0;
};
inline constexpr Space Space::dirs{};

// The space of the built-in parameterization P.
template <class P>
inline constexpr Space space_of = Space::from_id(std::uint16_t(1 + builtin_index<P>));

// The parameterizations with SIMD kernels, in the order of KernelParams.
inline constexpr std::array<Space, kKernelParamCount> kKernelSpaces = [] {
  std::array<Space, kKernelParamCount> a{};
  for (std::size_t i = 0; i < a.size(); ++i) a[i] = Space::from_id(std::uint16_t(i + 1));
  return a;
}();
// Every built-in parameterization: KernelParams, then PortableParams.
inline constexpr std::array<Space, kBuiltinParamCount> kBuiltinSpaces = [] {
  std::array<Space, kBuiltinParamCount> a{};
  for (std::size_t i = 0; i < a.size(); ++i) a[i] = Space::from_id(std::uint16_t(i + 1));
  return a;
}();

// Every parameterization: the built-in ones, then those registered, in the order registered.
std::vector<Space> parameterizations();

// Adds a parameterization at run time and returns its space. Its name must not be "dirs" nor a
// built-in one's (std::invalid_argument); registering a name again gives a new space, which the
// name then denotes (spaces of the older one stay valid). Thread-safe; never unregistered. A C++
// parameterization: register_parameterization<P>() (parameterization.hpp).
Space register_parameterization(std::shared_ptr<const ParamDescriptor> descriptor);

// A family of parameterizations with parameters (Dupuy & Jakob's per-material warp: the
// parameter is a BRDF): the name "PREFIX:ARGS" denotes the parameterization that `make(ARGS)`
// builds, registered under that whole name the first time space_from_name() meets it. `make`
// throws std::invalid_argument (or another std::exception) naming what is wrong with ARGS. A
// higher layer registers the family (the loader: register_brdf_parameterization_families), so that
// core stays below the BRDFs. Registering a prefix again replaces its factory.
using ParamFactory = std::function<std::shared_ptr<const ParamDescriptor>(std::string_view args)>;
void register_parameterization_family(std::string prefix, std::string usage, ParamFactory make);
// "PREFIX:USAGE" of each family, e.g. "dupuy-jakob:BRDF", for help texts.
std::vector<std::string> parameterization_families();

// A space and whether its isotropic (3D, canonical-pose) form is meant. `dirs` has no isotropic
// form: it is always the 6 Cartesian components (wi_x, wi_y, wi_z, wo_x, wo_y, wo_z).
struct Form {
  Space space = Space::dirs;
  bool isotropic = false;
  friend bool operator==(const Form&, const Form&) = default;
};

std::string_view name_of(Space space);
// The space of a name: "dirs", a parameterization's, or a family's "PREFIX:ARGS" (built and
// registered on first use; the family's errors propagate). nullopt for an unknown name.
std::optional<Space> space_from_name(std::string_view name);
std::string space_names();  // "dirs, spherical, halfdiff, ortho, hybrid" (and registered)
std::string parameterization_names(std::string_view last_separator = " or ");
// "spherical, halfdiff, ortho or hybrid"

// Number of coordinates of a form: 6 for dirs, 4 or 3 for a parameterization.
std::size_t dimension(Form form);

// Column names (CSV headers, NumPy docs) of a form.
std::span<const std::string_view> column_names(Form form);

// Checks a direction pair given by the user. Directions must be finite, unit within
// kUnitTolerance (on ‖ω‖² - 1), and not below the horizon by more than kDomainTolerance.
enum class PairStatus {
  ok,
  not_finite,
  wi_not_unit,
  wo_not_unit,
  wi_below_horizon,
  wo_below_horizon
};
inline constexpr double kUnitTolerance = 1e-6;
PairStatus check_pair(const DirPair<double>& p);
std::string_view describe(PairStatus status);

// The one rule for a pair a user gives (eval, convert, Python, the explorer): check_pair()'s
// status, and an accepted pair (ok) put onto the unit upper hemisphere as the conversions do
// (docs/reliability/numerics.md, "Every accepted direction pair round-trips"): a direction unit to
// rounding is kept bit for bit, one within kUnitTolerance of unit length is divided by its norm (a
// z below the horizon within tolerance put onto it first). A pair with another status is left as it
// is: the caller refuses it (not finite, not unit) or answers it (below the horizon: ρ = 0).
PairStatus accept_pair(DirPair<double>& pair);

}  // namespace halfback
