#!/usr/bin/python3
"""Every writer of halfback checked by every reader (docs/formats.md, "Writers and readers").

For each source BRDF, each writer makes a file or a spec:
  export-rgl   halfback export-rgl (defaults)                  -> .bsdf
  export-merl  halfback export-merl                            -> .binary
  recon-merl   halfback plan (hybrid, 20 000) + the source's values at its rows + reconstruct
                                                               -> .binary
  recon-rgl    the same plan and values, reconstruct           -> .bsdf
  factor       halfback factor (defaults)                      -> factored .json
  fit          halfback fit --model lambert+ggx (its SPEC)     -> a model spec
  nbrdf        halfback nbrdf train, 100 000 pairs, 10 epochs  -> a neural BRDF .h5 (+ .json)
and each output is read:
  python       halfback.load + eval at 40 000 valid pairs (half cosine-distributed, half within
               5° of the horizon): the count of non-finite values (must be 0);
  albedo       the luminance directional albedo of output and source (its reciprocal part for a
               writer whose output is reciprocal: RECIPROCAL_WRITERS) at θi = 0, 30, 60, 80, 85°
               (Monte Carlo, the same ωo for both: the cosine and three GGX lobes about the mirror
               direction, balance heuristic), the ratio output / source; and max_albedo, the
               largest RGB albedo of the output at those θi where the source's is at most 1
               (a writer that keeps the energy fails if it exceeds 1 by 3 standard errors);
  error        the study's measure against the source: relative L2 of ln(1 + Y) over pairs drawn
               from cos θi cos θo dωi dωo (Y the luminance);
  info, eval, fit, render, study
               the commands on the output: exit status 0, eval's values finite, render without
               a warning of non-finite samples.
A writer that refuses a source (an anisotropic BRDF in a MERL or RGL file) must refuse it with
status 1 or 2 and a message: the cell says "refused".

    /usr/bin/python3 scripts/writer_matrix.py [--small] [--no-commands] [--writers W,W]
        [--every N [--offset K]] [--halfback BIN] [--python DIR] [--shared DIR] [--csv OUT.csv]

--small: the CI set (a near-mirror, a white diffuse, a felt, a glossy paint, an RGL file and an
anisotropic model). Without it: every neural BRDF and RGL file of the shared data. Exit status 1
when a cell fails its tolerance (TOLERANCE below), so that a test can run it.
"""
import argparse
import csv
import glob
import os
import subprocess
import sys
import tempfile

import numpy as np

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
ALPHAS = (0.01, 0.05, 0.2)
ANGLES = (0, 30, 60, 80, 85)
WRITERS = ("export-rgl", "export-merl", "recon-merl", "recon-rgl", "factor", "fit", "nbrdf")
# The largest |albedo ratio - 1| a writer may give at θi <= 80° (85° is reported, not bounded: the
# readers' interpolation at the horizon is the format's). The exports keep the energy. A
# reconstruction from 20 000 measurements, a rank-2 factorization and a fitted model are
# approximations whose energy error is their own, reported and not bounded (None): a near-mirror
# loses most of its peak in each (docs/formats.md, "Writers and readers").
TOLERANCE = {"export-rgl": 0.10, "export-merl": 0.10, "recon-merl": None, "recon-rgl": None,
             "factor": None, "fit": None, "nbrdf": None}


def run(args, **kw):
    return subprocess.run(args, capture_output=True, text=True, **kw)


def ggx_d(cos_m, a):
    c2 = cos_m * cos_m
    t = (1 - c2) / np.maximum(c2, 1e-300)
    return 1 / (np.pi * a * a * c2 * c2 * (1 + t / (a * a)) ** 2)


def albedo_directions(wi, n, rng):
    """n directions ωo (some below the horizon), their mixture density, and n."""
    k = n // (1 + len(ALPHAS))
    u1, u2 = rng.random(k), rng.random(k)
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    out = [np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(0, 1 - u1))], 1)]
    for a in ALPHAS:
        u1, u2 = rng.random(k), rng.random(k)
        c = 1 / np.sqrt(1 + a * a * u1 / (1 - u1))
        s, phi = np.sqrt(np.maximum(0, 1 - c * c)), 2 * np.pi * u2
        m = np.stack([s * np.cos(phi), s * np.sin(phi), c], 1)
        out.append(2 * (m @ wi)[:, None] * m - wi)
    wo = np.concatenate(out)
    wo /= np.linalg.norm(wo, axis=1)[:, None]
    h = wi + wo
    h /= np.maximum(np.linalg.norm(h, axis=1), 1e-300)[:, None]
    pdf = np.maximum(wo[:, 2], 0) / np.pi
    for a in ALPHAS:
        pdf = pdf + ggx_d(np.clip(h[:, 2], 1e-12, 1), a) * np.maximum(h[:, 2], 0) / (
            4 * np.maximum(np.abs(h @ wi), 1e-300))
    return wo, pdf / (1 + len(ALPHAS)), len(out) * k


