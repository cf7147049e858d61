#!/usr/bin/env python3
"""The acquisition strategies of the study's gonio tables by kind of material (docs/study.md,
"Acquisition strategies by kind of material"): median error of each (parameterization, design,
budget) over the BRDFs of each group, the groups by how peaked the BRDF is.

A BRDF's group comes from a sampling table (metric 5): the half-vector table's albedo efficiency
against the cosine at 1 MiB (parameterization halfdiff, tabulated sampler) measures how peaked
ρ cos θi is: broad < 30, intermediate 30-300, peaked > 300.

    /usr/bin/python3 scripts/acquisition_by_kind.py --sampling SAMPLING.csv GONIO.csv [GONIO.csv ...]

Every gonio file's rows are read (the same BRDF in two files: their rows are merged; a row given
twice with different errors is an error). Prints a Markdown table.
"""
import argparse
import csv
import statistics
import sys

GROUPS = [("broad", 0, 30), ("intermediate", 30, 300), ("peaked", 300, float("inf"))]


def groups_of(sampling_path):
    group = {}
    with open(sampling_path, newline="") as f:
        for row in csv.DictReader(f):
            if (row["parameterization"], row["table_kib"], row["sampler"]) != ("halfdiff", "1024", "tabulated"):
                continue
            efficiency = float(row["efficiency_vs_cosine"])
            for name, lo, hi in GROUPS:
                if lo <= efficiency < hi:
                    group[row["brdf"]] = name
    return group


def read_rows(paths):
    errors = {}  # (brdf, parameterization, design, budget) -> (error, samples)
    for path in paths:
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                if row["spacing"] != "own" or row["dims"] != "3":
                    continue
                key = (row["brdf"], row["parameterization"], row["design"], int(row["budget"]))
                value = (float(row["error"]), int(row["samples"]))
                if key in errors and abs(errors[key][0] - value[0]) > 1e-9 * max(1, value[0]):
                    sys.exit(f"{path}: {key} differs from an earlier file's row")
                errors[key] = value
    return errors


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sampling", required=True)
    parser.add_argument("gonio", nargs="+")
    args = parser.parse_args()
    group = groups_of(args.sampling)
    errors = read_rows(args.gonio)
    strategies = sorted({k[1:] for k in errors}, key=lambda s: (s[2], s[0], s[1]))
    names = [g[0] for g in GROUPS]
    counts = {g: sum(1 for b in group.values() if b == g) for g in names}
    print("| strategy | budget | measurements (median) | "
          + " | ".join(f"{g} ({counts[g]})" for g in names) + " | all |")
    print("|---|---|---|" + "---|" * (len(names) + 1))
    for param, design, budget in strategies:
        rows = {b: errors[(b, param, design, budget)] for b in group if (b, param, design, budget) in errors}
        if not rows:
            continue
        cells = []
        for g in names:
            v = [e for b, (e, _) in rows.items() if group[b] == g]
            cells.append(f"{statistics.median(v):.4g}" if v else "–")
        measured = statistics.median(s for _, s in rows.values())
        label = f"{param} {design}" if design not in ("nielsen", "dupuy-jakob") else design
        print(f"| {label} | {budget} | {measured:.0f} | " + " | ".join(cells)
              + f" | {statistics.median(e for e, _ in rows.values()):.4g} ({len(rows)}) |")


if __name__ == "__main__":
    main()
