// Resampled tables (brdf/resample.hpp) as files: OpenEXR, NumPy .npz and .npy.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "halfback/brdf/resample.hpp"

namespace halfback {

// Writes a table, the format chosen by the extension (docs/formats.md, "Resampled tables"):
//   .exr  OpenEXR, float channels R, G, B and `valid`; the table as an image whose width is the
//         last axis and whose rows run over the other axes (row-major); string attributes
//         `halfback:*` state the parameterization, kind, sampling, shape, and each axis's name,
//         range, count and sample positions
//   .npz  NumPy archive (np.load): `rho` float64 (shape..., 3), `valid` bool (shape...),
//         `axis0`... float64 sample positions, `axis_names` and `metadata` (JSON) strings
//   .npy  NumPy array `rho` only, float64 (shape..., 3), NaN where invalid (no room for
//         metadata in that format: use .npz or .exr to keep the axes)
// The file is written to a temporary file and renamed into place. Throws std::invalid_argument
// for another extension and std::runtime_error (naming the file) on I/O errors.
void write_table(const std::filesystem::path& path, const ResampledTable& table);

enum class TableFormat { exr, npz, npy };
// The format write_table() picks for a path (case-insensitive extension), nullopt for another.
std::optional<TableFormat> table_format_from_path(const std::filesystem::path& path);

// The metadata of a table as a JSON object (what .npz and .exr carry).
std::string table_metadata_json(const ResampledTable& table);
}  // namespace halfback
