#include "halfback/formats/nbrdf.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#include "formats/nbrdf_kernel.hpp"
#include "halfback/brdf/rho_bound.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/util/format_error.hpp"

namespace halfback {

// ---------------------------------------------------------------------------------------------
// Input encoding
// ---------------------------------------------------------------------------------------------
std::array<double, nbrdf::kInputs> nbrdf::encode(const DirPair<double>& pair) {
  const auto e =
      nbrdf_detail::encode_pair(pair.wi.x, pair.wi.y, pair.wi.z, pair.wo.x, pair.wo.y, pair.wo.z);
  return {e.x0, 0.0, e.x2, e.d0, e.d1, e.d2};
}

namespace {

bool has_nan(const DirPair<double>& p) {
  return std::isnan(p.wi.x) || std::isnan(p.wi.y) || std::isnan(p.wi.z) || std::isnan(p.wo.x) ||
         std::isnan(p.wo.y) || std::isnan(p.wo.z);
}

bool below_horizon(const DirPair<double>& p) {
  return p.wi.z < 0 || p.wo.z < 0;
}

// A pair the network is evaluated at (eval() gives the others: 0 or NaN).
bool usable(const DirPair<double>& p) {
  return !has_nan(p) && !below_horizon(p);
}

// ---------------------------------------------------------------------------------------------
// The NumPy form
// ---------------------------------------------------------------------------------------------
constexpr std::string_view kFirstKernel = "_fc1.npy";

bool ends_with(std::string_view s, std::string_view tail) {
  return s.size() >= tail.size() && s.substr(s.size() - tail.size()) == tail;
}

// The *_fc1.npy files of a folder.
std::vector<std::filesystem::path> first_kernels_in(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> found;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (ends_with(it->path().filename().string(), kFirstKernel)) found.push_back(it->path());
  if (ec) throw FormatError(dir.string(), "directory", "cannot read: " + ec.message());
  std::sort(found.begin(), found.end());
  return found;
}

// NAME_fc1.npy of a path given as that file or as its folder.
std::filesystem::path first_kernel(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_directory(path, ec)) return path;
  const auto found = first_kernels_in(path);
  if (found.size() != 1)
    throw FormatError(path.string(), "folder",
                      found.empty() ? "holds no NAME_fc1.npy (the NumPy form of a neural BRDF)"
                                    : "holds " + std::to_string(found.size()) +
                                          " *_fc1.npy files; name the one to read");
  return found.front();
}

NbrdfLayer npy_layer(const std::filesystem::path& kernel_path,
                     const std::filesystem::path& bias_path) {
  NpyArray kernel = read_npy_float32(kernel_path);
  if (kernel.shape.size() != 2)
    throw FormatError(kernel_path.string(), "shape",
                      std::to_string(kernel.shape.size()) + " dimensions, a kernel has 2");
  std::error_code ec;
  if (!std::filesystem::exists(bias_path, ec))
    throw FormatError(bias_path.string(), "file",
                      "missing (the bias of " + kernel_path.filename().string() + ")");
  NpyArray bias = read_npy_float32(bias_path);
  if (bias.shape.size() != 1)
    throw FormatError(bias_path.string(), "shape",
                      std::to_string(bias.shape.size()) + " dimensions, a bias has 1");
  if (bias.shape[0] != kernel.shape[1])
    throw FormatError(bias_path.string(), "shape",
                      std::to_string(bias.shape[0]) + " values for a kernel of " +
                          std::to_string(kernel.shape[1]) + " outputs");
  return {kernel.shape[0], kernel.shape[1], std::move(kernel.values), std::move(bias.values)};
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Validation
// ---------------------------------------------------------------------------------------------
std::optional<Space> nbrdf::input_space(const std::string& input, const std::string& source) {
  if (input.empty() || input == kSztrajmanInput) return std::nullopt;
  auto refuse = [&](const std::string& why) -> std::optional<Space> {
    throw FormatError(source, kInputAttribute,
                      "'" + input + "': " + why +
                          "; this reader evaluates Sztrajman et al.'s input (" +
                          std::string(kSztrajmanInput) + ") and the isotropic coordinates of " +
                          parameterization_names());
  };
  if (input.find(':') != std::string::npos) return refuse("a family's member");
  const std::optional<Space> space = space_from_name(input);
  if (!space || space->is_dirs()) return refuse("not a parameterization");
  if (space->id() > kBuiltinParamCount) return refuse("not a built-in parameterization");
  return space;
}

void check_nbrdf_network(const NbrdfNetwork& net) {
  auto fail = [&](const std::string& field, const std::string& problem) {
    throw FormatError(net.source, field, problem);
  };
  const bool sztrajman = !nbrdf::input_space(net.input, net.source);
  const std::size_t inputs = sztrajman ? nbrdf::kInputs : 3;
  if (net.layers.empty() || net.layers.size() > nbrdf::kMaxLayers)
    fail("layers", std::to_string(net.layers.size()) + " dense layers, expected 1 to " +
                       std::to_string(nbrdf::kMaxLayers));
  for (std::size_t l = 0; l < net.layers.size(); ++l) {
    const NbrdfLayer& layer = net.layers[l];
    const std::string field = "layer " + std::to_string(l + 1);
    const std::size_t expected_in = l == 0 ? inputs : net.layers[l - 1].outputs;
    if (layer.inputs != expected_in)
      fail(field, std::to_string(layer.inputs) + " inputs, expected " +
                      std::to_string(expected_in) +
                      (l > 0       ? " (the previous layer's outputs)"
                       : sztrajman ? " (the encoded pair)"
                                   : " (the isotropic coordinates of " + net.input + ")"));
    if (layer.outputs == 0 || layer.outputs > nbrdf::kMaxWidth)
      fail(field, std::to_string(layer.outputs) + " outputs, expected 1 to " +
                      std::to_string(nbrdf::kMaxWidth));
    if (l + 1 == net.layers.size() && layer.outputs != nbrdf::kOutputs)
      fail(field, std::to_string(layer.outputs) + " outputs, the last layer must give 3 (RGB)");
    if (layer.kernel.size() != layer.inputs * layer.outputs || layer.bias.size() != layer.outputs)
      fail(field, "kernel or bias size does not match the layer's shape");
    auto finite = [](float v) { return std::isfinite(v); };
    if (!std::all_of(layer.kernel.begin(), layer.kernel.end(), finite))
      fail(field, "kernel has a NaN or infinite weight");
    if (!std::all_of(layer.bias.begin(), layer.bias.end(), finite))
      fail(field, "bias has a NaN or infinite value");
  }
}

namespace {

// An upper bound of ρ over every input the encoding can give, by interval arithmetic through the
// layers from the box sin θh, cos θh ∈ [0, 1], 0, d ∈ [−1, 1]³: each output's interval is the
// bias plus each weight times the end of its input's interval that maximizes (or minimizes) the
// product; ReLU clamps both ends at 0. Loose (it ignores that the inputs are tied), but rigorous.
double interval_rho_bound(const NbrdfNetwork& net) {
  std::vector<double> lo{0, 0, 0, -1, -1, -1}, hi{1, 0, 1, 1, 1, 1};
  for (std::size_t l = 0; l < net.layers.size(); ++l) {
    const NbrdfLayer& layer = net.layers[l];
    std::vector<double> out_lo(layer.outputs), out_hi(layer.outputs);
    for (std::size_t j = 0; j < layer.outputs; ++j) {
      double a = layer.bias[j], b = layer.bias[j];
      for (std::size_t k = 0; k < layer.inputs; ++k) {
        const double w = layer.kernel[k * layer.outputs + j];
        a += std::min(w * lo[k], w * hi[k]);
        b += std::max(w * lo[k], w * hi[k]);
      }
      const bool hidden = l + 1 < net.layers.size();
      out_lo[j] = hidden ? std::max(a, 0.0) : a;
      out_hi[j] = hidden ? std::max(b, 0.0) : b;
    }
    lo = std::move(out_lo);
    hi = std::move(out_hi);
  }
  return std::expm1(*std::max_element(hi.begin(), hi.end()));  // ρ = exp(y) − 1, increasing
}

}  // namespace

bool is_nbrdf_npy(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return first_kernels_in(path).size() == 1;
  return ends_with(path.filename().string(), kFirstKernel);
}

NbrdfNetwork read_nbrdf_npy(const std::filesystem::path& path) {
  const std::filesystem::path fc1 = first_kernel(path);
  const std::string file = fc1.filename().string();
  if (!ends_with(file, kFirstKernel))
    throw FormatError(fc1.string(), "file name", "expected NAME_fc1.npy");
  const std::string stem = file.substr(0, file.size() - kFirstKernel.size());
  const std::filesystem::path dir = fc1.parent_path();
  NbrdfNetwork network;
  network.source = fc1.string();
  network.form = "NumPy .npy files";
  for (std::size_t l = 1;; ++l) {
    const auto kernel = dir / (stem + "_fc" + std::to_string(l) + ".npy");
    std::error_code ec;
    if (l > 1 && !std::filesystem::exists(kernel, ec)) break;
    if (l > nbrdf::kMaxLayers)
      throw FormatError(network.source, "layers", "more than " + std::to_string(nbrdf::kMaxLayers));
    network.layers.push_back(npy_layer(kernel, dir / (stem + "_b" + std::to_string(l) + ".npy")));
  }
  return network;
}

std::shared_ptr<const NbrdfBrdf> load_nbrdf(const std::filesystem::path& path) {
  std::error_code ec;
  std::string magic(nbrdf::kHdf5Magic.size(), '\0');
  if (std::filesystem::is_regular_file(path, ec)) {
    std::ifstream in(path, std::ios::binary);
    in.read(magic.data(), std::streamsize(magic.size()));
    if (in.gcount() == std::streamsize(magic.size()) && magic == nbrdf::kHdf5Magic)
      return std::make_shared<NbrdfBrdf>(read_nbrdf_h5(path), path.stem().string());
  }
  if (!std::filesystem::is_directory(path, ec) && !is_nbrdf_npy(path))
    throw FormatError(path.string(), "format",
                      "neither an HDF5 file (Keras weights) nor NAME_fc1.npy or a folder "
                      "holding one (the NumPy form)");
  NbrdfNetwork network = read_nbrdf_npy(path);
  std::string label = std::filesystem::path(network.source).filename().string();
  label.resize(label.size() - kFirstKernel.size());
  return std::make_shared<NbrdfBrdf>(std::move(network), label);
}

// ---------------------------------------------------------------------------------------------
// The BRDF
// ---------------------------------------------------------------------------------------------
NbrdfBrdf::NbrdfBrdf(NbrdfNetwork network, std::string label)
    : network_(std::move(network)), label_(std::move(label)) {
  check_nbrdf_network(network_);
  input_space_ = nbrdf::input_space(network_.input, network_.source);
  check_rho_bound();
}

// The bound on ρ (brdf/rho_bound.hpp): proven everywhere by interval arithmetic when it can be,
// else checked on the probe set, where a network with an absurd output (a last bias of 100 gives
// ρ = e¹⁰⁰) is refused. Between the probe's pairs the writers and the renderer check the values
// they use.
void NbrdfBrdf::check_rho_bound() {
  // The interval bound's box is that of Sztrajman's input.
  const double proven =
      input_space_ ? std::numeric_limits<double>::infinity() : interval_rho_bound(network_);
  if (rho_within_bound(proven)) {
    rho_bound_ =
        fmt::format("ρ ≤ {:.4g} sr⁻¹ everywhere (interval arithmetic through the layers)", proven);
    return;
  }
  const RhoProbe probe = probe_rho(*this);
  if (const auto& excess = probe.excess)
    throw FormatError(
        network_.source, "network",
        rho_above_bound(excess->rho.max_channel(), describe_halfdiff(excess->pair)) +
            " (ρ = exp(y) − 1 of the last layer's outputs y: a corrupt or diverging network)");
  rho_bound_ = fmt::format(
      "within the bound of {:g} sr⁻¹ on the probe set (largest {:.4g} sr⁻¹); "
      "not proven everywhere",
      kMaxRho, probe.largest);
}

std::string NbrdfBrdf::name() const {
  return "nbrdf:" + label_;
}

std::string NbrdfBrdf::description() const {
  return "neural BRDF " + label_ + " (Sztrajman et al. 2021), a " + architecture() + " network";
}

std::string NbrdfBrdf::input_columns() const {
  std::string s;
  for (const std::string_view c : input_space_->param().columns(true)) {
    if (!s.empty()) s += ", ";
    s += c;
  }
  return s;
}

std::string NbrdfBrdf::architecture() const {
  std::string s = fmt::format("{}", network_.layers.front().inputs);
  for (const NbrdfLayer& layer : network_.layers) s += fmt::format("-{}", layer.outputs);
  return s;
}

std::size_t NbrdfBrdf::parameter_count() const {
  std::size_t n = 0;
  for (const NbrdfLayer& layer : network_.layers) n += layer.kernel.size() + layer.bias.size();
  return n;
}

std::vector<Brdf::Fact> NbrdfBrdf::facts() const {
  return {{"format", "neural BRDF (Sztrajman et al. 2021), " + network_.form},
          {"source", network_.source},
          {"architecture", architecture() + " (ReLU hidden layers, linear output, exp(y) - 1)"},
          {"parameters", std::to_string(parameter_count()) + " float32"},
          {"input",
           input_space_
               ? "the isotropic coordinates of " + network_.input + " (" + input_columns() + ")"
               : "(sin θh, 0, cos θh, d): d = ωo (the view direction) in the half-vector "
                 "frame"},
          {"ρ bound", rho_bound_}};
}

Rgb NbrdfBrdf::eval(const DirPair<double>& pair) const {
  if (has_nan(pair)) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan, nan};
  }
  if (below_horizon(pair)) return {0, 0, 0};
  std::array<float, nbrdf::kInputs> input{};
  if (input_space_) {
    const auto q = input_space_->param().forward_iso(pair);
    for (std::size_t i = 0; i < 3; ++i) input[i] = float(q[i]);
  } else {
    const auto x = nbrdf::encode(pair);
    for (std::size_t i = 0; i < nbrdf::kInputs; ++i) input[i] = float(x[i]);
  }
  const auto rho = nbrdf_detail::evaluate_one(network_, input);
  return {rho[0], rho[1], rho[2]};
}

