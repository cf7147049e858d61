// libFuzzer target for the environment map readers, Radiance .hdr and OpenEXR (see fuzz/run.sh):
// the input written to a file of the process's own (EnvMap::load reads paths: its size is checked
// against what the header declares before the pixels are read, class C of
// docs/reliability/readers.md), loaded, and looked up in a direction taken from the input's
// last bytes.
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "halfback/render/envmap.hpp"
#include "halfback/util/format_error.hpp"

using namespace halfback;

namespace {

volatile double sink;

const std::filesystem::path& scratch() {
  static const std::filesystem::path p = std::filesystem::temp_directory_path() /
                                         ("halfback-envmap-fuzz-" + std::to_string(::getpid()));
  return p;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::ofstream(scratch(), std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  try {
    const render::EnvMap map = render::EnvMap::load(scratch());
    double v[3] = {0.3, 0.4, 0.5};
    if (size >= 24) std::memcpy(v, data + size - 24, sizeof v);
    sink = map.eval({v[0], v[1], v[2]}).r;
  } catch (const FormatError&) {
  }
  return 0;
}
