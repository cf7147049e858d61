#!/usr/bin/env python3
"""A BRDF written in Python, shown in the explorer (docs/view.md, "From Python").

    PYTHONPATH=build/release/python python3 examples/view_python_brdf.py

prints the page's URL and serves until Ctrl-C. The function is checked before it is served
(shape, finite values, reciprocity, isotropy, energy): edit it to break one, and the ValueError
names the check."""

import numpy as np

import halfback


def blinn(wi, wo):
    """Lambert plus a normalized Blinn-Phong lobe of exponent 20, RGB."""
    h = wi + wo
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    lobe = 0.3 * (20 + 8) / (8 * np.pi) * np.clip(h[:, 2], 0, 1) ** 20
    return np.stack([0.5 / np.pi + lobe, 0.3 / np.pi + lobe, 0.2 / np.pi + lobe], axis=1)


if __name__ == "__main__":
    viewer = halfback.view(blinn, "ggx:alpha=0.2,f0=0.9")
    print(f"halfback view: serving on {viewer.url}", flush=True)
    try:
        viewer.wait()
    except KeyboardInterrupt:
        viewer.stop()