def albedos(source, out, n=100000):
    """Per θi of ANGLES: the RGB directional albedos of source and output, and their standard
    errors (Monte Carlo over the same ωo for both)."""
    result = []
    for i, t in enumerate(ANGLES):
        th = np.radians(t)
        wi = np.array([np.sin(th), 0, np.cos(th)])
        wo, pdf, total = albedo_directions(wi, n, np.random.default_rng(i + 1))
        up = wo[:, 2] > 0
        wo, pdf = wo[up], pdf[up]
        wis = np.tile(wi, (len(wo), 1))
        w = (wo[:, 2] / pdf)[:, None]
        terms = []
        for brdf in (source, out):
            f = np.nan_to_num(brdf.eval(wis, wo) * w)
            # The samples below the horizon count as zeros in the mean over `total`.
            mean = f.sum(axis=0) / total
            var = (np.sum(f * f, axis=0) / total - mean * mean) / total
            terms += [mean, np.sqrt(np.maximum(var, 0))]
        result.append(terms)
    return result


def albedo_ratios(found):
    """The luminance albedo ratio output / source per θi of albedos()."""
    ratios = []
    for a, _, b, _ in found:
        a, b = a @ LUMINANCE, b @ LUMINANCE
        ratios.append(b / a if a > 0 else float("nan"))
    return ratios


def above_one(found):
    """The largest output albedo (any θi, any channel) where the source's is at most 1, and
    whether it exceeds 1 by more than three standard errors: an export that creates light."""
    worst, created = 0.0, False
    for a, _, b, sb in found:
        for c in range(3):
            if a[c] <= 1:
                worst = max(worst, b[c])
                created |= bool(b[c] > 1 + 3 * sb[c])
    return worst, created


def cosine_directions(n, rng):
    u1, u2 = rng.random(n), rng.random(n)
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    return np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(0, 1 - u1))], 1)


def grazing_directions(n, rng):
    theta = np.radians(85 + 5 * rng.random(n))
    phi = 2 * np.pi * rng.random(n)
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi),
                     np.cos(theta)], 1)


def nonfinite(out, n=20000):
    rng = np.random.default_rng(11)
    wi = np.concatenate([cosine_directions(n, rng), grazing_directions(n, rng)])
    wo = np.concatenate([cosine_directions(n, rng), grazing_directions(n, rng)])
    keep = (wi[:, 2] > 0) & (wo[:, 2] > 0)
    return int((~np.isfinite(out.eval(wi[keep], wo[keep]))).any(axis=1).sum())


def study_error(source, out, n=50000):
    rng = np.random.default_rng(7)
    wi, wo = cosine_directions(n, rng), cosine_directions(n, rng)
    keep = (wi[:, 2] > 0) & (wo[:, 2] > 0)
    truth = np.log1p(np.maximum(source.eval(wi[keep], wo[keep]) @ LUMINANCE, 0))
    value = np.log1p(np.maximum(out.eval(wi[keep], wo[keep]) @ LUMINANCE, 0))
    ok = np.isfinite(truth)
    return float(np.sqrt(np.sum((value[ok] - truth[ok]) ** 2) / np.sum(truth[ok] ** 2)))


# Writers whose output is reciprocal by construction: a MERL file stores a configuration and its
# swap in one bin, and a plan measures a pair and its swap once. Their reference is the source's
# reciprocal part, (ρ(ωi, ωo) + ρ(ωo, ωi)) / 2: the neural BRDFs of RGL materials and the RGL
# files are not reciprocal (chm_mint's network: +16% of albedo at 80° against itself, -1.5%
# against its reciprocal part), and that is the data's, not the writer's.
RECIPROCAL_WRITERS = ("export-merl", "recon-merl", "recon-rgl")


class Reciprocal:
    """The reciprocal part of a BRDF, as an object with eval(wi, wo)."""

    def __init__(self, brdf):
        self.brdf = brdf

    def eval(self, wi, wo):
        return 0.5 * (self.brdf.eval(wi, wo) + self.brdf.eval(wo, wi))


