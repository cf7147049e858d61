#!/usr/bin/python3
"""Fitted materials in Blender's Cycles against halfback's renderer (docs/fit.md, "Verified in
Blender"). For each material: `halfback fit --emit blender` of a model to a measured BRDF, the
sphere rendered by `halfback render` (the fitted model) and by Cycles (the emitted script,
scripts/blender_sphere.py), in the same scene; prints the relative difference of the sphere's
pixels per material as a Markdown table and writes a figure.

usage: scripts/blender-compare.py --build build/release --out DIR [--shared ../shared]
       [--size 128] [--spp 256] [--env FILE|constant:V] [--quick]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

# label, measured BRDF (relative to the shared directory), model to fit.
MATERIALS = [
    ("paint", "data/nbrdf/merl_nbrdf/dark-red-paint.h5", "disney:anisotropic=0,subsurface=0"),
    ("metal", "data/nbrdf/merl_nbrdf/nickel.h5", "disney:anisotropic=0,subsurface=0"),
    ("plastic", "data/nbrdf/merl_nbrdf/green-plastic.h5", "disney:anisotropic=0,subsurface=0"),
    ("felt", "data/rgl/acrylic_felt_green_rgb.bsdf", "disney:anisotropic=0,subsurface=0"),
    ("wood", "data/nbrdf/merl_nbrdf/cherry-235.h5", "disney:anisotropic=0,subsurface=0"),
]
# Models whose Cycles form is exact (docs/fit.md): the floor of the comparison.
CONTROLS = [
    ("lambert", "lambert:albedo_r=0.7,albedo_g=0.4,albedo_b=0.2"),
    ("oren-nayar", "oren-nayar:albedo=0.6,sigma=0.5"),
]


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)}: exit {r.returncode}\n{r.stderr}")
    return r


def blender_render(blender, script, env, out, size, spp):
    run([blender, "-b", "--factory-startup", "--python", os.path.join(HERE, "blender_sphere.py"),
         "--", script, env, out, str(size), str(spp)])
    return np.load(out)


def sphere_mask(size, radius=0.97):
    """Pixels whose centre lies on the sphere, off its rim (halfback's orthographic camera spans
    [-1.25, 1.25])."""
    c = (np.arange(size) + 0.5) / size * 2.5 - 1.25
    x, y = np.meshgrid(c, -c)
    return x * x + y * y < radius * radius


def relative_difference(test, ref, mask):
    d = test[mask] - ref[mask]
    return {
        "relative_rmse": float(np.sqrt(np.mean(d * d)) / np.sqrt(np.mean(ref[mask] ** 2))),
        "mean_ratio": [float(test[mask][:, k].mean() / ref[mask][:, k].mean()) for k in range(3)],
    }


def tonemap(img, scale):
    return np.clip(img / scale, 0, 1) ** (1 / 2.2)


def figure(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(rows), 3, figsize=(7.5, 2.5 * len(rows)))
    for ax_row, (label, hb, cy, rel) in zip(np.atleast_2d(axes), rows):
        scale = np.percentile(hb[sphere_mask(hb.shape[0])], 99) or 1
        ax_row[0].imshow(tonemap(hb, scale))
        ax_row[1].imshow(tonemap(cy, scale))
        diff = (cy - hb).mean(axis=2) / scale
        im = ax_row[2].imshow(np.where(sphere_mask(hb.shape[0]), diff, np.nan), cmap="RdBu_r",
                              vmin=-0.25, vmax=0.25)
        ax_row[0].set_ylabel(f"{label}\n{100 * rel:.1f} %", rotation=0, ha="right", va="center")
        for ax in ax_row:
            ax.set_xticks([])
            ax.set_yticks([])
    np.atleast_2d(axes)[0][0].set_title("halfback render")
    np.atleast_2d(axes)[0][1].set_title("Blender Cycles")
    np.atleast_2d(axes)[0][2].set_title("Cycles - halfback")
    fig.colorbar(im, ax=axes, shrink=0.3, label="difference / white point")
    fig.savefig(path, dpi=110, bbox_inches="tight")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default="build/release")
    ap.add_argument("--out", required=True)
    ap.add_argument("--shared", default=os.path.join(HERE, "..", "..", "shared"))
    ap.add_argument("--blender", default="/usr/bin/blender")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--env", default=None, help="default: the shared uffizi.hdr")
    ap.add_argument("--samples", type=int, default=20000, help="fit samples")
    ap.add_argument("--quick", action="store_true", help="two materials, 64 px, 64 spp")
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(a.build, "python"))
    import halfback
    halfback_cli = os.path.join(a.build, "src", "cli", "halfback")
    env = a.env or os.path.join(a.shared, "data", "envmaps", "uffizi.hdr")
    materials = MATERIALS[:2] if a.quick else MATERIALS
    size, spp = (64, 64) if a.quick else (a.size, a.spp)
    os.makedirs(a.out, exist_ok=True)
    mask = sphere_mask(size)
    rows, table = [], []
    with tempfile.TemporaryDirectory() as tmp:
        jobs = [(label, None, spec) for label, spec in CONTROLS]
        for label, brdf, model in materials:
            script = os.path.join(a.out, f"{label}.py")
            fitted = run([halfback_cli, "fit", "--brdf", os.path.join(a.shared, brdf), "--model",
                          model, "--samples", str(a.samples), "-o",
                          os.path.join(a.out, f"{label}.json"), "--emit", f"blender:{script}"]).stdout.strip().splitlines()[-1]
            jobs.append((label, brdf, fitted))
        for label, brdf, spec in jobs:
            script = os.path.join(a.out, f"{label}.py")
            if brdf is None:
                with open(script, "w") as f:
                    f.write(halfback.emit(spec, "blender"))
            hb = halfback.load(spec).render(env=env, width=size, height=size, spp=spp)
            cy = blender_render(a.blender, script, env, os.path.join(tmp, f"{label}.npy"), size,
                                spp)
            d = relative_difference(cy, hb, mask)
            rows.append((label, hb, cy, d["relative_rmse"]))
            table.append({"material": label, "brdf": brdf, "spec": spec, **d})
            print(f"{label}: relative RMSE {100 * d['relative_rmse']:.2f} %, mean Cycles/halfback "
                  + ", ".join(f"{r:.3f}" for r in d["mean_ratio"]), flush=True)
    figure(rows, os.path.join(a.out, "blender-compare.png"))
    with open(os.path.join(a.out, "blender-compare.json"), "w") as f:
        json.dump(table, f, indent=1)
    print("\n| material | BRDF | relative RMSE | mean Cycles / halfback (r, g, b) |")
    print("|---|---|---|---|")
    for t in table:
        print(f"| {t['material']} | {os.path.basename(t['brdf']) if t['brdf'] else t['spec']} | "
              f"{100 * t['relative_rmse']:.2f} % | "
              + ", ".join(f"{r:.3f}" for r in t["mean_ratio"]) + " |")


if __name__ == "__main__":
    main()
