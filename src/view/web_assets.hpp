// The page's files (src/view/web/), embedded at build time by cmake/embed_files.cmake into the
// generated web_assets.cpp.
#pragma once

#include <span>
#include <string_view>

namespace halfback::view {

struct WebAsset {
  std::string_view name;  // file name, e.g. "app.js"
  std::span<const unsigned char> bytes;
};

std::span<const WebAsset> web_assets();
// The meshes of the lit mesh view (data/meshes/, "NAME.obj"), the same way.
std::span<const WebAsset> embedded_meshes();

}  // namespace halfback::view
