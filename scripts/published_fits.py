#!/usr/bin/python3
"""halfback's fits beside the published ones (docs/fit.md, "Against the published fits").

For every material of every BBM .fit file (Ngan et al. 2005's parameters of the MERL materials)
whose neural BRDF is in NBRDF_DIR (NAME.h5): the loss of the published parameters, and the loss
of halfback's own fit of the same model (Lambert + the lobe, its automatic starts only: the
published parameters are not a start), both under the same loss on the same layout of samples.

Writes OUT/published-fits.csv (a row per material and model) and OUT/published-fits.md (the
table of docs/fit.md). Runs on Debian's /usr/bin/python3 with the module built:

  PYTHONPATH=build/release/python /usr/bin/python3 scripts/published_fits.py \\
      --fits ../shared/data/fits --nbrdf ../shared/data/nbrdf/merl_nbrdf --out docs/fit-data
"""

import argparse
import concurrent.futures
import csv
import pathlib
import statistics
import sys
import time

import halfback

# Relative slack when comparing two losses computed on the same samples: a tie is a tie.
TIE = 1e-9


def one(target_path, entry, loss, samples):
    """The published loss and halfback's fit of one material and model."""
    target = halfback.load(str(target_path))
    published = halfback.fit_loss(target, entry["spec"], loss, samples, threads=1)
    ours = halfback.fit(target, entry["model"], loss, samples, threads=1)
    return {
        "material": entry["material"],
        "model": entry["model"],
        "loss": loss,
        "samples": samples,
        "published_loss": published,
        "halfback_loss": ours["loss_value"],
        "halfback_spec": ours["spec"],
        "published_spec": entry["spec"],
        "seconds": ours["seconds"],
    }


def tasks(fits_dir, nbrdf_dir, only, limit):
    for path in sorted(pathlib.Path(fits_dir).glob("*.fit")):
        try:
            entries = halfback.published_fits(path)
        except (ValueError, RuntimeError) as e:  # a model or a syntax halfback does not read
            print(f"published_fits.py: {path.name} left out: {e}", file=sys.stderr)
            continue
        if only and entries and entries[0]["model"].split("+")[-1] not in only:
            continue
        kept = [e for e in entries if (pathlib.Path(nbrdf_dir) / f"{e['material']}.h5").exists()]
        for e in kept[:limit]:
            yield pathlib.Path(nbrdf_dir) / f"{e['material']}.h5", e


def summary(rows):
    lines = [
        "| model | materials | median loss, published | median loss, halfback | halfback ≤ published |",
        "|---|---|---|---|---|",
    ]
    for model in sorted({r["model"] for r in rows}):
        rs = [r for r in rows if r["model"] == model]
        wins = sum(r["halfback_loss"] <= r["published_loss"] * (1 + TIE) for r in rs)
        lines.append(
            f"| {model} | {len(rs)} | {statistics.median(r['published_loss'] for r in rs):.4g} "
            f"| {statistics.median(r['halfback_loss'] for r in rs):.4g} "
            f"| {wins} ({100 * wins / len(rs):.0f} %) |"
        )
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fits", required=True, help="folder of BBM .fit files")
    ap.add_argument("--nbrdf", required=True, help="folder of the MERL neural BRDFs (NAME.h5)")
    ap.add_argument("--out", required=True, help="folder for published-fits.csv and .md")
    ap.add_argument("--loss", default="ngan")
    ap.add_argument("--samples", type=int, default=20000)
    ap.add_argument("--workers", type=int, default=2, help="fits at once (each on one thread)")
    ap.add_argument("--models", default="", help="comma-separated lobes (e.g. ward,lafortune)")
    ap.add_argument("--materials", type=int, default=10**9, help="at most this many per model")
    a = ap.parse_args()
    only = {m for m in a.models.split(",") if m}
    todo = list(tasks(a.fits, a.nbrdf, only, a.materials))
    if not todo:
        sys.exit(f"published_fits.py: no material of {a.fits} has a network in {a.nbrdf}")
    t0 = time.monotonic()
    rows = []
    with concurrent.futures.ThreadPoolExecutor(a.workers) as pool:  # fit releases the GIL
        futures = [pool.submit(one, path, e, a.loss, a.samples) for path, e in todo]
        for k, f in enumerate(concurrent.futures.as_completed(futures), 1):
            rows.append(f.result())
            print(f"\r{k}/{len(futures)} fits, {time.monotonic() - t0:.0f} s", end="", file=sys.stderr)
    print(file=sys.stderr)
    rows.sort(key=lambda r: (r["model"], r["material"]))
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "published-fits.csv", "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    table = summary(rows)
    (out / "published-fits.md").write_text(
        f"Loss {a.loss}, {a.samples} samples, {len(rows)} fits in {time.monotonic() - t0:.0f} s "
        f"({a.workers} at once).\n\n" + table, encoding="utf-8")
    print(table, end="")


if __name__ == "__main__":
    main()
