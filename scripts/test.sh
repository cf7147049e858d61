#!/usr/bin/env bash
# Quickstart step 2: the full test suite. Release build + tests, then the same tests under
# AddressSanitizer + UndefinedBehaviorSanitizer, then the file-format fuzzers for a bounded time.
set -euo pipefail
cd "$(dirname "$0")/.."
# ccache (when installed): paths relative to the tree, so that another clone hits the same cache.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1
export CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime

# RGL's reference loaders (rgl-epfl/brdf-loader: RGB and spectral) for the RGL writer's round-trip
# tests (src/loader/rgl_reference_test.cpp, rgl_spectral_reference_test.cpp): extracted from a
# local git mirror into the build tree when there is one, never copied into the repository;
# without them those tests skip.
brdf_loader_git="${HALFBACK_BRDF_LOADER_GIT:-../.mirror/rgl-epfl+brdf-loader/repo}"
powitacq_args=()
if git --git-dir="$brdf_loader_git" rev-parse --verify -q HEAD >/dev/null 2>&1; then
  mkdir -p build/release/brdf-loader
  git --git-dir="$brdf_loader_git" archive HEAD powitacq_rgb.h powitacq_rgb.inl \
    powitacq.h powitacq.inl LICENSE.md \
    | tar -x -C build/release/brdf-loader
  powitacq_args=(-DHALFBACK_POWITACQ_DIR="$PWD/build/release/brdf-loader")
fi

cmake --preset release ${CI:+-DHALFBACK_WERROR=ON} "${powitacq_args[@]}"
cmake --build --preset release
# The benchmarks are not in the default build; CI compiles them so that they keep compiling.
cmake --build --preset release --target halfback_benchmarks
ctest --preset release

cmake --preset asan ${CI:+-DHALFBACK_WERROR=ON}
cmake --build --preset asan
ctest --preset asan

# 20 s per target (9 targets): the whole CI run stays well under 30 minutes on 2 cores.
if [ -f fuzz/run.sh ]; then
  FUZZ_SECONDS="${FUZZ_SECONDS:-20}" bash fuzz/run.sh
fi
