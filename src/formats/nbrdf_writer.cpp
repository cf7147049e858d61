// Writing a neural BRDF as the authors' pair of files (formats/nbrdf.hpp, write_nbrdf): the Keras
// weights (nbrdf_h5.cpp builds the HDF5 image) and the Keras model description, a JSON file.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <stdexcept>
#include <string>

#include "halfback/formats/nbrdf.hpp"
#include "halfback/util/atomic_file.hpp"

namespace halfback {
namespace {

using Json = nlohmann::ordered_json;

// Keras 2.2's initializer of the authors' layers (RandomUniform ±0.05 kernels, zero biases):
// what a Keras user retraining from the description gets.
Json dense_config(const NbrdfLayer& layer, std::size_t index, bool last) {
  Json config;
  config["name"] = "dense_" + std::to_string(index + 1);
  config["trainable"] = true;
  if (index == 0) config["batch_input_shape"] = Json::array({nullptr, layer.inputs});
  config["dtype"] = "float32";
  config["units"] = layer.outputs;
  config["activation"] = last ? "linear" : "relu";
  config["use_bias"] = true;
  config["kernel_initializer"] = {
      {"class_name", "RandomUniform"},
      {"config", {{"minval", -0.05}, {"maxval", 0.05}, {"seed", nullptr}}}};
  config["bias_initializer"] = {{"class_name", "Zeros"}, {"config", Json::object()}};
  for (const char* key : {"kernel_regularizer", "bias_regularizer", "activity_regularizer",
                          "kernel_constraint", "bias_constraint"})
    config[key] = nullptr;
  return {{"class_name", "Dense"}, {"config", config}};
}

// The output layer y ↦ exp(y) − 1. The authors' files hold the lambda as marshalled Python
// bytecode, which only their Python version loads; this names a function instead, which Keras's
// model_from_json takes from custom_objects={"exp_minus_one": lambda y: K.exp(y) - 1}.
Json output_config() {
  Json config;
  config["name"] = "lambda_1";
  config["trainable"] = true;
  config["function"] = "exp_minus_one";
  config["function_type"] = "function";
  config["output_shape"] = nullptr;
  config["output_shape_type"] = "raw";
  config["arguments"] = Json::object();
  return {{"class_name", "Lambda"}, {"config", config}};
}

}  // namespace

std::string nbrdf_keras_json(const NbrdfNetwork& network, const std::vector<NbrdfNote>& notes) {
  check_nbrdf_network(network);
  Json layers = Json::array();
  for (std::size_t l = 0; l < network.layers.size(); ++l)
    layers.push_back(dense_config(network.layers[l], l, l + 1 == network.layers.size()));
  layers.push_back(output_config());
  Json model;
  model["class_name"] = "Sequential";
  model["config"] = {{"name", "sequential_1"}, {"layers", layers}};
  model["keras_version"] = "2.2.4";
  model["backend"] = "tensorflow";
  Json halfback;
  halfback["input"] = network.input.empty() ? std::string(nbrdf::kSztrajmanInput) : network.input;
  for (const NbrdfNote& note : notes) halfback[note.key] = note.value;
  model["halfback"] = halfback;
  return model.dump() + "\n";
}

std::filesystem::path nbrdf_json_path(const std::filesystem::path& h5) {
  std::filesystem::path json = h5;
  return json.replace_extension(".json");
}

void write_nbrdf(const std::filesystem::path& h5, const NbrdfNetwork& network,
                 const std::vector<NbrdfNote>& notes) {
  const std::filesystem::path json_path = nbrdf_json_path(h5);
  if (json_path == h5)
    throw std::invalid_argument("the weights file '" + h5.string() +
                                "' has the extension .json, the model description's; name it .h5");
  const std::string json = nbrdf_keras_json(network, notes);
  const std::string image = nbrdf_h5_image(network);
  // Both temporaries are complete before either is renamed into place.
  AtomicFile weights(h5), description(json_path);
  weights.write(image);
  description.write(json);
  description.commit();
  weights.commit();
}

}  // namespace halfback
