// The study of one BRDF in every parameterization (docs/study.md): the metrics of
// metrics.hpp, the virtual gonio-reflectometer of gonio.hpp and the image-space error of its
// reconstructions (image_metrics.hpp), as one table per metric (metric_tables.hpp). report.hpp
// writes the results of a set of BRDFs.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/acquire/gonio.hpp"
#include "halfback/acquire/nielsen.hpp"
#include "halfback/brdf/brdf.hpp"
#include "halfback/core/space.hpp"
#include "halfback/render/envmap.hpp"
#include "halfback/render/image.hpp"
#include "halfback/render/renderer.hpp"
#include "halfback/study/image_metrics.hpp"
#include "halfback/study/metrics.hpp"
#include "halfback/study/table.hpp"

namespace halfback::study {

// The parameterizations a study compares by default: every parameterization studied by default
// (ParamDescriptor::studied_by_default: the built-in ones but three that --params adds, then those
// registered so far), in the registry's order but with the spherical baseline last: halfdiff,
// ortho, hybrid, rectified-hybrid, ..., spherical.
std::vector<Space> default_studied();

// Stated maxima of a study's work (StudyConfig::validate refuses more; the sample budget's,
// acquire::kMaxSampleBudget, is a plan's too): a budget's tables and the test pairs take tens of
// bytes per sample, so these keep one study within a few GB and hours.
inline constexpr std::size_t kMaxTestPairs = 10'000'000;            // 50x the default
inline constexpr std::size_t kMaxGridCells = std::size_t(1) << 24;  // metrics 1-2, either form
inline constexpr std::size_t kMaxImageSize = 4096;                  // pixels a side, metric 4
inline constexpr std::size_t kMaxSamplerKib = 256 * 1024;           // a table of metric 5
inline constexpr std::size_t kMaxSamplerSamples = 1 << 20;          // per ωo, metric 5

// Every option of every metric of study_metrics() with its default value (metric.hpp), but the
// first option of a metric not on by default, which is empty (the metric off).
std::map<std::string, std::string> default_metric_options();

struct StudyConfig {
  // The parameterizations compared, in the order of every table's rows and the report's columns.
  std::vector<Space> params = default_studied();
  acquire::ErrorSpace space = acquire::ErrorSpace::log;
  // Made smaller by --quick (parts.hpp, apply_quick): the report says so (its headline can differ
  // from a full run's).
  bool quick = false;
  acquire::IsoGrid grid{64, 64, 64};                     // metrics 1-2, isotropic form
  std::array<std::size_t, 4> full_grid{16, 32, 16, 32};  // metrics 1-2, full form (anisotropic)
  std::vector<int> ranks{1, 2, 4, 8};
  // Metric 3: budgets of the 3D (isotropic form) and 4D (full form, anisotropic BRDFs only)
  // gonio-reflectometers, ascending; test pairs drawn from the measure.
  std::vector<std::size_t> budgets{1000, 3000, 10000, 30000, 100000};
  std::vector<std::size_t> budgets_4d{1000, 10000, 100000, 1000000};
  std::size_t test_pairs = 200000;
  double max_theta_deg = 85;  // the instrument's reach (GonioSetup), and of the test pairs
  std::uint64_t seed = 1;
  // The 3D gonio-reflectometer runs on isotropic BRDFs, the 4D one on anisotropic BRDFs.
  // Metric 4: the reconstructions at `image_budget` (one of `budgets`; of `budgets_4d` for an
  // anisotropic BRDF, if it is one of them) rendered on a sphere
  // under each environment, against the ground truth. Environment sampling only, with the same
  // random numbers for every image, so that the reconstructions see the same light directions
  // and the difference of two images is not drowned in Monte-Carlo noise.
  std::vector<render::Environment> environments;  // empty: no image-space error
  std::size_t image_budget = 10000;
  int image_size = 96, image_spp = 16;
  // Designs (design.hpp): the spacings of the gonio-reflectometer's cells. The own
  // spacing runs in both layouts (regular and stratified), the others in the regular layout only;
  // a spacing identical to own for a parameterization (angle in halfdiff) copies its results.
  // The learned spacing uses the warps in `learned` (learn_warps(), leave-one-out: set them for
  // each BRDF from the profiles of the others, taken on `profile_grid`); a parameterization
  // without learned warps has no learned rows.
  std::vector<acquire::Spacing> spacings{acquire::Spacing::own, acquire::Spacing::angle,
                                         acquire::Spacing::merl, acquire::Spacing::learned};
  std::vector<acquire::LearnedWarps> learned;
  acquire::IsoGrid profile_grid{32, 32, 32};
  // A fingerprint of the profiles the learned warps come from (parts.hpp: learned_fingerprint),
  // empty without them: part of the settings of a run, so that parts learned from other BRDFs
  // are never resumed or merged with these.
  std::string learned_from;
  // The options of the metrics (metric.hpp: MetricOption), as text by key ("fit_model"), e.g.
  // the sampling metric's sampler_kib and the fit metric's fit_model: every option of every
  // metric of study_metrics(), a metric that is off with its first option empty.
  std::map<std::string, std::string> options = default_metric_options();
  // Nielsen et al. 2015's minimal sampling (nielsen.hpp), with a database (none: no
  // rows): rows of halfdiff's gonio table, design nielsen, at each of `nielsen_counts`
  // measurements (ascending), isotropic BRDFs only, from the basis without the database's member
  // like the BRDF (leave-one-out). `nielsen_from` names the database (nielsen_fingerprint) in the
  // settings of a run, so that parts from other databases are never resumed or merged with these.
  std::shared_ptr<const acquire::NielsenDatabase> nielsen;
  std::vector<std::size_t> nielsen_counts{1, 2, 5, 10, 20, 40, 100};
  std::string nielsen_from;
  // Called from worker threads as stages finish (e.g. "gonio hybrid"): for progress displays.
  std::function<void(std::string_view stage)> progress;

