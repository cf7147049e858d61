#include "halfback/loader/load.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <mutex>
#include <string>
#include <system_error>

#include "halfback/brdf/registry.hpp"
#include "halfback/brdf/test_functions.hpp"
#include "halfback/core/space.hpp"
#include "halfback/formats/adaptive_param.hpp"
#include "halfback/formats/alta.hpp"
#include "halfback/formats/factored.hpp"
#include "halfback/formats/merl.hpp"
#include "halfback/formats/nbrdf.hpp"
#include "halfback/formats/rgl.hpp"
#include "halfback/models/analytic.hpp"
#include "halfback/models/register.hpp"
#include "halfback/util/format_error.hpp"
#include "loader/embedded.hpp"

namespace halfback {

namespace {

bool is_merl_header(const char* head, std::size_t n) {
  if (n < 12) return false;
  const unsigned char* p = reinterpret_cast<const unsigned char*>(head);
  auto i32 = [&](int k) {
    return std::int32_t(std::uint32_t(p[4 * k]) | std::uint32_t(p[4 * k + 1]) << 8 |
                        std::uint32_t(p[4 * k + 2]) << 16 | std::uint32_t(p[4 * k + 3]) << 24);
  };
  return i32(0) == merl::kThetaH && i32(1) == merl::kThetaD && i32(2) == merl::kPhiD;
}

// ALTA: text whose first non-blank line is a `#` line, with a #DIM line before any data line.
bool looks_like_alta(const std::string& head) {
  std::size_t pos = 0;
  bool first = true;
  while (pos < head.size()) {
    std::size_t eol = head.find('\n', pos);
    if (eol == std::string::npos) eol = head.size();
    std::string_view line(head.data() + pos, eol - pos);
    pos = eol + 1;
    while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
    if (line.empty() || line == "\r") continue;
    if (line.front() != '#') return false;  // data (or anything else) before #DIM
    if (first && line.size() < 2) return false;
    first = false;
    if (line.substr(0, 5) == "#DIM " || line.substr(0, 5) == "#DIM\t") return true;
  }
  return false;
}

}  // namespace

BrdfFileFormat detect_brdf_format(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    return is_nbrdf_npy(path) ? BrdfFileFormat::nbrdf_npy : BrdfFileFormat::unknown;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw FormatError(path.string(), "file", "cannot get its size: " + ec.message());
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FormatError(path.string(), "file", "cannot open for reading");
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (size == merl::kFileBytes && is_merl_header(head.data(), head.size()))
    return BrdfFileFormat::merl;
  if (head.size() >= 12 && head.compare(0, 12, std::string("tensor_file\0", 12)) == 0)
    return BrdfFileFormat::rgl;
  if (head.compare(0, nbrdf::kHdf5Magic.size(), nbrdf::kHdf5Magic) == 0)
    return BrdfFileFormat::nbrdf_h5;
  if (head.compare(0, 6, "\x93NUMPY") == 0 && is_nbrdf_npy(path)) return BrdfFileFormat::nbrdf_npy;
  if (looks_like_alta(head)) return BrdfFileFormat::alta;
  if (looks_like_factored(head)) return BrdfFileFormat::factored;
  return BrdfFileFormat::unknown;
}

std::vector<std::filesystem::path> brdf_files_in(const std::filesystem::path& dir,
                                                 std::optional<BrdfFileFormat> only) {
  std::error_code ec;
  std::vector<std::filesystem::path> files;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    const BrdfFileFormat f = detect_brdf_format(it->path());
    if (f != BrdfFileFormat::unknown && (!only || f == *only)) files.push_back(it->path());
  }
  if (ec) throw FormatError(dir.string(), "directory", "cannot read: " + ec.message());
  std::sort(files.begin(), files.end());
  return files;
}

