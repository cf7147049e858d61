"""BRDFs written in Python and the explorer started from Python (halfback.register_brdf,
halfback.view; docs/view.md, "From Python"): a callable served by the explorer's API, its slices
equal to its own values; callables that raise, return NaN or the wrong shape, or break
reciprocity, isotropy or energy refused with the check's message."""

import json
import urllib.error
import urllib.request

import numpy as np
import pytest

import halfback


def blinn(wi, wo):
    """Lambert plus a normalized Blinn-Phong lobe: reciprocal, isotropic, albedo below 1."""
    h = wi + wo
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    lobe = 0.3 * (20 + 8) / (8 * np.pi) * np.clip(h[:, 2], 0, 1) ** 20
    return np.stack([0.5 / np.pi + lobe, 0.3 / np.pi + lobe, 0.2 / np.pi + lobe], axis=1)


def get(viewer, path, **params):
    query = "&".join(
        f"{k}={urllib.request.quote(str(v))}"
        for k, vs in params.items()
        for v in (vs if isinstance(vs, list) else [vs])
    )
    url = f"http://127.0.0.1:{viewer.port}{path}?{query}&token={viewer.token}"
    with urllib.request.urlopen(url, timeout=60) as r:
        return r.read(), r.headers


def test_a_python_brdf_in_the_explorer_has_its_own_values():
    b = halfback.register_brdf("blinn_view", blinn)
    assert b.spec == "python:blinn_view" and halfback.load("python:blinn_view") == b
    with halfback.view("lambert:albedo=0.5", b) as viewer:
        assert viewer.url.startswith(f"http://127.0.0.1:{viewer.port}/?token=")
        info = json.loads(get(viewer, "/api/info")[0])
        assert info["specs"] == ["lambert:albedo=0.5", "python:blinn_view"]
        about = json.loads(get(viewer, "/api/brdf", brdf="arg:1")[0])
        assert about["name"] == "python:blinn_view" and about["reciprocal"]
        # The slices of two forms at a relative azimuth: rho at the pixel centres' canonical pairs.
        n = 16
        body, headers = get(
            viewer, "/api/slices", brdf="arg:1", forms="halfdiff,hybrid", azimuth=30, n=n
        )
        assert headers["X-Halfback-Forms"] == "halfdiff,hybrid"
        fields = np.frombuffer(body, dtype=np.float32).reshape(2, n, n, 3)
        forms = {f["space"]: f for f in info["forms"]}
        compared = 0
        for k, name in enumerate(["halfdiff", "hybrid"]):
            a0, a1 = (forms[name]["axes"][i]["max"] for i in (0, 1))
            j, i = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")  # row j: y
            q = np.stack(
                [(i.ravel() + 0.5) / n * a0, (j.ravel() + 0.5) / n * a1,
                 np.full(n * n, np.radians(30))], axis=1)
            d = halfback.convert(q, name, "dirs", isotropic=True)
            ok = np.isfinite(d).all(axis=1) & (d[:, 2] > 0) & (d[:, 5] > 0)
            expected = blinn(d[ok, :3], d[ok, 3:])
            served = fields[k].reshape(-1, 3)[ok]
            np.testing.assert_allclose(served, expected, rtol=2e-6, atol=1e-9)
            assert np.isnan(fields[k].reshape(-1, 3)[~np.isfinite(d).all(axis=1)]).all()
            compared += ok.sum()
        assert compared > 200
        # The polar plot of both BRDFs in one request, the Python one's equal to its own values.
        polar = json.loads(get(viewer, "/api/polar", brdf=["arg:0", "arg:1"], theta_o=40, n=9)[0])
        assert [c["brdf"] for c in polar["curves"]] == ["arg:0", "arg:1"]
        t = np.radians(polar["angles_deg"])
        wo = np.array([[np.sin(np.radians(40)) * np.cos(np.pi), 0, np.cos(np.radians(40))]])
        wi = np.stack([np.sin(t), np.zeros_like(t), np.cos(t)], axis=1)  # towards the mirror: +x
        inside = wi[:, 2] > 1e-9
        np.testing.assert_allclose(
            np.array(polar["curves"][1]["in_plane"])[inside],
            blinn(wi[inside], np.repeat(wo, inside.sum(), axis=0)), rtol=1e-9)
        # The lit mesh and sphere render it too (its sampler: the table of its values).
        body, _ = get(viewer, "/api/mesh", brdf="arg:1", size=16, theta_l=20)
        assert np.isfinite(np.frombuffer(body, dtype=np.float32)).all()
    assert not viewer.running
    with pytest.raises(urllib.error.URLError):
        get(viewer, "/api/info")


