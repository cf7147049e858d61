"""Neural BRDFs through halfback.load, against NumPy evaluating the same weights.

NumPy reads the authors' .npy form of blue-acrylic and runs the network in float32 (the encoding
of docs/formats.md, "Neural BRDFs", written here independently); halfback reads both the .npy
form and the Keras .h5 file. h5py is not available, so the .h5 is checked through the .npy path.
"""

import os
import pathlib

import numpy as np
import pytest

import halfback

SHARED = pathlib.Path(os.environ.get("HALFBACK_SHARED_DIR", "/nonexistent")) / "data" / "nbrdf"
MERL = SHARED / "merl_nbrdf"


def require_shared():
    if not (MERL / "npy" / "blue-acrylic_fc1.npy").exists():
        if os.environ.get("CI") == "true":
            pytest.fail("../shared/data/nbrdf is missing under CI")
        pytest.skip("../shared/data/nbrdf not found (set HALFBACK_SHARED_DIR)")


def random_pairs(n, seed):
    rng = np.random.default_rng(seed)

    def dirs():
        z = 0.02 + 0.98 * rng.random(n)
        phi = 2 * np.pi * rng.random(n)
        s = np.sqrt(1 - z * z)
        return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)

    return dirs(), dirs()


def numpy_network_input(wi, wo):
    """(sin th, 0, cos th, d) with d = wo (the view direction) in the frame of the half vector."""
    h = wi + wo
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    theta_h = np.arccos(np.clip(h[:, 2], -1, 1))
    phi_h = np.arctan2(h[:, 1], h[:, 0])

    def rotate(v, axis, angle):
        c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
        axis = np.broadcast_to(axis, v.shape)
        return v * c + np.cross(axis, v) * s + axis * np.sum(axis * v, 1, keepdims=True) * (1 - c)

    d = rotate(rotate(wo, np.array([0.0, 0, 1]), -phi_h), np.array([0.0, 1, 0]), -theta_h)
    return np.hstack([np.sin(theta_h)[:, None], np.zeros((len(wi), 1)),
                      np.cos(theta_h)[:, None], d]).astype(np.float32)


def numpy_nbrdf(folder, stem, x):
    for layer in (1, 2, 3):
        kernel = np.load(folder / f"{stem}_fc{layer}.npy")
        bias = np.load(folder / f"{stem}_b{layer}.npy")
        assert kernel.dtype == np.float32 and bias.dtype == np.float32
        x = x @ kernel + bias
        if layer < 3:
            x = np.maximum(x, 0)
    return np.maximum(np.exp(x) - 1, 0)


def test_npy_form_matches_numpy_to_float_rounding():
    require_shared()
    wi, wo = random_pairs(20000, 11)
    want = numpy_nbrdf(MERL / "npy", "blue-acrylic", numpy_network_input(wi, wo))
    b = halfback.load(str(MERL / "npy"))
    assert b.name == "nbrdf:blue-acrylic"
    got = b.eval(wi, wo)
    # float32 network: a few units of float rounding relative to max(1, rho) (exp(y) - 1 near 0
    # keeps an absolute error of the order of float's epsilon).
    err = np.abs(got - want) / np.maximum(1.0, np.abs(want))
    assert err.max() < 2e-5, err.max()
    assert np.median(err) < 1e-6
    # The single-pair path (eval of one row at a time) agrees with the batch.
    for i in range(0, 20000, 997):
        np.testing.assert_allclose(b.eval(wi[i:i + 1], wo[i:i + 1])[0], got[i], rtol=1e-5,
                                   atol=1e-6)


def test_h5_and_npy_forms_evaluate_identically():
    require_shared()
    wi, wo = random_pairs(5000, 12)
    h5 = halfback.load(str(MERL / "blue-acrylic.h5")).eval(wi, wo)
    npy = halfback.load(str(MERL / "npy" / "blue-acrylic_fc1.npy")).eval(wi, wo)
    np.testing.assert_array_equal(h5, npy)


def test_embedded_paper_materials_load_without_files():
    for name in ("gold-metallic-paint3", "colonial-maple-223", "pink-felt"):
        b = halfback.load("embedded:" + name)
        assert b.name == "nbrdf:" + name
        wi, wo = random_pairs(100, 13)
        rho = b.eval(wi, wo)
        assert rho.shape == (100, 3) and np.isfinite(rho).all() and (rho >= 0).all()
        assert rho.max() > 0


def test_a_bad_npy_folder_raises_a_clear_error(tmp_path):
    np.save(tmp_path / "x_fc1.npy", np.zeros((6, 21), dtype=np.float64))
    np.save(tmp_path / "x_b1.npy", np.zeros(21, dtype=np.float32))
    with pytest.raises(Exception, match=r"x_fc1.npy: dtype: '<f8', expected"):
        halfback.load(str(tmp_path))
