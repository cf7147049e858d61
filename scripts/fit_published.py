#!/usr/bin/python3
"""Every published fit set against halfback's fit of the same model under the same published
measure (docs/fit.md, "Beating the published fits").

For every BBM .fit file in FITS (Ngan et al. 2005, Löw et al. 2012, Bagher et al. 2012) and every
material whose neural BRDF is in NBRDF (NAME.h5): the published parameters' loss, and halfback's
fit's, both under the set's published loss (bbm-ngan for Ngan's sets, bbm-low-e1 / bbm-low-e2 for
Löw's E1 / E2 sets; Bagher et al.'s loss is not in BBM: its set is measured with bbm-low-e2) on
BBM's grid. halfback's fit runs from the published parameters (clamped to the registry's bounds)
and, with --starts both, also from the registry's defaults. Bagher's dependent K, Λ, c, k, θ0 are held at their
published values.

Writes OUT/fit-published.csv (a row per set and material) and OUT/fit-published.md (the table).
"""

import argparse
import concurrent.futures
import csv
import pathlib
import re
import statistics
import sys
import time

import halfback

TIE = 1e-9  # relative slack: the same loss on the same grid
BAGHER_DEPENDENT = ("kscale", "lambda", "c", "k", "theta0")


def loss_of_set(name):
    if name.startswith("ngan_"):
        return "bbm-ngan"
    if name.endswith("_E1.fit"):
        return "bbm-low-e1"
    return "bbm-low-e2"  # Löw's E2 sets; Bagher's (no loss of its own in BBM)


def terms_of(spec):
    """The terms of a sum ('+' before a lower-case letter, as the loader: not an exponent's)."""
    return re.split(r"\+(?=[a-z])", spec)


def split_dependent(spec):
    """(model with Bagher's dependent parameters held at their values, start without them)."""
    terms = terms_of(spec)
    model, start = [], []
    for t in terms:
        name, _, params = t.partition(":")
        kv = [p for p in params.split(",") if p]
        held = [p for p in kv if re.sub(r"_[rgb]$", "", p.split("=")[0]) in BAGHER_DEPENDENT]
        free = [p for p in kv if p not in held]
        model.append(name + (":" + ",".join(held) if held else ""))
        start.append(name + (":" + ",".join(free) if free else ""))
    return "+".join(model), "+".join(start)


def clamp_start(start):
    """The start with each value clamped into the registry's range of its parameter."""
    out = []
    for t in terms_of(start):
        name, _, params = t.partition(":")
        info = {p["name"]: p for p in halfback.models()[name]["params"]} if params else {}
        kv = []
        for p in params.split(",") if params else []:
            k, v = p.split("=")
            lo, hi = info[k]["min"], info[k]["max"]
            kv.append(f"{k}={min(max(float(v), lo), hi)!r}")
        out.append(name + (":" + ",".join(kv) if kv else ""))
    return "+".join(out)


def one(target_path, fit_file, entry, loss, from_defaults, max_iterations):
    target = halfback.load(str(target_path))
    published = halfback.fit_loss(target, entry["spec"], loss, 1, threads=1)
    model, start = split_dependent(entry["spec"])
    starts = [clamp_start(start)]
    if from_defaults:
        starts.append("+".join(t.split(":")[0] for t in terms_of(model)))
    ours = halfback.fit(target, model, loss, 1, threads=1, starts=starts,
                        max_iterations=max_iterations)
    return {
        "set": fit_file,
        "material": entry["material"],
        "loss": loss,
        "published_loss": published,
        "halfback_loss": ours["loss_value"],
        "seconds": ours["seconds"],
        "iterations": ours["iterations"],
        "halfback_spec": ours["spec"],
        "published_spec": entry["spec"],
    }


def tasks(fits_dir, nbrdf_dir, only, limit):
    for path in sorted(pathlib.Path(fits_dir).glob("*.fit")):
        if only and path.stem not in only:
            continue
        entries = [e for e in halfback.published_fits(path)
                   if (pathlib.Path(nbrdf_dir) / f"{e['material']}.h5").exists()]
        for e in entries[:limit]:
            yield pathlib.Path(nbrdf_dir) / f"{e['material']}.h5", path.name, e


