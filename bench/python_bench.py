#!/usr/bin/env python3
"""halfback from Python against the NumPy code a researcher would write, and against the C++
batch path, measured in the same run (docs/performance.md, "Through Python").

    PYTHONPATH=build/release/python /usr/bin/python3 bench/python_bench.py [--pairs N]
        [--conversions-only | --layouts-only]

Conversions dirs -> hybrid and hybrid -> dirs on N pairs (default 10^7), float64 and float32,
C-order (NumPy's default) and Fortran-order arrays, a new result and out=, alternated;
BRDF evaluation of a MERL table (nearest bin; NumPy: the reference lookup written with arrays)
and of an RGL material. The C++ figures come from build/release/bench/halfback_bench and
halfback_brdf_bench run by this script.

--layouts-only: C order against Fortran order alone (no NumPy, no C++), dirs <-> hybrid and
halfdiff, both precisions, a new result and out=, alternated ("Array layouts").
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

import halfback

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def best_of(f, repeat=3):
    # Process CPU time (all threads): on a shared machine, wall time counts the other processes.
    times = []
    for _ in range(repeat):
        t0 = time.process_time()
        f()
        times.append(time.process_time() - t0)
    return min(times)


def random_pairs(n, dtype):
    rng = np.random.default_rng(2015)
    z = rng.random((n, 2))
    phi = 2 * np.pi * rng.random((n, 2))
    s = np.sqrt(1 - z * z)
    x = np.stack([s[:, 0] * np.cos(phi[:, 0]), s[:, 0] * np.sin(phi[:, 0]), z[:, 0],
                  s[:, 1] * np.cos(phi[:, 1]), s[:, 1] * np.sin(phi[:, 1]), z[:, 1]], axis=1)
    return x.astype(dtype)


def numpy_hybrid(x):
    h = (x[:, 0:3] + x[:, 3:6]) / 2
    k = (x[:, 0:3] - x[:, 3:6]) / 2
    return np.stack([np.hypot(h[:, 0], h[:, 1]), np.mod(np.arctan2(h[:, 1], h[:, 0]), 2 * np.pi),
                     np.linalg.norm(k, axis=1), np.mod(np.arctan2(k[:, 1], k[:, 0]), 2 * np.pi)],
                    axis=1)


def numpy_hybrid_inverse(q):
    # h̄ and k from the coordinates; h_z from |h|² + |k|² = 1 and h·k = 0 (docs/math.md).
    hbar, phih, kn, phik = q.T
    hx, hy = hbar * np.cos(phih), hbar * np.sin(phih)
    hz = np.sqrt(np.maximum(1 - kn * kn - hbar * hbar, 0))
    # k = kbar (cos phik, sin phik) + kz n with h·k = 0 and |k| = kn.
    c = hx * np.cos(phik) + hy * np.sin(phik)
    a = c * c + hz * hz
    kbar = np.where(a > 0, kn * hz / np.sqrt(np.where(a > 0, a, 1)), kn)
    kx, ky = kbar * np.cos(phik), kbar * np.sin(phik)
    kz = np.where(hz > 0, -(hx * kx + hy * ky) / np.where(hz > 0, hz, 1), 0)
    return np.stack([hx + kx, hy + ky, hz + kz, hx - kx, hy - ky, hz - kz], axis=1)


def numpy_merl_nearest(table, x):
    # The reference reader's nearest-bin lookup with arrays: half and difference angles, bins,
    # φd folded to [0, π).
    wi, wo = x[:, 0:3], x[:, 3:6]
    h = wi + wo
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    th = np.arccos(np.clip(h[:, 2], -1, 1))
    ph = np.arctan2(h[:, 1], h[:, 0])
    # d = rot_b(-θh) rot_n(-φh) wi
    c, s = np.cos(-ph), np.sin(-ph)
    t = np.stack([c * wi[:, 0] - s * wi[:, 1], s * wi[:, 0] + c * wi[:, 1], wi[:, 2]], axis=1)
    c, s = np.cos(-th), np.sin(-th)
    d = np.stack([c * t[:, 0] + s * t[:, 2], t[:, 1], -s * t[:, 0] + c * t[:, 2]], axis=1)
    td = np.arccos(np.clip(d[:, 2], -1, 1))
    pd = np.arctan2(d[:, 1], d[:, 0])
    pd = np.where(pd < 0, pd + np.pi, pd)
    ith = np.clip((np.sqrt(th / (np.pi / 2)) * 90).astype(np.int64), 0, 89)
    itd = np.clip((td / (np.pi / 2) * 90).astype(np.int64), 0, 89)
    ipd = np.clip((pd / np.pi * 180).astype(np.int64), 0, 179)
    idx = (ith * 90 + itd) * 180 + ipd
    scale = np.array([1 / 1500, 1.15 / 1500, 1.66 / 1500])
    return table[:, idx].T * scale


def cxx_ns_per_pair(binary, filt, pairs, counter="s_per_pair"):
    env = dict(os.environ, HALFBACK_BENCH_PAIRS=str(pairs))
    out = subprocess.run([binary, f"--benchmark_filter={filt}", "--benchmark_min_time=0.3"],
                         capture_output=True, text=True, check=True, env=env).stdout
    result = {}
    for line in out.splitlines():
        m = re.match(r"(\S+)\s.*" + counter + r"=([\d.]+)([munkMG]?)s\b", line)
        if m:
            v = float(m.group(2)) * {"": 1, "m": 1e-3, "u": 1e-6, "n": 1e-9, "k": 1e3,
                                      "M": 1e6, "G": 1e9}[m.group(3)]
            result[m.group(1)] = v
    return result


def time_layouts(xc, src, dst, dim, dtype, n, repeat=3):
    """Seconds per pair of halfback.convert on C-order and Fortran-order arrays, a new result
    (for Fortran order: out= a fresh Fortran array, so that both pay the allocation) and out=."""
    xf = np.asfortranarray(xc)
    outc, outf = np.empty((n, dim), dtype), np.empty((n, dim), dtype, order="F")
    # The two layouts alternate, so that they share the machine's varying load.
    t = {"c": [], "c_out": [], "f": [], "f_out": []}
    for _ in range(repeat):
        t["c"].append(best_of(lambda: halfback.convert(xc, src, dst), 1))
        t["f"].append(best_of(
            lambda: halfback.convert(xf, src, dst, out=np.empty((n, dim), dtype, order="F")), 1))
        t["c_out"].append(best_of(lambda: halfback.convert(xc, src, dst, out=outc), 1))
        t["f_out"].append(best_of(lambda: halfback.convert(xf, src, dst, out=outf), 1))
    return {k: min(v) / n for k, v in t.items()}


def layouts(n):
    print(f"# halfback.convert, C order against Fortran order, {n} pairs, {os.cpu_count()} cores\n")
    print("| conversion | C order | F order | C / F | C order, out= | F order, out= | C / F, out= |")
    print("|---|---|---|---|---|---|---|")
    for dtype, tname in [(np.float64, "double"), (np.float32, "float")]:
        x = random_pairs(n, dtype)
        for space in ["hybrid", "halfdiff"]:
            q = halfback.convert(x, "dirs", space)
            for src, dst, xc, dim in [("dirs", space, x, 4), (space, "dirs", q, 6)]:
                t = time_layouts(xc, src, dst, dim, dtype, n)
                print(f"| {src} -> {dst}, {tname} | {t['c'] * 1e9:.1f} ns | {t['f'] * 1e9:.1f} ns | "
                      f"{t['c'] / t['f']:.2f}× | {t['c_out'] * 1e9:.1f} ns | "
                      f"{t['f_out'] * 1e9:.1f} ns | {t['c_out'] / t['f_out']:.2f}× |", flush=True)
            del q
        del x
    return 0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--pairs", type=int, default=10_000_000)
    ap.add_argument("--build", default=os.path.join(ROOT, "build", "release"))
    ap.add_argument("--conversions-only", action="store_true", help="skip the BRDF evaluations")
    ap.add_argument("--layouts-only", action="store_true",
                    help="only C order against Fortran order, hybrid and halfdiff")
    a = ap.parse_args()
    n = a.pairs
    if a.layouts_only:
        return layouts(n)
    print(f"# halfback through Python, {n} pairs, {os.cpu_count()} cores\n")
    print("| operation | NumPy | C order | C order, out= | F order | F order, out= | "
          "C++ batch (SoA) | vs NumPy | C / F order | C / F order, out= |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    cxx = cxx_ns_per_pair(os.path.join(a.build, "bench", "halfback_bench"),
                          r"^(forward|inverse)/hybrid/(float|double)/threads:[0-9]+/", n)
    threads = os.cpu_count()
    # halfback_bench's name suffix: wall time and process CPU time for several threads, CPU time
    # for one.
    timing = "/process_time/real_time" if threads > 1 else ""
    for dtype, tname in [(np.float64, "double"), (np.float32, "float")]:
        x = random_pairs(n, dtype)
        q = halfback.convert(x, "dirs", "hybrid")
        # C order (NumPy's default): rows of 6 and 4 values; Fortran order hands the engine
        # contiguous columns (its SoA path).
        cases = [("dirs -> hybrid", x, "dirs", "hybrid", 4, lambda: numpy_hybrid(x),
                  f"forward/hybrid/{tname}/threads:{threads}{timing}"),
                 ("hybrid -> dirs", q, "hybrid", "dirs", 6, lambda: numpy_hybrid_inverse(q),
                  f"inverse/hybrid/{tname}/threads:{threads}{timing}")]
        for label, xc, src, dst, dim, fnp, key in cases:
            t_np = best_of(fnp) / n
            t = time_layouts(xc, src, dst, dim, dtype, n)
            t_cxx = cxx.get(key, float("nan"))
            print(f"| {label}, {tname} | {t_np * 1e9:.1f} ns | {t['c'] * 1e9:.1f} ns | "
                  f"{t['c_out'] * 1e9:.1f} ns | {t['f'] * 1e9:.1f} ns | {t['f_out'] * 1e9:.1f} ns | "
                  f"{t_cxx * 1e9:.1f} ns | {t_np / t['c']:.1f}× faster | {t['c'] / t['f']:.2f}× | "
                  f"{t['c_out'] / t['f_out']:.2f}× |")
        del x, q
    if a.conversions_only:
        return 0
    # BRDF evaluation.
    x = random_pairs(n, np.float64)
    with tempfile.TemporaryDirectory() as tmp:
        merl_path = os.path.join(tmp, "ggx.binary")
        subprocess.run([os.path.join(a.build, "src", "cli", "halfback"), "export-merl", "--brdf",
                        "lambert:albedo=0.3+ggx:alpha=0.15,f0=0.5", "-o", merl_path], check=True,
                       capture_output=True)
        raw = np.fromfile(merl_path, dtype="<f8", offset=12).reshape(3, -1)
        merl = halfback.load(merl_path)
        t_np = best_of(lambda: numpy_merl_nearest(raw, x), 1) / n
        t_hb = best_of(lambda: merl.eval(x), 1) / n
        agree = np.abs(numpy_merl_nearest(raw, x[:100000]) - merl.eval(x[:100000]))
        print(f"| MERL nearest bin | {t_np * 1e9:.1f} ns | {t_hb * 1e9:.1f} ns | | | | | "
              f"{t_np / t_hb:.1f}× faster | | |")
        print(f"\n(The NumPy MERL lookup and halfback's give different values on "
              f"{(agree.max(axis=1) > 0).mean():.3%} of 10^5 pairs.)")
    rgl = halfback.load("embedded:ilm_l3_37_metallic")
    t_hb = best_of(lambda: rgl.eval(x), 1) / n
    print(f"| RGL metallic paint | — | {t_hb * 1e9:.1f} ns | | | | | | | |")


if __name__ == "__main__":
    sys.exit(main())
