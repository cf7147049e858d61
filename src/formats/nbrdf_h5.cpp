// The Keras weights file of a neural BRDF, read through the HDF5 C library (libhdf5-dev).
//
// Keras 2 writes: a root attribute `layer_names` (fixed-length strings), one group per layer with
// an attribute `weight_names` ("dense_1/kernel:0", "dense_1/bias:0"), and the weights as datasets
// at GROUP/WEIGHT_NAME. The layer types and activations are not in the weights file (they are in
// the separate model description, NAME.json): this reader takes the layers with weights as dense
// layers (two weights, a 2-D kernel and a 1-D bias), and requires the list to end with the single
// weightless output layer of the authors' networks (their Lambda y ↦ exp(y) − 1).
#include <hdf5.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "halfback/formats/nbrdf.hpp"
#include "halfback/util/bounded_read.hpp"
#include "halfback/util/format_error.hpp"

namespace halfback {
namespace {

// The superblock is looked for in the file's first bytes (a user block of up to 32 KiB before it).
constexpr std::size_t kSuperblockSearch = std::size_t(1) << 16;

// Debian's serial HDF5 is not thread-safe: every use of it holds this lock.
std::mutex& hdf5_mutex() {
  static std::mutex m;
  return m;
}

// An HDF5 identifier closed by `close` when it goes out of scope.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

class KerasReader {
 public:
  KerasReader(hid_t file, std::string name) : file_(file), name_(std::move(name)) {}

  NbrdfNetwork read() {
    const std::vector<std::string> layers = string_attribute(file_, "/", "layer_names");
    if (layers.empty()) fail("layer_names", "lists no layer");
    NbrdfNetwork network;
    network.source = name_;
    network.form = "Keras HDF5";
    network.input = input_name();
    for (std::size_t i = 0; i < layers.size(); ++i) {
      Handle group(H5Gopen2(file_, layers[i].c_str(), H5P_DEFAULT), H5Gclose);
      if (!group.valid()) fail(layers[i], "layer group listed in layer_names is missing");
      const auto weights = string_attribute(group.get(), layers[i], "weight_names");
      const bool last = i + 1 == layers.size();
      if (weights.empty() != last)
        fail(layers[i], last ? "the last layer has weights; expected the weightless output "
                               "layer (exp(y) - 1) after the dense layers"
                             : "a layer without weights before the last layer; only dense "
                               "layers are supported");
      if (!last) network.layers.push_back(dense_layer(group.get(), layers[i], weights));
    }
    return network;
  }

 private:
  [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
    throw FormatError(name_, field, problem);
  }

  // A file written by halfback names its input (nbrdf::kInputAttribute); the authors' files do not
  // and have Sztrajman et al.'s. NbrdfBrdf refuses a name it cannot evaluate.
  std::string input_name() const {
    if (H5Aexists(file_, nbrdf::kInputAttribute) <= 0) return std::string(nbrdf::kSztrajmanInput);
    const auto input = string_attribute(file_, "/", nbrdf::kInputAttribute);
    if (input.size() != 1) fail(nbrdf::kInputAttribute, "not one string");
    return input.front();
  }

  // A 0-D or 1-D attribute of fixed-length strings (NUL-padded or NUL-terminated).
  std::vector<std::string> string_attribute(hid_t loc, const std::string& where,
                                            const char* attr_name) const {
    const std::string field = where + " attribute " + attr_name;
    if (H5Aexists(loc, attr_name) <= 0) fail(field, "missing");
    Handle attr(H5Aopen(loc, attr_name, H5P_DEFAULT), H5Aclose);
    Handle type(H5Aget_type(attr.get()), H5Tclose);
    Handle space(H5Aget_space(attr.get()), H5Sclose);
    if (!attr.valid() || !type.valid() || !space.valid()) fail(field, "unreadable");
    // Keras writes an empty list as an empty float array (a layer without weights).
    if (H5Sget_simple_extent_npoints(space.get()) == 0) return {};
    if (H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) != 0)
      fail(field, "not fixed-length strings");
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank < 0 || rank > 1) fail(field, "not a list of strings");
    const hssize_t count = H5Sget_simple_extent_npoints(space.get());
    const std::size_t width = H5Tget_size(type.get());
    if (count < 0 || count > 1024 || width == 0 || width > 4096)
      fail(field, "implausible size (" + std::to_string(count) + " strings of " +
                      std::to_string(width) + " bytes)");
    std::string buffer(std::size_t(count) * width, '\0');
    if (H5Aread(attr.get(), type.get(), buffer.data()) < 0) fail(field, "unreadable");
    std::vector<std::string> out;
    for (hssize_t i = 0; i < count; ++i) {
      std::string s = buffer.substr(std::size_t(i) * width, width);
      s.resize(s.find('\0') == std::string::npos ? s.size() : s.find('\0'));
      out.push_back(std::move(s));
    }
    return out;
  }

