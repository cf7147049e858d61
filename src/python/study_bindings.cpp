// The study in Python (docs/study.md, "Running on whole databases"): halfback.study_brdf,
// study_profile, merge_study, and the SSIM of its image-space error (docs/study.md).
#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "acquisition.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/study/image_metrics.hpp"
#include "halfback/study/metric.hpp"
#include "halfback/study/parts.hpp"
#include "halfback/study/report.hpp"
#include "halfback/study/study.hpp"
#include "halfback/util/output_dir.hpp"
#include "metric_settings.hpp"
#include "py_brdf.hpp"

namespace py = pybind11;

namespace halfback::python {

namespace {

// ---------------------------------------------------------------------------------------------
// The study (docs/study.md, "Running on whole databases"): one BRDF at a time, for engines such as
// Dask, and the merge
// ---------------------------------------------------------------------------------------------

template <class T>
T setting(const py::handle& value, const std::string& key) {
  try {
    return value.cast<T>();
  } catch (const py::cast_error&) {
    throw py::value_error("settings['" + key + "']: expected " + py::type_id<T>() + ", got " +
                          py::repr(value).cast<std::string>());
  }
}

// The settings dict: the options of `halfback study`, '-' spelled '_', and the profiles of the
// study's BRDFs for the learned design (study_profile()'s texts, in the study's order).
struct PySettings {
  study::StudySettings settings;
  std::vector<std::string> profiles;
  bool has_profiles = false;
  bool designs_given = false;
  bool learned_left_out = false;  // the default designs without profiles: learned left out
};

// The keys of the metrics in the settings dict (study::study_metrics()): no_NAME for each metric
// that can be turned off, and each option's key.
std::string metric_setting_keys() {
  std::string keys;
  for (const study::Metric* m : study::study_metrics()) {
    if (m->switchable()) keys += (keys.empty() ? "no_" : ", no_") + std::string(m->name());
    for (const study::MetricOption& o : m->options()) keys += (keys.empty() ? "" : ", ") + o.key;
  }
  return keys;
}

// study_brdf's documentation of the metrics' keys, from the list (study::study_metrics()): no_NAME
// for each metric that can be turned off, and each option with its values as the settings
// resolve them (study::option_default).
std::string metric_settings_doc() {
  std::string offs, options;
  for (const study::Metric* m : study::study_metrics()) {
    if (m->switchable()) offs += (offs.empty() ? "no_" : ", no_") + std::string(m->name());
    const std::vector<study::MetricOption> own = m->options();
    for (std::size_t i = 0; i < own.size(); ++i)
      options += fmt::format("{}{} ({})", options.empty() ? "" : ", ", own[i].key,
                             python_option_values(*m, i));
  }
  const std::string text = fmt::format(
      "per metric of the study's list no_NAME ({}) and its options, each missing one taking its "
      "default: {}",
      offs, options);
  // In lines of at most 100 characters, as the rest of the docstring.
  std::string wrapped;
  std::size_t line = 0;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find(' ', at), text.size());
    const std::size_t word = end - at;
    if (line && line + 1 + word > 100) {
      wrapped += '\n';
      line = 0;
    } else if (line) {
      wrapped += ' ';
      ++line;
    }
    wrapped.append(text, at, word);
    line += word;
    at = end + 1;
  }
  return wrapped;
}

// A metric's key of the settings dict (no_NAME, or an option: text, an integer or a list of
// integers as its kind says); false when `key` is none of them.
bool read_metric_setting(study::StudySettings& s, const std::string& key, const py::handle& v) {
  for (const study::Metric* m : study::study_metrics()) {
    if (m->switchable() && key == "no_" + std::string(m->name())) {
      if (setting<bool>(v, key)) s.off.emplace_back(m->name());
      return true;
    }
    for (const study::MetricOption& o : m->options()) {
      if (key != o.key) continue;
      using Kind = study::MetricOption::Kind;
      if (o.kind == Kind::text) {
        s.options[key] = setting<std::string>(v, key);
      } else if (o.kind == Kind::count) {
        s.options[key] = std::to_string(setting<std::size_t>(v, key));
      } else {
        std::string text;
        for (const std::size_t n : setting<std::vector<std::size_t>>(v, key))
          text += (text.empty() ? "" : ",") + std::to_string(n);
        s.options[key] = text;
      }
      return true;
    }
  }
  return false;
}