def test_a_callable_is_registered_under_its_name():
    def grey_lambert(wi, wo):
        return np.full(len(wi), 0.4 / np.pi)  # (N,): grey

    with halfback.view(grey_lambert) as viewer:
        assert viewer.specs == ["python:grey_lambert"]
        body, _ = get(viewer, "/api/point", brdf="arg:0", wi="0,0,1", wo="0.6,0,0.8")
        assert json.loads(body)["rho"][0]["rgb"] == pytest.approx([0.4 / np.pi] * 3, rel=1e-12)


def refused(fn, **kwargs):
    with pytest.raises(ValueError) as e:
        halfback.view(fn, **kwargs)
    return str(e.value)


def test_callables_that_fail_a_check_are_refused_with_its_message():
    def raises(wi, wo):
        raise RuntimeError("no BRDF here")

    def nan(wi, wo):
        out = np.full((len(wi), 3), 0.1)
        out[len(wi) // 2] = np.nan
        return out

    def wrong_shape(wi, wo):
        return np.zeros((len(wi), 2))

    def not_an_array(wi, wo):
        return "rho"

    def negative(wi, wo):
        return -np.ones((len(wi), 3))

    def one_way(wi, wo):  # depends on wi alone: not reciprocal
        return np.repeat((0.1 + 0.5 * wi[:, 2:3]) / np.pi, 3, axis=1)

    def anisotropic(wi, wo):
        return np.repeat((0.1 + 0.05 * wi[:, 0:1] * wo[:, 0:1]) / np.pi, 3, axis=1)

    def too_bright(wi, wo):
        return np.full((len(wi), 3), 2 / np.pi)

    m = refused(raises)
    assert "failed the check 'vectorized'" in m and "RuntimeError: no BRDF here" in m
    m = refused(nan)
    assert "failed the check 'finite values'" in m and "nan" in m
    m = refused(wrong_shape)
    assert "'vectorized'" in m and "shape (7, 2)" in m and "expected (7, 3) or (7,)" in m
    assert "not an array" in refused(not_an_array)
    assert "'finite values'" in refused(negative)
    m = refused(one_way)
    assert "failed the check 'reciprocity'" in m and "reciprocal=False" in m
    m = refused(anisotropic)
    assert "failed the check 'isotropy'" in m and "isotropic=False" in m
    m = refused(too_bright)
    assert "failed the check 'energy'" in m and "above 1" in m
    # Declared so, the same functions pass those checks.
    assert all(c["passed"] for c in halfback.check_brdf(one_way, reciprocal=False))
    assert all(c["passed"] for c in halfback.check_brdf(anisotropic, isotropic=False))
    report = halfback.check_brdf(too_bright)
    assert [c["name"] for c in report] == [
        "vectorized", "finite values", "reciprocity", "isotropy", "energy"]
    assert [c["passed"] for c in report] == [True, True, True, True, False]
    with pytest.raises(ValueError, match="must be non-empty"):
        halfback.register_brdf("a/b", blinn)
    with pytest.raises(ValueError, match="no BRDF of that name"):
        halfback.load("python:never_registered")


def test_a_function_that_goes_wrong_after_registration_is_an_error_of_the_request():
    broken = {"now": False}

    def later_nan(wi, wo):
        out = np.full((len(wi), 3), 0.2 / np.pi)
        if broken["now"]:  # the checks passed; the server's requests find it
            out[:] = np.nan
        return out

    b = halfback.register_brdf("later_nan", later_nan)
    broken["now"] = True
    with halfback.view(b) as viewer:
        with pytest.raises(urllib.error.HTTPError) as e:
            get(viewer, "/api/slices", brdf="arg:0", forms="halfdiff", n=8)
        assert e.value.code == 400
        assert "not finite" in json.loads(e.value.read())["error"]
