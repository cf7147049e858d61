#!/usr/bin/python3
"""Factored models against analytic fits, per parameterization (docs/fit.md, "Factored models"):
which parameterization gives the smallest data-driven model for a given error?

For every BRDF given, every parameterization of --params and every rank of --ranks: the factored
model (halfback.factor, --counts cells) and its loss under --loss on fit()'s layout
(halfback.fit_loss), beside the loss of halfback's fit of --model (default lambert+ggx). Writes
OUT/factored.csv (a row per BRDF, parameterization and rank) and OUT/factored.md (per
parameterization: the median loss at each rank over the BRDFs, and on how many BRDFs it is the
smallest model that reaches the analytic fit's loss), and each model's image-space error under
--env with the study's image protocol (halfback.image_error: relative RMSE and mean ΔE2000 of the
rendered sphere against the BRDF's own). Runs on Debian's /usr/bin/python3:

  PYTHONPATH=build/release/python /usr/bin/python3 scripts/factor_study.py --out OUT BRDF...
"""

import argparse
import csv
import pathlib
import statistics
import sys
import tempfile
import time

import halfback


def factored_loss(brdf, param, rank, counts, loss, samples, env, tmp):
    """The factored model's size, its grid error, its loss and its image-space error."""
    r = halfback.factor(brdf, param, rank, counts)
    path = pathlib.Path(tmp) / "f.json"
    path.write_text(r["text"], encoding="utf-8")
    image = halfback.image_error(str(path), brdf, env)
    return (r["numbers"], r["relative_error"], halfback.fit_loss(brdf, str(path), loss, samples),
            image)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("brdfs", nargs="+", help="BRDF specs (files, embedded:NAME, models)")
    ap.add_argument("--out", required=True)
    ap.add_argument("--params", default="halfdiff,ortho,hybrid,rectified-hybrid,spherical")
    ap.add_argument("--ranks", default="1,2,4")
    ap.add_argument("--counts", default="32,32,32")
    ap.add_argument("--model", default="lambert+ggx")
    ap.add_argument("--loss", default="ngan")
    ap.add_argument("--samples", type=int, default=20000)
    ap.add_argument("--env", default="sky", help="environment of the image-space error")
    a = ap.parse_args()
    params = a.params.split(",")
    ranks = [int(r) for r in a.ranks.split(",")]
    counts = tuple(int(c) for c in a.counts.split(","))
    if len(counts) != 3:
        sys.exit("factor_study.py: --counts: expected three cell counts")
    rows, t0 = [], time.monotonic()
    with tempfile.TemporaryDirectory() as tmp:
        for k, spec in enumerate(a.brdfs, 1):
            brdf = halfback.load(spec)
            fitted = halfback.fit(brdf, a.model, a.loss, a.samples)
            n_fit = sum(p["fitted"] for p in fitted["parameters"])
            fit_image = halfback.image_error(fitted["spec"], brdf, a.env)
            for param in params:
                for rank in ranks:
                    numbers, grid_error, value, image = factored_loss(
                        brdf, param, rank, counts, a.loss, a.samples, a.env, tmp)
                    rows.append({"brdf": spec, "parameterization": param, "rank": rank,
                                 "numbers": numbers, "grid_error": grid_error, "loss": value,
                                 "image_relative_rmse": image["relative_rmse"],
                                 "image_delta_e2000": image["mean_delta_e2000"],
                                 "model": a.model,
                                 "model_numbers": n_fit, "model_loss": fitted["loss_value"],
                                 "model_image_relative_rmse": fit_image["relative_rmse"],
                                 "model_image_delta_e2000": fit_image["mean_delta_e2000"]})
            print(f"\r{k}/{len(a.brdfs)} BRDFs, {time.monotonic() - t0:.0f} s", end="",
                  file=sys.stderr)
    print(file=sys.stderr)
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "factored.csv", "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    md = [f"{len(a.brdfs)} BRDFs, loss {a.loss}, {a.samples} samples, {counts} cells, "
          f"{time.monotonic() - t0:.0f} s.", "",
          "| parameterization | " + " | ".join(f"median loss, rank {r}" for r in ranks)
          + f" | smallest to reach {a.model}'s loss (BRDFs) |",
          "|---|" + "---|" * (len(ranks) + 1)]
    wins = {p: 0 for p in params}
    for spec in a.brdfs:
        reach = [r for r in rows if r["brdf"] == spec and r["loss"] <= r["model_loss"]]
        if reach:
            best = min(r["numbers"] for r in reach)
            for p in {r["parameterization"] for r in reach if r["numbers"] == best}:
                wins[p] += 1
    for p in params:
        med = [statistics.median(r["loss"] for r in rows
                                 if r["parameterization"] == p and r["rank"] == rank)
               for rank in ranks]
        md.append(f"| {p} | " + " | ".join(f"{m:.4g}" for m in med) + f" | {wins[p]} |")
    model_loss = statistics.median({r["brdf"]: r["model_loss"] for r in rows}.values())
    md += ["", f"Median loss of {a.model} ({rows[0]['model_numbers']} numbers): {model_loss:.4g}.",
           "Numbers per factored model: 3 · rank · (sum of the counts).", "",
           f"Image-space error under {a.env} (the study's protocol): median relative RMSE / mean "
           "ΔE2000 of the sphere over the BRDFs.", "",
           "| parameterization | " + " | ".join(f"rank {r}" for r in ranks) + " |",
           "|---|" + "---|" * len(ranks)]
    for p in params:
        cells = []
        for rank in ranks:
            sel = [r for r in rows if r["parameterization"] == p and r["rank"] == rank]
            cells.append(f"{statistics.median(r['image_relative_rmse'] for r in sel):.3g} / "
                         f"{statistics.median(r['image_delta_e2000'] for r in sel):.3g}")
        md.append(f"| {p} | " + " | ".join(cells) + " |")
    per_brdf = {r["brdf"]: r for r in rows}.values()
    md += ["", f"{a.model}: "
           f"{statistics.median(r['model_image_relative_rmse'] for r in per_brdf):.3g} / "
           f"{statistics.median(r['model_image_delta_e2000'] for r in per_brdf):.3g}."]
    (out / "factored.md").write_text("\n".join(md) + "\n", encoding="utf-8")
    print("\n".join(md))


if __name__ == "__main__":
    main()
