#!/usr/bin/env bash
# Builds the file-format fuzzers (clang, libFuzzer + ASan + UBSan) and runs each for a bounded time.
#   FUZZ_SECONDS   seconds per fuzzer (default 30)
#   FUZZ_BUILD_DIR build directory (default build/fuzz)
# Crashes, leaks and timeouts make the script fail; reproducers are left in the build directory.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds="${FUZZ_SECONDS:-30}"
build="${FUZZ_BUILD_DIR:-build/fuzz}"
jobs="$(nproc 2>/dev/null || echo 2)"

cmake --preset fuzz -B "$build" >/dev/null
cmake --build "$build" -j "$jobs" --target merl_fuzz rgl_fuzz alta_fuzz npy_fuzz make_fuzz_seeds

corpus="$build/corpus"
mkdir -p "$corpus"
"$build/fuzz/make_fuzz_seeds" "$corpus"
artifacts="$build/artifacts"
mkdir -p "$artifacts"

status=0
for target in merl rgl alta npy; do
  case "$target" in
    merl) max_len=4096 ;;     # full-size files are built inside the target
    rgl)  max_len=65536 ;;
    alta) max_len=65536 ;;
    npy)  max_len=4096 ;;
  esac
  echo "== ${target}_fuzz: ${seconds}s"
  if ! "$build/fuzz/${target}_fuzz" "$corpus/$target" -max_total_time="$seconds" \
      -max_len="$max_len" -timeout=20 -rss_limit_mb=2560 -print_final_stats=1 \
      -artifact_prefix="$artifacts/${target}-" 2>"$build/${target}_fuzz.log"; then
    echo "${target}_fuzz FAILED; see $build/${target}_fuzz.log and $artifacts/" >&2
    tail -40 "$build/${target}_fuzz.log" >&2
    status=1
  else
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$build/${target}_fuzz.log" || true
  fi
done
exit "$status"
