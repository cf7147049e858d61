// ALTA data files (the text format of the ALTA BRDF library, Inria): reader and evaluation of the
// scattered measurements. docs/formats.md describes the format and the choices made here.
//
// A file is a header of `#KEY value` lines, then one sample per line: dim_in input coordinates,
// dim_out values, and (with #VS 1 or 2) a confidence interval on the first value:
//   #DIM 3 1                              input and output dimensions (required)
//   #PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI   the input parameterization
//   #PARAM_OUT INV_STERADIAN_COSINE_FACTOR  what the values are
//   #VS 0|1|2                             none | ± half-width | min and max
// Other `#` lines are comments (ALTA writes #SAMPLE, #ORIGIN, #URL, ...; they are kept).
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/brdf/brdf.hpp"

namespace halfback {

struct AltaData {
  std::size_t dim_in = 0, dim_out = 0;
  std::string param_in, param_out;  // as named in the file ("" when absent)
  int vs = 0;
  std::map<std::string, std::string> header;  // every `#KEY rest` line, KEY upper-case as written
  std::vector<double> x;                      // rows × dim_in
  std::vector<double> y;                      // rows × dim_out
  std::vector<double> interval;               // rows × 2 (min, max of the first value) when vs > 0
  std::vector<std::size_t> line;              // 1-based line number of each row
  std::size_t rows() const { return line.size(); }
};

// Reads an ALTA text file strictly: #DIM present and sane, a known parameterization whose
// dimension matches #DIM (when #PARAM_IN is given), #VS in {0, 1, 2}, every data line with exactly
// the expected number of finite numbers. Throws FormatError naming the file and the line.
AltaData read_alta(const std::filesystem::path& path);
AltaData parse_alta(std::string_view text, std::string_view name);

// Dimension of an ALTA input parameterization name, 0 when unknown.
std::size_t alta_param_dimension(std::string_view name);

struct AltaOptions {
  // Neighbours blended in each incidence slice (modified Shepard weights, docs/formats.md).
  int neighbours = 8;
  // Where there is no data (an incidence outside the measured ones, or a view direction farther
  // from every sample than the slice's support radius): NaN (default) or 0.
  bool zero_outside = false;
};

// ρ from the samples of an ALTA file with #PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI (θl, θv·cos Δφ,
// θv·sin Δφ) and #PARAM_OUT INV_STERADIAN or INV_STERADIAN_COSINE_FACTOR (ρ·cos θv, converted to
// ρ at load), one or three values. The light direction is ωi, the view direction ωo. A negative
// sample is read as 0 and counted (negative_samples(), facts()).
class AltaBrdf final : public Brdf {
 public:
  AltaBrdf(const AltaData& data, std::string name_for_messages, std::string label,
           AltaOptions options = {});
  ~AltaBrdf() override;

  std::string name() const override;
  std::string description() const override;
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return false; }
  Rgb eval(const DirPair<double>& pair) const override;
  std::vector<Fact> facts() const override;

  // ρ at the data's own coordinates (θl, θv·cos Δφ, θv·sin Δφ).
  Rgb eval_coords(double theta_l, double px, double py) const;

  std::size_t samples() const;          // used for evaluation
  std::size_t dropped_grazing() const;  // cosine-factor samples at θv ≈ 90°, see docs/formats.md
  std::size_t negative_samples() const;  // samples with a negative value, read as 0
  std::vector<double> incidence_angles() const;
  double support_radius(std::size_t slice) const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
  std::string label_;
  AltaOptions options_;
};

std::shared_ptr<const AltaBrdf> load_alta(const std::filesystem::path& path,
                                          AltaOptions options = {});

}  // namespace halfback
