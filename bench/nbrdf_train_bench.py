#!/usr/bin/python3
"""The training of a neural BRDF (docs/neural.md, "Speed"): halfback's training step against the
same step written with NumPy, in the same run, and one material trained at the default size on one
core against the authors' published network of that material.

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=build/release/python /usr/bin/python3 bench/nbrdf_train_bench.py \
        [--bench build/release/bench/halfback_neural_bench] [--halfback build/release/src/cli/halfback] \
        [--material cardboard_rgb | --no-train]

1. The step: one Adam step on a batch of 512 pairs of the authors' 6-21-21-3 network (forward
   pass, the loss mean |log(1 + rho' c) - log(1 + rho c)|, backward pass, Adam in Keras's form),
   timed by halfback_neural_bench (BM_TrainStep/1: one thread; BM_ForwardOnly its own baseline)
   and by a NumPy restatement of the same step in float64 (this file), whose gradient is first
   checked against central differences. Both report CPU time per step; NumPy on one BLAS thread
   (set OPENBLAS_NUM_THREADS=1, as above, for a one-core comparison).
2. The material (unless --no-train): `halfback nbrdf train --threads 1` on ../shared/data/rgl/
   MATERIAL.bsdf at the default size and settings, its CPU and wall time, and the study's log
   error of the result and of the published network against the RGL file (`halfback compare`).
"""

import argparse
import json
import os
import pathlib
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
WIDTHS = [6, 21, 21, 3]
BATCH = 512


def init(rng):
    """Keras's random_uniform(-0.05, 0.05) kernels, zero biases (the authors' initialization)."""
    return [(rng.uniform(-0.05, 0.05, (a, b)), np.zeros(b)) for a, b in zip(WIDTHS[:-1], WIDTHS[1:])]


def loss_and_grad(params, x, target, c):
    """The mean over the batch and 3 channels of |log(1 + rho' c) - log(1 + rho c)| and its
    gradient; rho' = exp(y) - 1, y the last (linear) layer, ReLU between."""
    acts = [x]
    for i, (w, b) in enumerate(params):
        z = acts[-1] @ w + b
        acts.append(z if i == len(params) - 1 else np.maximum(z, 0))
    y = acts[-1]
    ey = np.exp(y)
    pred = np.log1p((ey - 1) * c)
    diff = pred - np.log1p(target * c)
    n = diff.size
    loss = np.abs(diff).sum() / n
    dy = np.sign(diff) * c * ey / (1 + (ey - 1) * c) / n
    grads = []
    for i in range(len(params) - 1, -1, -1):
        w, _ = params[i]
        grads.append((acts[i].T @ dy, dy.sum(0)))
        if i:
            dy = (dy @ w.T) * (acts[i] > 0)
    return loss, grads[::-1]


class Adam:
    """Keras 2.2's Adam: lr_t = lr sqrt(1 - b2^t) / (1 - b1^t), p -= lr_t m / (sqrt(v) + eps)."""

    def __init__(self, params, lr=5e-4, b1=0.9, b2=0.999, eps=1e-7):
        self.lr, self.b1, self.b2, self.eps, self.t = lr, b1, b2, eps, 0
        self.m = [(np.zeros_like(w), np.zeros_like(b)) for w, b in params]
        self.v = [(np.zeros_like(w), np.zeros_like(b)) for w, b in params]

    def step(self, params, grads):
        self.t += 1
        lr_t = self.lr * np.sqrt(1 - self.b2**self.t) / (1 - self.b1**self.t)
        for layer, grad in enumerate(grads):
            for j in range(2):
                g = grad[j]
                m, v = self.m[layer][j], self.v[layer][j]
                m *= self.b1
                m += (1 - self.b1) * g
                v *= self.b2
                v += (1 - self.b2) * g * g
                params[layer][j][...] -= lr_t * m / (np.sqrt(v) + self.eps)


def batch_data(rng):
    """A batch of the authors' pairs of a GGX (as the C++ benchmark's), encoded as their input."""
    import halfback

    th, td, pd = rng.uniform(0, np.pi / 2, 4 * BATCH), rng.uniform(0, np.pi / 2, 4 * BATCH), rng.uniform(0, 2 * np.pi, 4 * BATCH)
    d = np.stack([np.sin(td) * np.cos(pd), np.sin(td) * np.sin(pd), np.cos(td)], 1)
    cs, sn = np.cos(th), np.sin(th)
    wo = np.stack([cs * d[:, 0] + sn * d[:, 2], d[:, 1], -sn * d[:, 0] + cs * d[:, 2]], 1)
    h = np.stack([sn, np.zeros_like(sn), cs], 1)
    wi = 2 * np.sum(h * wo, 1, keepdims=True) * h - wo
    keep = (wi[:, 2] > 0) & (wo[:, 2] > 0)
    wi, wo, h, d = wi[keep][:BATCH], wo[keep][:BATCH], h[keep][:BATCH], d[keep][:BATCH]
    x = np.concatenate([h, d], 1)
    target = halfback.load("ggx:alpha=0.3").eval(wi, wo)
    c = np.clip(h[:, 2] * d[:, 2] - h[:, 0] * d[:, 0], 0, 1)[:, None]
    return x, target, c