namespace {

// The paper's test functions as the model "test" with one named argument: "test:S".
void register_test_functions(ModelRegistry& registry) {
  registry.add({"test",
                "the paper's test functions: F = 1 - cos(theta_d), S = 1 - |h_bar|, "
                "G = 1 - (wi.n)(wo.n)",
                {{"fn",
                  "which function: F (Fresnel-like), S (specular) or G (grazing)",
                  1,
                  0,
                  2,
                  {"F", "S", "G"}}},
                [](const ModelArgs& a) {
                  const TestFunction fns[] = {TestFunction::fresnel, TestFunction::specular,
                                              TestFunction::grazing};
                  return std::make_shared<TestFunctionBrdf>(fns[int(a["fn"])]);
                }});
}

// The separators of a sum "lambert:albedo=0.3+sheen:alpha=0.4+./felt.bsdf": '+' followed by a
// letter (a model's name, a file's) or by '.', '/' or '~' (a path); a number's exponent sign,
// as in 1e+3, is followed by a digit.
bool starts_a_term(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '.' || c == '/' || c == '~';
}

std::vector<std::string_view> split_sum(std::string_view spec) {
  std::vector<std::string_view> parts;
  std::size_t start = 0;
  for (std::size_t i = 0; i + 1 < spec.size(); ++i)
    if (spec[i] == '+' && starts_a_term(spec[i + 1])) {
      parts.push_back(spec.substr(start, i - start));
      start = i + 1;
    }
  parts.push_back(spec.substr(start));
  return parts;
}

BrdfPtr load_one(std::string_view spec);

bool path_exists(std::string_view spec) {
  std::error_code ec;
  return std::filesystem::exists(std::filesystem::path{std::string(spec)}, ec);
}

}  // namespace

ModelRegistry& model_registry() {
  static ModelRegistry registry;
  static std::once_flag builtins;
  std::call_once(builtins, [] {
    models::register_analytic_models(registry);
    register_test_functions(registry);
  });
  return registry;
}

std::vector<std::string> embedded_material_names() {
  std::vector<std::string> names;
  for (const detail::EmbeddedFile& f : detail::embedded_files()) names.emplace_back(f.name);
  return names;
}

BrdfPtr load_brdf(std::string_view spec) {
  if (path_exists(spec)) return load_one(spec);  // a file name may contain '+'
  return load_sum(spec, load_one);
}

BrdfPtr load_sum(std::string_view spec,
                 const std::function<BrdfPtr(std::string_view term)>& load_term) {
  const auto parts = split_sum(spec);
  const auto empty_term = [](std::string_view p) { return p.empty() || p.back() == '+'; };
  if (spec.find('+') != std::string_view::npos && std::ranges::any_of(parts, empty_term))
    throw std::invalid_argument("'" + std::string(spec) +
                                "': a sum has an empty term (a sum is SPEC+SPEC+..., e.g. "
                                "lambert:albedo=0.3+ggx:alpha=0.2)");
  if (parts.size() == 1) return load_term(spec);
  std::vector<BrdfPtr> terms;
  for (const auto part : parts) terms.push_back(load_term(part));
  return std::make_shared<models::Sum>(std::move(terms));
}