// One key of the settings dict.
void read_setting(PySettings& out, const std::string& key, const py::handle& v) {
  study::StudySettings& s = out.settings;
  if (key == "params")
    s.params = setting<std::vector<std::string>>(v, key);
  else if (key == "space" || key == "error_space")
    s.space = setting<std::string>(v, key);
  else if (key == "spacings" || key == "designs") {  // "designs": the older name
    s.designs = setting<std::vector<std::string>>(v, key);
    out.designs_given = true;
  } else if (key == "profiles") {
    out.profiles = setting<std::vector<std::string>>(v, key);
    out.has_profiles = true;
  } else if (key == "quick")
    s.quick = setting<bool>(v, key);
  else if (key == "metrics")
    s.metrics = setting<std::vector<std::string>>(v, key);
  else if (read_metric_setting(s, key, v))
    return;
  else if (key == "budgets")
    s.budgets = setting<std::vector<std::size_t>>(v, key);
  else if (key == "budgets_4d")
    s.budgets_4d = setting<std::vector<std::size_t>>(v, key);
  else if (key == "test_pairs")
    s.test_pairs = setting<std::size_t>(v, key);
  else if (key == "image_budget")
    s.image_budget = setting<std::size_t>(v, key);
  else if (key == "image_size")
    s.image_size = setting<int>(v, key);
  else if (key == "image_spp")
    s.image_spp = setting<int>(v, key);
  else if (key == "max_theta")  // radians, as every angle of the Python API
    s.max_theta = reach_degrees(setting<double>(v, key), "settings[\"max_theta\"]");
  else if (key == "seed")
    s.seed = setting<std::uint64_t>(v, key);
  else if (key == "env")
    s.environments = setting<std::vector<std::string>>(v, key);
  else
    throw py::value_error("settings: unknown key '" + key +
                          "' (accepted: params, space, spacings, profiles, quick, budgets, "
                          "budgets_4d, test_pairs, env, image_budget, image_size, image_spp, "
                          "max_theta, seed, metrics, " +
                          metric_setting_keys() + ")");
}

PySettings study_settings(const py::object& settings) {
  PySettings out;
  study::StudySettings& s = out.settings;
  if (!settings.is_none())
    for (const auto& [k, v] : settings.cast<py::dict>()) read_setting(out, py::str(k), v);
  // The defaults work alone (a new user's first call, docs/reliability/python.md): without
  // profiles, the default designs leave out the learned one, which needs the profiles of the
  // study's other BRDFs; asked for by name, it still needs them.
  if (!out.has_profiles && !out.designs_given)
    out.learned_left_out = std::erase(s.designs, std::string("learned")) > 0;
  return out;
}

// The configuration of the settings for the BRDF labeled `label`: with the learned design, its
// warps from the profiles of the others.
study::StudyConfig config_for(const PySettings& s, const std::string& label) {
  study::StudyConfig config = study::make_config(s.settings);
  if (!study::wants_learned(config)) return config;
  if (!s.has_profiles)
    throw std::invalid_argument(
        "settings: the learned design needs settings['profiles'], the study_profile() of every "
        "BRDF of the study in its order (or leave 'learned' out of settings['designs'])");
  std::vector<study::LabeledProfile> profiles;
  for (std::size_t i = 0; i < s.profiles.size(); ++i)
    profiles.push_back(
        study::profile_from_text(s.profiles[i], "settings['profiles'][" + std::to_string(i) + "]"));
  study::set_learned(config, profiles, label);
  return config;
}

py::dict study_one_brdf(const std::string& spec, const py::object& settings) {
  const PySettings s = study_settings(settings);
  // Not silently: the caller learns that a default design is not in the result, and how to have
  // it (a UserWarning, which a script can turn into an error or silence).
  if (s.learned_left_out &&
      PyErr_WarnEx(PyExc_UserWarning,
                   "study_brdf: the learned design (one of the default designs) is left out: it "
                   "needs settings['profiles'], the study_profile() of every BRDF of the study; "
                   "give them, or name settings['designs'] to choose the designs",
                   2) != 0)  // the caller of halfback.study_brdf, not the module's wrapper
    throw py::error_already_set();
  study::BrdfResult result;
  std::string described;
  {
    py::gil_scoped_release release;
    const BrdfPtr brdf = load_brdf(spec);
    const std::string label = study::study_label(spec, *brdf);
    const study::StudyConfig config = config_for(s, label);
    result = study::study_brdf(*brdf, label, config);
    described = study::describe_config(config);
  }
  py::dict d;
  for (const auto& [name, table] : study::to_tables(result)) d[py::str(name)] = table;
  d["settings"] = described;
  py::list images;
  for (const render::Image& im : result.example_images) {
    py::array_t<float> a({py::ssize_t(im.height), py::ssize_t(im.width), py::ssize_t(3)});
    std::copy(im.rgb.begin(), im.rgb.end(), a.mutable_data());
    images.append(a);
  }
  d["renderings"] = images;
  return d;
}

