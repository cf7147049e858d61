// One entry point for every BRDF source: a file (MERL .binary, RGL .bsdf, ALTA text, a neural
// BRDF's Keras .h5 or NumPy files), recognized
// by its content, or an analytic model spec "name:key=value,..." from the model registry.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/brdf/registry.hpp"

namespace halfback {

enum class BrdfFileFormat { unknown, merl, rgl, alta, nbrdf_h5, nbrdf_npy, factored };

// The format of a file from its content: MERL by its size and 90/90/180 header, RGL by the
// "tensor_file\0" magic, ALTA by its `#` header lines (a #DIM line before the first data line),
// a neural BRDF's Keras weights by the HDF5 signature "\x89HDF\r\n\x1a\n". The NumPy form of a
// neural BRDF (six files) is recognized by a NumPy signature in a file named NAME_fc1.npy, and a
// folder is that form when it holds exactly one *_fc1.npy (any other folder is unknown).
// Throws FormatError when the file cannot be read.
BrdfFileFormat detect_brdf_format(const std::filesystem::path& path);

// The regular files of a directory whose content is a BRDF format (`only` that one, if given),
// sorted by path. Throws FormatError when the directory cannot be read.
std::vector<std::filesystem::path> brdf_files_in(const std::filesystem::path& dir,
                                                 std::optional<BrdfFileFormat> only = {});

// If `spec` names an existing file, reads it with the reader its content calls for (the file's
// extension only picks the reader whose error to report when the content matches no format).
// Otherwise `spec` is a model spec for model_registry(). Throws FormatError for file
// problems and std::invalid_argument for a spec that is neither a file nor a valid model spec.
//
// "embedded:NAME" loads one of the measured materials compiled into the library (CC0 RGL
// measurements and MIT-licensed neural fits of MERL measurements, data/README.md), so that the
// default figures need no file.
BrdfPtr load_brdf(std::string_view spec);

// Registers with core's registry the parameterization families whose parameter is a BRDF spec:
// "dupuy-jakob:SPEC", Dupuy & Jakob 2018's half vector warped by the visible normals of SPEC's
// recovered NDF (formats/adaptive_param.hpp). After it, every tool that takes a parameterization
// by name takes these. The CLI and the Python module call it at start; calling it again is
// harmless.
void register_brdf_parameterization_families();

// A spec that may be a sum "lambert:albedo=0.3+ggx:alpha=0.2" ('+' followed by a lowercase
// letter separates terms), each term loaded by `load_term`: load_brdf() is load_sum(spec,
// <a file or a model>); the explorer passes its own term loader, which confines files to its
// roots. Throws std::invalid_argument for an empty term.
BrdfPtr load_sum(std::string_view spec,
                 const std::function<BrdfPtr(std::string_view term)>& load_term);

// The process-wide registry that load_brdf() reads model specs with, holding every built-in
// model (analytic models and the paper's test functions). Models added to it become loadable.
ModelRegistry& model_registry();

// The NAMEs of "embedded:NAME": ilm_l3_37_metallic, colodur_azure_4e, acrylic_felt_green (RGL),
// gold-metallic-paint3, colonial-maple-223, pink-felt (neural BRDFs of MERL materials).
std::vector<std::string> embedded_material_names();

}  // namespace halfback