def gradient_check(params, x, target, c):
    """The largest difference of the analytic gradient from central differences, relative to the
    gradient's largest component, over every parameter."""
    _, grads = loss_and_grad(params, x, target, c)
    worst, scale = 0.0, max(np.abs(g).max() for pair in grads for g in pair)
    for layer in range(len(params)):
        for j in range(2):
            p = params[layer][j]
            for idx in np.ndindex(p.shape):
                keep = p[idx]
                p[idx] = keep + 1e-6
                up, _ = loss_and_grad(params, x, target, c)
                p[idx] = keep - 1e-6
                down, _ = loss_and_grad(params, x, target, c)
                p[idx] = keep
                worst = max(worst, abs((up - down) / 2e-6 - grads[layer][j][idx]))
    return worst / scale


def numpy_step_time(repeats):
    rng = np.random.default_rng(2)
    x, target, c = batch_data(rng)
    params = init(rng)
    check = gradient_check([(w.copy(), b.copy()) for w, b in params], x, target, c)
    adam = Adam(params)
    for _ in range(20):  # warm-up
        adam.step(params, loss_and_grad(params, x, target, c)[1])
    cpu0, wall0 = time.process_time(), time.perf_counter()
    for _ in range(repeats):
        adam.step(params, loss_and_grad(params, x, target, c)[1])
    return (time.process_time() - cpu0) / repeats, (time.perf_counter() - wall0) / repeats, check


def cpp_step_times(bench):
    out = subprocess.run([bench, "--benchmark_filter=BM_TrainStep/1|BM_ForwardOnly", "--benchmark_format=json",
                          "--benchmark_repetitions=3", "--benchmark_report_aggregates_only=true"],
                         capture_output=True, text=True, check=True).stdout
    times = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("aggregate_name") == "median":
            unit = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]]
            times[b["run_name"]] = (b["cpu_time"] * unit, b["real_time"] * unit)
    return times


def train_material(exe, material):
    rgl = ROOT.parent / "shared/data/rgl" / f"{material}.bsdf"
    published = ROOT.parent / "shared/data/nbrdf/rgl-isotropic_nbrdf" / f"{material}.h5"
    with tempfile.TemporaryDirectory() as tmp:
        net = pathlib.Path(tmp) / f"{material}.h5"
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        wall = time.perf_counter()
        summary = subprocess.run([exe, "nbrdf", "train", "--brdf", str(rgl), "-o", str(net), "--threads", "1", "-q"],
                                 capture_output=True, text=True, check=True).stdout.strip()
        wall = time.perf_counter() - wall
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
        errors = {}
        for label, spec in (("halfback", net), ("published", published)):
            path = pathlib.Path(tmp) / f"{label}.json"
            subprocess.run([exe, "compare", str(rgl), str(spec), "--json", str(path)], capture_output=True, check=True)
            errors[label] = json.loads(path.read_text())["study_errors"]["values"]["log"]
    return summary, cpu, wall, errors


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--bench", default=str(ROOT / "build/release/bench/halfback_neural_bench"))
    parser.add_argument("--halfback", default=str(ROOT / "build/release/src/cli/halfback"))
    parser.add_argument("--material", default="cardboard_rgb")
    parser.add_argument("--no-train", action="store_true")
    parser.add_argument("--repeats", type=int, default=300)
    args = parser.parse_args()
    if os.environ.get("OPENBLAS_NUM_THREADS") != "1":
        print("note: OPENBLAS_NUM_THREADS is not 1: NumPy may use more than one core", file=sys.stderr)

    cpp = cpp_step_times(args.bench)
    np_cpu, np_wall, check = numpy_step_time(args.repeats)
    if check > 1e-5:
        sys.exit(f"the NumPy step's gradient differs from central differences by {check:.2g} of its largest component")
    step_cpu, step_wall = cpp["BM_TrainStep/1/real_time"] if "BM_TrainStep/1/real_time" in cpp else cpp["BM_TrainStep/1"]
    fwd_cpu, fwd_wall = cpp.get("BM_ForwardOnly/real_time", cpp.get("BM_ForwardOnly", (float("nan"),) * 2))
    print(f"training step, batch {BATCH}, 6-21-21-3, one thread (CPU / wall per step):")
    print(f"  halfback (C++, Eigen, double)  {step_cpu * 1e3:.3f} ms / {step_wall * 1e3:.3f} ms")
    print(f"  halfback forward pass only     {fwd_cpu * 1e3:.3f} ms / {fwd_wall * 1e3:.3f} ms")
    print(f"  NumPy (float64, same step)     {np_cpu * 1e3:.3f} ms / {np_wall * 1e3:.3f} ms "
          f"(gradient within {check:.1g} of central differences)")
    print(f"  NumPy / halfback: {np_cpu / step_cpu:.2f}x CPU time")
    if not args.no_train:
        summary, cpu, wall, errors = train_material(args.halfback, args.material)
        print(f"\n{summary}")
        print(f"{args.material}: {cpu:.1f} s CPU, {wall:.1f} s wall on one thread; study log error "
              f"{errors['halfback']:.4f} against the published network's {errors['published']:.4f}")


if __name__ == "__main__":
    main()
