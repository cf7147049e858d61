#!/bin/bash
# Every number and figure of docs/answers.md ("which parameterization for what"), from a built tree:
#
#   scripts/answers.sh [--quick] [--out DIR] [--update-docs]
#
# The whole run (default) studies the whole shared data (../shared/data: the 100 MERL and 51 RGL
# neural BRDFs, the 12 RGL files, the 2 ALTA files, and the model panel of docs/study.md) in one
# `halfback study` with every metric (the gonio-reflectometer in every design, the sequential
# design and Nielsen et al.'s minimal sampling among them; images under five environments;
# sampling; fitting), Dupuy & Jakob's own layout beside it, and the factored models of 14 MERL
# networks (scripts/factor_study.py); then scripts/answers.py turns their CSV files into the
# page's tables and figures. It is long (estimated at about two hours on 2 cores from the times of
# its parts, docs/answers.md) and resumable: run the same command again after an interruption and
# the studies continue where they stopped (`halfback study --resume`).
#
# --quick: the same steps on 8 BRDFs with the study's --quick settings (about two minutes on 2
# cores): a check that the pipeline works, not numbers to quote.
# --update-docs: write the figures to docs/answers-data/ and the tables into docs/answers.md
# (only from a whole run; a quick run's numbers never go into the docs).
#
# Dask: the study is the long part and already uses both cores of one machine (a task per
# parameterization, the renderings in parallel); on several machines, run it with Dask as
# docs/study.md ("Scaling out") shows and give its output directory to scripts/answers.py.
set -euo pipefail
cd "$(dirname "$0")/.."
quick=0 update=0 out=""
while [ $# -gt 0 ]; do
  case $1 in
    --quick) quick=1 ;;
    --update-docs) update=1 ;;
    --out) out=$2; shift ;;
    -h|--help) sed -n '2,23p' "$0"; exit 0 ;;
    *) echo "answers.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done
if [ $quick = 1 ] && [ $update = 1 ]; then
  echo "answers.sh: --update-docs takes a whole run's numbers, not --quick's" >&2
  exit 2
fi
[ -n "$out" ] || out=$([ $quick = 1 ] && echo out/answers-quick || echo out/answers)
halfback=build/release/src/cli/halfback
data=${HALFBACK_SHARED_DIR:-../shared}/data
for need in "$halfback" build/release/python "$data/nbrdf/merl_nbrdf" "$data/rgl"; do
  [ -e "$need" ] || { echo "answers.sh: $need is missing (build the tree; the shared data)" >&2; exit 2; }
done
python=/usr/bin/python3
export PYTHONPATH=$PWD/build/release/python${PYTHONPATH:+:$PYTHONPATH}
mkdir -p "$out"
start=$(date +%s)
say() { echo "answers.sh: [$(( $(date +%s) - start )) s] $*" >&2; }

# A study into $1 with the remaining arguments; resumed when an earlier run left its parts there.
study() {
  local dir=$1; shift
  local resume=()
  [ -f "$dir/parts/settings.txt" ] && resume=(--resume)
  "$halfback" study -q -o "$dir" "${resume[@]}" "$@"
}

models=(ggx:alpha=0.05,f0=0.9 ggx:alpha=0.3,f0=0.9 "ggx:alpha_x=0.1,alpha_y=0.4,f0=0.9"
        "beckmann:alpha_x=0.3,alpha_y=0.08,f0=0.9" beckmann:alpha=0.2,f0=0.9 abc lambert
        "lambert:albedo=0.3+sheen:alpha=0.4,color=0.6" test:S test:G test:F)
merl14=(aluminium brass chrome nickel gold-metallic-paint3 blue-metallic-paint gray-plastic
        green-acrylic black-phenolic delrin blue-fabric light-brown-fabric colonial-maple-223
        white-paint)
if [ $quick = 1 ]; then
  files=("$data/rgl/cardboard_rgb.bsdf" "$data/rgl/ilm_l3_37_metallic_rgb.bsdf"
         "$data/nbrdf/merl_nbrdf/gold-metallic-paint3.h5" "$data/nbrdf/merl_nbrdf/pink-felt.h5"
         "$data/nbrdf/merl_nbrdf/colonial-maple-223.h5")
  brdfs=("${files[@]}" ggx:alpha=0.2 beckmann:alpha=0.2,f0=0.9 lambert)
  nielsen=()
  for m in nickel delrin blue-fabric white-paint brass; do
    nielsen+=("--nielsen-database=$data/nbrdf/merl_nbrdf/$m.h5")
  done
  settings=(--quick --env sky --image-size 32 --image-spp 4)
  dj_brdfs=("${files[@]}")
  factored=("${files[@]:2:3}")
  factor_settings=(--ranks 1,2 --counts 16,16,16 --samples 4000)
else
  folders=("$data/nbrdf/merl_nbrdf" "$data/nbrdf/rgl-isotropic_nbrdf" "$data/rgl")
  brdfs=("${folders[@]}" "$data/alta" "${models[@]}")
  nielsen=("--nielsen-database=$data/nbrdf/merl_nbrdf")
  settings=(--env "sky,studio,sunset,$data/envmaps/uffizi.hdr,$data/envmaps/grace.hdr")
  dj_brdfs=("${folders[@]}")
  factored=()
  for m in "${merl14[@]}"; do factored+=("$data/nbrdf/merl_nbrdf/$m.h5"); done
  factor_settings=(--ranks 1,2,4,8)
fi

say "the study (every metric) of ${#brdfs[@]} BRDF specs into $out/study"
study "$out/study" "${settings[@]}" "${nielsen[@]}" -- "${brdfs[@]}"
say "Dupuy & Jakob's layout into $out/dupuy-jakob"
dj_quick=()
[ $quick = 1 ] && dj_quick=(--quick)
study "$out/dupuy-jakob" "${dj_quick[@]}" --params halfdiff,dupuy-jakob:per-material --designs own \
  --no-images --no-sampling --no-fit --budgets 1000,10000,100000 "${dj_brdfs[@]}"
say "factored models of ${#factored[@]} BRDFs into $out/factored"
$python scripts/factor_study.py --out "$out/factored" "${factor_settings[@]}" "${factored[@]}" >/dev/null
say "the tables and figures"
page=()
figures=$out/answers
if [ $update = 1 ]; then
  figures=docs/answers-data
  page=(--page docs/answers.md)
fi
$python scripts/answers.py --out "$figures" "${page[@]}" --factored "$out/factored/factored.csv" \
  "$out/study" "$out/dupuy-jakob"
say "done: $figures/answers.md"
