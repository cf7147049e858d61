// halfback.fit, fit_loss and published_fits (docs/fit.md).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <numbers>
#include <optional>
#include <string>

#include "halfback/fit/emit.hpp"
#include "halfback/fit/factor.hpp"
#include "halfback/fit/fit.hpp"
#include "halfback/fit/published.hpp"
#include "halfback/fit/sample_limit.hpp"
#include "py_brdf.hpp"

namespace py = pybind11;

namespace halfback::python {

namespace {

// ---------------------------------------------------------------------------------------------
// Fitting (docs/fit.md): halfback.fit, the GIL released while it runs
// ---------------------------------------------------------------------------------------------

py::dict fit_result_dict(const fit::FitResult& r, const std::optional<fit::FitEnergy>& e) {
  py::list params;
  for (const fit::Param& p : r.model.params) {
    py::dict d;
    d["term"] = p.term;
    d["model"] = r.model.terms[p.term];
    d["name"] = p.name;
    d["value"] = p.value;
    d["fitted"] = p.fitted;
    d["min"] = p.min;
    d["max"] = p.max;
    params.append(d);
  }
  py::dict out;
  out["spec"] = r.spec;
  out["loss"] = std::string(fit::name_of(r.loss));
  out["loss_value"] = r.loss_value;
  py::list terms;  // each term's albedo share and whether it is a dead lobe (docs/fit.md)
  for (std::size_t t = 0; t < r.model.terms.size() && t < r.albedo_share.size(); ++t) {
    py::dict d;
    d["model"] = r.model.terms[t];
    d["albedo_share"] = r.albedo_share[t];
    d["loss_without"] = r.loss_without[t];
    d["dead"] = bool(r.dead[t]);
    terms.append(d);
  }
  out["layout"] = r.layout;
  out["samples"] = r.samples;
  out["missing"] = r.missing;
  out["out_of_reach"] = r.out_of_reach;
  out["parameters"] = params;
  out["terms"] = terms;
  // docs/fit.md, "Energy": above 1, the fitted model creates light. None when not asked for.
  if (e) {
    py::dict energy;
    energy["max_albedo"] = e->max_albedo;
    energy["theta_deg"] = e->theta_deg;
    energy["standard_error"] = e->standard_error;
    energy["creates_energy"] = e->creates_energy();
    out["energy"] = energy;
  } else {
    out["energy"] = py::none();
  }
  out["starts"] = r.starts;
  out["iterations"] = r.iterations;
  out["seconds"] = r.seconds;
  return out;
}

py::dict fit_brdf(const py::object& brdf, const std::string& model, const std::string& loss,
                  std::size_t samples, int threads, const std::vector<std::string>& starts,
                  int max_iterations, double max_theta, bool energy) {
  fit::FitOptions o;
  o.starts = starts;
  if (max_iterations < 1) throw py::value_error("max_iterations must be at least 1");
  o.max_iterations = max_iterations;
  if (!(max_theta > 0 && max_theta <= std::numbers::pi / 2))
    throw py::value_error("max_theta = " + std::to_string(max_theta) +
                          " rad: the reach must be in (0, pi/2] (radians)");
  o.max_theta = max_theta;
  const auto l = fit::parse_loss(loss);
  if (!l) throw py::value_error("loss '" + loss + "': expected " + fit::loss_names());
  o.loss = *l;
  fit::check_fit_samples(samples, "samples");  // ValueError above the CLI's bound
  o.samples = samples;
  o.threads = threads;
  const BrdfPtr target = brdf_of(brdf);
  fit::FitResult r;
  std::optional<fit::FitEnergy> e;
  {
    py::gil_scoped_release release;
    r = fit::fit(*target, model, o);
    if (energy) e = fit::fitted_energy(r.spec);  // 0.2-0.7 s: a batch of fits may leave it out
  }
  return fit_result_dict(r, e);
}

double fit_loss(const py::object& brdf, const py::object& model, const std::string& loss,
                std::size_t samples, int threads) {
  const auto l = fit::parse_loss(loss);
  if (!l) throw py::value_error("loss '" + loss + "': expected " + fit::loss_names());
  fit::check_fit_samples(samples, "samples");
  const BrdfPtr target = brdf_of(brdf), m = brdf_of(model);
  py::gil_scoped_release release;
  return fit::loss_of(*target, *m, *l, samples, threads);
}

// halfback.factor: fit/factor.hpp's model as a dict (the file's text under "text").
py::dict factor(const py::object& brdf, const std::string& param, std::size_t rank,
                const std::array<std::size_t, 3>& counts, int threads) {
  const auto space = space_from_name(param);
  if (!space || space->is_dirs())
    throw py::value_error("param '" + param + "': not a parameterization");
  const BrdfPtr target = brdf_of(brdf);
  fit::FactorResult r;
  {
    py::gil_scoped_release release;
    r = fit::factor_brdf(*target, *space, {.rank = rank, .counts = counts, .threads = threads});
  }
  py::dict d;
  d["text"] = factored_text(r.model);
  d["numbers"] = r.model.numbers();
  d["relative_error"] = r.relative_error;
  d["sweeps"] = r.sweeps;
  return d;
}

py::list published_fits(const std::string& path) {
  py::list out;
  for (const fit::PublishedFit& f : fit::read_published_fits(path)) {
    py::dict d;
    d["material"] = f.material;
    d["line"] = f.line;
    d["spec"] = fit::spec_of(f);
    d["model"] = fit::model_of(f);
    out.append(d);
  }
  return out;
}

// fit()'s layout of n pairs as arrays (for baselines written in Python: bench/fit_scipy_bench.py).
py::dict fit_samples(std::size_t n) {
  fit::check_fit_samples(n, "n");
  const fit::Samples s = fit::halfdiff_samples(n);
  const auto rows = py::ssize_t(s.pairs.size());
  py::array_t<double> wi({rows, py::ssize_t(3)}), wo({rows, py::ssize_t(3)}), weight(rows),
      cos_i(rows);
  auto a = wi.mutable_unchecked<2>(), b = wo.mutable_unchecked<2>();
  auto w = weight.mutable_unchecked<1>(), c = cos_i.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < rows; ++i) {
    const auto& p = s.pairs[std::size_t(i)];
    a(i, 0) = p.wi.x, a(i, 1) = p.wi.y, a(i, 2) = p.wi.z;
    b(i, 0) = p.wo.x, b(i, 1) = p.wo.y, b(i, 2) = p.wo.z;
    w(i) = s.weight[std::size_t(i)], c(i) = s.cos_i[std::size_t(i)];
  }
  py::dict out;
  out["wi"] = wi, out["wo"] = wo, out["weight"] = weight, out["cos_i"] = cos_i;
  out["layout"] = std::string(fit::kLayoutName);
  return out;
}

// A model spec as a renderer's material (fit/emit.hpp): unknown targets and models the renderer
// lacks raise ValueError (std::invalid_argument).
std::string emit(const std::string& spec, const std::string& target, const std::string& name) {
  const auto renderer = fit::parse_renderer(target);
  if (!renderer)
    throw py::value_error("target '" + target + "': expected " + fit::renderer_names());
  return fit::emit_material(fit::parse_model(spec), *renderer, name);
}

}  // namespace

