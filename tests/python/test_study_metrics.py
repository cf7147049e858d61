"""The study's SSIM against a NumPy port of Wang et al. 2004 on a fixed pair of images, and
halfback.image_error, the study's image-space error of one BRDF against another."""

import os
import pathlib

import numpy as np
import pytest

import halfback


def gaussian_window(radius=5, sigma=1.5):
    """The 11 x 11 Gaussian of Wang et al. 2004, normalized to sum 1."""
    t = np.arange(-radius, radius + 1, dtype=np.float64)
    g = np.exp(-(t**2) / (2 * sigma**2))
    g /= g.sum()
    return np.outer(g, g)


def filter_valid(image, window):
    """The window's weighted sums at every pixel where it lies inside the image."""
    size = window.shape[0]
    views = np.lib.stride_tricks.sliding_window_view(image, (size, size))
    return np.einsum("ijkl,kl->ij", views, window)


def ssim_numpy(x, y, mask=None):
    """SSIM map on the full windows (K1 = 0.01, K2 = 0.03, L = 1), mean over the mask there."""
    c1, c2 = 0.01**2, 0.03**2
    w = gaussian_window()
    mx, my = filter_valid(x, w), filter_valid(y, w)
    vx = filter_valid(x * x, w) - mx * mx
    vy = filter_valid(y * y, w) - my * my
    cxy = filter_valid(x * y, w) - mx * my
    numerator = (2 * mx * my + c1) * (2 * cxy + c2)
    ssim_map = numerator / ((mx**2 + my**2 + c1) * (vx + vy + c2))
    if mask is None:
        return float(ssim_map.mean())
    r = w.shape[0] // 2
    inner = mask[r : mask.shape[0] - r, r : mask.shape[1] - r] != 0
    return float(ssim_map[inner].mean())


def fixed_pair():
    """A reference with smooth structure and edges, and a blurred, noisy, shifted copy."""
    v, u = np.mgrid[0:48, 0:40] / 40.0
    reference = 0.5 + 0.3 * np.sin(7 * u) * np.cos(5 * v) + 0.15 * (u + v > 0.9)
    rng = np.random.default_rng(20040401)
    noise = 0.04 * rng.standard_normal(reference.shape)
    test = 0.9 * np.roll(reference, 1, axis=1) + 0.05 + noise
    return np.clip(test, 0, 1), np.clip(reference, 0, 1)


def test_ssim_matches_a_numpy_port():
    test, reference = fixed_pair()
    expected = ssim_numpy(test, reference)
    assert 0.3 < expected < 0.99  # a pair that is neither equal nor unrelated
    assert halfback.ssim(test, reference) == pytest.approx(expected, rel=1e-12, abs=1e-12)
    # Symmetric, and 1 for equal images.
    assert halfback.ssim(reference, test) == pytest.approx(expected, rel=1e-12)
    assert halfback.ssim(reference, reference) == pytest.approx(1.0, abs=1e-12)


def test_ssim_mask_selects_the_pixels():
    test, reference = fixed_pair()
    mask = np.zeros(reference.shape, dtype=np.uint8)
    mask[10:30, 8:20] = 1
    assert halfback.ssim(test, reference, mask) == pytest.approx(
        ssim_numpy(test, reference, mask), rel=1e-12
    )


def test_ssim_refuses_bad_input():
    test, reference = fixed_pair()
    with pytest.raises(ValueError, match="same shape"):
        halfback.ssim(test, reference[:-1])
    with pytest.raises(ValueError, match="window"):
        halfback.ssim(test[:8, :8], reference[:8, :8])
    with pytest.raises(ValueError, match="mask"):
        halfback.ssim(test, reference, np.ones((3, 3)))


def test_image_error_is_the_brdf_error_not_noise():
    # Environment sampling with the same random numbers: a Lambertian 10 % brighter is 10 % off
    # at every pixel, whatever the noise of each rendering; a BRDF against itself is exact.
    for env in ("sky", "studio"):
        e = halfback.image_error("lambert:albedo=0.55", "lambert:albedo=0.5", env=env)
        assert e["relative_rmse"] == pytest.approx(0.1, abs=1e-7)  # float pixels
        assert e["pixels"] > 0
    same = halfback.image_error("embedded:pink-felt", halfback.load("embedded:pink-felt"))
    assert same["relative_rmse"] == 0 and same["mean_delta_e2000"] == 0 and same["ssim"] == 1
    small = halfback.image_error("ggx:alpha=0.21", "ggx:alpha=0.2", settings={"image_size": 64})
    assert 0 < small["relative_rmse"] < 0.2 and small["ssim"] < 1


def test_image_error_refuses_bad_input():
    with pytest.raises(ValueError, match="environment 'nope'"):
        halfback.image_error("lambert", "lambert", env="nope")
    with pytest.raises(ValueError, match=">= 8 pixels"):
        halfback.image_error("lambert", "lambert", settings={"image_size": -3})


def test_image_error_refuses_a_reference_without_values_somewhere():
    # An ALTA file measured at a few incidence angles only has no value elsewhere: no truth to
    # compare with (the study skips such images too).
    alta = pathlib.Path(os.environ.get("HALFBACK_SHARED_DIR", "/nonexistent")) / "data" / "alta"
    path = alta / "retro-3M-jaune.dat"
    if not path.exists():
        pytest.skip("../shared/data/alta not found (set HALFBACK_SHARED_DIR)")
    with pytest.raises(ValueError, match="retro-3M-jaune gave [0-9]+ values that are not finite"):
        halfback.image_error("lambert", str(path))
