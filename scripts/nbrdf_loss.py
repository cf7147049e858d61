#!/usr/bin/python3
"""Sztrajman et al.'s training loss of neural BRDFs against a BRDF (docs/neural.md).

Usage: scripts/nbrdf_loss.py TARGET NETWORK... [--pairs N] [--seed S]
(with PYTHONPATH naming halfback's Python module, e.g. build/release/python)

Pairs are drawn as the authors draw them (theta_h, theta_d uniform in [0, pi/2], phi_d uniform in
[0, 2 pi), phi_h = 0), those with a direction at or below the horizon dropped, and for each
NETWORK (any BRDF spec halfback loads: a trained .h5, the authors' published one) the mean over
pairs and channels of |log(1 + rho' c) - log(1 + rho c)| is printed, rho' the network's value,
rho TARGET's, c the cosine of the view direction (the direction in the network's d). Written
here apart from the C++ trainer (NumPy), so that it checks the loss the trainer reports.
"""

import argparse

import numpy as np

import halfback


def authors_pairs(n, seed):
    rng = np.random.default_rng(seed)
    theta_h = rng.uniform(0, np.pi / 2, n)
    theta_d = rng.uniform(0, np.pi / 2, n)
    phi_d = rng.uniform(0, 2 * np.pi, n)
    d = np.stack([np.sin(theta_d) * np.cos(phi_d), np.sin(theta_d) * np.sin(phi_d), np.cos(theta_d)], 1)
    # d is the view direction in the frame of h = (sin theta_h, 0, cos theta_h): rotate it back.
    c, s = np.cos(theta_h), np.sin(theta_h)
    wo = np.stack([c * d[:, 0] + s * d[:, 2], d[:, 1], -s * d[:, 0] + c * d[:, 2]], 1)
    h = np.stack([s, np.zeros(n), c], 1)
    wi = 2 * np.sum(h * wo, 1, keepdims=True) * h - wo
    keep = (wi[:, 2] > 0) & (wo[:, 2] > 0)
    return wi[keep], wo[keep]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("target")
    parser.add_argument("networks", nargs="+")
    parser.add_argument("--pairs", type=int, default=200000, help="pairs drawn (default 200000)")
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()
    wi, wo = authors_pairs(args.pairs, args.seed)
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    cosine = np.clip(wo[:, 2], 0, 1)[:, None]
    truth = halfback.load(args.target).eval(wi, wo)
    print(f"{len(wi)} of {args.pairs} pairs drawn have both directions above the horizon")
    for spec in args.networks:
        rho = halfback.load(spec).eval(wi, wo)
        loss = np.mean(np.abs(np.log1p(rho * cosine) - np.log1p(truth * cosine)))
        print(f"{spec}: {loss:.6f}")


if __name__ == "__main__":
    main()
