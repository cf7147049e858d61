"""Tests of the Python module against independent NumPy formulas, the CLI, and bad input."""

import os
import pathlib
import re
import subprocess
import sys
import tempfile

import numpy as np
import pytest

import halfback
from helpers import results_from_threads

PARAMS = ["spherical", "halfdiff", "ortho", "hybrid"]


def random_dirs(n, seed=1, zmin=0.0):
    rng = np.random.default_rng(seed)
    z = zmin + (1 - zmin) * rng.random((n, 2))
    phi = 2 * np.pi * rng.random((n, 2))
    s = np.sqrt(1 - z * z)
    return np.stack([s[:, 0] * np.cos(phi[:, 0]), s[:, 0] * np.sin(phi[:, 0]), z[:, 0],
                     s[:, 1] * np.cos(phi[:, 1]), s[:, 1] * np.sin(phi[:, 1]), z[:, 1]], axis=1)


def numpy_hybrid(x):
    """The hybrid forward map, written here with NumPy (what a researcher would write)."""
    h = (x[:, 0:3] + x[:, 3:6]) / 2
    k = (x[:, 0:3] - x[:, 3:6]) / 2
    hbar = np.hypot(h[:, 0], h[:, 1])
    phi_h = np.mod(np.arctan2(h[:, 1], h[:, 0]), 2 * np.pi)
    knorm = np.linalg.norm(k, axis=1)
    phi_k = np.mod(np.arctan2(k[:, 1], k[:, 0]), 2 * np.pi)
    return np.stack([hbar, phi_h, knorm, phi_k], axis=1)


def angle_diff(a, b):
    d = np.mod(np.abs(a - b), 2 * np.pi)
    return np.minimum(d, 2 * np.pi - d)


def test_hybrid_matches_numpy_formula():
    x = random_dirs(10000, zmin=0.01)
    q = halfback.convert(x, "dirs", "hybrid")
    ref = numpy_hybrid(x)
    np.testing.assert_allclose(q[:, [0, 2]], ref[:, [0, 2]], atol=1e-14)
    assert angle_diff(q[:, [1, 3]], ref[:, [1, 3]]).max() < 1e-12


@pytest.mark.parametrize("param", PARAMS)
@pytest.mark.parametrize("isotropic", [False, True])
def test_round_trip_float64(param, isotropic):
    x = random_dirs(20000, seed=2, zmin=0.05)
    q = halfback.convert(x, "dirs", param, isotropic=isotropic)
    assert q.shape == (len(x), 3 if isotropic else 4) and q.dtype == np.float64
    back = halfback.convert(q, param, "dirs", isotropic=isotropic)
    if not isotropic:
        np.testing.assert_allclose(back, x, atol=1e-12)
    else:  # the canonical pose: same isotropic coordinates again
        q2 = halfback.convert(back, "dirs", param, isotropic=True)
        np.testing.assert_allclose(q2[:, :2], q[:, :2], atol=1e-12)
        assert angle_diff(q2[:, 2], q[:, 2]).max() < 1e-9


@pytest.mark.parametrize("param", PARAMS)
def test_float32_stays_float32(param):
    x = random_dirs(5000, seed=3, zmin=0.1).astype(np.float32)
    q = halfback.convert(x, "dirs", param)
    assert q.dtype == np.float32
    back = halfback.convert(q, param, "dirs")
    assert back.dtype == np.float32
    assert np.abs(back - x).max() < 1e-4


def test_non_contiguous_and_fortran_inputs_give_the_same_result():
    x = random_dirs(3000, seed=4)
    ref = halfback.convert(x, "dirs", "ortho")
    wide = np.zeros((3000, 12))
    wide[:, ::2] = x  # column stride 2
    np.testing.assert_array_equal(halfback.convert(wide[:, ::2], "dirs", "ortho"), ref)
    np.testing.assert_array_equal(halfback.convert(np.asfortranarray(x), "dirs", "ortho"), ref)
    np.testing.assert_array_equal(halfback.convert(x[::-1], "dirs", "ortho"), ref[::-1])
    np.testing.assert_array_equal(halfback.convert(x.tolist(), "dirs", "ortho"), ref)


def test_valid_and_nan_handling():
    x = random_dirs(10, seed=5)
    x[1, 2] = np.nan
    x[2, 5] = -0.5  # below the horizon (and not unit)
    x[3, 0] *= 1.1  # not unit
    mask = halfback.valid(x, "dirs")
    assert mask.dtype == np.bool_
    assert mask.tolist() == [True, False, False, False] + [True] * 6
    q = halfback.convert(x, "dirs", "hybrid")
    assert np.isnan(q[1:4]).all() and not np.isnan(q[[0, 4]]).any()


