#!/usr/bin/env bash
# The main job on embedded data: converts the example direction pairs to every parameterization
# and back, printing where the results are.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/release/src/cli/halfback
out=out/main-job
mkdir -p "$out"
for p in spherical halfdiff ortho hybrid; do
  "$bin" convert --from dirs --to "$p" --jacobian -i examples/pairs.csv -o "$out/pairs.$p.csv"
  "$bin" convert --from "$p" --to dirs -i <(cut -d, -f1-4 "$out/pairs.$p.csv") -o "$out/pairs.$p.back.csv"
done
echo "halfback: main job done; results in $out/:"
ls "$out"
echo
echo "hybrid coordinates of examples/pairs.csv:"
column -s, -t < "$out/pairs.hybrid.csv" | head -12
