#!/bin/bash
# Every published fit set (../shared/data/fits) against halfback's fit of the same model under the
# same published loss, on the MERL neural BRDFs; writes docs/fit-data/fit-published.{csv,md}
# (docs/fit.md, "Beating the published fits"). Needs the Python module built
# (build/release/python). Extra arguments go to scripts/fit_published.py (e.g. --sets
# low_cooktorrance_E2 --materials 3 for a subset).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
shared=${HALFBACK_SHARED_DIR:-$root/../shared}
PYTHONPATH="$root/build/release/python" exec nice /usr/bin/python3 "$root/scripts/fit_published.py" \
  --fits "$shared/data/fits" --nbrdf "$shared/data/nbrdf/merl_nbrdf" \
  --out "$root/docs/fit-data" --workers 2 "$@"