def write(hb, writer, source, tmp):
    """The writer's output (a path or a spec), or None with the refusal's message."""
    if writer == "export-rgl":
        path = os.path.join(tmp, "out.bsdf")
        r = run([hb, "export-rgl", "-q", "--brdf", source, "-o", path])
    elif writer == "export-merl":
        path = os.path.join(tmp, "out.binary")
        r = run([hb, "export-merl", "--brdf", source, "-o", path])
    elif writer in ("recon-merl", "recon-rgl"):
        return reconstruct(hb, writer, source, tmp)
    elif writer == "nbrdf":
        # A short training (1/64 of the default's steps), so that the matrix stays fast: its
        # error is the short training's (docs/neural.md has the default's).
        path = os.path.join(tmp, "out.h5")
        r = run([hb, "nbrdf", "train", "-q", "--brdf", source, "--samples", "100000", "--epochs",
                 "10", "-o", path])
    elif writer == "factor":
        path = os.path.join(tmp, "out.json")
        r = run([hb, "factor", "--brdf", source, "-o", path])
    else:
        r = run([hb, "fit", "--brdf", source, "--model", "lambert+ggx", "-o",
                 os.path.join(tmp, "fit.json")])
        path = r.stdout.strip()
    if r.returncode:
        return None, r.returncode, r.stderr.strip().splitlines()[-1] if r.stderr else ""
    return path, 0, ""


def reconstruct(hb, writer, source, tmp):
    import halfback
    plan = os.path.join(tmp, "plan.csv")
    r = run([hb, "plan", "--param", "hybrid", "--budget", "20000", "-o", plan])
    if r.returncode:
        return None, r.returncode, r.stderr.strip()
    rows = np.genfromtxt(plan, delimiter=",", names=True)
    wi = np.stack([rows["wi_x"], rows["wi_y"], rows["wi_z"]], 1)
    wo = np.stack([rows["wo_x"], rows["wo_y"], rows["wo_z"]], 1)
    wi /= np.linalg.norm(wi, axis=1)[:, None]
    wo /= np.linalg.norm(wo, axis=1)[:, None]
    values = halfback.load(source).eval(wi, wo)
    measured = os.path.join(tmp, "values.csv")
    with open(measured, "w") as f:
        f.write("row,r,g,b\n")
        for k, v in enumerate(values):
            f.write(f"{k},{v[0]!r},{v[1]!r},{v[2]!r}\n")
    path = os.path.join(tmp, "recon" + (".binary" if writer == "recon-merl" else ".bsdf"))
    r = run([hb, "reconstruct", "--plan", plan.replace(".csv", ".json"), "--measurements",
             measured, "-o", path])
    if r.returncode:
        return None, r.returncode, r.stderr.strip().splitlines()[-1]
    return path, 0, ""


def commands(hb, out, tmp):
    """The CLI readers on an output: the names of those that failed."""
    failed = []
    if run([hb, "info", out]).returncode:
        failed.append("info")
    pairs = "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0.6,0,0.8,-0.3,0.2,0.9327379\n" \
            "0.9998,0,0.0199960,0,0.9998,0.0199960\n"
    r = run([hb, "eval", "--brdf", out], input=pairs)
    if r.returncode or any(not np.isfinite(float(x)) for line in r.stdout.split("\n")[1:]
                           if line for x in line.split(",")):
        failed.append("eval")
    if run([hb, "fit", "--brdf", out, "--model", "ggx", "--samples", "2000", "-o",
            os.path.join(tmp, "refit.json")]).returncode:
        failed.append("fit")
    r = run([hb, "render", "--brdf", out, "--width", "32", "--height", "32", "--spp", "4",
             "-o", os.path.join(tmp, "r.png")])
    if r.returncode or "not finite" in r.stderr or "NaN" in r.stderr:
        failed.append("render")
    if run([hb, "study", out, "--quick", "--no-images", "--no-sampling", "--no-fit",
            "--budgets", "1000", "--params", "hybrid", "-o", os.path.join(tmp, "st")]).returncode:
        failed.append("study")
    return failed


def small_set(shared):
    nb = os.path.join(shared, "data/nbrdf/merl_nbrdf")
    return [os.path.join(nb, "chrome-steel.h5"), "lambert:albedo=0.9", "embedded:pink-felt",
            "embedded:gold-metallic-paint3", "embedded:acrylic_felt_green",
            "ggx:alpha_x=0.1,alpha_y=0.4,f0=0.8"]