def summary(rows):
    lines = ["| set | loss | materials | median loss, published | median loss, halfback "
             "| halfback ≤ published | worst ratio halfback/published |",
             "|---|---|---|---|---|---|---|"]
    for s in sorted({r["set"] for r in rows}):
        rs = [r for r in rows if r["set"] == s]
        wins = sum(r["halfback_loss"] <= r["published_loss"] * (1 + TIE) for r in rs)
        worst = max(rs, key=lambda r: r["halfback_loss"] / r["published_loss"])
        lines.append(
            f"| {s} | {rs[0]['loss']} | {len(rs)} | {statistics.median(r['published_loss'] for r in rs):.4g} "
            f"| {statistics.median(r['halfback_loss'] for r in rs):.4g} | {wins} ({100 * wins / len(rs):.0f} %) "
            f"| {worst['halfback_loss'] / worst['published_loss']:.4f} ({worst['material']}) |")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fits", required=True)
    ap.add_argument("--nbrdf", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--workers", type=int, default=2, help="fits at once (each on one thread)")
    ap.add_argument("--sets", default="", help="comma-separated file stems (e.g. low_cooktorrance_E2)")
    ap.add_argument("--materials", type=int, default=10**9, help="at most this many per set")
    ap.add_argument("--max-iterations", type=int, default=30,
                    help="of each Levenberg-Marquardt run (from the published start the loss only "
                         "falls, so a cap costs accuracy, never the comparison)")
    ap.add_argument("--starts", choices=("published", "both"), default="published",
                    help="the published parameters alone, or also the registry's defaults")
    ap.add_argument("--table-of", default="",
                    help="only write the table of this CSV (e.g. the partial one of a stopped run)")
    ap.add_argument("--no-shortcuts", action="store_true",
                    help="the fitter without its shortcuts (the baseline of docs/fit.md, "
                         "\"What a fit costs\")")
    a = ap.parse_args()
    if a.no_shortcuts:
        halfback._core._set_fit_shortcuts(False)
    if a.table_of:
        rows = list(csv.DictReader(open(a.table_of, encoding="utf-8")))
        for r in rows:
            r["published_loss"], r["halfback_loss"] = float(r["published_loss"]), float(r["halfback_loss"])
        print(summary(rows), end="")
        return
    only = {s for s in a.sets.split(",") if s}
    todo = list(tasks(a.fits, a.nbrdf, only, a.materials))
    # Round robin over the sets (the k-th material of every set before the (k+1)-th): a run
    # stopped early has covered every set alike.
    rank = {}
    for i, (_, f, _) in enumerate(todo):
        rank[i] = sum(1 for _, g, _ in todo[:i] if g == f)
    todo = [t for _, t in sorted(enumerate(todo), key=lambda it: (rank[it[0]], it[1][1]))]
    if not todo:
        sys.exit(f"fit_published.py: no material of {a.fits} has a network in {a.nbrdf}")
    t0, c0 = time.monotonic(), time.process_time()
    rows = []
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    partial = out / "fit-published.partial.csv"  # each row as it comes: a stopped run keeps them
    with concurrent.futures.ThreadPoolExecutor(a.workers) as pool, \
            open(partial, "w", newline="", encoding="utf-8") as pf:  # fit releases the GIL
        futures = [pool.submit(one, p, f, e, loss_of_set(f), a.starts == "both",
                               a.max_iterations) for p, f, e in todo]
        pw = None
        for k, fut in enumerate(concurrent.futures.as_completed(futures), 1):
            rows.append(fut.result())
            if pw is None:
                pw = csv.DictWriter(pf, fieldnames=list(rows[0]))
                pw.writeheader()
            pw.writerow(rows[-1])
            pf.flush()
            print(f"\r{k}/{len(futures)} fits, {time.monotonic() - t0:.0f} s", end="", file=sys.stderr)
    print(file=sys.stderr)
    rows.sort(key=lambda r: (r["set"], r["material"]))
    with open(out / "fit-published.csv", "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    partial.unlink()
    table = summary(rows)
    (out / "fit-published.md").write_text(
        f"{len(rows)} fits in {time.monotonic() - t0:.0f} s wall, {time.process_time() - c0:.0f} s "
        f"CPU ({a.workers} at once), BBM's default "
        f"grids (docs/fit.md), starts: {a.starts}, at most {a.max_iterations} iterations a run.\n\n" + table, encoding="utf-8")
    print(table, end="")


if __name__ == "__main__":
    main()
