#!/usr/bin/env bash
# Quickstart step 2: the full test suite. Release build + tests, then the same tests under
# AddressSanitizer + UndefinedBehaviorSanitizer, then the file-format fuzzers for a bounded time.
set -euo pipefail
cd "$(dirname "$0")/.."

cmake --preset release
cmake --build --preset release
ctest --preset release

cmake --preset asan
cmake --build --preset asan
ctest --preset asan

if [ -f fuzz/run.sh ]; then
  bash fuzz/run.sh
fi
