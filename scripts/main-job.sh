#!/usr/bin/env bash
# The main job, on data embedded in the project (no file needed): the paper's Figures 1-5 with
# `halfback figure paper` (three measured RGL materials are compiled into the library), and the
# example direction pairs of examples/pairs.csv converted to every parameterization and back.
# Prints where the results are.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/release/src/cli/halfback
out=out/main-job
mkdir -p "$out"

"$bin" figure paper --out "$out/figures"

for p in spherical halfdiff ortho hybrid; do
  "$bin" convert --from dirs --to "$p" --jacobian -i examples/pairs.csv -o "$out/pairs.$p.csv"
  "$bin" convert --from "$p" --to dirs -i <(cut -d, -f1-4 "$out/pairs.$p.csv") -o "$out/pairs.$p.back.csv"
done
echo
echo "hybrid coordinates of examples/pairs.csv ($out/pairs.hybrid.csv):"
column -s, -t < "$out/pairs.hybrid.csv" | head -6
echo
echo "halfback: main job done. Figures 1-5 (PNG, SVG, PDF) in $out/figures/, conversions in $out/."
