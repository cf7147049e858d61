// BRDFs shared by the benchmarks (not part of the library).
#pragma once

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

#include "halfback/brdf/brdf.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::bench {

// A smooth isotropic lobe (tabulated into MERL data by the lookup benchmarks).
class Lobe final : public Brdf {
 public:
  std::string name() const override { return "lobe"; }
  std::string description() const override { return "bench lobe"; }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& p) const override {
    const double hz = p.wi.z + p.wo.z, hx = p.wi.x + p.wo.x, hy = p.wi.y + p.wo.y;
    const double c = hz / std::sqrt(hx * hx + hy * hy + hz * hz);
    const double lobe = 5 * std::pow(c, 40.0);
    return {0.1 + lobe, 0.2 + lobe, 0.3 + lobe};
  }
  using Brdf::eval;
};

// The neural BRDF of MERL's blue-acrylic from ../shared (HALFBACK_SHARED_DIR overrides where that
// is), or an embedded network when the shared data is absent. Loaded once.
inline const Brdf& neural_brdf(const char* source_dir) {
  static const BrdfPtr brdf = [source_dir] {
    const char* shared = std::getenv("HALFBACK_SHARED_DIR");
    const std::filesystem::path file =
        (shared && *shared ? std::filesystem::path(shared)
                           : std::filesystem::path(source_dir) / ".." / "shared") /
        "data/nbrdf/merl_nbrdf/blue-acrylic.h5";
    std::error_code ec;
    return std::filesystem::exists(file, ec) ? load_brdf(file.string())
                                             : load_brdf("embedded:gold-metallic-paint3");
  }();
  return *brdf;
}

}  // namespace halfback::bench
