// Neural BRDFs (Sztrajman, Rainer, Ritschel, Weyrich 2021, "Neural BRDF Representation and
// Importance Sampling", Computer Graphics Forum 40(6)): one small multilayer perceptron per
// material, read from the authors' Keras weights file (.h5, HDF5) or from their six-file NumPy
// form (NAME_fc1.npy ... NAME_fc3.npy kernels, NAME_b1.npy ... NAME_b3.npy biases).
//
// The network maps x = (sin θh, 0, cos θh, dx, dy, dz) — the half vector with its azimuth rotated
// to 0 and Rusinkiewicz's difference vector d — through dense layers with ReLU activations, a
// last dense layer without activation, and y ↦ max(exp(y) − 1, 0): ρ in RGB, 1/sr, no cosine.
// docs/formats.md ("Neural BRDFs") describes both files, the checks, and the direction convention
// (d is ωo, the view direction, expressed in the half-vector frame), which tests against the RGL
// reader decide.
#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/core/space.hpp"

namespace halfback {

// A float32 NumPy array read from a .npy file (format 1.0, 2.0 or 3.0; dtype '<f4'; C order).
struct NpyArray {
  std::vector<std::size_t> shape;
  std::vector<float> values;  // C order
};

// Parses a .npy file strictly: magic, version, header length inside the file, a header dict with
// exactly 'descr', 'fortran_order' and 'shape', descr '<f4' (other dtypes and big-endian data are
// rejected by name), fortran_order False, and a data size that is exactly the shape's. Nothing
// is allocated from the shape before it has been checked against the file's size. Throws
// FormatError naming `name`.
NpyArray parse_npy_float32(std::span<const std::byte> bytes, std::string_view name);
NpyArray read_npy_float32(const std::filesystem::path& path);

// One dense layer: y = x·kernel + bias, kernel stored inputs × outputs in row-major order
// (Keras's layout).
struct NbrdfLayer {
  std::size_t inputs = 0, outputs = 0;
  std::vector<float> kernel;  // inputs × outputs
  std::vector<float> bias;    // outputs
};

struct NbrdfNetwork {
  std::vector<NbrdfLayer> layers;  // ReLU after each but the last
  std::string source;              // the file or folder it was read from
  std::string form;                // "Keras HDF5" or "NumPy .npy files"
  // What the network takes (nbrdf::kInputAttribute): "" or nbrdf::kSztrajmanInput for
  // nbrdf::encode()'s 6 numbers, else the name of a built-in parameterization for its 3 isotropic
  // coordinates (ParamDescriptor::forward_iso, in its axes' units).
  std::string input;
};

namespace nbrdf {
inline constexpr std::size_t kInputs = 6, kOutputs = 3;
// The widest layer this reader evaluates (the published networks have 21 units): single-pair
// evaluation keeps its activations in fixed arrays of this size.
inline constexpr std::size_t kMaxWidth = 64;
inline constexpr std::size_t kMaxLayers = 16;
// The parameterization whose isotropic coordinates a network takes, or none for Sztrajman's
// input (network.input "" or kSztrajmanInput). Throws FormatError naming `source` when the name
// is neither: not a built-in parameterization (a family's member "PREFIX:ARGS" is never looked
// up: it could load a file), or a registered one (which another process does not have).
std::optional<Space> input_space(const std::string& input, const std::string& source);
// The HDF5 signature, the first 8 bytes of an .h5 file.
inline constexpr std::string_view kHdf5Magic{"\x89HDF\r\n\x1a\n", 8};
// The input of a network, as a file written by halfback names it: the root attribute
// kInputAttribute of the .h5 and "halfback"."input" of the .json. kSztrajmanInput is encode()'s;
// a file without the attribute (the authors') has it. A network trained on another
// parameterization's coordinates carries that parameterization's name there; the reader evaluates
// the built-in parameterizations' (3 inputs) and refuses any other name.
inline constexpr std::string_view kSztrajmanInput = "sztrajman-halfdiff";
inline constexpr const char* kInputAttribute = "halfback_input";

// The network input of a pair: (sin θh, 0, cos θh, d) with d = ωo rotated by −φh about n and by
// −θh about the binormal (Rusinkiewicz 1998, with the roles of the two directions exchanged: the
// networks were trained with the view direction in d). θh = 0 takes φh = 0; ωo = −ωi (both
// grazing) takes h = n.
std::array<double, kInputs> encode(const DirPair<double>& pair);
}  // namespace nbrdf

// The Keras weights file: root attribute `layer_names`, each layer a group with attribute
// `weight_names`; layers with weights must be dense (a float32 kernel in × out and bias out), and
// the list must end with exactly one layer without weights (the authors' output Lambda). A root
// attribute kInputAttribute gives network.input.
NbrdfNetwork read_nbrdf_h5(const std::filesystem::path& path);
// The same from a file image in memory (an embedded material); `name` stands for the file.
NbrdfNetwork parse_nbrdf_h5(std::span<const std::byte> image, std::string_view name);
// The NumPy form: `path` is NAME_fc1.npy, or a folder holding exactly one *_fc1.npy; the layers
// are NAME_fc1.npy/NAME_b1.npy, NAME_fc2.npy/NAME_b2.npy, ... up to the first missing kernel.
NbrdfNetwork read_nbrdf_npy(const std::filesystem::path& path);
// Writes `network` as the authors' pair of files: `h5` (the Keras 2 weights file, as read_nbrdf_h5
// reads it, with the root attributes keras_version and backend that Keras's load_weights reads,
// and kInputAttribute = network.input, kSztrajmanInput when empty) and `h5` with the extension
// .json (the Keras model description: Dense layers with ReLU, a linear last one, and the output
// Lambda exp(y) − 1, named as a function "exp_minus_one" that Keras's model_from_json finds in its
// custom_objects; plus an object "halfback" holding "input" and `notes`, which Keras ignores). Both
// files are written to temporaries and renamed into place only when both are complete
// (util/atomic_file.hpp). Throws FormatError for a network that NbrdfBrdf would refuse
// (check_nbrdf_network: an input it cannot evaluate among them), std::invalid_argument for an .h5
// path ending in .json, std::system_error when a file cannot be written.
struct NbrdfNote {
  std::string key, value;
};
void write_nbrdf(const std::filesystem::path& h5, const NbrdfNetwork& network,
                 const std::vector<NbrdfNote>& notes = {});
// The .json path write_nbrdf() writes beside `h5`.
std::filesystem::path nbrdf_json_path(const std::filesystem::path& h5);
// The two files' contents (write_nbrdf's), for callers that write them elsewhere.
std::string nbrdf_h5_image(const NbrdfNetwork& network);
std::string nbrdf_keras_json(const NbrdfNetwork& network, const std::vector<NbrdfNote>& notes);

// Whether `path` is the NumPy form: a file named *_fc1.npy, or a folder with exactly one such file.
bool is_nbrdf_npy(const std::filesystem::path& path);

// The checks of NbrdfBrdf's constructor but the bound on ρ: an input this reader evaluates
// (network.input: Sztrajman's, or a built-in parameterization's name), 1 to kMaxLayers layers,
// input width 6 (Sztrajman's) or 3 (a parameterization's), output 3, each layer's inputs the
// previous one's outputs, widths ≤ kMaxWidth, kernel and bias sizes, every weight finite. Throws
// FormatError naming network.source.
void check_nbrdf_network(const NbrdfNetwork& network);

class NbrdfBrdf final : public Brdf {
 public:
  // Validates the network (check_nbrdf_network) and ρ within the bound on a BRDF's value
  // (brdf/rho_bound.hpp: proven everywhere by interval arithmetic for Sztrajman's input, or else
  // checked on its probe set). Throws FormatError naming network.source. A network of a
  // parameterization's coordinates is evaluated one pair at a time, in eval_batch too.
  NbrdfBrdf(NbrdfNetwork network, std::string label);

