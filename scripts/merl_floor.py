#!/usr/bin/python3
"""The error a MERL file adds by its lookup (docs/formats.md, "The lookup's floor").

For each source BRDF, `halfback export-merl` writes a .binary file; the file is read with MERL's
own nearest-bin lookup (FILE) and with trilinear interpolation (merl-trilinear:FILE), and each is
compared with the source in the study's measure: the relative L2 error of ln(1 + Y) (Y the Rec. 709
luminance of rho) over pairs drawn from cos(theta_i) cos(theta_o) dwi dwo, on the pairs whose
angles are both at most 80 degrees and on the whole hemisphere. For the RGL files, whose data is
not reciprocal (a MERL file is), the within-80-degree error against the source's reciprocal part
(rho(wi, wo) + rho(wo, wi)) / 2 is printed too. Every value is computed by `halfback eval`.

    /usr/bin/python3 scripts/merl_floor.py [--pairs N] [--seed S] [--halfback BIN]
        [--shared DIR] [--sources SPEC,SPEC,...]

Prints a Markdown table (the one of docs/formats.md, with the reciprocal column) on stdout. About
25 s for the six default sources at 200 000 pairs (two cores).
"""
import argparse
import io
import os
import subprocess
import sys
import tempfile

import numpy as np

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])


def sources(shared):
    nb = os.path.join(shared, "data/nbrdf/merl_nbrdf")
    rgl = os.path.join(shared, "data/rgl")
    return [
        ("gold-metallic-paint3 (network)", os.path.join(nb, "gold-metallic-paint3.h5")),
        ("blue-metallic-paint (network)", os.path.join(nb, "blue-metallic-paint.h5")),
        ("pink-felt (network)", os.path.join(nb, "pink-felt.h5")),
        ("ilm_l3_37_metallic (RGL)", os.path.join(rgl, "ilm_l3_37_metallic_rgb.bsdf")),
        ("cardboard (RGL)", os.path.join(rgl, "cardboard_rgb.bsdf")),
        ("acrylic_felt_green (RGL)", os.path.join(rgl, "acrylic_felt_green_rgb.bsdf")),
    ]


def cosine_directions(n, rng):
    u1, u2 = rng.random(n), rng.random(n)
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    return np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(0, 1 - u1))], 1)


def evaluate(hb, spec, pairs_csv):
    """rho (n x 3) of `spec` at the pairs of `pairs_csv`, by `halfback eval`."""
    r = subprocess.run([hb, "eval", "--brdf", spec, "-i", pairs_csv], capture_output=True,
                       text=True)
    if r.returncode != 0:
        sys.exit(f"halfback eval --brdf {spec}: {r.stderr.strip()}")
    return np.loadtxt(io.StringIO(r.stdout), delimiter=",", skiprows=1, ndmin=2)


def error(truth_rgb, value_rgb, keep):
    truth = np.log1p(np.maximum(truth_rgb[keep] @ LUMINANCE, 0))
    value = np.log1p(np.maximum(value_rgb[keep] @ LUMINANCE, 0))
    bad = ~np.isfinite(value)
    if bad.any():
        sys.exit(f"{int(bad.sum())} values are not finite at valid pairs")
    return float(np.sqrt(np.sum((value - truth) ** 2) / np.sum(truth ** 2)))


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--pairs", type=int, default=200000)
    p.add_argument("--seed", type=int, default=7)
    p.add_argument("--halfback", default=os.path.join(root, "build/release/src/cli/halfback"))
    p.add_argument("--shared", default=os.path.join(root, "../shared"))
    p.add_argument("--sources", default="", help="NAME=SPEC,... instead of the table's six")
    args = p.parse_args()
    chosen = sources(args.shared)
    if args.sources:
        chosen = [tuple(item.split("=", 1)) if "=" in item else (item, item)
                  for item in args.sources.split(",")]
    rng = np.random.default_rng(args.seed)
    wi, wo = cosine_directions(args.pairs, rng), cosine_directions(args.pairs, rng)
    keep_all = (wi[:, 2] > 0) & (wo[:, 2] > 0)
    cos80 = np.cos(np.radians(80))
    keep_80 = keep_all & (wi[:, 2] >= cos80) & (wo[:, 2] >= cos80)
    print(f"{args.pairs} cosine-distributed pairs (seed {args.seed}), {int(keep_80.sum())} with "
          "both angles within 80 degrees\n")
    print("| source | both θ ≤ 80°: nearest | trilinear | whole hemisphere: nearest | trilinear "
          "| ≤ 80° against the reciprocal part: nearest | trilinear |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as tmp:
        forward = os.path.join(tmp, "pairs.csv")
        swapped = os.path.join(tmp, "swapped.csv")
        header = "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z"
        np.savetxt(forward, np.hstack([wi, wo]), delimiter=",", header=header, comments="",
                   fmt="%.17g")
        np.savetxt(swapped, np.hstack([wo, wi]), delimiter=",", header=header, comments="",
                   fmt="%.17g")
        for name, spec in chosen:
            binary = os.path.join(tmp, "out.binary")
            r = subprocess.run([args.halfback, "export-merl", "--brdf", spec, "-o", binary],
                               capture_output=True, text=True)
            if r.returncode != 0:
                sys.exit(f"export-merl --brdf {spec}: {r.stderr.strip()}")
            source = evaluate(args.halfback, spec, forward)
            nearest = evaluate(args.halfback, binary, forward)
            trilinear = evaluate(args.halfback, "merl-trilinear:" + binary, forward)
            cells = [error(source, nearest, keep_80), error(source, trilinear, keep_80),
                     error(source, nearest, keep_all), error(source, trilinear, keep_all)]
            if spec.endswith(".bsdf"):
                reciprocal = 0.5 * (source + evaluate(args.halfback, spec, swapped))
                cells += [error(reciprocal, nearest, keep_80),
                          error(reciprocal, trilinear, keep_80)]
            text = " | ".join(f"{c:.3f}" for c in cells)
            print(f"| {name} | {text}" + (" | – | –" if len(cells) == 4 else "") + " |",
                  flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
