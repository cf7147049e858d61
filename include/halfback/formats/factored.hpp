// A data-driven factored BRDF (docs/fit.md, "Factored models"): on the
// isotropic coordinates (a, b, φ) of a parameterization, each colour channel is
//   ρ_c(a, b, φ) = exp( clamp(Σ_r f_cr(a) g_cr(b) h_cr(φ), 0, M_c) ) − 1,
// a sum of `rank` separable terms in log(1 + ρ) space, each factor tabulated at the cell centres
// of the parameterization's default isotropic grid of the file's counts and interpolated linearly
// (held constant beyond the outermost centres). M_c, the largest log(1 + ρ_c) of the data it was
// fitted to, bounds the products where no data constrained them (a product of factors each
// fitted on other cells can exceed every value seen). Its size is 3 · rank · (na + nb + nφ) + 3
// numbers.
//
// File (`.json`): a JSON object, its first key "format": "halfback-factored-brdf", then
// "version" 1, "name", "parameterization" (a name space_from_name() takes), "rank", "counts"
// [na, nb, nφ], "max_log" [M_r, M_g, M_b], and "factors": {"r"|"g"|"b": [term: {"a": [...],
// "b": [...], "phi": [...]}]}.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/brdf/resample.hpp"
#include "halfback/core/space.hpp"

namespace halfback {

struct FactoredTerm {
  std::vector<double> a, b, phi;  // the factors at the cell centres of each axis
};

struct FactoredModel {
  Space space = space_of<Hybrid>;  // a parameterization, not dirs
  std::string name = "factored";
  std::array<std::size_t, 3> counts{32, 32, 32};
  std::array<std::vector<FactoredTerm>, 3> channels;  // r, g, b: `rank` terms each
  std::array<double, 3> max_log{0, 0, 0};             // M_c (finite, ≥ 0)

  std::size_t rank() const { return channels[0].size(); }
  std::size_t numbers() const { return 3 * rank() * (counts[0] + counts[1] + counts[2]) + 3; }
  // The isotropic grid whose cell centres the factors sample.
  GridSpec grid() const;
};

class FactoredBrdf final : public Brdf {
 public:
  // Throws std::invalid_argument for dirs, empty counts, a rank of 0, factors of the wrong length
  // or not finite.
  explicit FactoredBrdf(FactoredModel model);

  std::string name() const override { return model_.name; }
  std::string description() const override;
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return false; }  // as its parameterization makes it
  Rgb eval(const DirPair<double>& pair) const override;

  const FactoredModel& model() const { return model_; }

 private:
  double factor_at(const std::vector<double>& f, std::size_t axis, double x) const;

  FactoredModel model_;
  GridSpec grid_;
};

// Writes the file atomically (nothing is left on failure). Throws std::runtime_error naming it.
void write_factored(const std::filesystem::path& path, const FactoredModel& model);
// The file's text. Throws std::invalid_argument as FactoredBrdf's constructor.
std::string factored_text(const FactoredModel& model);
// Throws FormatError naming the file and the field: not JSON, another format, a wrong version,
// an unknown parameterization, counts or rank out of range (at most 4096 cells an axis and 64
// terms), factors of the wrong length or not finite numbers.
FactoredModel read_factored(const std::filesystem::path& path);
// The same from text (`source` names it in errors): for the fuzzer and the Python module.
FactoredModel parse_factored(std::string_view text, const std::string& source);
// Whether a file's first bytes are those of such a file (the loader's detection).
bool looks_like_factored(std::string_view head);

}  // namespace halfback
