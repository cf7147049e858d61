#!/usr/bin/python3
"""halfback's neural BRDFs against the authors' published ones, on the RGL measurements.

Usage: scripts/nbrdf_vs_published.py [--rgl DIR] [--published DIR] [--out DIR] [--halfback EXE]
                                     [--lock FILE] [--threads T] [--train-args ARGS] [--loss LOSS]
                                     [--materials A,B,...] [--also DIR] [--baseline JSON]
                                     [--markdown FILE] [--json FILE]
(with PYTHONPATH naming halfback's Python module, e.g. build/release/python)

For each RGL file NAME.bsdf of --rgl that has a published network NAME.h5 in --published
(Sztrajman et al. 2021's, asztr/Neural-BRDF), trains a network from the file with
`halfback nbrdf train` at the default size (6-21-21-3), one thread, with --train-args (default:
a learning rate of 1e-3 falling to 1e-5, 3 restarts; '' for the authors' settings) and
`--loss LOSS` (default sztrajman, the authors' loss; study-log, halfback's loss in the study's
log measure: docs/neural.md, "The losses") into
OUT/NAME.h5 (a network already there is kept, so a run can be resumed: delete it to train
again), then measures both networks against the RGL file, each with the same pairs:

- the authors' training loss, mean |log(1 + rho' c) - log(1 + rho c)| (scripts/nbrdf_loss.py's
  restatement in NumPy; 200,000 pairs drawn the authors' way from seed 7, those with a direction
  at or below the horizon left out);
- the study's measures (`halfback compare RGL NET --json`): the relative, mu-weighted L2 error of
  the luminance in each error space on the study's 200,000 test pairs; `log` is the study's
  default space and the one the verdict uses;
- the study's image metric (halfback.image_error: a sphere under the `sky` environment, the
  study's protocol): the relative RMSE of the radiance and the mean CIEDE2000 difference.

--materials restricts the run to the named materials; --also adds a column of the study log
error of networks trained otherwise (NAME.h5 in a folder), --baseline one of the halfback
networks of an earlier run's --json (e.g. the authors' loss, against this run's study-log).

Prints a Markdown table (and writes it to --markdown), the count of materials where halfback's
network is at least as accurate as the published one in the study's measure, and writes every
number to --json. Training runs one material at a time, under an exclusive lock on --lock when
given (a shared machine's test lock).
"""

import argparse
import fcntl
import json
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

import halfback

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from nbrdf_loss import authors_pairs  # noqa: E402

SPACES = ["linear", "log", "cbrt", "nielsen", "low"]
# The training of the comparison (docs/neural.md, "Against the published networks"): the default
# size, a higher learning rate falling geometrically to 1e-5 at the last epoch, 3 restarts.
DEFAULT_TRAIN_ARGS = "--learning-rate 1e-3 --final-learning-rate 1e-5 --restarts 3"


def train(exe, rgl, out, threads, lock, extra):
    """Trains OUT from RGL unless OUT exists; returns the summary line (or None when kept)."""
    if out.exists():
        return None
    command = [exe, "nbrdf", "train", "--brdf", str(rgl), "-o", str(out), "--threads", str(threads), "-q", *extra]
    handle = open(lock, "a") if lock else None
    try:
        if handle:
            fcntl.flock(handle, fcntl.LOCK_EX)
        start_cpu = os.times()
        start = time.monotonic()
        result = subprocess.run(command, capture_output=True, text=True)
        wall = time.monotonic() - start
        end_cpu = os.times()
    finally:
        if handle:
            handle.close()
    if result.returncode != 0:
        sys.exit(f"{' '.join(command)} failed ({result.returncode}): {result.stderr.strip()}")
    cpu = end_cpu.children_user - start_cpu.children_user + end_cpu.children_system - start_cpu.children_system
    summary = result.stdout.strip()
    out.with_suffix(".log").write_text(f"{summary}\nwall {wall:.1f} s, cpu {cpu:.1f} s\n")
    return summary


