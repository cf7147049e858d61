"""The tables of `halfback resample`, read back by NumPy itself (.npz and .npy)."""

import json
import os
import subprocess

import numpy as np
import pytest

CLI = os.environ.get("HALFBACK_CLI")
pytestmark = pytest.mark.skipif(not CLI, reason="HALFBACK_CLI (the halfback binary) is not set")


def resample(tmp_path, name, *args):
    out = tmp_path / name
    subprocess.run([CLI, "resample", *args, "-o", str(out)], check=True, capture_output=True)
    return out


def test_npz_holds_the_table_its_axes_and_metadata(tmp_path):
    out = resample(tmp_path, "s.npz", "--brdf", "test:S", "--param", "hybrid", "--size", "24,16,12")
    with np.load(out, allow_pickle=False) as z:
        assert set(z.files) == {"rho", "valid", "axis0", "axis1", "axis2", "axis_names", "metadata"}
        rho, valid = z["rho"], z["valid"]
        assert rho.shape == (24, 16, 12, 3) and rho.dtype == np.float64
        assert valid.shape == (24, 16, 12) and valid.dtype == np.bool_
        assert list(z["axis_names"]) == ["hbar", "k", "dphi"]
        np.testing.assert_allclose(z["axis0"], (np.arange(24) + 0.5) / 24, rtol=0, atol=1e-15)
        np.testing.assert_allclose(z["axis2"], (np.arange(12) + 0.5) / 12 * 2 * np.pi, atol=1e-15)
        meta = json.loads(str(z["metadata"]))
        hbar = z["axis0"][:, None, None]
        k = z["axis1"][None, :, None]
    assert meta["parameterization"] == "hybrid" and meta["kind"] == "isotropic"
    assert [a["count"] for a in meta["axes"]] == [24, 16, 12]
    assert meta["valid_points"] == int(valid.sum())
    # S = 1 − ‖h̄‖ wherever the point is a pair of directions; NaN elsewhere.
    s = np.broadcast_to(1 - hbar, valid.shape)
    np.testing.assert_allclose(rho[valid][:, 0], s[valid], atol=1e-12)
    assert np.isnan(rho[~valid]).all()
    # ‖h‖² + ‖k‖² = 1 bounds the hybrid domain: ‖h̄‖² + ‖k‖² ≤ 1 at every valid point.
    assert (np.broadcast_to(hbar**2 + k**2, valid.shape)[valid] <= 1 + 1e-12).all()
    assert 0 < valid.sum() < valid.size


def test_npy_is_the_rho_array(tmp_path):
    out = resample(tmp_path, "g.npy", "--brdf", "lambert:albedo=0.5", "--param", "halfdiff",
                   "--kind", "slice", "--azimuth", "90", "--size", "10", "--nodes")
    rho = np.load(out)
    assert rho.shape == (10, 10, 3)
    # At φd = 90° every (θh, θd) is valid (both z = cos θh cos θd ≥ 0): ρ = 0.5/π everywhere
    # above the horizon. The last nodes (θh or θd = 90°) are at the horizon, z = 0 up to
    # rounding, where the models give 0 or 0.5/π depending on the sign of that rounding.
    np.testing.assert_allclose(rho[:-1, :-1], 0.5 / np.pi, rtol=1e-15)
    edge = np.concatenate([rho[-1], rho[:, -1]])
    assert np.isin(edge, [0.0, 0.5 / np.pi]).all()
