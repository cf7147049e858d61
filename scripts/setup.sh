#!/usr/bin/env bash
# Quickstart step 1: install halfback's dependencies (Debian 12, as root or with sudo), build it,
# and run the main job on the data embedded in the project.
set -euo pipefail
cd "$(dirname "$0")/.."
# ccache (when installed): paths relative to the tree, so that another clone hits the same cache.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1
export CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime

packages=$(grep -v '^\s*#' scripts/debian-packages.txt | tr '\n' ' ')
if command -v apt-get >/dev/null; then
  sudo=""
  [ "$(id -u)" = 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends $packages
else
  echo "setup: apt-get not found; install these packages yourself: $packages" >&2
fi

cmake --preset release ${CI:+-DHALFBACK_WERROR=ON}
cmake --build --preset release

bash scripts/main-job.sh