def training_record(out):
    """What the training of OUT printed (its .log beside it), parsed."""
    log = out.with_suffix(".log")
    if not log.exists():
        return {}
    text = log.read_text()
    record = {"summary": text.splitlines()[0]}
    m = re.search(r"\((\d+) steps, ([0-9.]+) ms per step, ([0-9.]+) s\), loss ([0-9.e+-]+)", text)
    if m:
        record.update(steps=int(m[1]), ms_per_step=float(m[2]), seconds=float(m[3]), loss=float(m[4]))
    m = re.search(r"wall ([0-9.]+) s, cpu ([0-9.]+) s", text) or re.search(r"([0-9.]+) s wall ([0-9.]+) s user", text)
    if m:
        record.update(wall_s=float(m[1]), cpu_s=float(m[2]))
    return record


def study_errors(exe, rgl, net, threads):
    with tempfile.TemporaryDirectory() as tmp:
        path = pathlib.Path(tmp) / "compare.json"
        command = [exe, "compare", str(rgl), str(net), "--json", str(path), "--threads", str(threads)]
        result = subprocess.run(command, capture_output=True, text=True)
        if result.returncode != 0:
            sys.exit(f"{' '.join(command)} failed ({result.returncode}): {result.stderr.strip()}")
        data = json.loads(path.read_text())
    return {"study": data["study_errors"]["values"], "fit_losses": data["fit_losses"]["values"]}


def measure(exe, rgl, net, wi, wo, cosine, truth, threads):
    rho = halfback.load(str(net)).eval(wi, wo)
    loss = float(np.mean(np.abs(np.log1p(rho * cosine) - np.log1p(truth * cosine))))
    image = halfback.image_error(str(net), str(rgl))
    return {"loss": loss, **study_errors(exe, rgl, net, threads), "image": image}