// A result dict of study_one_brdf as a BrdfResult, of a study of `params` (its settings').
study::BrdfResult result_of(const py::dict& d, const std::vector<Space>& params,
                            const std::string& source) {
  study::StudyTables tables;
  std::vector<std::string> names{"brdf"};
  for (const study::MetricTable& t : study::stored_tables()) names.push_back(t.name);
  for (const std::string& name : names) {
    if (!d.contains(name)) throw py::value_error(source + ": no table '" + name + "'");
    tables[name] = d[name.c_str()].cast<std::string>();
  }
  study::BrdfResult b = study::from_tables(tables, params, source);
  if (d.contains("renderings"))
    for (const auto& item : d["renderings"].cast<py::list>()) {
      const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(item);
      if (!a || a.ndim() != 3 || a.shape(2) != 3)
        throw py::value_error(source + ": a rendering is not an (H, W, 3) array");
      render::Image im{int(a.shape(1)), int(a.shape(0)), {}};
      im.rgb.assign(a.data(), a.data() + a.size());
      b.example_images.push_back(std::move(im));
    }
  return b;
}

std::string study_one_profile(const std::string& spec, const py::object& settings) {
  const PySettings s = study_settings(settings);
  py::gil_scoped_release release;
  const study::StudyConfig config = study::make_config(s.settings);
  const BrdfPtr brdf = load_brdf(spec);
  return study::profile_text(study::study_profile(*brdf, study::study_label(spec, *brdf), config));
}

py::dict merge_study(const std::string& out, const py::list& parts) {
  study::MergedParts merged;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const py::handle item = parts[i];
    if (py::isinstance<py::dict>(item)) {
      const py::dict d = item.cast<py::dict>();
      const std::string source = "parts[" + std::to_string(i) + "]";
      if (!d.contains("settings")) throw py::value_error(source + ": no 'settings'");
      const std::string settings = d["settings"].cast<std::string>();
      const auto params = study::config_from_description(settings, source).params;
      study::merge_into(merged, settings, source, {result_of(d, params, source)});
    } else {
      const std::string dir = py::str(py::module_::import("os").attr("fspath")(item));
      study::MergedParts one = study::read_parts({dir});
      study::merge_into(merged, one.settings, dir, std::move(one.results));
    }
  }
  if (merged.results.empty()) throw py::value_error("parts: no result to merge");
  study::StudyOutput written;
  {
    py::gil_scoped_release release;
    create_output_directory(out);
    double seconds = 0;
    for (const study::BrdfResult& b : merged.results) seconds += b.seconds;
    written = study::write_study(out, merged.results, merged.config, seconds);
  }
  py::dict d;
  d["markdown"] = written.markdown;
  d["files"] = written.files;
  return d;
}