// fit()'s docstring, with every loss of the registry (fit::kLosses).
const std::string& fit_doc() {
  static const std::string doc =
      [] {
        std::string own, bbm;
        for (fit::Loss l : fit::kLosses) {
          std::string& list = fit::is_bbm(l) ? bbm : own;
          list += (list.empty() ? "" : ", ") + std::string(fit::name_of(l));
        }
        return R"doc(Fits an analytic model or a sum of lobes ("lambert+ggx"; values given, as in
"ggx:f0=0.9", are held) to a BRDF (a spec, as for load(), or a Brdf), as `halfback fit`
(docs/fit.md), the GIL released while it runs.
loss: one of halfback's losses,
  )doc" + own + R"doc(,
or of the published losses exactly as BBM defines them, measured on BBM's grid (samples then
unused),
  )doc" + bbm + R"doc(
(docs/fit.md, "Losses" and "Published losses").
starts: when not empty, the only starts (specs of the same terms whose values set the fitted
parameters).
max_iterations: of each Levenberg-Marquardt run.
Returns a dict: spec (load() reads it), loss, loss_value, layout ("halfdiff-halton", or
"halfdiff-halton-turned" for a model that can be anisotropic), samples (those fitted), missing
(left out: NaN values) and out_of_reach (left out: θi or θo above max_theta, radians),
parameters (a list of dicts: term, model, name, value, fitted, min, max; a parameter without
effect is not fitted), terms (a list of dicts: model, albedo_share, loss_without, dead: a dead
lobe has a share below 1e-4 or a loss_without within 0.1 % of loss_value), energy (a dict:
max_albedo, theta_deg, standard_error, creates_energy — the fitted model's largest directional
albedo, docs/fit.md "Energy"; None with energy=False, which saves its 0.2-0.7 s in a batch of
fits), starts, iterations, seconds. A bad model or loss raises ValueError; a target the fit cannot use (not finite, negative or zero where sampled,
anisotropic) raises RuntimeError.)doc";
      }();
  return doc;
}