def test_domain_mask_for_tuples():
    # Azimuths are periodic (π/2 − 2π is π/2); beyond 65536 rad they are no angle.
    q = np.array([[0.6, 0.0, 0.6, 0.0], [0.6, 0.0, 0.6, np.pi / 2], [0.5, 0.0, 0.5, 1e9],
                  [0.6, 0.0, 0.6, np.pi / 2 - 2 * np.pi]])
    assert halfback.valid(q, "ortho").tolist() == [False, True, False, True]
    d = halfback.convert(q, "ortho", "dirs")
    assert np.isnan(d[[0, 2]]).all() and (d[1, [2, 5]] >= 0).all()
    assert np.allclose(d[3], d[1], atol=1e-12)


def test_jacobian_integrates_to_the_measure_of_pairs():
    # ∫ J over the box of hybrid coordinates (with the validity mask) = (2π)².
    rng = np.random.default_rng(6)
    n = 400000
    q = np.stack([rng.random(n), 2 * np.pi * rng.random(n), rng.random(n),
                  2 * np.pi * rng.random(n)], axis=1)
    j = np.nan_to_num(halfback.jacobian(q, "hybrid"), nan=0.0) * (2 * np.pi) ** 2
    mean, se = j.mean(), j.std() / np.sqrt(n)
    assert abs(mean - 4 * np.pi ** 2) < 3 * se and se < 0.01 * 4 * np.pi ** 2


def test_columns():
    assert halfback.columns("hybrid") == ["hbar", "phi_h", "k", "phi_k"]
    assert halfback.columns("ortho", isotropic=True) == ["hbar", "kbar", "dphi"]


def test_simd_isa_is_the_one_halfback_isa_asks_for():
    assert halfback.simd_isa() in ("scalar", "sse2", "avx2", "avx512")
    # A fresh interpreter with HALFBACK_ISA=scalar (every CPU runs it) uses the scalar kernels;
    # its conversions agree with these (a few ulp: not the same atan2).
    x = random_dirs(1000, seed=7)
    code = ("import sys, numpy as np, halfback; x = np.load(sys.argv[1]); "
            "np.save(sys.argv[2], halfback.convert(x, 'dirs', 'hybrid')); print(halfback.simd_isa())")
    with tempfile.TemporaryDirectory() as d:
        np.save(os.path.join(d, "x.npy"), x)
        out = subprocess.run([sys.executable, "-c", code, os.path.join(d, "x.npy"),
                              os.path.join(d, "q.npy")], env={**os.environ, "HALFBACK_ISA": "scalar"},
                             capture_output=True, text=True, check=True)
        assert out.stdout.strip() == "scalar"
        q = np.load(os.path.join(d, "q.npy"))
    here = halfback.convert(x, "dirs", "hybrid")
    eps = np.finfo(np.float64).eps
    assert np.abs(q[:, [0, 2]] - here[:, [0, 2]]).max() <= 4 * eps  # norms in [0, 1]
    assert angle_diff(q[:, [1, 3]], here[:, [1, 3]]).max() <= 8 * 2 * np.pi * eps


@pytest.mark.parametrize("call,exc,text", [
    (lambda: halfback.convert(np.zeros((3, 5)), "dirs", "hybrid"), ValueError, "shape (N, 6)"),
    (lambda: halfback.convert(np.zeros(6), "dirs", "hybrid"), ValueError, "shape (N, 6)"),
    (lambda: halfback.convert(np.zeros((3, 6)), "dirs", "hybird"), ValueError, "unknown parameterization 'hybird'"),
    (lambda: halfback.convert(np.zeros((3, 6), dtype=complex), "dirs", "hybrid"), TypeError, "float32 or float64"),
    (lambda: halfback.convert(np.array([["a"] * 6]), "dirs", "hybrid"), TypeError, "float32 or float64"),
    (lambda: halfback.jacobian(np.zeros((3, 6)), "dirs"), ValueError, "not dirs"),
    (lambda: halfback.convert(np.zeros((3, 4)), "hybrid", "dirs", isotropic=True), ValueError, "shape (N, 3)"),
])
def test_bad_input_raises_clear_errors(call, exc, text):
    with pytest.raises(exc, match=None) as info:
        call()
    assert text in str(info.value)


def test_thread_safety():
    x = random_dirs(200000, seed=7)
    ref = halfback.convert(x, "dirs", "halfdiff")
    for r in results_from_threads(lambda: halfback.convert(x, "dirs", "halfdiff")):
        np.testing.assert_array_equal(r, ref)


