#!/usr/bin/env bash
# Quickstart step 2: the full test suite. Release build + tests, then the same tests under
# AddressSanitizer + UndefinedBehaviorSanitizer, then the file-format fuzzers for a bounded time.
set -euo pipefail
cd "$(dirname "$0")/.."
# ccache (when installed): paths relative to the tree, so that another clone hits the same cache.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1
export CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime

cmake --preset release ${CI:+-DHALFBACK_WERROR=ON}
cmake --build --preset release
ctest --preset release

cmake --preset asan ${CI:+-DHALFBACK_WERROR=ON}
cmake --build --preset asan
ctest --preset asan

if [ -f fuzz/run.sh ]; then
  bash fuzz/run.sh
fi
