#!/usr/bin/python3
"""The paper's question asked of neural BRDFs, with the other models of a given size on one chart
(docs/study.md, "Neural networks").

Usage: scripts/neural_study.py OUT [BRDF...] [--params LIST] [--widths LIST] [--samples N]
                               [--epochs E] [--ranks LIST] [--models LIST] [--halfback EXE]
                               [--threads T] [--no-study] [--no-others]

BRDF...: files, folders (their .bsdf, .h5, .binary and .dat files, in subfolders too) or specs
(default: ../shared/data/rgl; the whole shared data is ../shared/data/nbrdf ../shared/data/rgl
../shared/data/alta; give a few files for a subset). For them:

1. `halfback study BRDF... --metrics neural` into OUT/study (networks of each parameterization's
   coordinates at each hidden width, Sztrajman et al.'s vectors beside halfdiff, one training
   budget; their error is the study's log-space reconstruction error on its test pairs);
2. (unless --no-others) the models of other kinds, each measured with `halfback compare BRDF MODEL`
   on the same test pairs (200,000, seed 1, theta <= 85 degrees) in the same space: analytic fits
   (`halfback fit --model M`, each of --models) and factored models (`halfback factor --param P
   --rank R`, each built-in parameterization of --params at each of --ranks);
3. the chart OUT/neural-error-vs-bytes.png (and .svg): the median over the BRDFs of the error
   against the model's bytes (4 per number: float32), one colour per parameterization, networks
   (circles, joined across widths), factored models (squares, joined across ranks) and analytic
   fits (black crosses: they have no parameterization), both axes logarithmic; and OUT/summary.md,
   the same numbers as a table.
Every number goes to OUT/summary.json. A run resumes: a study already in OUT/study and models
already fitted are kept.
"""

import argparse
import csv
import json
import pathlib
import statistics
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
DEFAULT_PARAMS = "halfdiff,hybrid,ortho,rectified-hybrid,stereographic,dupuy-jakob:per-material"
COLOURS = ["#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e", "#e6ab02", "#a6761d", "#666666"]


class Refused(Exception):
    """A command's data error (status 1): e.g. a fit of a BRDF with missing values."""


def run(command):
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode == 1:
        raise Refused(f"{' '.join(map(str, command))}: {result.stderr.strip()}")
    if result.returncode != 0:
        sys.exit(f"{' '.join(map(str, command))} failed ({result.returncode}): {result.stderr.strip()}")
    return result.stdout


def log_error(exe, brdf, model, json_path):
    if not json_path.exists():
        run([exe, "compare", brdf, model, "--json", str(json_path)])
    return json.loads(json_path.read_text())["study_errors"]["values"]["log"]


def stem(spec):
    """A name for a BRDF's models: its folder and file stem (rgl.cardboard_rgb), or the spec."""
    path = pathlib.Path(spec)
    if path.exists():
        return f"{path.parent.name}.{path.stem}"
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in spec)


def analytic_size(spec):
    """The numbers of a fitted model's spec "a:x=1,y=2+b:z=3": its parameters."""
    return sum(len([kv for kv in term.split(":", 1)[1].split(",") if "=" in kv]) if ":" in term else 0
               for term in spec.split("+"))


