// Run-time names for the coordinate spaces, for code that picks a parameterization from user
// input (CLI, Python, file metadata). Compile-time code uses the structs of param.hpp directly.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include "halfback/core/param.hpp"

namespace halfback {

enum class Space { dirs, spherical, halfdiff, ortho, hybrid };

inline constexpr std::array<Space, 4> kParameterizations{Space::spherical, Space::halfdiff,
                                                         Space::ortho, Space::hybrid};

// A space and whether its isotropic (3D, canonical-pose) form is meant. `dirs` has no isotropic
// form: it is always the 6 Cartesian components (wi_x, wi_y, wi_z, wo_x, wo_y, wo_z).
struct Form {
  Space space = Space::dirs;
  bool isotropic = false;
  friend bool operator==(const Form&, const Form&) = default;
};

// Calls f(P{}) with the parameterization struct named by `space`; throws std::invalid_argument
// for dirs, which is not a parameterization.
template <class F>
decltype(auto) visit_parameterization(Space space, F&& f) {
  switch (space) {
    case Space::spherical:
      return f(Spherical{});
    case Space::halfdiff:
      return f(HalfDiff{});
    case Space::ortho:
      return f(Ortho{});
    case Space::hybrid:
      return f(Hybrid{});
    case Space::dirs:
      break;
  }
  throw std::invalid_argument(
      "dirs is not a parameterization (expected spherical, halfdiff, "
      "ortho or hybrid)");
}

std::string_view name_of(Space space);
std::optional<Space> space_from_name(std::string_view name);
std::string space_names();  // "dirs, spherical, halfdiff, ortho, hybrid"

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

}  // namespace halfback