def test_agrees_with_the_cli(tmp_path):
    cli = os.environ.get("HALFBACK_CLI")
    if not cli or not os.path.exists(cli):
        pytest.skip("HALFBACK_CLI not set (run through ctest)")
    x = random_dirs(50, seed=8)
    src = tmp_path / "in.csv"
    np.savetxt(src, x, delimiter=",", header="wi_x,wi_y,wi_z,wo_x,wo_y,wo_z", comments="",
               fmt="%.17g")
    done = subprocess.run([cli, "convert", "--from", "dirs", "--to", "hybrid", "-i", str(src)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.strip().splitlines()
    assert lines[0].split(",")[:4] == ["hbar", "phi_h", "k", "phi_k"]
    cli_q = np.array([[float(v) for v in line.split(",")[:4]] for line in lines[1:]])
    np.testing.assert_array_equal(cli_q, halfback.convert(x, "dirs", "hybrid"))


def test_convert_into_out():
    x = random_dirs(1000, seed=21, zmin=0.05)
    ref = halfback.convert(x, "dirs", "hybrid")
    out = np.full((1000, 4), -1.0)
    r = halfback.convert(x, "dirs", "hybrid", out=out)
    assert r is out
    np.testing.assert_array_equal(out, ref)
    # Any strides: a column-major array, and a view into a wider one.
    f = np.asfortranarray(np.zeros((1000, 4)))
    np.testing.assert_array_equal(halfback.convert(x, "dirs", "hybrid", out=f), ref)
    wide = np.zeros((1000, 8))
    halfback.convert(x, "dirs", "hybrid", out=wide[:, ::2])
    np.testing.assert_array_equal(wide[:, ::2], ref)
    with pytest.raises(ValueError, match=r"out must have shape \(1000, 4\), got \(1000, 3\)"):
        halfback.convert(x, "dirs", "hybrid", out=np.zeros((1000, 3)))
    with pytest.raises(TypeError, match="dtype float64"):
        halfback.convert(x, "dirs", "hybrid", out=np.zeros((1000, 4), np.float32))
    ro = np.zeros((1000, 4))
    ro.flags.writeable = False
    with pytest.raises(ValueError, match="read-only"):
        halfback.convert(x, "dirs", "hybrid", out=ro)


def test_parameterizations_describe_every_space_and_the_stubs_name_them():
    table = halfback.parameterizations()
    names = [p["name"] for p in table]
    assert names[:4] == ["spherical", "halfdiff", "ortho", "hybrid"]
    for p in table:
        assert len(p["axes"]) == 4 and len(p["iso_axes"]) == 3
        assert [a["column"] for a in p["axes"]] == halfback.columns(p["name"])
        assert [a["column"] for a in p["iso_axes"]] == halfback.columns(p["name"], isotropic=True)
        for a in p["axes"] + p["iso_axes"]:
            assert a["kind"] in ("angle", "azimuth", "length")
            assert a["unit"] == ("" if a["kind"] == "length" else "rad")
            assert a["lo"] < a["hi"]
    # The stubs are generated from the same list (src/python/stubgen.cpp).
    stubs = (pathlib.Path(halfback.__file__).parent / "__init__.pyi").read_text()
    literal = re.search(r"^Param = Literal\[(.*)\]$", stubs, re.M).group(1)
    assert [n.strip().strip('"') for n in literal.split(",")] == ["dirs"] + names
    public = [n for n in dir(halfback._core) if not n.startswith("_")]
    missing = [n for n in public if not re.search(rf"^(def|class) {n}\b", stubs, re.M)]
    assert missing == []


def test_out_overlapping_the_input_gives_the_separate_result():
    # docs/reliability/python.md: out sharing x's memory (one row ahead, strides swapped)
    # gave errors up to 6; x is copied first, so every layout gives the result of a separate out.
    from numpy.lib.stride_tricks import as_strided

    rng = np.random.default_rng(7)

    def unit_rows(k):
        v = rng.normal(size=(k, 3))
        v[:, 2] = np.abs(v[:, 2]) + 0.05
        return v / np.linalg.norm(v, axis=1, keepdims=True)

    q = halfback.convert(np.hstack([unit_rows(1000), unit_rows(1000)]), "dirs", "halfdiff")
    q = q[halfback.valid(q, "halfdiff")][:500]
    n = len(q)
    expected = halfback.convert(q, "halfdiff", "spherical")
    same = q.copy()
    np.testing.assert_allclose(halfback.convert(same, "halfdiff", "spherical", out=same), expected, rtol=0, atol=1e-12)
    buf = np.zeros((n + 1, 4))
    buf[:-1] = q  # input b[:-1], out b[1:]: out one row ahead
    got = halfback.convert(buf[:-1], "halfdiff", "spherical", out=buf[1:])
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)
    flat = np.zeros(4 * n)
    x = as_strided(flat, shape=(n, 4), strides=(32, 8))
    x[:] = q
    out = as_strided(flat, shape=(n, 4), strides=(8, 8 * n))  # the same bytes, other strides
    got = halfback.convert(x, "halfdiff", "spherical", out=out)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)
