// What the view serves: the BRDFs and environments a request may name, resolved and cached.
//
// A BRDF spec in a request is one of
//   arg:N          the N-th BRDF named on the command line (0-based; loaded with load_brdf);
//   file:PATH      a file under one of the --root directories (PATH relative to the root);
//   embedded:NAME  a material compiled into the library;
//   anything else  an analytic model spec for model_registry() ("ggx:alpha=0.2"), never a file.
//   arg:N          also a BRDF given as an object (a Python callable: Catalog's `given`), never
//                  loaded from its spec;
// A mesh spec (/api/mesh) is embedded:NAME (the meshes compiled into the server) or file:PATH (a
// .obj under a root, at most kMaxMeshBytes).
// An environment spec is a built-in name (sky, default, studio, sunset), "constant:V" or
// "constant:R,G,B", or file:PATH (a .hdr or .exr under a root).
//
// A parameterization name (forms=, colour=, form=) is one of the registry's, or
// "dupuy-jakob:BRDF" with BRDF a BRDF spec as above: that member is built for the view from
// brdf(BRDF) and never registered (see form()).
//
// Paths, the one rule of every spec a request carries (refuse_paths): a file is named file:PATH
// alone; an absolute PATH, or one with a `..` component, is refused, and so is a path anywhere
// else (a BRDF term, an environment, a parameterization or model name holding '/' or '\\', or a
// `..`), whether or not the file exists. The path is resolved with
// std::filesystem::weakly_canonical (symbolic links followed) and must stay inside the canonical
// root. Problems are RequestErrors carrying the HTTP status.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "fields.hpp"
#include "halfback/brdf/brdf.hpp"
#include "halfback/render/envmap.hpp"
#include "halfback/render/mesh.hpp"

namespace halfback::view {

// A request that cannot be served: the status (4xx) and a message for the user.
class RequestError : public std::runtime_error {
 public:
  RequestError(int status, const std::string& message)
      : std::runtime_error(message), status_(status) {}
  int status() const noexcept { return status_; }

 private:
  int status_;
};

// The confinement rule above for one spec (a BRDF term, an environment, a parameterization or
// model name), lexically: for file:PATH the checks of PATH (400 empty or with a NUL byte, 403
// absolute or with `..`), for any other spec 403 if it holds a '/', a '\\' or is `..`. Whether
// PATH stays inside a root is resolve()'s. Every spec a request carries passes here before it
// is read or named in an answer.
void refuse_paths(std::string_view spec);

class Catalog {
 public:
  // `given`: BRDFs given as objects, by index of `specs` (nullptr, or missing: load the spec).
  Catalog(std::vector<std::string> specs, const std::vector<std::filesystem::path>& roots,
          std::vector<BrdfPtr> given = {});

  const std::vector<std::string>& specs() const { return specs_; }

  // The BRDF of a request spec (see above); cached (kMaxCachedBrdfs, least recently used out).
  BrdfPtr brdf(std::string_view spec) const;
  // The same BRDF as the renderer samples it (render::with_importance_sampling), cached with it.
  BrdfPtr sampled_brdf(std::string_view spec) const;
  // The parameterization a request names (see above): a registered one, or a dupuy-jakob member
  // built from brdf(BRDF) for the view alone, cached (kMaxCachedForms, least recently used out)
  // and never registered, so that requests do not grow the process's registry. nullopt for a
  // name that is neither (after refuse_paths: a name holding a path is a 403).
  std::optional<ViewForm> form(std::string_view name) const;
  // The mesh of a request spec (see above); cached (the last kMaxCachedMeshes).
  std::shared_ptr<const render::Mesh> mesh(std::string_view spec) const;
  // The environment of a request spec; cached.
  std::shared_ptr<const render::EnvMap> environment(std::string_view spec) const;

  // The file a root-relative path names (see above). Throws RequestError: 403 for an absolute
  // path, a `..` component or a path leaving its root, 404 when no root holds it.
  std::filesystem::path resolve(std::string_view relative) const;

  // Root-relative paths (generic form) of the files under the roots whose extension suggests a
  // BRDF (.binary, .bsdf, .h5, .alta, .txt), an environment (.hdr, .exr) or a mesh (.obj); at
  // most `limit` of
  // each, sorted.
  struct Listing {
    std::vector<std::string> brdfs, environments, meshes;
  };
  Listing list_files(std::size_t limit) const;

 private:
  struct FormEntry {
    std::shared_ptr<const ParamDescriptor> param;
    std::uint64_t used = 0;
  };
  struct Entry {
    BrdfPtr brdf;
    BrdfPtr sampled;  // built on first use
    std::uint64_t used = 0;
  };
  // A spec: one term, or a sum of terms (as load_brdf() splits it), each term loaded by
  // load_term: arg:N, file: (confined to the roots), embedded:, or a model spec (never a path).
  BrdfPtr load(std::string_view spec) const;
  BrdfPtr load_term(std::string_view spec) const;
  void evict_locked() const;  // drops the least recently used BRDFs beyond kMaxCachedBrdfs

  std::vector<std::string> specs_;
  std::vector<BrdfPtr> given_;
  std::vector<std::filesystem::path> roots_;  // canonical
  mutable std::mutex mutex_;
  mutable std::map<std::string, Entry, std::less<>> brdfs_;
  mutable std::map<std::string, std::shared_ptr<const render::EnvMap>, std::less<>> envs_;
  mutable std::map<std::string, std::shared_ptr<const render::Mesh>, std::less<>> meshes_;
  mutable std::map<std::string, FormEntry, std::less<>> forms_;
  mutable std::uint64_t clock_ = 0;
};

}  // namespace halfback::view
