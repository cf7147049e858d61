// BRDFs written in Python (halfback.register_brdf) and the explorer started from Python
// (halfback.view): the counterpart of BRDF Explorer's .brdf files. A vectorized NumPy callable
// eval(wi, wo) -> rho becomes a Brdf, checked before it is registered or served (its shape, finite
// non-negative values, reciprocity, isotropy, energy); halfback.view serves it with the others in
// the same process, the server on a thread of its own.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "halfback/brdf/albedo.hpp"
#include "halfback/view/api.hpp"
#include "halfback/view/server.hpp"
#include "py_brdf.hpp"

namespace py = pybind11;

namespace halfback::python {

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A Python callable as a BRDF: eval(wi, wo) on (N, 3) float64 arrays of unit directions (ωi the
// light, ωo the view; n = +z), returning ρ in sr⁻¹ as (N, 3) RGB or (N,) grey. Pairs below the
// horizon give 0 without a call (the Brdf contract), pairs with NaN give NaN. Every result is
// checked: a raise, another shape, a value not finite or negative is an error naming the BRDF.
class PyFunctionBrdf final : public Brdf {
 public:
  PyFunctionBrdf(std::string name, std::string description, py::object fn, bool isotropic,
                 bool reciprocal)
      : name_(std::move(name)),
        description_(std::move(description)),
        fn_(std::move(fn)),
        isotropic_(isotropic),
        reciprocal_(reciprocal) {}
  ~PyFunctionBrdf() override {
    if (!Py_IsInitialized()) {  // the interpreter is gone: leak the callable, touch nothing
      fn_.release();
      return;
    }
    py::gil_scoped_acquire gil;
    fn_ = py::object();
  }

  std::string name() const override { return "python:" + name_; }
  std::string description() const override {
    return description_.empty() ? "a BRDF written in Python (" + name_ + ")" : description_;
  }
  bool isotropic() const override { return isotropic_; }
  bool reciprocal() const override { return reciprocal_; }
  std::vector<Fact> facts() const override {
    return {{"written in", "Python (halfback.register_brdf)"}};
  }

  Rgb eval(const DirPair<double>& pair) const override {
    Rgb out;
    eval_batch({&pair, 1}, {&out, 1});
    return out;
  }

  void eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const override {
    call(pairs, out, true);
  }
  // The call and its shape's check alone (the check `vectorized`: values are the next check's).
  void eval_unchecked(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const {
    call(pairs, out, false);
  }

 private:
  void call(std::span<const DirPair<double>> pairs, std::span<Rgb> out, bool check_values) const {
    if (out.size() != pairs.size())
      throw std::invalid_argument("eval_batch: pairs and out differ in size");
    std::vector<std::size_t> called;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const DirPair<double>& p = pairs[k];
      const bool nan = std::isnan(p.wi.x + p.wi.y + p.wi.z + p.wo.x + p.wo.y + p.wo.z);
      if (nan) {
        out[k] = Rgb{NAN, NAN, NAN};
      } else if (!(p.wi.z > 0 && p.wo.z > 0)) {
        out[k] = Rgb{0, 0, 0};
      } else {
        called.push_back(k);
      }
    }
    if (called.empty()) return;
    const std::size_t m = called.size();
    py::gil_scoped_acquire gil;
    Array wi({py::ssize_t(m), py::ssize_t(3)}), wo({py::ssize_t(m), py::ssize_t(3)});
    double* a = wi.mutable_data();
    double* b = wo.mutable_data();
    for (std::size_t i = 0; i < m; ++i) {
      const DirPair<double>& p = pairs[called[i]];
      a[3 * i] = p.wi.x, a[3 * i + 1] = p.wi.y, a[3 * i + 2] = p.wi.z;
      b[3 * i] = p.wo.x, b[3 * i + 1] = p.wo.y, b[3 * i + 2] = p.wo.z;
    }
    py::object result;
    try {
      result = fn_(wi, wo);
    } catch (py::error_already_set& e) {
      throw std::invalid_argument(fmt::format("BRDF {}: eval raised {}", name(), e.what()));
    }
    const Array r = Array::ensure(result);
    if (!r) {
      PyErr_Clear();
      throw std::invalid_argument(
          fmt::format("BRDF {}: eval returned {}, not an array of numbers", name(),
                      py::str(py::type::of(result).attr("__name__")).cast<std::string>()));
    }
    const bool grey = r.ndim() == 1 && std::size_t(r.shape(0)) == m;
    const bool rgb = r.ndim() == 2 && std::size_t(r.shape(0)) == m && r.shape(1) == 3;
    if (!grey && !rgb) {
      std::string shape;
      for (py::ssize_t d = 0; d < r.ndim(); ++d)
        shape += (d ? ", " : "") + std::to_string(r.shape(d));
      throw std::invalid_argument(
          fmt::format("BRDF {}: eval of {} pairs returned shape ({}{}), expected ({}, 3) or ({},)",
                      name(), m, shape, r.ndim() == 1 ? "," : "", m, m));
    }
    const double* v = r.data();
    for (std::size_t i = 0; i < m; ++i) {
      const Rgb x = grey ? Rgb{v[i], v[i], v[i]} : Rgb{v[3 * i], v[3 * i + 1], v[3 * i + 2]};
      const bool good = std::isfinite(x.r) && std::isfinite(x.g) && std::isfinite(x.b) &&
                        x.r >= 0 && x.g >= 0 && x.b >= 0;
      if (check_values && !good) {
        const DirPair<double>& p = pairs[called[i]];
        throw std::invalid_argument(fmt::format(
            "BRDF {}: eval gave ({}, {}, {}), not finite and non-negative, at wi = ({:.6g}, "
            "{:.6g}, {:.6g}), wo = ({:.6g}, {:.6g}, {:.6g})",
            name(), x.r, x.g, x.b, p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z));
      }
      out[called[i]] = x;
    }
  }

  std::string name_, description_;
  py::object fn_;
  bool isotropic_, reciprocal_;
};

// The registered Python BRDFs, by name ("python:NAME" in halfback.load).
std::mutex registry_mutex;
std::map<std::string, BrdfPtr>& python_brdfs() {
  static auto* r = new std::map<std::string, BrdfPtr>;  // leaked: outlives the interpreter
  return *r;
}

struct CheckResult {
  std::string name;
  bool passed = true;
  std::string detail;
};

Vec3<double> direction(double cos_theta, double phi) {
  const double s = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
  return {s * std::cos(phi), s * std::sin(phi), cos_theta};
}

std::string pair_text(const DirPair<double>& p) {
  return fmt::format("wi = ({:.4f}, {:.4f}, {:.4f}), wo = ({:.4f}, {:.4f}, {:.4f})", p.wi.x, p.wi.y,
                     p.wi.z, p.wo.x, p.wo.y, p.wo.z);
}

// The checks of a Python BRDF, in order; each after the first runs only when those before pass.
// Called without the GIL (the BRDF takes it for each call).
std::vector<CheckResult> check_brdf(const PyFunctionBrdf& brdf, bool isotropic, bool reciprocal) {
  std::vector<CheckResult> checks;
  const auto run = [&](const char* name, const auto& body) {
    CheckResult c{name, true, ""};
    if (!checks.empty() && !checks.back().passed) return;
    try {
      c.detail = body();
      c.passed = c.detail.empty();
    } catch (const std::exception& e) {
      c.passed = false;
      c.detail = e.what();
    }
    checks.push_back(std::move(c));
  };
  // Pairs over the upper hemisphere (cos θ uniform in (0, 1], grazing ones included), seeded.
  std::mt19937_64 rng(20150801);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<DirPair<double>> pairs(4096);
  for (auto& p : pairs) {
    p.wi = direction(1 - u(rng) * 0.9999, 2 * std::numbers::pi * u(rng));
    p.wo = direction(1 - u(rng) * 0.9999, 2 * std::numbers::pi * u(rng));
  }
  std::vector<Rgb> rho(pairs.size());
  run("vectorized", [&]() -> std::string {  // an odd count: no broadcasting by luck
    std::vector<Rgb> few(7);
    brdf.eval_unchecked(std::span(pairs).first(7), few);
    return "";
  });
  run("finite values", [&]() -> std::string {
    brdf.eval_batch(pairs, rho);  // throws naming the first value not finite or negative
    return "";
  });
  const auto differs = [](const Rgb& a, const Rgb& b) {
    const auto one = [](double x, double y) {
      return std::abs(x - y) > 1e-6 * std::max({1.0, std::abs(x), std::abs(y)});
    };
    return one(a.r, b.r) || one(a.g, b.g) || one(a.b, b.b);
  };
  if (reciprocal)
    run("reciprocity", [&]() -> std::string {
      std::vector<DirPair<double>> swapped(pairs.size());
      for (std::size_t k = 0; k < pairs.size(); ++k) swapped[k] = {pairs[k].wo, pairs[k].wi};
      std::vector<Rgb> back(pairs.size());
      brdf.eval_batch(swapped, back);
      for (std::size_t k = 0; k < pairs.size(); ++k)
        if (differs(rho[k], back[k]))
          return fmt::format(
              "rho(wi, wo) = {:.6g} but rho(wo, wi) = {:.6g} at {} (give "
              "reciprocal=False for a BRDF that is not reciprocal)",
              rho[k].g, back[k].g, pair_text(pairs[k]));
      return "";
    });
  if (isotropic)
    run("isotropy", [&]() -> std::string {
      std::vector<DirPair<double>> turned(pairs.size());
      for (std::size_t k = 0; k < pairs.size(); ++k) {
        const double a = 2 * std::numbers::pi * double(k) / double(pairs.size()) + 0.3;
        const double c = std::cos(a), s = std::sin(a);
        const auto r = [&](const Vec3<double>& v) {
          return Vec3<double>{c * v.x - s * v.y, s * v.x + c * v.y, v.z};
        };
        turned[k] = {r(pairs[k].wi), r(pairs[k].wo)};
      }
      std::vector<Rgb> back(pairs.size());
      brdf.eval_batch(turned, back);
      for (std::size_t k = 0; k < pairs.size(); ++k)
        if (differs(rho[k], back[k]))
          return fmt::format(
              "rho changes from {:.6g} to {:.6g} when the pair at {} turns about "
              "the normal (give isotropic=False for an anisotropic BRDF)",
              rho[k].g, back[k].g, pair_text(pairs[k]));
      return "";
    });
  run("energy", [&]() -> std::string {
    // The directional albedo (cosine-weighted, 48² strata) at a few incidences: at most 1, but
    // for 3 standard errors of the estimate.
    for (const double deg : {0.0, 30.0, 60.0, 75.0, 85.0}) {
      const double t = deg * std::numbers::pi / 180;
      const AlbedoEstimate a = directional_albedo(brdf, {std::sin(t), 0, std::cos(t)}, 48);
      for (const auto& [mean, se] :
           {std::pair{a.mean.r, a.standard_error.r}, std::pair{a.mean.g, a.standard_error.g},
            std::pair{a.mean.b, a.standard_error.b}})
        if (mean - 3 * se > 1)
          return fmt::format(
              "the directional albedo is {:.4g} (± {:.2g}) at theta_i = {}°, above "
              "1: the BRDF reflects more than it receives",
              mean, se, deg);
    }
    return "";
  });
  return checks;
}

py::list report_list(const std::vector<CheckResult>& checks) {
  py::list out;
  for (const CheckResult& c : checks) {
    py::dict d;
    d["name"] = c.name;
    d["passed"] = c.passed;
    d["detail"] = c.detail;
    out.append(d);
  }
  return out;
}

std::shared_ptr<PyFunctionBrdf> make_function_brdf(const std::string& name, py::object eval,
                                                   bool isotropic, bool reciprocal,
                                                   const std::string& description) {
  if (name.empty() || name.find_first_of("/\\:+,= ") != std::string::npos)
    throw py::value_error("register_brdf: the name '" + name +
                          "' must be non-empty, without '/', '\\\\', ':', '+', ',', '=' or spaces");
  if (!PyCallable_Check(eval.ptr())) throw py::type_error("register_brdf: eval is not callable");
  return std::make_shared<PyFunctionBrdf>(name, description, std::move(eval), isotropic,
                                          reciprocal);
}

std::vector<CheckResult> checks_without_gil(const PyFunctionBrdf& brdf, bool isotropic,
                                            bool reciprocal) {
  py::gil_scoped_release release;  // the BRDF takes it back for each call, from any thread
  return check_brdf(brdf, isotropic, reciprocal);
}

// The explorer served from this process: the Api, its Server and the thread that runs it.
class Viewer {
 public:
  Viewer(view::ApiConfig config, int workers, std::string host)
      : api_(std::make_unique<view::Api>(std::move(config))),
        server_(std::make_unique<view::Server>(*api_, workers)),
        host_(std::move(host)) {}
  ~Viewer() { stop(); }

  void start(int port) {
    api_->load_specs();
    port_ = server_->bind(host_, port);
    thread_ = std::thread([this] { server_->run(); });
  }
  void stop() {
    if (!thread_.joinable()) return;
    const auto join = [this] {
      server_->stop();
      thread_.join();
    };
    if (Py_IsInitialized() && PyGILState_Check()) {
      py::gil_scoped_release release;  // requests in flight may be waiting for the GIL
      join();
    } else {
      join();
    }
  }
  bool running() const { return thread_.joinable(); }
  // Waits for the server (stopped from another thread), at most `seconds` (< 0: for ever);
  // returns whether it is still running.
  bool wait(double seconds) {
    py::gil_scoped_release release;
    const auto start = std::chrono::steady_clock::now();
    while (thread_.joinable()) {
      {
        py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C
      }
      if (seconds >= 0 &&
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >=
              seconds)
        return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }
  std::string url() const {
    const std::string shown = host_.find(':') != std::string::npos ? "[" + host_ + "]" : host_;
    return fmt::format("http://{}:{}/?token={}", shown, port_, api_->config().token);
  }
  int port() const { return port_; }
  const view::ApiConfig& config() const { return api_->config(); }

 private:
  std::unique_ptr<view::Api> api_;
  std::unique_ptr<view::Server> server_;
  std::string host_;
  int port_ = 0;
  std::thread thread_;
};

}  // namespace

BrdfPtr registered_python_brdf(const std::string& spec) {
  if (spec.rfind("python:", 0) != 0) return nullptr;
  std::lock_guard lock(registry_mutex);
  const auto it = python_brdfs().find(spec.substr(7));
  if (it == python_brdfs().end())
    throw py::value_error("'" + spec + "': no BRDF of that name was registered (register_brdf)");
  return it->second;
}

void bind_view(py::module_& m) {
  m.def(
      "check_brdf",
      [](py::object eval, bool isotropic, bool reciprocal) {
        const auto brdf =
            make_function_brdf("unchecked", std::move(eval), isotropic, reciprocal, "");
        return report_list(checks_without_gil(*brdf, isotropic, reciprocal));
      },
      py::arg("eval"), py::arg("isotropic") = true, py::arg("reciprocal") = true,
      R"doc(Runs register_brdf's checks on eval without registering it: a list of dicts (name,
passed, detail), in order, stopping at the first that fails.)doc");
  m.def(
      "register_brdf",
      [](const std::string& name, py::object eval, bool isotropic, bool reciprocal,
         const std::string& description) {
        const auto brdf =
            make_function_brdf(name, std::move(eval), isotropic, reciprocal, description);
        for (const CheckResult& c : checks_without_gil(*brdf, isotropic, reciprocal))
          if (!c.passed)
            throw py::value_error(
                fmt::format("BRDF '{}' failed the check '{}': {}", name, c.name, c.detail));
        {
          std::lock_guard lock(registry_mutex);
          python_brdfs()[name] = brdf;
        }
        return PyBrdf{brdf, "python:" + name};
      },
      py::arg("name"), py::arg("eval"), py::arg("isotropic") = true, py::arg("reciprocal") = true,
      py::arg("description") = "",
      R"doc(A BRDF written in Python: eval(wi, wo) takes (N, 3) float64 arrays of unit directions
(wi: light, wo: view; frame n = +z, both above the horizon) and returns rho in 1/sr as an (N, 3)
RGB or (N,) grey array. Before it is registered it is checked: called on 7 pairs (it must not
raise and must return that shape), on 4096 pairs of the hemisphere (finite, non-negative values),
rho(wi, wo) = rho(wo, wi) to 1e-6 (unless reciprocal=False), invariance under turns about the
normal (unless isotropic=False), and a directional albedo of at most 1 (within 3 standard errors)
at 0, 30, 60, 75 and 85 degrees. A failed check raises ValueError naming it. Returns a Brdf
(spec "python:NAME", which load() then takes too) for every function of the module and for
view(); its results are checked at every call after that as well.)doc");
  py::class_<Viewer>(
      m, "Viewer",
      "The explorer served from this Python process (view()): url, port, stop(), wait().")
      .def_property_readonly("url", &Viewer::url, "The page's URL, with its token.")
      .def_property_readonly("port", &Viewer::port)
      .def_property_readonly("token", [](const Viewer& v) { return v.config().token; })
      .def_property_readonly(
          "specs", [](const Viewer& v) { return v.config().specs; },
          "The BRDFs shown, as the page names them (arg:0, arg:1, ...).")
      .def_property_readonly("running", &Viewer::running)
      .def("stop", &Viewer::stop, "Stops the server (requests in flight are answered 503).")
      .def(
          "wait",
          [](Viewer& v, py::object timeout) {
            return v.wait(timeout.is_none() ? -1.0 : timeout.cast<double>());
          },
          py::arg("timeout") = py::none(),
          "Serves until stop() or Ctrl-C (KeyboardInterrupt), at most `timeout` seconds; "
          "returns whether it still runs.")
      .def(
          "__enter__", [](Viewer& v) -> Viewer& { return v; }, py::return_value_policy::reference)
      .def("__exit__", [](Viewer& v, const py::args&) { v.stop(); })
      .def("__repr__",
           [](const Viewer& v) {
             return "<halfback.Viewer " + (v.running() ? v.url() : std::string("stopped")) + ">";
           })
      .def("_repr_html_", [](const Viewer& v) {
        return fmt::format("<a href=\"{0}\" target=\"_blank\">halfback view: {0}</a>", v.url());
      });
  m.def(
      "_view",
      [](const py::list& brdfs, const std::vector<std::string>& roots, const std::string& host,
         int port, int threads, int workers) {
        view::ApiConfig c;
        c.token = view::random_token();
        c.host = host;
        c.threads = threads;
        for (const auto& r : roots) c.roots.emplace_back(r);
        if (brdfs.size() > 8)
          throw py::value_error(
              fmt::format("view: at most 8 BRDFs at once (got {})", brdfs.size()));
        for (const py::handle b : brdfs) {
          if (py::isinstance<py::str>(b)) {
            c.specs.push_back(b.cast<std::string>());
            c.given.push_back(nullptr);
          } else if (py::isinstance<PyBrdf>(b)) {
            const PyBrdf& p = b.cast<const PyBrdf&>();
            c.specs.push_back(p.spec.empty() ? p.brdf->name() : p.spec);
            c.given.push_back(p.brdf);
          } else {
            throw py::type_error("view: a BRDF is a spec (str), a Brdf or a callable eval(wi, wo)");
          }
        }
        if (workers < 1 || workers > 64) throw py::value_error("view: workers must be in 1…64");
        auto v = std::make_unique<Viewer>(std::move(c), workers, host);
        try {
          v->start(port);
        } catch (const std::exception& e) {
          throw py::value_error(std::string("view: ") + e.what());
        }
        if (!view::is_loopback(host))
          PyErr_WarnEx(PyExc_RuntimeWarning,
                       ("view: serving on " + host +
                        ", not a loopback address: the token crosses the network in clear text")
                           .c_str(),
                       1);
        return v;
      },
      py::arg("brdfs"), py::arg("roots"), py::arg("host"), py::arg("port"), py::arg("threads"),
      py::arg("workers"));
}

}  // namespace halfback::python
