#!/bin/bash
# The fixed quick studies that show a change of the study's code leaves its outputs as they were:
# three BRDFs (an anisotropic one among them), three parameterizations, every metric, a fixed
# seed; once with every metric (OUT/full), once without the sampling metric, whose timings vary
# from run to run (OUT/nosamp). Compare two such directories with compare_study_runs.py:
#   scripts/quick_study_runs.sh OLD_HALFBACK /tmp/before
#   scripts/quick_study_runs.sh build/release/src/cli/halfback /tmp/after
#   scripts/compare_study_runs.py /tmp/before/full /tmp/after/full
#   scripts/compare_study_runs.py /tmp/before/nosamp /tmp/after/nosamp
set -euo pipefail
if [ $# -ne 2 ]; then
  echo "usage: $0 HALFBACK OUT_DIR" >&2
  exit 2
fi
halfback=$1 out=$2
quick=(--quick -q --seed 7 --params halfdiff,hybrid,spherical --env sky --image-size 32
       --image-spp 4)
brdfs=(ggx:alpha=0.2 lambert beckmann:alpha_x=0.1,alpha_y=0.3)
"$halfback" study "${quick[@]}" --out "$out/full" "${brdfs[@]}"
"$halfback" study "${quick[@]}" --no-sampling --out "$out/nosamp" "${brdfs[@]}"