void bind_fit(py::module_& m) {
  m.def("fit", &fit_brdf, py::arg("brdf"), py::arg("model"), py::arg("loss") = "ngan",
        py::arg("samples") = 20000, py::arg("threads") = 0,
        py::arg("starts") = std::vector<std::string>{}, py::arg("max_iterations") = 200,
        py::arg("max_theta") = std::numbers::pi / 2, py::arg("energy") = true, fit_doc().c_str());

  m.def("fit_loss", &fit_loss, py::arg("brdf"), py::arg("model"), py::arg("loss") = "ngan",
        py::arg("samples") = 20000, py::arg("threads") = 0,
        R"doc(The loss of `model` (a spec or a Brdf) against `brdf` on fit()'s layout of `samples`
pairs (turned when `model` is anisotropic), as fit() measures it: fit(b, m, loss,
n)["loss_value"] is fit_loss(b, its spec, loss, n). A published bbm-* loss is measured on
BBM's default grid (samples unused; docs/fit.md, "Published losses").
The GIL is released while it runs. A bad loss raises ValueError; a target the fit cannot use,
RuntimeError.)doc");
  m.def("factor", &factor, py::arg("brdf"), py::arg("param") = "hybrid", py::arg("rank") = 2,
        py::arg("counts") = std::array<std::size_t, 3>{32, 32, 32}, py::arg("threads") = 0,
        R"doc(A factored model of a BRDF (a spec or a Brdf) in a parameterization, as `halfback
factor` (docs/fit.md, "Factored models"), the GIL released while it runs: a dict with text (the
JSON file: write it to a .json file, which load() reads), numbers (its size), relative_error
(μ-weighted, in log(1 + ρ), on its grid) and sweeps. A bad rank, counts or parameterization, or
an anisotropic BRDF, raises ValueError; a BRDF not finite somewhere, RuntimeError.)doc");
  m.def("_set_fit_shortcuts", &fit::detail::set_fit_shortcuts, py::arg("on"),
        R"doc(Turns the fitter's shortcuts on (the default) or off, for measuring their effect
(docs/fit.md, "What a fit costs"); the results agree to the optimizer's tolerance.)doc");
  m.def("fit_samples", &fit_samples, py::arg("n"),
        R"doc(fit()'s layout of n pairs (docs/fit.md, "Sample layout") as a dict of arrays: wi and
wo (n, 3), weight (n,; mean 1) and cos_i (n,). A prefix of the layout of more pairs is the layout
of fewer, up to the weights' normalisation. n = 0 raises ValueError.)doc");
  m.def(
      "published_fits", &published_fits, py::arg("path"),
      R"doc(The published fits of a BBM .fit file (Ngan et al. 2005; ../shared/data/fits/): a list of
dicts material, line, spec (a halfback spec of the registry's restatements of BBM's models,
load() reads it) and model (its terms, as fit() takes them: "lambert+ward"). A malformed file
raises RuntimeError naming the line; a model halfback lacks, ValueError.)doc");
  m.def("emit", &emit, py::arg("spec"), py::arg("target"), py::arg("name") = "halfback_fit",
        R"doc(The model `spec` (fit()'s "spec", or any spec of the models a target has) as a
renderer's own material named `name`, the text `halfback fit --emit` writes (docs/fit.md,
"Renderer-ready output"): target "mitsuba3" (a Mitsuba 3 scene file holding one <bsdf>: lambert,
ggx, beckmann, lambert plus one of them), "pbrt-v4" (a MakeNamedMaterial: lambert, ggx),
"blender" (a Python script that builds the material in Blender's Cycles: sums of lambert,
oren-nayar, ggx and disney) or "materialx" (a MaterialX 1.38 document: sums of lambert,
oren-nayar and ggx, or disney alone). A comment at the top says what the conversion loses. An
unknown target, or a model the renderer has no material for (ward, abc, beckmann in pbrt-v4,
...), raises ValueError pointing to `halfback export-rgl`.)doc");
}

}  // namespace halfback::python