  // A float32 dataset of the expected rank (dimensions in `dims`), read into `values`.
  std::vector<float> float_dataset(hid_t group, const std::string& path, int rank,
                                   std::vector<hsize_t>& dims) const {
    Handle data(H5Dopen2(group, path.c_str(), H5P_DEFAULT), H5Dclose);
    if (!data.valid()) fail(path, "dataset named in weight_names is missing");
    Handle type(H5Dget_type(data.get()), H5Tclose);
    Handle space(H5Dget_space(data.get()), H5Sclose);
    if (!type.valid() || !space.valid()) fail(path, "unreadable");
    if (H5Tget_class(type.get()) != H5T_FLOAT || H5Tget_size(type.get()) != 4)
      fail(path, "dtype is not float32");
    const int actual = H5Sget_simple_extent_ndims(space.get());
    if (actual != rank)
      fail(path, std::to_string(actual) + " dimensions, expected " + std::to_string(rank));
    dims.assign(std::size_t(rank), 0);
    H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
    hsize_t count = 1;
    for (const hsize_t d : dims) {
      if (d == 0 || d > nbrdf::kMaxWidth)
        fail(path,
             "dimension " + std::to_string(d) + " outside 1.." + std::to_string(nbrdf::kMaxWidth));
      count *= d;
    }
    std::vector<float> values(count);
    if (H5Dread(data.get(), H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0)
      fail(path, "cannot read its data (truncated or corrupt file?)");
    return values;
  }

  NbrdfLayer dense_layer(hid_t group, const std::string& layer,
                         const std::vector<std::string>& weights) const {
    auto ends_with = [](const std::string& s, std::string_view tail) {
      return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
    };
    if (weights.size() != 2 || !ends_with(weights[0], "kernel:0") ||
        !ends_with(weights[1], "bias:0"))
      fail(layer, "weight_names is not (kernel, bias): not a dense layer");
    NbrdfLayer out;
    std::vector<hsize_t> kdims, bdims;
    out.kernel = float_dataset(group, weights[0], 2, kdims);
    out.bias = float_dataset(group, weights[1], 1, bdims);
    out.inputs = kdims[0];
    out.outputs = kdims[1];
    if (bdims[0] != kdims[1])
      fail(layer, "bias has " + std::to_string(bdims[0]) + " values for " +
                      std::to_string(kdims[1]) + " outputs");
    return out;
  }

  hid_t file_;
  std::string name_;
};

// The end of the file its superblock declares (base address + "end of file address"), read from
// the file's first bytes `b` (HDF5's H5Fget_eoa refuses the in-memory driver of the embedded
// files). HDF5 reads only what it needs and accepts any data after that end; this reader does
// not. The superblock is at 0, or after a user block at 512, 1024, 2048, ... bytes; its versions
// 0 and 1 hold the address after 24 (28) bytes and two addresses, versions 2 and 3 after 12 bytes
// and two addresses (the HDF5 file format specification, "Superblock").
void require_declared_end(std::span<const std::byte> b, std::uint64_t size,
                          const std::string& name) {
  auto u8 = [&](std::size_t i) { return static_cast<unsigned>(b[i]); };
  for (std::size_t at = 0; at + 64 <= b.size(); at = at ? 2 * at : 512) {
    if (std::memcmp(b.data() + at, nbrdf::kHdf5Magic.data(), nbrdf::kHdf5Magic.size()) != 0)
      continue;
    const unsigned version = u8(at + 8);
    if (version > 3) break;
    const unsigned offsets = u8(at + (version < 2 ? 13 : 9));
    if (offsets != 2 && offsets != 4 && offsets != 8) break;
    auto address = [&](std::size_t i) {
      std::uint64_t v = 0;
      for (unsigned k = offsets; k-- > 0;) v = v << 8 | u8(i + k);
      return v;
    };
    const std::size_t fields = at + (version == 0 ? 24 : version == 1 ? 28 : 12);
    const std::uint64_t base = address(fields), end = address(fields + 2 * offsets);
    require_declared_size(name, base + end, size, "the end of file address in its superblock");
    return;
  }
  throw FormatError(
      name, "HDF5 superblock",
      "not found, or of an unknown version, in the first " + std::to_string(b.size()) + " bytes");
}

// `head`: the file's first bytes, of `size`.
NbrdfNetwork read_open_file(hid_t file, const std::string& name, std::span<const std::byte> head,
                            std::uint64_t size) {
  Handle handle(file, H5Fclose);
  if (!handle.valid())
    throw FormatError(name, "HDF5", "cannot be opened (truncated or corrupt HDF5 file)");
  require_declared_end(head, size, name);
  return KerasReader(handle.get(), name).read();
}

void silence_hdf5_errors() {
  // The library prints its error stack to stderr by default; the reader reports its own errors.
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

// ---------------------------------------------------------------------------------------------
// Writing: Keras 2's layout (what read() reads), in an in-memory file whose image is returned
// ---------------------------------------------------------------------------------------------
[[noreturn]] void write_failed(const std::string& what) {
  throw std::runtime_error("writing the HDF5 image of a neural BRDF: " + what + " failed");
}

// A 1-D attribute of fixed-length, NUL-padded strings (h5py's form of a NumPy 'S' array); an
// empty list is an empty float array, as Keras writes it.
void write_strings(hid_t loc, const char* name, const std::vector<std::string>& items) {
  const hsize_t n = items.size();
  Handle space(H5Screate_simple(1, &n, nullptr), H5Sclose);
  if (items.empty()) {
    Handle attr(H5Acreate2(loc, name, H5T_IEEE_F32LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                H5Aclose);
    if (!attr.valid()) write_failed(std::string("attribute ") + name);
    return;
  }
  std::size_t width = 1;
  for (const auto& s : items) width = std::max(width, s.size());
  std::string buffer(items.size() * width, '\0');
  for (std::size_t i = 0; i < items.size(); ++i)
    buffer.replace(i * width, items[i].size(), items[i]);
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  if (!type.valid() || H5Tset_size(type.get(), width) < 0 ||
      H5Tset_strpad(type.get(), H5T_STR_NULLPAD) < 0)
    write_failed("a string type");
  Handle attr(H5Acreate2(loc, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!attr.valid() || H5Awrite(attr.get(), type.get(), buffer.data()) < 0)
    write_failed(std::string("attribute ") + name);
}

// A scalar fixed-length string attribute (h5py's form of a NumPy bytes scalar, which Keras's
// load_weights decodes from keras_version and backend).
void write_string(hid_t loc, const char* name, const std::string& value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  if (!type.valid() || H5Tset_size(type.get(), std::max<std::size_t>(value.size(), 1)) < 0 ||
      H5Tset_strpad(type.get(), H5T_STR_NULLPAD) < 0)
    write_failed("a string type");
  std::string buffer = value.empty() ? std::string(1, '\0') : value;
  Handle attr(H5Acreate2(loc, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!attr.valid() || H5Awrite(attr.get(), type.get(), buffer.data()) < 0)
    write_failed(std::string("attribute ") + name);
}

// A float32 dataset at `path` below `group` (intermediate groups created).
void write_floats(hid_t group, const std::string& path, const std::vector<hsize_t>& dims,
                  const std::vector<float>& values) {
  Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  // No modification times in the object headers: the same network gives the same bytes.
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_obj_track_times(dcpl.get(), false);
  Handle space(H5Screate_simple(int(dims.size()), dims.data(), nullptr), H5Sclose);
  Handle data(H5Dcreate2(group, path.c_str(), H5T_IEEE_F32LE, space.get(), lcpl.get(), dcpl.get(),
                         H5P_DEFAULT),
              H5Dclose);
  if (!data.valid() ||
      H5Dwrite(data.get(), H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0)
    write_failed("dataset " + path);
}

void write_keras_layers(hid_t file, const NbrdfNetwork& network) {
  std::vector<std::string> names;
  for (std::size_t l = 0; l < network.layers.size(); ++l)
    names.push_back("dense_" + std::to_string(l + 1));
  names.push_back("lambda_1");  // the output exp(y) - 1, without weights
  write_strings(file, "layer_names", names);
  for (std::size_t l = 0; l < names.size(); ++l) {
    Handle gcpl(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
    H5Pset_obj_track_times(gcpl.get(), false);
    Handle group(H5Gcreate2(file, names[l].c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT),
                 H5Gclose);
    if (!group.valid()) write_failed("group " + names[l]);
    if (l == network.layers.size()) {
      write_strings(group.get(), "weight_names", {});
      continue;
    }
    const NbrdfLayer& layer = network.layers[l];
    const std::string kernel = names[l] + "/kernel:0", bias = names[l] + "/bias:0";
    write_strings(group.get(), "weight_names", {kernel, bias});
    write_floats(group.get(), kernel, {layer.inputs, layer.outputs}, layer.kernel);
    write_floats(group.get(), bias, {layer.outputs}, layer.bias);
  }
}

}  // namespace

std::string nbrdf_h5_image(const NbrdfNetwork& network) {
  check_nbrdf_network(network);
  std::lock_guard lock(hdf5_mutex());
  silence_hdf5_errors();
  // The core driver without a backing store: the file lives in memory only.
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!fapl.valid() || H5Pset_fapl_core(fapl.get(), 1 << 16, false) < 0)
    write_failed("setting up an in-memory file");
  Handle file(H5Fcreate("nbrdf-image.h5", H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), H5Fclose);
  if (!file.valid()) write_failed("creating an in-memory file");
  write_keras_layers(file.get(), network);
  write_string(file.get(), "backend", "tensorflow");
  write_string(file.get(), "keras_version", "2.2.4");
  write_string(file.get(), nbrdf::kInputAttribute,
               network.input.empty() ? std::string(nbrdf::kSztrajmanInput) : network.input);
  if (H5Fflush(file.get(), H5F_SCOPE_GLOBAL) < 0) write_failed("flushing the in-memory file");
  const ssize_t size = H5Fget_file_image(file.get(), nullptr, 0);
  if (size <= 0) write_failed("sizing the file image");
  std::string image(std::size_t(size), '\0');
  if (H5Fget_file_image(file.get(), image.data(), image.size()) != size)
    write_failed("copying the file image");
  return image;
}

NbrdfNetwork read_nbrdf_h5(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw FormatError(name, "file", ec ? ec.message() : "not a regular file");
  std::lock_guard lock(hdf5_mutex());
  silence_hdf5_errors();
  if (H5Fis_hdf5(name.c_str()) <= 0)
    throw FormatError(name, "HDF5", "not an HDF5 file (no HDF5 signature)");
  BoundedFile file(path);
  return read_open_file(H5Fopen(name.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), name,
                        file.head(kSuperblockSearch), file.size());
}

NbrdfNetwork parse_nbrdf_h5(std::span<const std::byte> image, std::string_view name_view) {
  const std::string name(name_view);
  if (image.size() < nbrdf::kHdf5Magic.size() ||
      std::string_view(reinterpret_cast<const char*>(image.data()), nbrdf::kHdf5Magic.size()) !=
          nbrdf::kHdf5Magic)
    throw FormatError(name, "HDF5", "not an HDF5 file (no HDF5 signature)");
  std::lock_guard lock(hdf5_mutex());
  silence_hdf5_errors();
  // The core driver opens a copy of the image as an in-memory file.
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!fapl.valid() || H5Pset_fapl_core(fapl.get(), 1 << 16, false) < 0 ||
      H5Pset_file_image(fapl.get(), const_cast<std::byte*>(image.data()), image.size()) < 0)
    throw FormatError(name, "HDF5", "cannot set up an in-memory file");
  return read_open_file(H5Fopen(name.c_str(), H5F_ACC_RDONLY, fapl.get()), name,
                        image.first(std::min(image.size(), kSuperblockSearch)), image.size());
}

}  // namespace halfback
