#!/usr/bin/python3
"""halfback's fit against the same fit written with SciPy's least_squares, measured in the same run
(docs/performance.md, "Fitting").

    PYTHONPATH=build/release/python /usr/bin/python3 bench/fit_scipy_bench.py [--samples N]

The fit: Lambert + GGX (albedo_r/g/b, alpha, f0_r/g/b) to the embedded neural BRDF
gold-metallic-paint3 under Ngan's loss, on fit()'s layout of N pairs (halfback.fit_samples), one
thread. SciPy's model is written with NumPy and checked against halfback's own evaluation of the
same spec (to 1e-12 relative) before anything is timed; its residuals are those of docs/fit.md.
Both start from the same points: the registry's defaults, the roughness of the target's peak
width, and the grid of 5 roughnesses (docs/fit.md, "Starts"). SciPy runs twice:

  plain     every start on all N samples (what a SciPy user writes first);
  strategy  halfback's strategy: every start on the first 4096 samples, the best one again on all.

Needs python3-scipy (Debian), for this benchmark only.
"""

import argparse
import math
import time

import numpy as np
from scipy.optimize import least_squares

import halfback

TARGET = "embedded:gold-metallic-paint3"
COARSE = 4096
LO = np.array([0, 0, 0, 1e-3, 0, 0, 0], dtype=float)
HI = np.array([1, 1, 1, 10, 1, 1, 1], dtype=float)


def lambert_ggx(x, wi, wo):
    """ρ of lambert:albedo_r/g/b + ggx:alpha,f0_r/g/b (Schlick, Smith height-correlated G2)."""
    albedo, alpha, f0 = x[0:3], x[3], x[4:7]
    h = wi + wo
    h2 = np.einsum("ij,ij->i", h, h)
    inv_a2 = 1 / (alpha * alpha)
    q = (h[:, 0] ** 2 + h[:, 1] ** 2) * inv_a2 + h[:, 2] ** 2
    li = np.sqrt(alpha**2 * (wi[:, 0] ** 2 + wi[:, 1] ** 2) + wi[:, 2] ** 2)
    lo = np.sqrt(alpha**2 * (wo[:, 0] ** 2 + wo[:, 1] ** 2) + wo[:, 2] ** 2)
    cos_d = np.einsum("ij,ij->i", wi, h) / np.sqrt(h2)
    scalar = h2 * h2 / (math.pi * alpha * alpha) / (2 * q * q * (li * wo[:, 2] + lo * wi[:, 2]))
    m = 1 - np.clip(cos_d, 0, 1)
    m5 = m**5
    fresnel = f0[None, :] + (1 - f0[None, :]) * m5[:, None]
    return albedo[None, :] / math.pi + fresnel * scalar[:, None]


def residuals(x, wi, wo, t, c_sw):
    """Ngan's residuals, sqrt(w) cos θi (ρ − t) per sample and channel (docs/fit.md)."""
    return ((lambert_ggx(x, wi, wo) - t) * c_sw[:, None]).ravel()


def peak_roughness(target):
    """The start from the data: as fit.cpp's roughness_from_peak (θh from 0 to 85°, θd = 0)."""
    th = np.radians(np.arange(86))
    w = np.stack([np.sin(th), np.zeros_like(th), np.cos(th)], axis=1)
    lum = target.eval(w, w).mean(axis=1)
    floor, height = lum.min(), lum[0] - lum.min()
    if not height > 0 or lum.max() > lum[0]:
        return None
    for deg in range(1, 86):
        if lum[deg] - floor <= height / 2:
            return math.tan(math.radians(deg)) / math.sqrt(math.sqrt(2) - 1)
    return None


def starts(target):
    default = np.array([0.5, 0.5, 0.5, 0.2, 0.04, 0.04, 0.04])
    out = [default]
    alpha = peak_roughness(target)
    if alpha is not None:
        out.append(default.copy())
        out[-1][3] = min(max(alpha, LO[3]), HI[3])
    for q in (0.1, 0.3, 0.5, 0.7, 0.9):
        out.append(default.copy())
        out[-1][3] = math.exp(math.log(LO[3]) + q * (math.log(HI[3]) - math.log(LO[3])))
    return out