void NbrdfBrdf::eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const {
  if (out.size() != pairs.size())
    throw std::invalid_argument("NbrdfBrdf::eval_batch: output size differs from the pairs'");
  if (input_space_) {  // a parameterization's coordinates: one pair at a time
    parallel_for(pairs.size(), 4096, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) out[i] = eval(pairs[i]);
    });
    return;
  }
  using nbrdf_detail::kBlock;
  parallel_for(pairs.size(), 16 * kBlock, [&](std::size_t begin, std::size_t end) {
    alignas(64) double block[6 * kBlock];
    alignas(64) float outputs[nbrdf::kOutputs * kBlock];
    for (std::size_t start = begin; start < end; start += kBlock) {
      const std::size_t count = std::min(kBlock, end - start);
      for (std::size_t p = 0; p < kBlock; ++p) {
        // Pairs past the end, below the horizon or with a NaN are evaluated at normal incidence
        // and view, and overwritten below.
        DirPair<double> pair{{0, 0, 1}, {0, 0, 1}};
        if (p < count && usable(pairs[start + p])) pair = pairs[start + p];
        const double v[6] = {pair.wi.x, pair.wi.y, pair.wi.z, pair.wo.x, pair.wo.y, pair.wo.z};
        for (std::size_t i = 0; i < 6; ++i) block[i * kBlock + p] = v[i];
      }
      nbrdf_detail::evaluate_block(network_, block, outputs);
      for (std::size_t p = 0; p < count; ++p) {
        const DirPair<double>& pair = pairs[start + p];
        if (!usable(pair))
          out[start + p] = eval(pair);
        else
          out[start + p] = {outputs[p], outputs[kBlock + p], outputs[2 * kBlock + p]};
      }
    }
  });
}

}  // namespace halfback