namespace {

// "embedded:NAME": a measured material compiled into the library (data/README.md): an RGL file,
// or a neural BRDF's Keras weights (by the HDF5 signature).
BrdfPtr load_embedded(std::string_view name) {
  for (const detail::EmbeddedFile& f : detail::embedded_files()) {
    if (f.name != name) continue;
    const auto* b = reinterpret_cast<const std::byte*>(f.bytes.data());
    const std::string label = "embedded:" + std::string(name);
    const std::span<const std::byte> bytes(b, f.bytes.size());
    if (bytes.size() >= nbrdf::kHdf5Magic.size() &&
        std::memcmp(b, nbrdf::kHdf5Magic.data(), nbrdf::kHdf5Magic.size()) == 0)
      return std::make_shared<NbrdfBrdf>(parse_nbrdf_h5(bytes, label), std::string(name));
    return std::make_shared<RglBrdf>(
        parse_tensor_file(std::vector<std::byte>(b, b + f.bytes.size()), label),
        std::string(name) + "_rgb");
  }
  std::string known;
  for (const std::string& n : embedded_material_names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("'embedded:" + std::string(name) +
                              "': no such embedded material (embedded: " + known + ")");
}

// The BRDF of an existing file (or folder: a neural BRDF's NumPy form).
BrdfPtr load_file(const std::filesystem::path& path) {
  std::error_code ec;
  // A folder is a BRDF only as the NumPy form of a neural BRDF (its reader says what is
  // missing).
  if (std::filesystem::is_directory(path, ec)) return load_nbrdf(path);
  if (!std::filesystem::is_regular_file(path, ec))
    throw FormatError(path.string(), "file", "not a regular file");
  BrdfFileFormat format = detect_brdf_format(path);
  if (format == BrdfFileFormat::unknown) {
    // The content matches no format: let the reader the extension names say what is wrong.
    const std::string ext = path.extension().string();
    if (ext == ".binary")
      format = BrdfFileFormat::merl;
    else if (ext == ".bsdf")
      format = BrdfFileFormat::rgl;
    else if (ext == ".dat" || ext == ".alta")
      format = BrdfFileFormat::alta;
    else if (ext == ".h5")
      format = BrdfFileFormat::nbrdf_h5;
    else if (ext == ".npy")
      format = BrdfFileFormat::nbrdf_npy;
    else
      throw FormatError(path.string(), "format",
                        "not a MERL .binary (34992012 bytes, 90 90 180 header), RGL .bsdf "
                        "(\"tensor_file\" magic), ALTA text file (#DIM header), neural BRDF "
                        "(HDF5 .h5, or NAME_fc1.npy), factored BRDF (JSON, \"format\": "
                        "\"halfback-factored-brdf\")");
  }
  switch (format) {
    case BrdfFileFormat::merl:
      return load_merl(path);
    case BrdfFileFormat::rgl:
      return load_rgl(path);
    case BrdfFileFormat::alta:
      return load_alta(path);
    case BrdfFileFormat::nbrdf_h5:
      return std::make_shared<NbrdfBrdf>(read_nbrdf_h5(path), path.stem().string());
    case BrdfFileFormat::nbrdf_npy:
      return load_nbrdf(path);
    case BrdfFileFormat::factored:
      return std::make_shared<FactoredBrdf>(read_factored(path));
    case BrdfFileFormat::unknown:
      break;
  }
  throw FormatError(path.string(), "format", "unknown");  // (every format returns above)
}

// "merl-trilinear:PATH": a MERL file read with trilinear interpolation between bin centres instead
// of the reference reader's nearest bin (docs/formats.md, "Lookups").
BrdfPtr load_merl_trilinear(std::string_view path_text) {
  const std::filesystem::path path{std::string(path_text)};
  std::error_code ec;
  if (path_text.empty() || !std::filesystem::is_regular_file(path, ec))
    throw std::invalid_argument("'merl-trilinear:" + std::string(path_text) +
                                "': not an existing file (merl-trilinear:FILE.binary)");
  if (detect_brdf_format(path) != BrdfFileFormat::merl)
    throw FormatError(path.string(), "format",
                      "not a MERL .binary (merl-trilinear: reads MERL files only)");
  return load_merl(path, {.lookup = MerlLookup::trilinear});
}

BrdfPtr load_one(std::string_view spec) {
  constexpr std::string_view embedded = "embedded:", trilinear = "merl-trilinear:";
  if (spec.substr(0, embedded.size()) == embedded)
    return load_embedded(spec.substr(embedded.size()));
  if (spec.substr(0, trilinear.size()) == trilinear)
    return load_merl_trilinear(spec.substr(trilinear.size()));
  const std::filesystem::path path{std::string(spec)};
  std::error_code ec;
  if (spec.empty() || !std::filesystem::exists(path, ec)) return model_registry().create(spec);
  // What a file holds is data, never the command line's fault: a value that a BRDF's constructor
  // refuses (std::invalid_argument) is a FormatError naming the file, like the readers' own.
  try {
    return load_file(path);
  } catch (const std::invalid_argument& e) {
    throw FormatError(path.string(), "data", e.what());
  }
}

}  // namespace
void register_brdf_parameterization_families() {
  register_parameterization_family("dupuy-jakob", "BRDF", [](std::string_view spec) {
    if (spec.empty())
      throw std::invalid_argument(
          "dupuy-jakob: a BRDF is needed after the colon (dupuy-jakob:BRDF, e.g. "
          "dupuy-jakob:ggx:alpha=0.2 or dupuy-jakob:FILE.bsdf)");
    if ("dupuy-jakob:" + std::string(spec) == kPerMaterialWarp) return per_material_placeholder();
    const BrdfPtr brdf = load_brdf(spec);
    if (!path_exists(spec))
      return adaptive_parameterization(*brdf, "dupuy-jakob:" + std::string(spec));
    // A file's BRDF that no warp can be made of (NaN everywhere, ...) is bad data.
    try {
      return adaptive_parameterization(*brdf, "dupuy-jakob:" + std::string(spec));
    } catch (const std::invalid_argument& e) {
      throw FormatError(std::string(spec), "data", e.what());
    }
  });
}

}  // namespace halfback
