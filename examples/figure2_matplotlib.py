#!/usr/bin/env python3
"""Figure 2 of Barla et al. 2015 with matplotlib, from halfback's arrays.

The paper's test functions S = 1 - |h_bar| (red), G = 1 - (wi.n)(wo.n) (blue) and
F = 1 - cos(theta_d) (white) as isolines on 2D slices of the isotropic forms of halfdiff, ortho
and hybrid at relative azimuths 0, 45 and 90 degrees; grey where no pair of directions has those
coordinates.

    PYTHONPATH=build/release/python /usr/bin/python3 examples/figure2_matplotlib.py fig2.png
"""

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import halfback  # noqa: E402

PARAMS = ["halfdiff", "ortho", "hybrid"]
AZIMUTHS = [0, 45, 90]
FUNCTIONS = [("S", "tab:red"), ("G", "tab:blue"), ("F", "white")]
LEVELS = np.arange(0.1, 1.0, 0.1)
AXIS_LABELS = {"theta_h": r"$\theta_h$", "theta_d": r"$\theta_d$", "hbar": r"$\|\bar h\|$",
               "kbar": r"$\|\bar k\|$", "k": r"$\|k\|$"}


def main(out, size=201):
    fig, axes = plt.subplots(3, 3, figsize=(10, 10), constrained_layout=True)
    for row, param in enumerate(PARAMS):
        for col, azimuth in enumerate(AZIMUTHS):
            ax = axes[row, col]
            ax.set_facecolor("0.8")  # outside the domain
            for letter, colour in FUNCTIONS:
                t = halfback.load(f"test:{letter}").resample(param, "slice", size,
                                                            azimuth=np.radians(azimuth),
                                                            nodes=True)
                x, y = t["axes"]
                values = np.where(t["valid"], t["rho"][..., 0], np.nan)
                if letter == "S":  # the domain, once per panel
                    ax.pcolormesh(x, y, np.where(t["valid"], 0.0, np.nan).T, cmap="gray",
                                  vmin=0, vmax=8, shading="nearest")
                ax.contour(x, y, values.T, levels=LEVELS, colors=colour, linewidths=0.8)
            names = t["axis_names"]
            ax.set_xlabel(AXIS_LABELS[names[0]])
            ax.set_ylabel(AXIS_LABELS[names[1]])
            ax.set_title(f"{param}, azimuth {azimuth}°", fontsize=10)
            ax.set_aspect("equal")
    fig.suptitle("S (red), G (blue), F (white) on slices of the isotropic forms")
    fig.savefig(out, dpi=80)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "fig2-matplotlib.png")
