// halfback.nbrdf_train (docs/neural.md): a neural BRDF trained from a BRDF, written as the
// authors' .h5 + .json.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "halfback/formats/nbrdf.hpp"
#include "halfback/neural/train.hpp"
#include "py_brdf.hpp"

namespace py = pybind11;

namespace halfback::python {

namespace {

// The layers as (kernel (inputs, outputs), bias (outputs,)) float32 arrays: the trained weights,
// as written.
py::list layer_arrays(const NbrdfNetwork& network) {
  py::list layers;
  for (const NbrdfLayer& layer : network.layers) {
    py::array_t<float> kernel({py::ssize_t(layer.inputs), py::ssize_t(layer.outputs)});
    std::copy(layer.kernel.begin(), layer.kernel.end(), kernel.mutable_data());
    py::array_t<float> bias(py::ssize_t(layer.outputs));
    std::copy(layer.bias.begin(), layer.bias.end(), bias.mutable_data());
    layers.append(py::make_tuple(kernel, bias));
  }
  return layers;
}

py::dict nbrdf_train(const py::object& brdf, const std::string& output,
                     const std::vector<std::size_t>& hidden, std::size_t samples,
                     std::size_t epochs, std::size_t batch, double learning_rate,
                     std::uint64_t seed, int threads, const std::string& param,
                     double final_learning_rate, std::size_t restarts, std::size_t restart_epochs,
                     const std::string& loss) {
  NbrdfTrainOptions o;
  o.param = param;
  o.hidden = hidden;
  o.samples = samples;
  o.epochs = epochs;
  o.batch = batch;
  o.learning_rate = learning_rate;
  o.final_learning_rate = final_learning_rate;
  o.restarts = restarts;
  o.restart_epochs = restart_epochs;
  o.loss = loss;
  o.seed = seed;
  o.threads = threads;
  try {
    check_nbrdf_train_options(o);
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
  if (nbrdf_json_path(output).string() == output)
    throw py::value_error("output '" + output + "': name the weights file NAME.h5");
  const BrdfPtr target = brdf_of(brdf);
  NbrdfTrainResult r;
  {
    py::gil_scoped_release release;
    try {
      r = train_nbrdf(*target, o);
    } catch (const std::domain_error& e) {
      throw std::runtime_error(e.what());
    }
    write_nbrdf(output, r.network, nbrdf_train_notes(*target, o, r));
  }
  py::dict d;
  d["h5"] = output;
  d["json"] = nbrdf_json_path(output).string();
  d["layers"] = layer_arrays(r.network);
  d["loss"] = r.loss;
  d["epoch_losses"] = r.epoch_losses;
  d["drawn"] = r.drawn;
  d["pairs"] = r.pairs;
  d["steps"] = r.steps;
  d["seconds"] = r.seconds;
  return d;
}

}  // namespace

void bind_nbrdf(py::module_& m) {
  m.def("nbrdf_train", &nbrdf_train, py::arg("brdf"), py::arg("output"),
        py::arg("hidden") = std::vector<std::size_t>{21, 21}, py::arg("samples") = 640000,
        py::arg("epochs") = 100, py::arg("batch") = 512, py::arg("learning_rate") = 5e-4,
        py::arg("seed") = 0, py::arg("threads") = 0, py::arg("param") = "",
        py::arg("final_learning_rate") = 0.0, py::arg("restarts") = 1,
        py::arg("restart_epochs") = 5, py::arg("loss") = std::string(kNbrdfLosses[0]),
        R"doc(Trains a neural BRDF (Sztrajman et al. 2021) on a BRDF (a spec or a Brdf), as
`halfback nbrdf train` (docs/neural.md), the GIL released while it runs, and writes `output`
(NAME.h5, the Keras weights) and NAME.json (the Keras model description) beside it; load()
reads the result. param: "" for the authors' input (sin theta_h, 0, cos theta_h, d), or a
built-in parameterization whose isotropic coordinates the network takes instead.
final_learning_rate, restarts, restart_epochs: the learning-rate schedule and the restarts of
`--final-learning-rate`, `--restarts`, `--restart-epochs` (docs/neural.md). loss: "sztrajman"
(the authors' loss and pairs) or "study-log" (halfback's loss in the study's log measure, on
pairs weighted to cos theta_i cos theta_o dw_i dw_o), as `--loss` (docs/neural.md, "The losses"). Returns a dict: h5, json, layers (a list of (kernel (inputs, outputs), bias)
float32 arrays, as written), loss (of the written network over the pairs), epoch_losses, drawn,
pairs (kept: both directions above the horizon), steps, seconds. Options out of range raise
ValueError; an anisotropic BRDF, or one that is NaN, infinite or negative where sampled, or 0 at
every pair, RuntimeError; nothing is written then.)doc");
}

}  // namespace halfback::python