def solve(x0, wi, wo, t, c_sw):
    r = least_squares(residuals, x0, bounds=(LO, HI), args=(wi, wo, t, c_sw), method="trf",
                      jac="2-point", x_scale="jac", ftol=1e-9, xtol=1e-10, gtol=1e-12,
                      max_nfev=2000)
    return r.x, float(np.mean(r.fun**2)), r.nfev


def scipy_plain(x0s, wi, wo, t, c_sw):
    best = min((solve(x0, wi, wo, t, c_sw) for x0 in x0s), key=lambda s: s[1])
    return best[0], best[1]


def scipy_strategy(x0s, wi, wo, t, w, c):
    k = COARSE
    cw = np.sqrt(w[:k] * (k / w[:k].sum())) * c[:k]
    coarse = min((solve(x0, wi[:k], wo[:k], t[:k], cw) for x0 in x0s), key=lambda s: s[1])
    x, loss, _ = solve(coarse[0], wi, wo, t, np.sqrt(w) * c)
    return x, loss


def spec_of(x):
    return (f"lambert:albedo_r={x[0]!r},albedo_g={x[1]!r},albedo_b={x[2]!r}"
            f"+ggx:alpha={x[3]!r},f0_r={x[4]!r},f0_g={x[5]!r},f0_b={x[6]!r}")


def check_model(wi, wo):
    x = np.array([0.1, 0.2, 0.3, 0.15, 0.9, 0.5, 0.05])
    ours = lambert_ggx(x, wi, wo)
    theirs = halfback.load(spec_of(x)).eval(wi, wo)
    err = np.max(np.abs(ours - theirs) / np.maximum(np.abs(theirs), 1e-300))
    assert err < 1e-12, f"the NumPy model differs from halfback's by {err:.3g} relative"


def timed(f, *args):
    t0 = time.perf_counter()
    out = f(*args)
    return out, time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--samples", type=int, default=100000)
    a = ap.parse_args()
    target = halfback.load(TARGET)
    s = halfback.fit_samples(a.samples)
    wi, wo, w, c = s["wi"], s["wo"], s["weight"], s["cos_i"]
    check_model(wi, wo)
    t = target.eval(wi, wo)
    x0s = starts(target)

    ours, t_ours = timed(halfback.fit, TARGET, "lambert+ggx", "ngan", a.samples, 1)
    (x_plain, l_plain), t_plain = timed(scipy_plain, x0s, wi, wo, t, np.sqrt(w) * c)
    (x_strat, l_strat), t_strat = timed(scipy_strategy, x0s, wi, wo, t, w, c)
    # Each loss as halfback measures it, so that the three are comparable to the last digit.
    lp = halfback.fit_loss(TARGET, spec_of(x_plain), "ngan", a.samples, 1)
    ls = halfback.fit_loss(TARGET, spec_of(x_strat), "ngan", a.samples, 1)
    print(f"{a.samples} samples, {len(x0s)} starts, one thread")
    print("| fit | seconds | loss | halfback faster by |")
    print("|---|---|---|---|")
    print(f"| halfback.fit | {t_ours:.3f} | {ours['loss_value']:.7g} | |")
    print(f"| SciPy, plain | {t_plain:.3f} | {lp:.7g} | {t_plain / t_ours:.1f}x |")
    print(f"| SciPy, halfback's strategy | {t_strat:.3f} | {ls:.7g} | {t_strat / t_ours:.1f}x |")
    # The target through Python is evaluated in batches, fit() per pair: a neural BRDF in float32
    # differs at 1e-8 between the two, and so do the losses.
    assert abs(l_plain - lp) <= 1e-6 * lp and abs(l_strat - ls) <= 1e-6 * ls, "losses disagree"


if __name__ == "__main__":
    main()