  std::string name() const override;
  std::string description() const override;
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return false; }  // nothing makes the fit reciprocal
  // ρ(ωi, ωo); 0 when a direction is below the horizon (z < 0), NaN when the pair has a NaN.
  // Allocates nothing (fixed arrays of kMaxWidth floats).
  Rgb eval(const DirPair<double>& pair) const override;
  // Blocks of pairs through the layers as small matrix products in float, over all threads.
  void eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const override;
  std::vector<Fact> facts() const override;

  const NbrdfNetwork& network() const { return network_; }
  // "6-21-21-3"; and the number of weights and biases.
  std::string architecture() const;
  std::size_t parameter_count() const;

 private:
  void check_rho_bound();
  std::string input_columns() const;  // "theta_h, theta_d, phi_d" of a parameterization's input

  NbrdfNetwork network_;
  std::string label_;
  std::string rho_bound_;             // what is known of the bound on ρ (a fact)
  std::optional<Space> input_space_;  // a parameterization's coordinates, or Sztrajman's input
};

// Reads either form (the .h5 file by its HDF5 signature, else the NumPy form); the BRDF's name is
// "nbrdf:STEM" (the file name without extension, or NAME of NAME_fc1.npy).
std::shared_ptr<const NbrdfBrdf> load_nbrdf(const std::filesystem::path& path);

}  // namespace halfback
