"""Parameterizations written in Python: checked before use, refused with the failed check named,
and then taken by name everywhere, with the numbers of the same map written in C++."""

import math
import time

import numpy as np
import pytest

import halfback

TAU = 2 * np.pi
AXES = [("hbar", "length", 0, 1), ("phi_h", "azimuth", 0, TAU),
        ("k", "length", 0, 1), ("phi_k", "azimuth", 0, TAU)]


def azimuth(y, x):
    p = np.arctan2(y, x)
    p = np.where(p < 0, p + TAU, p)
    p = np.where(p >= TAU, 0.0, p)
    return np.where((x == 0) & (y == 0), 0.0, p)


def hybrid_forward(wi, wo):
    """The hybrid parameterization (docs/math.md 2.4), written with NumPy as a user would."""
    h, k = (wi + wo) / 2, (wi - wo) / 2
    return np.stack([np.minimum(np.hypot(h[:, 0], h[:, 1]), 1), azimuth(h[:, 1], h[:, 0]),
                     np.minimum(np.linalg.norm(k, axis=1), 1), azimuth(k[:, 1], k[:, 0])], 1)


def hybrid_inverse(q):
    hbar, phi_h, k, phi_k = q.T
    hx, hy = hbar * np.cos(phi_h), hbar * np.sin(phi_h)
    hz2 = 1 - hbar * hbar - k * k
    hz = np.sqrt(np.maximum(hz2, 0))
    c = hbar * np.cos(phi_k - phi_h)
    d2 = hz * hz + c * c
    d = np.sqrt(np.where(d2 > 0, d2, 1.0))
    sin_k, cos_k = np.where(d2 > 0, hz / d, 1.0), np.where(d2 > 0, -c / d, 0.0)
    kz, kbar = k * cos_k, k * sin_k
    kx, ky = kbar * np.cos(phi_k), kbar * np.sin(phi_k)
    wi = np.stack([hx + kx, hy + ky, hz + kz], 1)
    wo = np.stack([hx - kx, hy - ky, hz - kz], 1)
    bad = (hz2 < -1e-12) | (wi[:, 2] < -1e-9) | (wo[:, 2] < -1e-9)
    wi[bad] = np.nan
    wo[bad] = np.nan
    return wi, wo


def hybrid_jacobian(q):
    hbar, phi_h, k, phi_k = q.T
    hz2 = np.maximum(1 - hbar * hbar - k * k, 0)
    c = hbar * np.cos(phi_k - phi_h)
    return 4 * hbar * k / (hz2 + c * c)


def random_dirs(n, seed=1):
    rng = np.random.default_rng(seed)
    z = 0.02 + 0.98 * rng.random((n, 2))
    phi = TAU * rng.random((n, 2))
    s = np.sqrt(1 - z * z)
    return np.stack([s[:, 0] * np.cos(phi[:, 0]), s[:, 0] * np.sin(phi[:, 0]), z[:, 0],
                     s[:, 1] * np.cos(phi[:, 1]), s[:, 1] * np.sin(phi[:, 1]), z[:, 1]], 1)


@pytest.fixture(scope="module")
def py_hybrid():
    p = halfback.Parameterization("py-hybrid", hybrid_forward, hybrid_inverse, AXES,
                                  jacobian=hybrid_jacobian, summary="hybrid, in NumPy")
    assert halfback.register_parameterization(p) == "py-hybrid"
    return p


def test_a_correct_parameterization_passes_every_check():
    p = halfback.Parameterization("py-hybrid-unregistered", hybrid_forward, hybrid_inverse, AXES)
    report = p.check(pairs=5000, box_samples=100000)
    assert report["passed"], report["text"]
    assert [c["name"] for c in report["checks"]] == [
        "vectorized", "range", "round trip", "domain", "jacobian", "isotropic", "reciprocity"]


def test_it_converts_like_the_same_map_in_cpp(py_hybrid):
    x = random_dirs(20000)
    for iso in (False, True):
        ours = halfback.convert(x, "dirs", "py-hybrid", isotropic=iso)
        cpp = halfback.convert(x, "dirs", "hybrid", isotropic=iso)
        assert np.allclose(ours, cpp, atol=1e-12, rtol=0)
        back = halfback.convert(ours, "py-hybrid", "dirs", isotropic=iso)
        assert np.allclose(back, halfback.convert(cpp, "hybrid", "dirs", isotropic=iso), atol=1e-10)
        assert np.allclose(halfback.jacobian(ours, "py-hybrid", isotropic=iso),
                           halfback.jacobian(cpp, "hybrid", isotropic=iso), rtol=1e-9)
    assert halfback.columns("py-hybrid", isotropic=True) == ["hbar", "k", "dphi_k"]
    assert "py-hybrid" in [p["name"] for p in halfback.parameterizations()]


def test_the_slower_path_is_measured(py_hybrid):
    x = random_dirs(200000)
    t0 = time.perf_counter()
    halfback.convert(x, "dirs", "hybrid")
    t1 = time.perf_counter()
    halfback.convert(x, "dirs", "py-hybrid")
    t2 = time.perf_counter()
    print(f"convert 2e5 pairs: C++ hybrid {1e3 * (t1 - t0):.1f} ms, NumPy hybrid {1e3 * (t2 - t1):.1f} ms")


def failure(forward=hybrid_forward, inverse=hybrid_inverse, axes=AXES, **kw):
    p = halfback.Parameterization("faulty", forward, inverse, axes, **kw)
    with pytest.raises(ValueError) as e:
        halfback.register_parameterization(p, pairs=3000, box_samples=50000)
    return str(e.value)


