#include "catalog.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>
#include <system_error>

#include "halfback/formats/adaptive_param.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/render/brdf_sampler.hpp"
#include "halfback/render/renderer.hpp"
#include "halfback/util/format_error.hpp"
#include "halfback/view/api.hpp"
#include "web_assets.hpp"

namespace halfback::view {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kMaxCachedEnvironments = 8;

bool starts_with(std::string_view s, std::string_view prefix) {
  return s.substr(0, prefix.size()) == prefix;
}

// Whether `path` is `root` or inside it (both canonical), component by component.
bool is_inside(const fs::path& path, const fs::path& root) {
  auto p = path.begin();
  for (auto r = root.begin(); r != root.end(); ++r, ++p) {
    if (r->empty()) continue;  // a trailing separator
    if (p == path.end() || *p != *r) return false;
  }
  return true;
}

std::string lower_extension(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

bool is_environment_file(const fs::path& p) {
  const std::string e = lower_extension(p);
  return e == ".hdr" || e == ".exr";
}

bool is_mesh_file(const fs::path& p) {
  return lower_extension(p) == ".obj";
}

constexpr std::size_t kMaxCachedMeshes = 4;

bool is_brdf_file(const fs::path& p) {
  const std::string e = lower_extension(p);
  return e == ".binary" || e == ".bsdf" || e == ".h5" || e == ".alta" || e == ".txt";
}

}  // namespace

Catalog::Catalog(std::vector<std::string> specs, const std::vector<fs::path>& roots,
                 std::vector<BrdfPtr> given)
    : specs_(std::move(specs)), given_(std::move(given)) {
  given_.resize(specs_.size());
  for (const fs::path& root : roots) {
    std::error_code ec;
    fs::path canonical = fs::canonical(root, ec);
    if (ec || !fs::is_directory(canonical, ec))
      throw std::invalid_argument(
          fmt::format("--root '{}': not a readable directory", root.string()));
    roots_.push_back(std::move(canonical));
  }
}

namespace {

// The lexical checks of a root-relative path (refuse_paths, resolve).
void check_relative(std::string_view relative) {
  if (relative.empty()) throw RequestError(400, "empty file path");
  if (relative.find('\0') != std::string_view::npos)
    throw RequestError(400, "file path with a NUL byte");
  const fs::path rel{std::string(relative)};
  if (rel.is_absolute() || rel.has_root_directory() || rel.has_root_name())
    throw RequestError(403, fmt::format("'{}': absolute paths are refused; give a path relative "
                                        "to a --root directory",
                                        relative.substr(0, 256)));
  for (const fs::path& part : rel)
    if (part == "..")
      throw RequestError(
          403, fmt::format("'{}': '..' is refused in file paths", relative.substr(0, 256)));
}

constexpr std::string_view kDupuyJakob = "dupuy-jakob:";

}  // namespace

void refuse_paths(std::string_view spec) {
  if (starts_with(spec, "file:")) return check_relative(spec.substr(5));
  if (spec.find_first_of("/\\") != std::string_view::npos || spec == "..")
    throw RequestError(403, fmt::format("'{}': a path; files are named file:PATH, with PATH "
                                        "relative to a --root directory",
                                        spec.substr(0, 256)));
}

fs::path Catalog::resolve(std::string_view relative) const {
  check_relative(relative);
  const fs::path rel{std::string(relative)};
  if (roots_.empty())
    throw RequestError(403, "no --root directory was given: files cannot be loaded");
  for (const fs::path& root : roots_) {
    std::error_code ec;
    const fs::path candidate = fs::weakly_canonical(root / rel, ec);
    if (ec || !fs::exists(candidate, ec)) continue;
    if (!is_inside(candidate, root))
      throw RequestError(403, fmt::format("'{}' leads outside the --root directories (a symbolic "
                                          "link?)",
                                          relative));
    return candidate;
  }
  throw RequestError(404, fmt::format("'{}': no such file under the --root directories", relative));
}

BrdfPtr Catalog::load(std::string_view spec) const {
  if (spec.empty()) throw RequestError(400, "empty BRDF spec");
  if (spec.size() > kMaxSpecBytes)
    throw RequestError(413, fmt::format("BRDF spec longer than {} bytes", kMaxSpecBytes));
  if (starts_with(spec, "file:")) {  // a file name may contain '+': the whole spec first
    try {
      return load_term(spec);
    } catch (const RequestError& e) {
      if (e.status() != 404) throw;
    }
  }
  // Every term passes the confinement rule before any is loaded: a path in a sum is a 403
  // whatever its other terms are.
  static const BrdfPtr checked = model_registry().create("lambert");
  (void)load_sum(spec, [](std::string_view term) {
    refuse_paths(term);
    return checked;
  });
  return load_sum(spec, [this](std::string_view term) { return load_term(term); });
}

BrdfPtr Catalog::load_term(std::string_view spec) const {
  refuse_paths(spec);
  if (starts_with(spec, "arg:")) {
    const std::string_view n = spec.substr(4);
    std::size_t index = 0;
    for (const char c : n) {
      if (c < '0' || c > '9' || index > specs_.size()) {
        index = specs_.size();
        break;
      }
      index = index * 10 + std::size_t(c - '0');
    }
    if (n.empty() || index >= specs_.size())
      throw RequestError(404, fmt::format("'{}': the command line named {} BRDF(s) (arg:0 ...)",
                                          spec, specs_.size()));
    if (given_[index]) return given_[index];
    return load_brdf(specs_[index]);
  }
  if (starts_with(spec, "file:")) {
    // A reader's message names the file by its resolved path: the page sees the root-relative one
    // (where the roots are is not the page's business).
    const std::string_view relative = spec.substr(5);
    const std::string path = resolve(relative).string();
    const auto hidden = [&](const std::exception& e) {
      std::string message = e.what();
      for (std::size_t at; (at = message.find(path)) != std::string::npos;)
        message.replace(at, path.size(), relative);
      for (const fs::path& root : roots_)
        for (std::size_t at; (at = message.find(root.string())) != std::string::npos;)
          message.replace(at, root.string().size(), "<root>");
      return message;
    };
    try {
      return load_brdf(path);
    } catch (const RequestError&) {
      throw;
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const FormatError& e) {
      throw RequestError(400, hidden(e));
    } catch (const std::invalid_argument& e) {
      throw RequestError(400, hidden(e));
    } catch (const std::out_of_range& e) {
      throw RequestError(400, hidden(e));
    } catch (const std::exception& e) {
      throw RequestError(500, hidden(e));
    }
  }
  if (starts_with(spec, "embedded:")) {
    const auto names = embedded_material_names();
    if (std::find(names.begin(), names.end(), spec.substr(9)) == names.end())
      throw RequestError(404, fmt::format("'{}': no such embedded material", spec));
    return load_brdf(spec);
  }
  return model_registry().create(spec);  // never a file: a model spec only
}

void Catalog::evict_locked() const {
  while (brdfs_.size() > kMaxCachedBrdfs) {
    auto oldest = std::min_element(brdfs_.begin(), brdfs_.end(), [](const auto& a, const auto& b) {
      return a.second.used < b.second.used;
    });
    brdfs_.erase(oldest);
  }
}

BrdfPtr Catalog::brdf(std::string_view spec) const {
  {
    std::lock_guard lock(mutex_);
    if (auto it = brdfs_.find(spec); it != brdfs_.end()) {
      it->second.used = ++clock_;
      return it->second.brdf;
    }
  }
  BrdfPtr loaded = load(spec);  // outside the lock: a large file does not hold the other tabs
  std::lock_guard lock(mutex_);
  Entry& e = brdfs_[std::string(spec)];
  if (!e.brdf) e.brdf = std::move(loaded);
  e.used = ++clock_;
  BrdfPtr result = e.brdf;
  evict_locked();
  return result;
}

BrdfPtr Catalog::sampled_brdf(std::string_view spec) const {
  BrdfPtr base = brdf(spec);
  {
    std::lock_guard lock(mutex_);
    if (auto it = brdfs_.find(spec); it != brdfs_.end() && it->second.sampled)
      return it->second.sampled;
  }
  // The sampler refers to the BRDF: one block owns both, the result points at the sampler.
  struct Owner {
    BrdfPtr base;
    std::shared_ptr<const Brdf> sampler;
  };
  auto owner = std::make_shared<Owner>();
  owner->base = base;
  owner->sampler =
      render::choose_brdf_sampler(*base, render::RenderSettings{}).brdf;  // as render()
  BrdfPtr sampled(owner, owner->sampler.get());
  std::lock_guard lock(mutex_);
  if (auto it = brdfs_.find(spec); it != brdfs_.end() && it->second.brdf == base)
    it->second.sampled = sampled;
  return sampled;
}

std::optional<ViewForm> Catalog::form(std::string_view name) const {
  if (name.size() > kMaxSpecBytes)
    throw RequestError(413,
                       fmt::format("parameterization name longer than {} bytes", kMaxSpecBytes));
  if (!starts_with(name, kDupuyJakob)) {
    refuse_paths(name);
    for (const Space s : parameterizations())  // the registry's names only: nothing is built
      if (name_of(s) == name) return ViewForm(s);
    return std::nullopt;
  }
  {
    std::lock_guard lock(mutex_);
    if (auto it = forms_.find(name); it != forms_.end()) {
      it->second.used = ++clock_;
      return ViewForm(it->second.param);
    }
  }
  const std::string_view spec = name.substr(kDupuyJakob.size());
  if (spec.empty())
    throw RequestError(400, "dupuy-jakob: a BRDF is needed after the colon (dupuy-jakob:BRDF)");
  const BrdfPtr brdf = this->brdf(spec);  // confined as any BRDF of a request
  auto param = adaptive_parameterization(*brdf, std::string(name));
  std::lock_guard lock(mutex_);
  FormEntry& e = forms_[std::string(name)];
  if (!e.param) e.param = std::move(param);
  e.used = ++clock_;
  ViewForm result(e.param);
  while (forms_.size() > kMaxCachedForms)
    forms_.erase(std::min_element(forms_.begin(), forms_.end(), [](const auto& a, const auto& b) {
      return a.second.used < b.second.used;
    }));
  return result;
}

std::shared_ptr<const render::EnvMap> Catalog::environment(std::string_view spec) const {
  if (spec.size() > kMaxSpecBytes)
    throw RequestError(413, fmt::format("environment spec longer than {} bytes", kMaxSpecBytes));
  refuse_paths(spec);
  {
    std::lock_guard lock(mutex_);
    if (auto it = envs_.find(spec); it != envs_.end()) return it->second;
  }
  std::shared_ptr<const render::EnvMap> map;
  const auto builtins = render::EnvMap::builtin_names();
  if (std::find(builtins.begin(), builtins.end(), spec) != builtins.end() || spec == "default" ||
      starts_with(spec, "constant:")) {
    map = std::make_shared<const render::EnvMap>(render::EnvMap::from_spec(spec));
  } else if (starts_with(spec, "file:")) {
    const fs::path path = resolve(spec.substr(5));
    if (!is_environment_file(path))
      throw RequestError(400, fmt::format("'{}': an environment file is a .hdr or .exr", spec));
    map = std::make_shared<const render::EnvMap>(render::EnvMap::load(path));
  } else {
    throw RequestError(400, fmt::format("unknown environment '{}' (expected sky, studio, sunset, "
                                        "constant:V, constant:R,G,B or file:PATH)",
                                        spec));
  }
  std::lock_guard lock(mutex_);
  if (envs_.size() >= kMaxCachedEnvironments) envs_.clear();
  envs_.emplace(std::string(spec), map);
  return map;
}

std::shared_ptr<const render::Mesh> Catalog::mesh(std::string_view spec) const {
  if (spec.size() > kMaxSpecBytes)
    throw RequestError(413, fmt::format("mesh spec longer than {} bytes", kMaxSpecBytes));
  refuse_paths(spec);
  {
    std::lock_guard lock(mutex_);
    if (auto it = meshes_.find(spec); it != meshes_.end()) return it->second;
  }
  std::string text, name;
  if (starts_with(spec, "embedded:")) {
    name = std::string(spec.substr(9));
    bool found = false;
    for (const WebAsset& m : embedded_meshes())
      if (m.name == name + ".obj") {
        text.assign(reinterpret_cast<const char*>(m.bytes.data()), m.bytes.size());
        found = true;
      }
    if (!found)
      throw RequestError(404, fmt::format("'{}': no such embedded mesh (embedded:{})",
                                          spec.substr(0, 256), kEmbeddedMesh));
  } else if (starts_with(spec, "file:")) {
    const std::string_view relative = spec.substr(5);
    const fs::path path = resolve(relative);
    if (!is_mesh_file(path))
      throw RequestError(400, fmt::format("'{}': a mesh file is a Wavefront .obj", spec));
    std::error_code ec;
    const auto size = fs::file_size(path, ec);
    if (ec) throw RequestError(400, fmt::format("'{}': cannot be read", spec));
    if (size > kMaxMeshBytes)
      throw RequestError(413, fmt::format("'{}': {} bytes, above the limit of {} for a mesh", spec,
                                          size, kMaxMeshBytes));
    std::ifstream in(path, std::ios::binary);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (!in && !in.eof()) throw RequestError(400, fmt::format("'{}': cannot be read", spec));
    name = std::string(relative);  // the root's place on disk is not the page's business
  } else {
    throw RequestError(400, fmt::format("unknown mesh '{}' (expected embedded:{} or "
                                        "file:PATH.obj under a --root)",
                                        spec.substr(0, 256), kEmbeddedMesh));
  }
  auto mesh = std::make_shared<const render::Mesh>(render::parse_obj(text, name));
  std::lock_guard lock(mutex_);
  if (meshes_.size() >= kMaxCachedMeshes) meshes_.clear();
  meshes_.emplace(std::string(spec), mesh);
  return mesh;
}

Catalog::Listing Catalog::list_files(std::size_t limit) const {
  Listing listing;
  for (const fs::path& root : roots_) {
    std::error_code ec;
    std::size_t visited = 0;  // bounded: a huge tree does not stall the request
    for (fs::recursive_directory_iterator it(root, ec), end; !ec && it != end && visited < 20000;
         it.increment(ec), ++visited) {
      if (!it->is_regular_file(ec)) continue;
      std::error_code ec2;
      const fs::path real = fs::weakly_canonical(it->path(), ec2);
      if (ec2 || !is_inside(real, root)) continue;  // a link out of the root is not offered
      const std::string rel = it->path().lexically_relative(root).generic_string();
      if (is_environment_file(real) && listing.environments.size() < limit)
        listing.environments.push_back(rel);
      else if (is_mesh_file(real) && listing.meshes.size() < limit)
        listing.meshes.push_back(rel);
      else if (is_brdf_file(real) && listing.brdfs.size() < limit)
        listing.brdfs.push_back(rel);
    }
  }
  std::sort(listing.brdfs.begin(), listing.brdfs.end());
  std::sort(listing.environments.begin(), listing.environments.end());
  std::sort(listing.meshes.begin(), listing.meshes.end());
  return listing;
}

}  // namespace halfback::view