def add_others(args, exe, brdf, params, models_dir, points):
    """The analytic fits and factored models of one BRDF, measured; adds them to points."""
    name = stem(brdf)
    for model in args.models.split(","):
        fit_json = models_dir / f"{name}.{model}.fit.json"
        spec_file = models_dir / f"{name}.{model}.spec"
        if not spec_file.exists():
            spec_file.write_text(run([exe, "fit", "--brdf", brdf, "--model", model, "-o", str(fit_json)]).strip())
        spec = spec_file.read_text().strip()
        error = log_error(exe, brdf, spec, models_dir / f"{name}.{model}.compare.json")
        points.setdefault(("analytic fit", model, 0), [4 * analytic_size(spec), []])[1].append(error)
    for param in params:
        if ":" in param:  # a family's member: factor takes built-in and registered ones
            continue
        for rank in map(int, args.ranks.split(",")):
            model = models_dir / f"{name}.{param}.r{rank}.json"
            if not model.exists():
                run([exe, "factor", "--brdf", brdf, "--param", param, "--rank", str(rank), "-o", str(model),
                    "--threads", args.threads])
            counts = [32, 32, 32]  # factor's default --counts
            size = 3 * rank * sum(counts) + 3
            error = log_error(exe, brdf, str(model), models_dir / f"{name}.{param}.r{rank}.compare.json")
            points.setdefault(("factored", param, rank), [4 * size, []])[1].append(error)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("out")
    parser.add_argument("brdfs", nargs="*")
    parser.add_argument("--params", default=DEFAULT_PARAMS)
    parser.add_argument("--widths", default="8,16,21,32,64")
    parser.add_argument("--samples", default="100000")
    parser.add_argument("--epochs", default="20")
    parser.add_argument("--learning-rate", default="0.001")
    parser.add_argument("--ranks", default="1,2,4")
    parser.add_argument("--models", default="lambert+ggx,lambert+ggx+ggx")
    parser.add_argument("--halfback", default=str(ROOT / "build/release/src/cli/halfback"))
    parser.add_argument("--threads", default="0")
    parser.add_argument("--no-study", action="store_true", help="use the study already in OUT/study")
    parser.add_argument("--no-others", action="store_true", help="networks only")
    args = parser.parse_args()

    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    brdfs = []
    for spec in args.brdfs or [str(ROOT.parent / "shared/data/rgl")]:
        path = pathlib.Path(spec)
        if path.is_dir():  # its BRDF files, in its folders too (the study reads each as a file)
            brdfs += sorted(str(p) for p in path.rglob("*") if p.suffix in (".bsdf", ".h5", ".binary", ".dat"))
        else:
            brdfs.append(spec)
    params = args.params.split(",")
    exe = args.halfback

    study = out / "study"
    if not args.no_study and not (study / "neural.csv").exists():
        run([exe, "study", *brdfs, "-o", str(study), "--metrics", "neural", "--params", args.params,
             "--neural-widths", args.widths, "--neural-samples", args.samples, "--neural-epochs", args.epochs,
             "--neural-learning-rate", args.learning_rate, "-q"])
    # points[(kind, parameterization, size label)] = (bytes, [errors per BRDF])
    points = {}
    with open(study / "neural.csv", newline="") as f:
        for row in csv.DictReader(f):
            kind = "network (vectors)" if row["input"] == "vectors" else "network"
            label = "sztrajman-vectors" if row["input"] == "vectors" else row["parameterization"]
            key = (kind, label, int(row["width"]))
            points.setdefault(key, [int(row["bytes"]), []])[1].append(float(row["error"]))

    if not args.no_others:
        models_dir = out / "models"
        models_dir.mkdir(exist_ok=True)
        for brdf in brdfs:
            try:
                add_others(args, exe, brdf, params, models_dir, points)
            except Refused as e:  # no other models for this BRDF
                print(f"skipped: {e}", file=sys.stderr)

    summary = [{"kind": k[0], "parameterization": k[1], "size": k[2], "bytes": v[0], "brdfs": len(v[1]),
                "median_error": statistics.median(v[1]), "errors": v[1]} for k, v in sorted(points.items())]
    (out / "summary.json").write_text(json.dumps({"brdfs": brdfs, "points": summary}, indent=2))
    lines = ["| model | parameterization | width / rank | bytes | BRDFs | median log error |",
             "| --- | --- | --- | --- | --- | --- |"]
    for p in sorted(summary, key=lambda p: (p["kind"], p["parameterization"], p["bytes"])):
        lines.append(f"| {p['kind']} | {p['parameterization']} | {p['size'] or '–'} | {p['bytes']} | {p['brdfs']} "
                     f"| {p['median_error']:.4f} |")
    (out / "summary.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5.5))
    labels = sorted({p["parameterization"] for p in summary if p["kind"] != "analytic fit"},
                    key=lambda s: (s == "sztrajman-vectors", s))
    colour = {label: COLOURS[i % len(COLOURS)] for i, label in enumerate(labels)}
    for kind, marker, style in (("network", "o", "-"), ("network (vectors)", "o", "-"), ("factored", "s", "--")):
        for label in labels:
            ps = sorted((p for p in summary if p["kind"] == kind and p["parameterization"] == label),
                        key=lambda p: p["bytes"])
            if ps:
                ax.plot([p["bytes"] for p in ps], [p["median_error"] for p in ps], marker=marker, linestyle=style,
                        color=colour[label], label=f"{kind}, {label}")
    fits = [p for p in summary if p["kind"] == "analytic fit"]
    for i, p in enumerate(fits):
        ax.plot(p["bytes"], p["median_error"], "kx", markersize=9)
        ax.annotate(p["parameterization"], (p["bytes"], p["median_error"]), textcoords="offset points",
                    xytext=(-10, 8 if i % 2 == 0 else -14), fontsize=8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("bytes (4 per number)")
    ax.set_ylabel("median relative error, log space (the study's measure)")
    ax.set_title(f"Error against size, {len(brdfs)} BRDFs: networks (o), factored (□), analytic fits (×)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(out / "neural-error-vs-bytes.png", dpi=110)
    fig.savefig(out / "neural-error-vs-bytes.svg")


if __name__ == "__main__":
    main()