def test_a_wrong_inverse_is_refused_naming_the_check():
    assert "round trip: the inverse returns the pair swapped" in failure(
        inverse=lambda q: hybrid_inverse(q)[::-1])
    shifted = lambda q: tuple(w + np.array([1e-3, 0, 0]) for w in hybrid_inverse(q))
    assert "round trip: pair -> q -> pair is off by" in failure(inverse=shifted)


def test_a_wrong_range_is_refused_naming_the_coordinate():
    narrow = AXES[:2] + [("k", "length", 0, 0.5)] + AXES[3:]
    assert "range: coordinate 2 ('k')" in failure(axes=narrow)


def test_a_wrong_jacobian_is_refused():
    assert "jacobian: J differs from the finite-difference volume" in failure(
        jacobian=lambda q: 1.02 * hybrid_jacobian(q))


def test_a_non_vectorized_callable_is_refused():
    def per_pair(wi, wo):  # math functions: one pair at a time
        return np.array([math.hypot(*(wi[0, :2] + wo[0, :2])) / 2, 0.0, 0.0, 0.0])
    assert "vectorized:" in failure(forward=per_pair)
    assert "vectorized:" in failure(forward=lambda wi, wo: [math.atan2(wi[0, 1], wi[0, 0])])


def test_bad_declarations_are_refused_at_once():
    with pytest.raises(ValueError, match="kind 'radius'"):
        halfback.Parameterization("x", hybrid_forward, hybrid_inverse,
                                  [("a", "radius", 0, 1)] + AXES[1:])
    with pytest.raises(ValueError, match="must be an azimuth"):
        halfback.Parameterization("x", hybrid_forward, hybrid_inverse, AXES, isotropic_drop=0)
    with pytest.raises(ValueError, match="four"):
        halfback.Parameterization("x", hybrid_forward, hybrid_inverse, AXES[:3])
    with pytest.raises(ValueError, match="must be finite, lo < hi"):
        halfback.Parameterization("x", hybrid_forward, hybrid_inverse,
                                  [("hbar", "length", 0, float("nan"))] + AXES[1:])
    with pytest.raises(ValueError, match="sampler_chart: 'polar'"):
        halfback.Parameterization("x", hybrid_forward, hybrid_inverse, AXES, sampler_chart="polar")
    with pytest.raises(ValueError, match="callables"):
        halfback.Parameterization("x", 3, hybrid_inverse, AXES)
    with pytest.raises(ValueError, match="not allowed"):
        halfback.Parameterization("dirs", hybrid_forward, hybrid_inverse, AXES)


def test_a_map_returning_the_wrong_shape_is_refused_as_not_vectorized():
    assert "vectorized: forward must return an array of shape" in failure(
        forward=lambda wi, wo: hybrid_forward(wi, wo)[:, :3])
    assert "vectorized: inverse must return a tuple" in failure(
        inverse=lambda q: np.concatenate(hybrid_inverse(q), 1))


def test_the_study_gives_the_numbers_of_the_same_map_in_cpp(py_hybrid):
    settings = {"quick": True, "params": ["hybrid", "py-hybrid"], "designs": ["own"],
                "budgets": [300, 1000], "test_pairs": 3000}
    r = halfback.study_brdf("ggx:alpha=0.3", settings)

    def rows(table):
        out = {}
        for line in r[table].splitlines()[1:]:
            f = line.split(",")
            out.setdefault(f[1], []).append(float(f[2] if table == "azimuthal" else f[4]))
        return out

    for table in ("azimuthal", "gonio"):
        t = rows(table)
        assert np.allclose(t["py-hybrid"], t["hybrid"], rtol=1e-6), (table, t)


def test_results_are_checked_at_every_call_after_registration():
    # A map that passes the checks at registration and goes wrong later (state, or a region the
    # checks did not sample) is refused at the call that shows it: an inverse returning |wi| = 1.5
    # was reported valid (and resampled through), a forward returning inf passed through convert.
    wrong = {"on": False}

    def forward(wi, wo):
        q = hybrid_forward(wi, wo)
        if wrong["on"]:
            q[:, 0] = np.inf
        return q

    def inverse(q):
        wi, wo = hybrid_inverse(q)
        return (1.5 * wi, wo) if wrong["on"] else (wi, wo)

    p = halfback.Parameterization("py-goes-wrong", forward, inverse, AXES,
                                  jacobian=hybrid_jacobian)
    halfback.register_parameterization(p, pairs=3000, box_samples=50000)
    x = random_dirs(100)
    q = halfback.convert(x, "dirs", "py-goes-wrong")
    assert np.isfinite(q).all()
    wrong["on"] = True
    with pytest.raises(ValueError, match="py-goes-wrong: inverse returned a pair that is not valid"
                       r".*\|wi\| = 1\.5"):
        halfback.convert(q, "py-goes-wrong", "dirs")
    with pytest.raises(ValueError, match="py-goes-wrong: forward returned coordinates that are "
                       "not finite, \\(inf"):
        halfback.convert(x, "dirs", "py-goes-wrong")
    with pytest.raises(ValueError, match="py-goes-wrong: inverse returned"):
        halfback.load("ggx:alpha=0.3").resample("py-goes-wrong", kind="isotropic", size=4)
    wrong["on"] = False
    assert np.allclose(halfback.convert(q, "py-goes-wrong", "dirs")[:, :6], x, atol=1e-9)
