// `halfback info`: what a BRDF is — its format and data facts (Brdf::facts), symmetries, the
// largest value over a grid of configurations, and the directional albedo at a few incidences.
#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <string>

#include "command.hpp"
#include "halfback/brdf/albedo.hpp"
#include "halfback/brdf/resample.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::cli {

namespace {

struct InfoOptions {
  std::string brdf;
  int albedo_samples = 128;
};

std::string rgb_text(const Rgb& v) {
  return fmt::format("{:.6g}, {:.6g}, {:.6g}", v.r, v.g, v.b);
}

int run_info(const InfoOptions& o) {
  const BrdfPtr brdf = brdf_argument(o.brdf, "SPEC");
  std::vector<Brdf::Fact> lines;
  lines.push_back({"name", brdf->name()});
  lines.push_back({"description", brdf->description()});
  for (Brdf::Fact& f : brdf->facts()) lines.push_back(std::move(f));
  lines.push_back({"isotropic", brdf->isotropic() ? "yes" : "no"});
  lines.push_back({"reciprocal", brdf->reciprocal() ? "yes" : "no (as declared by the data)"});

  // The largest ρ over the nodes of an isotropic halfdiff grid (θh = 0 and θd = 0 included, so
  // the specular and retro-reflective peaks are sampled). Azimuth of the half vector: 0.
  const GridSpec grid = [] {
    GridSpec g = default_grid(space_of<HalfDiff>, GridKind::isotropic, {91, 91, 73});
    g.sampling = GridSampling::nodes;
    g.axes[2].hi = 2 * std::numbers::pi * 72 / 73;
    return g;
  }();
  const ResampledTable t = resample(*brdf, grid);
  double best = -1;
  std::size_t where = 0;
  std::vector<DirPair<double>> pairs(grid.points());
  std::vector<std::uint8_t> ok(grid.points());
  grid_pairs(grid, 0, pairs, ok);
  const double min_z = std::cos(89 * std::numbers::pi / 180);
  for (std::size_t p = 0; p < grid.points(); ++p) {
    // Grazing pairs (θ > 89°) are left out: there ρ of many models grows without bound while
    // ρ·cos θ stays finite, and no measurement reaches them.
    if (!t.valid[p] || pairs[p].wi.z < min_z || pairs[p].wo.z < min_z) continue;
    const double lum = std::max({t.rgb[3 * p], t.rgb[3 * p + 1], t.rgb[3 * p + 2]});
    if (lum > best) best = lum, where = p;
  }
  if (best >= 0) {
    const double deg = 180 / std::numbers::pi;
    const std::array<double, 4> q = grid.point(where);
    // At θh = 0 every φd is the same pair turned about n: the scan's first maximum is one of
    // equals (it printed 34.5° once and 0° after), so say "any".
    const std::string phi_d = q[0] == 0 ? "any" : fmt::format("{:.3g}°", q[2] * deg);
    lines.push_back(
        {"max ρ (θ ≤ 89°)",
         fmt::format("{} sr⁻¹ at θh = {:.3g}°, θd = {:.3g}°, φd = {} ({} grid points)",
                     rgb_text({t.rgb[3 * where], t.rgb[3 * where + 1], t.rgb[3 * where + 2]}),
                     q[0] * deg, q[1] * deg, phi_d, t.valid_count())});
  }

  for (const double theta_deg : {0.0, 30.0, 60.0, 80.0}) {
    const double th = theta_deg * std::numbers::pi / 180;
    const AlbedoEstimate a =
        directional_albedo(*brdf, {std::sin(th), 0, std::cos(th)}, o.albedo_samples);
    const std::string label = fmt::format("albedo at θi = {:g}°", theta_deg);
    if (!(a.measured > 0)) {
      lines.push_back({label, "undefined: no ωo at this incidence was measured"});
      continue;
    }
    // Missing values are left out of the average; say how much of the hemisphere it covers.
    const std::string coverage =
        a.measured < 1 ? fmt::format(
                             ", mean over the measured {:.4g} % of the cosine-weighted "
                             "hemisphere",
                             100 * a.measured)
                       : std::string();
    lines.push_back(
        {label, fmt::format("{}  (± {:.2g}{})", rgb_text(a.mean),
                            std::max({a.standard_error.r, a.standard_error.g, a.standard_error.b}),
                            coverage)});
  }

  std::size_t width = 0;
  for (const auto& l : lines) width = std::max(width, l.label.size());
  std::string s;
  for (const auto& l : lines) s += fmt::format("{:<{}}  {}\n", l.label + ":", width + 1, l.value);
  Output out("-");
  out.write(s);
  out.commit();
  return kExitOk;
}

}  // namespace

Command register_info(CLI::App& parent) {
  auto o = std::make_shared<InfoOptions>();
  CLI::App* app = parent.add_subcommand(
      "info", "Describe a BRDF: format, data facts, symmetries, largest value, albedo");
  app->add_option("brdf", o->brdf, "BRDF SPEC: a MERL, RGL or ALTA file, or a model")->required();
  app->add_option("--albedo-samples", o->albedo_samples,
                  "Stratified samples per axis of the albedo estimates (N x N)")
      ->check(CLI::Range(4, 4096))
      ->capture_default_str();
  app->footer(
      "The albedo a(wi) = integral of rho(wi, wo) cos(theta_o) dwo is estimated by stratified\n"
      "sampling, cosine-weighted and, when the BRDF samples itself, combined with its sampler\n"
      "(MIS; ± one standard error, of the largest channel). The largest\n"
      "value is searched on a 91 x 91 x 73 grid of (theta_h, theta_d, phi_d), peaks included,\n"
      "over the pairs with both directions within 89 degrees of the normal.\n"
      "Example:\n"
      "  halfback info ggx:alpha=0.2\n"
      "  halfback info ../shared/data/rgl/paper_white_rgb.bsdf");
  return {app, [o] { return run_info(*o); }};
}

}  // namespace halfback::cli