def whole_set(shared):
    data = os.path.join(shared, "data")
    return sorted(glob.glob(os.path.join(data, "nbrdf/*/*.h5"))) + sorted(
        glob.glob(os.path.join(data, "rgl/*.bsdf")))


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--small", action="store_true")
    p.add_argument("--halfback", default=os.path.join(root, "build/release/src/cli/halfback"))
    p.add_argument("--python", default=os.path.join(root, "build/release/python"))
    p.add_argument("--shared", default=os.path.join(root, "../shared"))
    p.add_argument("--csv", default="")
    p.add_argument("--writers", default=",".join(WRITERS),
                   help="comma-separated, of: " + ", ".join(WRITERS))
    p.add_argument("--every", type=int, default=1, help="every Nth source of the set only")
    p.add_argument("--offset", type=int, default=0,
                   help="with --every N: the sources at OFFSET, OFFSET + N, ... (0 to N - 1)")
    p.add_argument("--no-commands", action="store_true",
                   help="leave out the CLI readers (info, eval, fit, render, study): the Python "
                        "reader's checks only, about 4x faster")
    args = p.parse_args()
    sys.path.insert(0, args.python)
    import halfback

    if not os.path.isdir(os.path.join(args.shared, "data/nbrdf")):
        if os.environ.get("CI") == "true":
            print(f"{args.shared}/data is missing under CI")
            return 1
        print(f"{args.shared}/data not found: skipped")
        return 77
    sources = (small_set(args.shared) if args.small else whole_set(args.shared))[args.offset::args.every]
    writers = args.writers.split(",")
    if any(w not in WRITERS for w in writers):
        p.error(f"--writers: one of {', '.join(WRITERS)}")
    fields = ["source", "writer", "status", "nonfinite", "error"] + \
        [f"albedo_{t}" for t in ANGLES] + ["max_albedo", "commands_failed"]
    rows, failures = [], []
    for source in sources:
        src = halfback.load(source)
        for writer in writers:
            with tempfile.TemporaryDirectory() as tmp:
                out, status, message = write(args.halfback, writer, source, tmp)
                row = {"source": source.replace(args.shared + "/data/", ""), "writer": writer}
                if out is None:
                    row["status"] = f"refused ({status}): {message}"
                    if src.isotropic or status not in (1, 2) or not message:
                        failures.append(f"{source} {writer}: {message or 'no message'}")
                else:
                    o = halfback.load(out)
                    ref = Reciprocal(src) if writer in RECIPROCAL_WRITERS else src
                    row["status"] = "written"
                    row["nonfinite"] = nonfinite(o)
                    row["error"] = f"{study_error(ref, o):.4f}"
                    found = albedos(ref, o)
                    ratios = albedo_ratios(found)
                    for t, r in zip(ANGLES, ratios):
                        row[f"albedo_{t}"] = f"{r:.4f}"
                    most, created = above_one(found)
                    bound = TOLERANCE[writer]
                    row["max_albedo"] = f"{most:.4f}"
                    row["commands_failed"] = "" if args.no_commands else " ".join(
                        commands(args.halfback, out, tmp))
                    worst = max(abs(r - 1) for t, r in zip(ANGLES, ratios) if t <= 80)
                    # Light created: a failure for the writers that keep the energy (bounded).
                    created = created and bound is not None
                    if row["nonfinite"] or row["commands_failed"] or created or \
                            (bound is not None and not worst <= bound):
                        failures.append(f"{source} {writer}: nonfinite {row['nonfinite']}, "
                                        f"albedo ratios {ratios}, largest albedo {most:.4f}, "
                                        f"commands failed '{row['commands_failed']}'")
                rows.append(row)
                print(",".join(str(row.get(f, "")) for f in fields), flush=True)
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=fields)
            w.writeheader()
            w.writerows(rows)
    summarize(rows)
    for f in failures:
        print("FAILED: " + f)
    print(f"{len(rows) - len(failures)} passed, {len(failures)} failed")
    return 1 if failures else 0


def summarize(rows):
    for writer in WRITERS:
        cells = [r for r in rows if r["writer"] == writer and r["status"] == "written"]
        if not cells:
            continue
        ratios = [(abs(float(r[f"albedo_{t}"]) - 1), float(r[f"albedo_{t}"]), t, r["source"])
                  for r in cells for t in ANGLES if t <= 80]
        worst = max(ratios)
        errors = sorted(float(r["error"]) for r in cells)
        most = max((float(r["max_albedo"]), r["source"]) for r in cells)
        print(f"# {writer}: {len(cells)} written; worst albedo ratio (<= 80°) {worst[1]:.3f} "
              f"({worst[3]}, {worst[2]}°); non-finite {sum(int(r['nonfinite']) for r in cells)}; "
              f"error median {errors[len(errors) // 2]:.4f}, max {errors[-1]:.4f}; largest "
              f"albedo where the source's is <= 1: {most[0]:.4f} ({most[1]})")


if __name__ == "__main__":
    sys.exit(main())
