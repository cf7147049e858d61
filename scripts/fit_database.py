#!/usr/bin/python3
"""Fits every neural BRDF of one or more folders with each of several models (the
whole-database fit; docs/fit.md, "The whole database").

For every NAME.h5 under each --nbrdf folder and every model of --models (default: Lambert plus
each of Ngan et al.'s seven lobes), halfback.fit under one loss; each fit runs on one thread,
--workers at once. Writes OUT/fits.csv (a row per material and model: folder, material, model,
loss, loss value, seconds, iterations, spec) and prints the wall time and the median loss per
model. Runs on Debian's /usr/bin/python3 with the module built:

  PYTHONPATH=build/release/python /usr/bin/python3 scripts/fit_database.py \\
      --nbrdf ../shared/data/nbrdf/merl_nbrdf ../shared/data/nbrdf/rgl-isotropic_nbrdf \\
      --out /tmp/fits
"""

import argparse
import concurrent.futures
import csv
import pathlib
import statistics
import sys
import time

import halfback

NGAN_MODELS = ["lambert+" + lobe for lobe in
               ("ward", "ward-duer", "blinn-phong", "lafortune", "cook-torrance",
                "ashikhmin-shirley", "he")]


def one(path, model, loss, samples):
    r = halfback.fit(str(path), model, loss, samples, threads=1, energy=False)  # not reported
    return {
        "folder": path.parent.name,
        "material": path.stem,
        "model": model,
        "loss": loss,
        "loss_value": r["loss_value"],
        "seconds": r["seconds"],
        "iterations": r["iterations"],
        "spec": r["spec"],
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--nbrdf", nargs="+", required=True, help="folders of neural BRDFs (NAME.h5)")
    ap.add_argument("--out", required=True, help="folder for fits.csv")
    ap.add_argument("--models", default=",".join(NGAN_MODELS), help="comma-separated models")
    ap.add_argument("--loss", default="ngan")
    ap.add_argument("--samples", type=int, default=20000)
    ap.add_argument("--workers", type=int, default=2, help="fits at once (each on one thread)")
    ap.add_argument("--per-folder", type=int, default=0,
                    help="only the first N networks of each folder (0: all; a subset to time)")
    ap.add_argument("--no-shortcuts", action="store_true",
                    help="the fitter without its shortcuts (the baseline of docs/fit.md, "
                         "\"What a fit costs\")")
    a = ap.parse_args()
    if a.no_shortcuts:
        halfback._core._set_fit_shortcuts(False)
    models = [m for m in a.models.split(",") if m]
    known = set(halfback.models())
    for m in models:
        for term in m.split("+"):
            if term.split(":")[0] not in known:
                sys.exit(f"fit_database.py: --models: '{term}' is not a model of halfback")
    paths = []
    for d in a.nbrdf:
        found = sorted(pathlib.Path(d).glob("*.h5"))
        paths += found[:a.per_folder] if a.per_folder > 0 else found
    if not paths:
        sys.exit(f"fit_database.py: no NAME.h5 in {' '.join(a.nbrdf)}")
    t0, c0 = time.monotonic(), time.process_time()
    rows = []
    with concurrent.futures.ThreadPoolExecutor(a.workers) as pool:  # fit releases the GIL
        futures = [pool.submit(one, p, m, a.loss, a.samples) for p in paths for m in models]
        for k, f in enumerate(concurrent.futures.as_completed(futures), 1):
            rows.append(f.result())
            print(f"\r{k}/{len(futures)} fits, {time.monotonic() - t0:.0f} s", end="", file=sys.stderr)
    wall, cpu = time.monotonic() - t0, time.process_time() - c0
    print(file=sys.stderr)
    rows.sort(key=lambda r: (r["folder"], r["material"], r["model"]))
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "fits.csv", "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"{len(rows)} fits of {len(paths)} BRDFs in {wall:.0f} s wall, {cpu:.0f} s CPU "
          f"({a.workers} at once), loss {a.loss}, {a.samples} samples")
    print("| model | median loss | median seconds |")
    print("|---|---|---|")
    for m in models:
        rs = [r for r in rows if r["model"] == m]
        print(f"| {m} | {statistics.median(r['loss_value'] for r in rs):.4g} "
              f"| {statistics.median(r['seconds'] for r in rs):.2f} |")


if __name__ == "__main__":
    main()