def main():
    root = pathlib.Path(__file__).resolve().parent.parent
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rgl", default=str(root.parent / "shared/data/rgl"))
    parser.add_argument("--published", default=str(root.parent / "shared/data/nbrdf/rgl-isotropic_nbrdf"))
    parser.add_argument("--out", default="nbrdf-rgl", help="folder of the trained networks (default nbrdf-rgl)")
    parser.add_argument("--halfback", default=str(root / "build/release/src/cli/halfback"))
    parser.add_argument("--lock", help="train under an exclusive lock on this file")
    parser.add_argument("--threads", type=int, default=1, help="threads of the training (default 1)")
    parser.add_argument("--pairs", type=int, default=200000)
    parser.add_argument("--train-args", default=DEFAULT_TRAIN_ARGS,
                        help=f"options of `nbrdf train` beside the default size (default '{DEFAULT_TRAIN_ARGS}'; "
                        "'' for the authors' settings)")
    parser.add_argument("--loss", default="sztrajman", choices=["sztrajman", "study-log"],
                        help="`nbrdf train --loss` (default sztrajman, the authors')")
    parser.add_argument("--materials", help="only these materials (comma-separated names)")
    parser.add_argument("--baseline", metavar="JSON",
                        help="an earlier run's --json: its halfback study log error in a column of its own")
    parser.add_argument("--also", metavar="DIR",
                        help="networks NAME.h5 trained otherwise (e.g. with the authors' settings): their study "
                        "log error in a column of their own")
    parser.add_argument("--markdown", help="write the table here too")
    parser.add_argument("--json", help="write every number here")
    args = parser.parse_args()

    out_dir = pathlib.Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    materials = sorted(p.stem for p in pathlib.Path(args.rgl).glob("*.bsdf")
                       if (pathlib.Path(args.published) / f"{p.stem}.h5").exists())
    if args.materials:
        wanted = args.materials.split(",")
        unknown = sorted(set(wanted) - set(materials))
        if unknown:
            sys.exit(f"--materials: no RGL file with a published network named {', '.join(unknown)}")
        materials = [m for m in materials if m in wanted]
    if not materials:
        sys.exit(f"no RGL file of {args.rgl} has a published network in {args.published}")
    baseline = {}
    if args.baseline:
        for row in json.loads(pathlib.Path(args.baseline).read_text())["materials"]:
            baseline[row["material"]] = row["halfback"]["study"]["log"]
    train_args = args.train_args.split() + ["--loss", args.loss]

    wi, wo = authors_pairs(args.pairs, 7)
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    cosine = np.clip(wo[:, 2], 0, 1)[:, None]

    results = []
    for name in materials:
        rgl = pathlib.Path(args.rgl) / f"{name}.bsdf"
        ours = out_dir / f"{name}.h5"
        summary = train(args.halfback, rgl, ours, args.threads, args.lock, train_args)
        if summary:
            print(summary, file=sys.stderr)
        truth = halfback.load(str(rgl)).eval(wi, wo)
        row = {"material": name, "training": training_record(ours)}
        row["halfback"] = measure(args.halfback, rgl, ours, wi, wo, cosine, truth, args.threads)
        row["published"] = measure(args.halfback, rgl, pathlib.Path(args.published) / f"{name}.h5",
                                   wi, wo, cosine, truth, args.threads)
        if args.also:
            other = pathlib.Path(args.also) / f"{name}.h5"
            row["also"] = study_errors(args.halfback, rgl, other, args.threads)["study"] if other.exists() else None
        results.append(row)
        print(f"{name}: log error {row['halfback']['study']['log']:.4f} (published "
              f"{row['published']['study']['log']:.4f})", file=sys.stderr)

    lines = [
        "| RGL material | loss, halfback | loss, published | study log error, halfback | published "
        "| linear, halfback | published | image rel. RMSE, halfback | published | mean ΔE00, halfback "
        "| published |" + (" study log error, `--also` |" if args.also else "")
        + (" study log error, `--baseline` |" if args.baseline else ""),
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |" + (" --- |" if args.also else "")
        + (" --- |" if args.baseline else ""),
    ]
    wins = {"loss": 0, "log": 0, "linear": 0, "image": 0}
    for r in results:
        h, p = r["halfback"], r["published"]
        wins["loss"] += h["loss"] <= p["loss"]
        wins["log"] += h["study"]["log"] <= p["study"]["log"]
        wins["linear"] += h["study"]["linear"] <= p["study"]["linear"]
        wins["image"] += h["image"]["relative_rmse"] <= p["image"]["relative_rmse"]

        def pair(a, b, fmt="{:.4f}"):
            sa, sb = fmt.format(a), fmt.format(b)
            return (f"**{sa}**" if a <= b else sa), (f"**{sb}**" if b < a else sb)

        cells = [*pair(h["loss"], p["loss"], "{:.5f}"), *pair(h["study"]["log"], p["study"]["log"]),
                 *pair(h["study"]["linear"], p["study"]["linear"]),
                 *pair(h["image"]["relative_rmse"], p["image"]["relative_rmse"]),
                 *pair(h["image"]["mean_delta_e2000"], p["image"]["mean_delta_e2000"], "{:.3f}")]
        if args.also:
            cells.append(f"{r['also']['log']:.4f}" if r.get("also") else "–")
        if args.baseline:
            b = baseline.get(r["material"])
            cells.append(f"{b:.4f}" if b is not None else "–")
            r["baseline_log"] = b
        lines.append(f"| {r['material']} | " + " | ".join(cells) + " |")
    n = len(results)
    lines.append("")
    lines.append(f"halfback's network at least as accurate as the published one: {wins['log']} of {n} in the "
                 f"study's measure (log space), {wins['linear']} of {n} in its linear space, {wins['loss']} of "
                 f"{n} in the authors' loss, {wins['image']} of {n} in the image metric's relative RMSE.")
    table = "\n".join(lines) + "\n"
    print(table)
    if args.markdown:
        pathlib.Path(args.markdown).write_text(table)
    if args.json:
        pathlib.Path(args.json).write_text(json.dumps({"materials": results, "wins": wins, "count": n, "loss": args.loss,
                                                     "train_args": args.train_args}, indent=2))


if __name__ == "__main__":
    main()
