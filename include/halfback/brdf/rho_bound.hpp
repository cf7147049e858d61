// The one bound on a BRDF's value (docs/reliability/readers.md, "One bound on a BRDF's value").
//
// ρ above kMaxRho is a corrupt file or a diverging network, never a measurement: a perfect mirror
// averaged over MERL's smallest bin is about 2·10⁶ sr⁻¹, and the sharpest published RGL material
// (chm_mint) stays below 7·10⁶. Every reader refuses data whose ρ can exceed it (MERL per bin, ALTA
// per sample, RGL from its tables, neural BRDFs on a probe set), every writer refuses to store
// such a value, and they all say so in the same words (rho_above_bound), naming the file or the
// BRDF as the cause.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "halfback/brdf/brdf.hpp"

namespace halfback {

inline constexpr double kMaxRho = 1e10;  // sr⁻¹

// Whether a value is within the bound: finite and at most kMaxRho (NaN, a missing value, is
// within; so are negative values, which readers treat as missing or noise).
inline bool rho_within_bound(double rho) {
  return !(rho > kMaxRho);
}
inline bool rho_within_bound(const Rgb& rho) {
  return rho_within_bound(rho.r) && rho_within_bound(rho.g) && rho_within_bound(rho.b);
}

// The one message: "ρ = 1e+31 sr⁻¹ at WHERE, above the bound of 1e+10 sr⁻¹ on a BRDF's value"
// ("ρ overflows to infinity at WHERE, ..." for an infinite ρ; no " at WHERE" when `where` is
// empty). `quantity` names what is bounded when it is not ρ itself (RGL stores ρ·cos θo).
std::string rho_above_bound(double rho, std::string_view where = {},
                            std::string_view quantity = "ρ");

// The pair of a probe set where a BRDF is above the bound, and its value there.
struct RhoExcess {
  DirPair<double> pair;
  Rgb rho;
};

// The probe set: an isotropic halfdiff grid (32 θh, denser near the specular peak, × 32 θd ×
// 32 φd, φh = 0; for an anisotropic BRDF also φh = π/4, π/2, 3π/4) of the pairs whose directions
// are both within 89° of the normal (beyond, ρ of many models grows without bound while ρ·cos θ
// stays finite). What one evaluation of it finds: the first pair where ρ is above the bound (or
// none), and the largest channel of ρ over it.
struct RhoProbe {
  std::optional<RhoExcess> excess;
  double largest = 0;
};
RhoProbe probe_rho(const Brdf& brdf);
std::optional<RhoExcess> find_rho_above_bound(const Brdf& brdf);  // probe_rho(brdf).excess

// (θh, θd, φd, φh) of a pair in degrees: "θh = 1.2°, θd = 30°, φd = 90°" (φh when not 0).
std::string describe_halfdiff(const DirPair<double>& pair);

// std::invalid_argument naming the BRDF when find_rho_above_bound finds a pair: "NAME: ρ = ...
// sr⁻¹ at θh = ..., above the bound of ... on a BRDF's value (`why`)".
void require_rho_bound(const Brdf& brdf, const std::string& why);

}  // namespace halfback
