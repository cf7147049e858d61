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
cmake --build "$build" -j "$jobs" --target merl_fuzz rgl_fuzz alta_fuzz npy_fuzz h5_fuzz factored_fuzz envmap_fuzz \
  view_fuzz view_wire_fuzz plan_fuzz make_fuzz_seeds make_plan_seeds

corpus="$build/corpus"
mkdir -p "$corpus"
"$build/fuzz/make_fuzz_seeds" "$corpus"
# Keras .h5 seeds: the embedded networks, each also with trailing data and extended by zeros.
mkdir -p "$corpus/h5"
for h5 in data/nbrdf/*.h5; do
  name="$(basename "$h5" .h5)"
  cp "$h5" "$corpus/h5/$name.h5"
  { cat "$h5"; printf 'junk'; } > "$corpus/h5/$name-trailing.h5"
  cp "$h5" "$corpus/h5/$name-zeros.h5"
  truncate -s +2048 "$corpus/h5/$name-zeros.h5"
done
# Seeds of the view's request handler: one request per file (fuzz/view_fuzz.cpp).
mkdir -p "$corpus/view"
k=0
for seed in "/api/info?token=t" "/?token=t" "/static/app.js?token=t" \
    "/api/slices?token=t&brdf=arg:0&forms=halfdiff&azimuth=30&n=16" \
    "/api/slices?token=t&brdf=arg:0&brdf=arg:1&azimuth=-20&n=8" \
    "/api/slices?token=t&brdf=lambert&forms=hybrid,spherical,ortho&n=4" \
    "/api/hemisphere?token=t&brdf=arg:1&colour=rho&theta_o=40&phi_o=180&n=8" \
    "/api/hemisphere?token=t&colour=ortho&n=8" "/api/polar?token=t&brdf=ggx:alpha=0.2&n=19" \
    "/api/point?token=t&brdf=arg:0&wi=0,0,1&wo=0.6,0,0.8" \
    "/api/point?token=t&brdf=lambert&form=hybrid&iso=1&coords=0.2,0.3,1" \
    "/api/brdf?token=t&brdf=file:../x" "/api/render?token=t&brdf=arg:1&pass=3" \
    "/api/albedo?token=t&brdf=arg:0&angles=4&n=8" \
    "/api/fit?token=t&brdf=arg:1&model=lambert%2Bggx:f0=0.9&loss=low-e2&samples=100" \
    "/api/slices?token=t&brdf=arg:0&pose=45&n=4" \
    "/api/brdf?token=t&brdf=lambert:albedo=0.3%2Bggx:alpha=0.1%2Bfile:../x" \
    $'/api/info\ncookie: halfback_token_8765=t\norigin: http://127.0.0.1:8765' \
    $'/api/info?token=t\nHost: 127.0.0.1:8765' \
    $'/api/info?token=t\norigin: http://127.0.0.1:8765\nOrigin: http://localhost:8765' \
    $'/api/info\ncookie: halfback_token_8765=t\nCookie: halfback_token_8765=t' \
    "/api/slices?token=t&brdf=lambert&forms=dupuy-jakob:ggx:alpha=0.2,halfdiff&n=4" \
    "/api/hemisphere?token=t&colour=dupuy-jakob:arg:0&n=4" \
    "/api/point?token=t&brdf=arg:0&form=dupuy-jakob:lambert&iso=1&coords=0.2,0.3,0.5" \
    "/api/slices?token=t&brdf=arg:0&forms=dupuy-jakob:file:../x&n=2" \
    "/api/render?token=t&brdf=arg:0&env=/etc/passwd" \
    "/api/fit?token=t&brdf=arg:1&model=lambert%2Blambert%2Blambert%2Blambert%2Blambert&samples=20000" \
    "/api/fit?token=t&brdf=arg:1&model=ggx+&samples=100" \
    "/api/fit?token=t&brdf=arg:1&model=+ggx+:+alpha+=0.3&samples=100" \
    "/api/slices?token=t&brdf=arg:0&brdf=arg:1&n=512&values=rgb" \
    "/api/mesh?token=t&brdf=arg:0&brdf=arg:1&light=point&theta_l=30&phi_l=45&size=16" \
    "/api/mesh?token=t&brdf=arg:1&mesh=embedded:rounded-cube&light=env&env=studio&size=8&spp=2&pass=3&yaw=-40&pitch=80" \
    "/api/mesh?token=t&brdf=arg:0&mesh=file:../x.obj&size=8" \
    "/api/mesh?token=t&brdf=arg:0&mesh=/etc/passwd&light=env&env=file:../x.hdr" \
    "/api/polar?token=t&brdf=arg:0&brdf=arg:1&brdf=lambert&n=9" \
    "/api/hemisphere?token=t&brdf=arg:0&brdf=arg:1&brdf=ggx&colour=rho&values=luminance&n=8" \
    "/api/pointlight?token=t&brdf=arg:0&brdf=arg:1&size=8&theta_l=20" \
    "/api/albedo?token=t&brdf=arg:0&brdf=arg:1&angles=3&n=2" \
    "/api/polar?token=t&brdf=a&brdf=b&brdf=c&brdf=d&brdf=e&brdf=f&brdf=g&brdf=h&brdf=i"; do
  printf '%s' "$seed" > "$corpus/view/seed$k"
  k=$((k + 1))
done
# Seeds of the view's socket side: a connection's bytes, cut at "~~\n" into pieces sent apart
# (fuzz/view_wire_fuzz.cpp): pipelined, trickled, cut mid-line, repeated Host/Origin, unfinished,
# a fit whose client closes its side at once (the computation's abandonment).
mkdir -p "$corpus/view_wire"
host=$'Host: 127.0.0.1:8765\r\n'
k=0
for seed in $'GET /api/info?token=t HTTP/1.1\r\n'"$host"$'\r\n' \
    $'GET /api/info?token=t HTTP/1.1\r\n'"$host"$'\r\nGET /api/point?token=t&brdf=arg:0&wi=0,0,1&wo=0,0,1 HTTP/1.1\r\n'"$host"$'Connection: close\r\n\r\n' \
    $'GET /api/info?token=t HTTP/1.1\r\n'"$host$host"$'\r\n' \
    $'GET /api/info?token=t HTTP/1.1\r\n'"$host"$'Origin: http://127.0.0.1:8765\r\norigin: http://localhost:8765\r\n\r\n' \
    $'GET /api/info?token=t HTTP/1.1\r\n~~\n'"$host"$'~~\nX-A: b\r\n~~\nX-A: b\r\n~~\n\r\n' \
    $'GE~~\nT /api/slices?token=t&brdf=arg:0&n=8 HTTP/1.1\r\nHo~~\nst: 127.0.0.1:8765\r\n\r~~\n\n' \
    $'GET /api/info?token=t HTTP/1.1\r\n'"$host"$'X-Unfinished: ' \
    $'GET /api/info?token=t HTTP/1.0\r\n'"$host"$'\r\n' \
    $'POST /api/info?token=t HTTP/1.1\r\n'"$host"$'Content-Length: 5\r\n\r\nhello' \
    $'GET /api/info?token=t HTTP/1.1\r\n'"$host"$'Expect: 100-continue\r\nRange: bytes=0-3\r\n\r\n' \
    $'GET /api/fit?token=t&brdf=arg:1&model=ggx&samples=2000 HTTP/1.1\r\n'"$host"$'\r\n'; do
  printf '%s' "$seed" > "$corpus/view_wire/seed$k"
  k=$((k + 1))
done
artifacts="$build/artifacts"
mkdir -p "$artifacts"

status=0
# Seeds of the plans' sidecars: small plans written by the planner itself (the pilots that
# `plan --pilot` reads among them), broken ones, and sidecars above 1 MiB in plan_big.
"$build/fuzz/make_plan_seeds" "$corpus/plan" "$corpus/plan_big"
# The sidecars above 1 MiB, each run once (the fuzzing below cuts its inputs at -max_len).
echo "== plan_fuzz: the sidecars above 1 MiB, once each"
if ! "$build/fuzz/plan_fuzz" "$corpus"/plan_big/*.json 2>"$build/plan_big_fuzz.log"; then
  echo "plan_fuzz FAILED on a sidecar above 1 MiB; see $build/plan_big_fuzz.log" >&2
  tail -40 "$build/plan_big_fuzz.log" >&2
  status=1
fi
for target in merl rgl alta npy h5 factored envmap view view_wire plan; do
  case "$target" in
    merl) max_len=4096 ;;     # full-size files are built inside the target
    rgl)  max_len=65536 ;;
    alta) max_len=65536 ;;
    npy)  max_len=4096 ;;
    h5)   max_len=32768 ;;  # options below
    factored) max_len=16384 ;;
    envmap) max_len=32768 ;;
    view) max_len=2048 ;;
    view_wire) max_len=4096 ;;
    plan) max_len=16384 ;;
  esac
  # HDF5 leaks a few allocations of its own on some corrupt files (the leak's stack is inside
  # libhdf5): those are suppressed, any other leak still fails the run.
  export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp"
  dict=()
  [ -f "fuzz/$target.dict" ] && dict=("-dict=fuzz/$target.dict")
  # libhdf5 allocates a metadata entry's size as read from the file before reading it (H5C_protect):
  # a corrupt header asks for terabytes. In a release build malloc returns null there and HDF5
  # reports a corrupt file (NbrdfH5.AbsurdAddressInTheRootEntryIsAnError); the fuzzer must see the
  # same, so for h5 a failed allocation returns null and the limit is on memory touched
  # (-rss_limit_mb), not reserved.
  asan_options=""
  extra=()
  if [ "$target" = h5 ]; then
    asan_options="allocator_may_return_null=1"
    extra=(-malloc_limit_mb=1048576)
  fi
  echo "== ${target}_fuzz: ${seconds}s"
  if ! ASAN_OPTIONS="$asan_options" "$build/fuzz/${target}_fuzz" "$corpus/$target" "${dict[@]}" \
      "${extra[@]}" -max_total_time="$seconds" -max_len="$max_len" -timeout=20 \
      -rss_limit_mb=2560 -print_final_stats=1 -artifact_prefix="$artifacts/${target}-" 2>"$build/${target}_fuzz.log"; then
    echo "${target}_fuzz FAILED; see $build/${target}_fuzz.log and $artifacts/" >&2
    tail -40 "$build/${target}_fuzz.log" >&2
    status=1
  else
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$build/${target}_fuzz.log" || true
  fi
done
exit "$status"