// The study's SSIM (Wang et al. 2004), for checking it against other implementations.
void bind_image_metrics(py::module_& m) {
  using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;
  m.def(
      "ssim",
      [](const Doubles& x, const Doubles& y, std::optional<Doubles> mask) {
        if (x.ndim() != 2 || y.ndim() != 2 || x.shape(0) != y.shape(0) || x.shape(1) != y.shape(1))
          throw py::value_error("ssim: x and y must be 2D arrays of the same shape");
        const auto h = int(x.shape(0)), w = int(x.shape(1));
        const std::size_t n = std::size_t(x.size());
        std::vector<std::uint8_t> selected(n, 1);
        if (mask) {
          if (mask->ndim() != 2 || mask->shape(0) != h || mask->shape(1) != w)
            throw py::value_error("ssim: the mask must have the shape of the images");
          for (std::size_t k = 0; k < n; ++k) selected[k] = mask->data()[k] != 0;
        }
        try {
          return study::ssim({x.data(), n}, {y.data(), n}, w, h, selected);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
      },
      py::arg("x"), py::arg("y"), py::arg("mask") = py::none(),
      R"doc(The structural similarity of two 2D images with values in [0, 1] (Wang et al. 2004:
11 x 11 Gaussian window of sigma 1.5, K1 = 0.01, K2 = 0.03, L = 1), averaged over the pixels whose
whole window is inside the image and where mask (same shape; default all) is nonzero. The SSIM of
`halfback study`'s image-space error (docs/study.md).)doc");
}

// study::image_error of two BRDFs (docs/study.md, "Image-space error"), as a dict.
py::dict image_error(const py::object& test, const py::object& reference, const std::string& env,
                     const py::object& settings) {
  const BrdfPtr t = brdf_of(test), r = brdf_of(reference);
  const study::StudyConfig config = study::make_config(study_settings(settings).settings);
  study::ImageError e;
  {
    py::gil_scoped_release release;
    const render::Environment environment = render::load_environment(env);
    e = study::image_error(*t, *r, *environment.map, config);
  }
  py::dict d;
  d["relative_rmse"] = e.relative_rmse;
  d["mean_delta_e2000"] = e.mean_delta_e;
  d["p95_delta_e2000"] = e.p95_delta_e;
  d["mae"] = e.mae;
  d["rmse"] = e.rmse;
  d["ssim"] = e.ssim;
  d["pixels"] = e.pixels;
  return d;
}

}  // namespace

void bind_study(py::module_& m) {
  bind_image_metrics(m);
  m.def("image_error", &image_error, py::arg("test"), py::arg("reference"), py::arg("env") = "sky",
        py::arg("settings") = py::none(),
        R"doc(The image-space error of `test` against `reference` (Brdf objects or specs) with the
study's image protocol: both rendered on a sphere under env (a built-in name, a constant or an
.exr/.hdr file) by environment sampling with the same random numbers, compared over the sphere's
pixels. settings: study settings (image_size, image_spp, seed; default 96, 16, the study's seed).
Returns a dict: relative_rmse, mean_delta_e2000, p95_delta_e2000, mae, rmse, ssim, pixels.)doc");
  // Built once, from the list of metrics (pybind11 keeps a copy).
  const std::string study_brdf_doc =
      std::string(
          R"doc(The study of one BRDF (as `halfback study SPEC`), the GIL released while it runs.

spec: a file or model spec, as for load(). settings: a dict of the options of `halfback study`
with '-' spelled '_': params (a list of parameterization names; missing: all of them, spherical
last), space (the error space), spacings (a list; "designs" is its older name), quick, budgets,
budgets_4d, test_pairs, env (a list), image_budget, image_size, image_spp, max_theta (the
reach, in radians as every angle of the Python API, from pi/180 to pi/2; default 85 degrees;
`halfback study --max-theta` takes degrees), seed, metrics (a list of the metrics to run), and
)doc") +
      metric_settings_doc() + R"doc(;
and, for the learned spacing (a default one), profiles: the study_profile() texts of every BRDF of
the study, this one's included, in the study's order (the warps are learned from all but this
one's). Without profiles, the default spacings leave the learned one out with a UserWarning; a
`spacings` list that names "learned" without profiles raises a ValueError.
Returns a dict of tables as CSV text ("brdf", "azimuthal", "separability", "gonio", "image": one
row per parameterization and measurement, as in the CSV files of the study, numbers in exact round-trip form, e.g. for
pandas.read_csv(io.StringIO(t))), "settings" (the resolved settings, which merge_study checks)
and "renderings" (the example images, (H, W, 3) float32). Independent of any other BRDF: map it
over BRDFs with any engine (docs/study.md, "Scaling out").)doc";
  m.def("study_brdf", &study_one_brdf, py::arg("spec"), py::arg("settings") = py::none(),
        study_brdf_doc.c_str());
  m.def("study_profile", &study_one_profile, py::arg("spec"), py::arg("settings") = py::none(),
        R"doc(The profile of one BRDF for the learned design (as text), the GIL released: what the
learned warps of the other BRDFs are fitted on. settings: as for study_brdf (its error space
matters). Map it over the study's BRDFs first, then pass the list as settings["profiles"].)doc");
  m.def("merge_study", &merge_study, py::arg("out"), py::arg("parts"),
        R"doc(Writes the study's report of several results into directory `out` (as
`halfback study --merge`): parts is a list of result dicts of study_brdf and of output directories
of `halfback study`, in the order of the report. All must have the same settings, and a BRDF may
appear once. Returns {"markdown": report.md's text, "files": the files written}.)doc");
}

}  // namespace halfback::python