  // Throws std::invalid_argument naming a bad setting (no parameterization or one given twice,
  // unsorted budgets, an image budget that is not one of them, sizes of 0). No budgets: no
  // gonio-reflectometer and no images.
  void validate() const;
  // The option of that key; std::logic_error when no metric has it (a bug).
  const std::string& option(const std::string& key) const;
};

// The typed records of the gonio and image tables' rows (metric_tables.hpp).
struct GonioPoint {
  acquire::Design design = acquire::Design::regular;  // the layout
  std::size_t budget = 0, samples = 0;
  double error = 0;
  acquire::Spacing spacing = acquire::Spacing::own;
};

struct ImagePoint {
  acquire::Design design = acquire::Design::regular;
  std::size_t samples = 0;
  std::string environment;
  double relative_rmse = 0, mean_delta_e = 0, p95_delta_e = 0;
  double mae = 0, rmse = 0, ssim = 0;  // Sztrajman et al. 2021's protocol (ImageError)
};

// A row of the sampling table: a sampler in a parameterization's chart at a table size, against
// the cosine and the BRDF's own sampler (`own_sampler` "none" and efficiency 0 when it has none).
// The samplers: "tabulated" (render::TabulatedSampler) and "factored" (render::FactoredSampler,
// kFactoredTerms terms; Lawrence et al. 2004's manner).
inline constexpr int kFactoredTerms = 4;
struct SamplingPoint {
  std::size_t kib = 0;  // the memory asked
  std::string sampler = "tabulated";
  double sampler_kib = 0;  // the memory its tables take
  std::string chart;
  double relative_variance = 0, relative_variance_error = 0, ns_per_sample = 0;
  double efficiency_vs_cosine = 0;
  std::string own_sampler = "none";
  double efficiency_vs_own = 0;
  // Dupuy & Jakob 2018's sampler (the VNDF and luminance warps of the BRDF's RGL export) in at
  // most `kib` KiB of sampling tables: the KiB it took and this table's efficiency against it;
  // both 0 where there is none (an anisotropic BRDF, one the export refuses, or no size that fits).
  double vndf_warp_kib = 0, efficiency_vs_vndf_warp = 0;
  // The fitted-mixture sampler (Sztrajman et al. 2021 sample their neural BRDFs through fitted
  // analytic lobes): the fit metric's model (option fit_model) fitted to the whole BRDF, sampled as
  // the mixture of its lobes' own samplers; this table's efficiency against it, 0 where there is no
  // fit.
  double efficiency_vs_fitted_mixture = 0;
  // The sphere of the image protocol (under the study's first environment) rendered with this
  // sampler's samples alone and with MIS (one environment and one BRDF sample): the image's
  // relative variance per pixel sample (render::relative_pixel_variance over the sphere: Σ
  // variance / Σ mean², the squared relative RMSE of one sample per pixel), and the efficiency
  // against the same strategy with cosine sampling.
  double pixel_relative_variance_brdf = 0, pixel_relative_variance_mis = 0;
  double pixel_efficiency_vs_cosine_brdf = 0, pixel_efficiency_vs_cosine_mis = 0;
};

struct BrdfResult {
  std::string label;
  bool isotropic = true;
  std::vector<Space> params;  // the parameterizations studied (StudyConfig::params)
  // One table per metric, those of stored_tables() in its order; the rows of each
  // parameterization together, in the order of `params`.
  std::vector<MetricTable> tables;
  // Under the first environment: the BRDF's rendering, then its regular-design reconstructions
  // at the image budget in the order of `params` (empty when there are no images).
  std::vector<render::Image> example_images;
  double seconds = 0;

  // The table of that name; std::invalid_argument when there is none.
  const MetricTable& table(std::string_view name) const;
};

// Every metric of `brdf` in every parameterization of config.params (one task each; the
// renderings then use all cores). Throws what the metrics throw.
BrdfResult study_brdf(const Brdf& brdf, const std::string& label, const StudyConfig& config);

// The render settings of the study's image protocol: config.image_size, image_spp and seed,
// environment sampling only (the same light directions for every BRDF).
render::RenderSettings image_settings(const StudyConfig& config);

// The image-space error of `test` against `reference` under `env` with the study's image
// protocol (config.image_size, image_spp and seed; environment sampling, so both are evaluated at
// the same light directions): a model, a fit or a factored model scored as the reconstructions
// are. Throws std::invalid_argument when the reference gives a value that is not finite in its
// rendering (an ALTA file without data somewhere), and what compare_images throws.
ImageError image_error(const Brdf& test, const Brdf& reference, const render::EnvMap& env,
                       const StudyConfig& config);

}  // namespace halfback::study
