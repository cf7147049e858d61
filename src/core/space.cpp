#include "halfback/core/space.hpp"

#include <cmath>

namespace halfback {

namespace {
constexpr std::array<std::string_view, 5> kNames{"dirs", "spherical", "halfdiff", "ortho",
                                                 "hybrid"};
constexpr std::array<std::string_view, 6> kDirColumns{"wi_x", "wi_y", "wi_z",
                                                      "wo_x", "wo_y", "wo_z"};
}  // namespace

std::string_view name_of(Space space) {
  return kNames[static_cast<std::size_t>(space)];
}

std::optional<Space> space_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kNames.size(); ++i)
    if (kNames[i] == name) return static_cast<Space>(i);
  return std::nullopt;
}

std::string space_names() {
  std::string s;
  for (auto n : kNames) {
    if (!s.empty()) s += ", ";
    s += n;
  }
  return s;
}

std::size_t dimension(Form form) {
  if (form.space == Space::dirs) return 6;
  return form.isotropic ? 3 : 4;
}

std::span<const std::string_view> column_names(Form form) {
  if (form.space == Space::dirs) return kDirColumns;
  return visit_parameterization(form.space, [&](auto p) -> std::span<const std::string_view> {
    using P = decltype(p);
    if (form.isotropic) return P::iso_columns;
    return P::columns;
  });
}

PairStatus check_pair(const DirPair<double>& p) {
  const double v[6] = {p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z};
  for (double x : v)
    if (!std::isfinite(x)) return PairStatus::not_finite;
  if (std::abs(detail::dot(p.wi, p.wi) - 1.0) > kUnitTolerance) return PairStatus::wi_not_unit;
  if (std::abs(detail::dot(p.wo, p.wo) - 1.0) > kUnitTolerance) return PairStatus::wo_not_unit;
  if (p.wi.z < -kDomainTolerance<double>) return PairStatus::wi_below_horizon;
  if (p.wo.z < -kDomainTolerance<double>) return PairStatus::wo_below_horizon;
  return PairStatus::ok;
}

std::string_view describe(PairStatus status) {
  switch (status) {
    case PairStatus::ok:
      return "valid";
    case PairStatus::not_finite:
      return "a direction component is not a finite number";
    case PairStatus::wi_not_unit:
      return "wi is not a unit vector";
    case PairStatus::wo_not_unit:
      return "wo is not a unit vector";
    case PairStatus::wi_below_horizon:
      return "wi is below the horizon (wi_z < 0)";
    case PairStatus::wo_below_horizon:
      return "wo is below the horizon (wo_z < 0)";
  }
  return "unknown";
}

}  // namespace halfback
