"""halfback.load / Brdf: values against closed forms and the CLI, shapes, dtypes, errors."""

import os
import pickle
import subprocess

import numpy as np
import pytest

import halfback
from helpers import results_from_threads


def unit_rows(n, seed=3, zmin=0.05):
    rng = np.random.default_rng(seed)
    z = zmin + (1 - zmin) * rng.random(n)
    phi = 2 * np.pi * rng.random(n)
    s = np.sqrt(1 - z * z)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)


def test_lambert_is_albedo_over_pi_and_zero_below_the_horizon():
    b = halfback.load("lambert:albedo=0.5")
    wi, wo = unit_rows(1000, 1), unit_rows(1000, 2)
    rho = b.eval(wi, wo)
    assert rho.shape == (1000, 3) and rho.dtype == np.float64
    np.testing.assert_allclose(rho, 0.5 / np.pi, rtol=1e-15)
    below = wo.copy()
    below[:, 2] *= -1
    assert (b.eval(wi, below) == 0).all()
    # One (N, 6) array is the same as two (N, 3) ones; float32 and lists are accepted.
    np.testing.assert_array_equal(b.eval(np.hstack([wi, wo])), rho)
    np.testing.assert_allclose(b.eval(wi.astype(np.float32), wo.tolist()), rho, rtol=1e-6)


def test_ggx_at_normal_incidence_matches_its_closed_form():
    # D(0) = 1/(pi alpha^2), G = 1 and F = f0 at normal incidence and view: rho = D F / 4.
    b = halfback.load("ggx:alpha=0.3,f0=0.9")
    n = np.array([[0.0, 0.0, 1.0]])
    np.testing.assert_allclose(b.eval(n, n)[0], 0.9 / (np.pi * 0.09) / 4, rtol=1e-12)


def test_non_contiguous_and_nan_rows():
    b = halfback.load("ggx:alpha=0.2")
    pairs = np.hstack([unit_rows(100, 4), unit_rows(100, 5)])
    wide = np.zeros((100, 12))
    wide[:, ::2] = pairs  # strided columns
    np.testing.assert_array_equal(b.eval(wide[:, ::2]), b.eval(pairs))
    pairs[7, 0] = np.nan
    rho = b.eval(pairs)
    assert np.isnan(rho[7]).all() and np.isfinite(np.delete(rho, 7, axis=0)).all()


def test_bad_input_raises_clear_errors():
    b = halfback.load("lambert")
    with pytest.raises(ValueError, match=r"wi must have shape \(N, 3\), got \(4, 2\)"):
        b.eval(np.zeros((4, 2)), np.zeros((4, 3)))
    with pytest.raises(ValueError, match="same number of rows"):
        b.eval(unit_rows(3), unit_rows(4))
    with pytest.raises(ValueError, match=r"row 1: wo is not a unit vector"):
        b.eval(unit_rows(2), np.array([[0, 0, 1.0], [0, 0, 2.0]]))
    with pytest.raises(TypeError, match="float array"):
        b.eval(np.array([["a", "b", "c"]]), unit_rows(1))
    with pytest.raises(ValueError, match="neither an existing file nor a known BRDF model"):
        halfback.load("glossy")
    with pytest.raises(ValueError, match="alpha"):
        halfback.load("ggx:alpha=-1")
    with pytest.raises(ValueError, match="no such embedded material"):
        halfback.load("embedded:gold")


def test_info_albedo_and_models():
    b = halfback.load("embedded:acrylic_felt_green")
    info = b.info
    assert info["name"] == "rgl:acrylic_felt_green_rgb" and info["isotropic"] is True
    assert "RGL tensor_file" in info["format"]
    (mean, err) = halfback.load("lambert:albedo=0.25").albedo(0.3, 64)
    np.testing.assert_allclose(mean, 0.25, rtol=1e-6)
    assert set(["lambert", "ggx", "beckmann", "abc", "sheen", "test"]) <= set(halfback.models())
    assert repr(b) == "<halfback.Brdf rgl:acrylic_felt_green_rgb>"


def test_resample_slice_matches_the_closed_form_and_the_cli(tmp_path):
    t = halfback.load("test:S").resample("hybrid", "slice", (20, 10), azimuth=np.radians(30))
    assert t["rho"].shape == (20, 10, 3) and t["valid"].shape == (20, 10)
    assert t["axis_names"] == ["hbar", "k"]
    hbar = t["axes"][0][:, None]
    np.testing.assert_allclose(np.broadcast_to(1 - hbar, (20, 10))[t["valid"]],
                               t["rho"][..., 0][t["valid"]], atol=1e-12)
    assert t["metadata"]["slice_azimuth"] == pytest.approx(np.radians(30))
    cli = os.environ.get("HALFBACK_CLI")
    if cli:
        out = tmp_path / "s.npz"
        subprocess.run([cli, "resample", "--brdf", "test:S", "--param", "hybrid", "--kind",
                        "slice", "--azimuth", "30", "--size", "20,10", "-o", str(out)], check=True,
                       capture_output=True)
        with np.load(out) as z:
            np.testing.assert_array_equal(z["rho"], t["rho"])
            np.testing.assert_array_equal(z["valid"], t["valid"])
    with pytest.raises(ValueError, match="kind"):
        halfback.load("lambert").resample("hybrid", "cube")
    with pytest.raises(ValueError, match="no axis 'theta_h'"):
        halfback.load("lambert").resample("hybrid", ranges={"theta_h": (0, 1)})


def test_eval_agrees_with_the_cli(tmp_path):
    cli = os.environ.get("HALFBACK_CLI")
    if not cli:
        pytest.skip("HALFBACK_CLI not set (run through ctest)")
    pairs = np.hstack([unit_rows(50, 8), unit_rows(50, 9)])
    path = tmp_path / "p.csv"
    np.savetxt(path, pairs, delimiter=",", header="wi_x,wi_y,wi_z,wo_x,wo_y,wo_z", comments="",
               fmt="%.17g")
    out = subprocess.run([cli, "eval", "--brdf", "embedded:colodur_azure_4e", "-i", str(path)],
                         check=True, capture_output=True, text=True).stdout
    ref = np.loadtxt(out.splitlines()[1:], delimiter=",")
    np.testing.assert_array_equal(halfback.load("embedded:colodur_azure_4e").eval(pairs), ref)


def test_hemisphere_view_is_figure_1s_data():
    h = halfback.hemisphere("hybrid", np.radians(40), 65)
    first, second, region = h["first"], h["second"], h["region"]
    assert first.shape == second.shape == region.shape == (65, 65)
    inside = region == 2
    assert np.isnan(first[~inside]).all() and np.isfinite(first[inside]).all()
    # The centre pixel (u = v = 0) is wi = n: hbar = |(n + wo)/2| projected = sin(40°)/2.
    assert abs(h["u"][32]) < 1e-12 and abs(h["v"][32]) < 1e-12
    assert first[32, 32] == pytest.approx(np.sin(np.radians(40)) / 2, abs=1e-12)
    # The same pair through convert(): hybrid's second coordinate |k| at the centre.
    wo = np.array(h["wo"])
    q = halfback.convert(np.hstack([[0, 0, 1], wo])[None, :], "dirs", "hybrid")
    assert second[32, 32] == pytest.approx(q[0, 2], abs=1e-12)
    with pytest.raises(ValueError, match="theta_o"):
        halfback.hemisphere("hybrid", 2.0)
    with pytest.raises(ValueError, match="projection"):
        halfback.hemisphere("hybrid", 0.1, projection="mercator")


def test_render_furnace_and_errors():
    img = halfback.load("lambert:albedo=0.3").render("constant:1", 24, 24, 16, threads=2)
    assert img.shape == (24, 24, 3) and img.dtype == np.float32
    assert img[12, 12] == pytest.approx([0.3, 0.3, 0.3], abs=0.02)
    assert (img[0, 0] == 1).all()
    assert (halfback.load("ggx").render("constant:0", 8, 8, 2) == 0).all()
    with pytest.raises(ValueError, match="strategy"):
        halfback.load("lambert").render(strategy="path")
    with pytest.raises(ValueError, match="missing.hdr"):  # a spec that names nothing
        halfback.load("lambert").render("missing.hdr")
    with pytest.raises(ValueError, match="brdf_sampling"):
        halfback.load("lambert").render(brdf_sampling="pilot")


def test_render_brdf_sampling_choices_agree():
    # A network has no sampler of its own: the table, the cosine and the automatic choice render
    # the same sphere in expectation (a constant sky: the pixel is the directional albedo).
    felt = halfback.load("embedded:pink-felt")
    means = [
        felt.render("constant:1", 16, 16, 256, brdf_sampling=s)[4:12, 4:12].mean()
        for s in ("table", "cosine", "auto")
    ]
    assert max(means) / min(means) < 1.02


def test_brdf_eval_from_several_threads():
    b = halfback.load("embedded:ilm_l3_37_metallic")
    pairs = np.hstack([unit_rows(5000, 11), unit_rows(5000, 12)])
    ref = b.eval(pairs)
    for r in results_from_threads(lambda: b.eval(pairs)):
        np.testing.assert_array_equal(r, ref)


def test_figure2_example_draws_the_nine_panels(tmp_path):
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    import importlib.util

    here = os.path.dirname(os.path.abspath(__file__))
    path = os.path.join(here, "..", "..", "examples", "figure2_matplotlib.py")
    spec = importlib.util.spec_from_file_location("figure2_matplotlib", path)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    out = tmp_path / "fig2.png"
    example.main(str(out), size=61)
    image = matplotlib.image.imread(str(out))
    assert image.shape[0] > 500 and image.shape[1] > 500
    # The invalid region is drawn light grey (0.8) and the valid one black: both are present.
    rgb = image[..., :3]
    assert (np.abs(rgb - 0.8).max(axis=2) < 0.02).mean() > 0.05
    assert (rgb.max(axis=2) < 0.05).mean() > 0.2


def test_bad_grids_and_render_settings_raise():
    b = halfback.load("lambert")
    with pytest.raises(ValueError, match="size must be positive"):
        b.resample("hybrid", size=0)
    with pytest.raises(ValueError, match="4 axes, got 2 sample counts"):
        b.resample("hybrid", "full", size=(4, 4))
    with pytest.raises(ValueError, match="finite"):
        b.resample("hybrid", ranges={"k": (0, float("nan"))})
    with pytest.raises(ValueError, match="param"):
        b.resample("spectral")
    # Wrong types are named with what was given and what is accepted (not pybind's cast error).
    with pytest.raises(TypeError, match=r"size must be an int or a sequence of ints .* str 'abc'"):
        b.resample("hybrid", size="abc")
    with pytest.raises(TypeError, match=r"size must be an int .* float 2\.5"):
        b.resample("hybrid", size=2.5)
    with pytest.raises(TypeError, match=r"size must be an int .* list \[4, 'x', 4\]"):
        b.resample("hybrid", size=[4, "x", 4])
    with pytest.raises(TypeError, match=r"ranges\['k'\] must be a \(lo, hi\) pair .* str 'ab'"):
        b.resample("hybrid", ranges={"k": "ab"})
    with pytest.raises(TypeError, match=r"ranges\['k'\] must be a \(lo, hi\) pair"):
        b.resample("hybrid", ranges={"k": (0, 1, 2)})
    with pytest.raises(ValueError):
        b.render(width=0)
    with pytest.raises(ValueError, match="pixels"):
        halfback.hemisphere("hybrid", 0.1, pixels=1)


# docs/reliability/python.md: the same rules as the command line.

def test_albedo_of_a_non_finite_angle_raises():
    b = halfback.load("lambert:albedo=0.25")
    for theta in (float("nan"), float("inf"), -float("inf")):
        with pytest.raises(ValueError, match="theta_i"):
            b.albedo(theta)
    (mean, _) = b.albedo(0.0, 16)
    np.testing.assert_allclose(mean, 0.25, rtol=1e-6)


def test_isotropic_needs_a_parameterization_on_one_side():
    x = np.array([[0.0, 0.0, 1.0, 0.6, 0.0, 0.8]])
    with pytest.raises(ValueError, match="isotropic needs a parameterization"):
        halfback.convert(x, "dirs", "dirs", isotropic=True)
    np.testing.assert_array_equal(halfback.convert(x, "dirs", "dirs"), x)
    assert halfback.convert(x, "dirs", "hybrid", isotropic=True).shape == (1, 3)
    cli = os.environ.get("HALFBACK_CLI")
    if cli:
        r = subprocess.run([cli, "convert", "--from", "dirs", "--to", "dirs", "--isotropic"],
                           input="wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,1,0.6,0,0.8\n",
                           capture_output=True, text=True)
        assert r.returncode == 2 and "isotropic needs a parameterization" in r.stderr


def test_slice_azimuths_wrap_into_0_2pi_and_beyond_two_turns_raise():
    # Radians, as every angle of the Python API (docs/reliability/python.md), from -2 pi to 2 pi:
    # a value beyond (90, meant as degrees) is refused, not wrapped.
    b = halfback.load("ggx:alpha=0.3")
    ref = b.resample("hybrid", "slice", 12, azimuth=1.5 * np.pi)
    assert ref["valid"].any()
    assert ref["metadata"]["slice_azimuth"] == pytest.approx(1.5 * np.pi)
    for az in (-0.5 * np.pi, np.nextafter(-0.5 * np.pi, 0)):
        t = b.resample("hybrid", "slice", 12, azimuth=az)
        np.testing.assert_array_equal(t["valid"], ref["valid"])
        np.testing.assert_allclose(t["rho"], ref["rho"], rtol=1e-12)  # fmod's last bit
        assert t["metadata"]["slice_azimuth"] == pytest.approx(ref["metadata"]["slice_azimuth"])
    zero = b.resample("hybrid", "slice", 12, azimuth=0.0)
    np.testing.assert_array_equal(b.resample("hybrid", "slice", 12, azimuth=2 * np.pi)["rho"],
                                  zero["rho"])
    for az in (3.5 * np.pi, -2.5 * np.pi, 90.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="azimuth.*radians"):
            b.resample("hybrid", "slice", 12, azimuth=az)


def test_an_all_invalid_table_warns():
    with pytest.warns(RuntimeWarning, match="no grid point is inside the domain"):
        t = halfback.load("lambert").resample("hybrid", "slice", 4, ranges={"k": (1.5, 2)})
    assert not t["valid"].any()


def test_eval_normalizes_near_unit_directions_as_convert_does():
    # docs/reliability/numerics.md: the CLI's rule (accept_pair) in Python: a grazing
    # mirror pair with |wi| = 1 + 4e-7 gives the unit pair's rho (GGX alpha = 0.001: the mirror
    # peak, 2.4e8).
    t = np.radians(89.0)
    wi = np.array([[np.sin(t), 0.0, np.cos(t)]])
    wo = np.array([[-np.sin(t), 0.0, np.cos(t)]])
    b = halfback.load("ggx:alpha=0.001")
    unit = b.eval(wi, wo)
    near = b.eval(wi * (1 + 4e-7), wo)
    np.testing.assert_allclose(near, unit, rtol=1e-9)
    assert unit[0, 0] > 1e8  # the mirror peak (unnormalized: its half vector tilts off it)


def test_all_nan_rows_evaluate_to_nan():
    # docs/reliability/python.md: a row of NaN is answered NaN, as a row with one NaN
    # (not 0, 0, 0).
    b = halfback.load("ggx:alpha=0.2")
    pairs = np.array([[np.nan] * 6, [0, 0, 1, 0, 0, 1], [np.inf, 0, 0, 0, 0, 1]])
    rho = b.eval(pairs)
    assert np.isnan(rho[0]).all() and np.isnan(rho[2]).all() and np.isfinite(rho[1]).all()


def test_albedo_takes_radians_in_its_range():
    # docs/reliability/python.md: albedo(30.0), degrees by mistake, and negative angles
    # gave plausible numbers; every angle of the Python API is in radians, checked against its
    # range.
    b = halfback.load("lambert:albedo=0.5")
    (mean, _) = b.albedo(np.radians(30.0), 16)
    assert mean[0] == pytest.approx(0.5, rel=1e-12)
    for theta in (30.0, -0.1, 2.0):
        with pytest.raises(ValueError, match=r"radians, in \[0, pi/2\].*math.radians"):
            b.albedo(theta)


def test_a_new_users_conveniences():
    # A new user's rough edges (docs/reliability/python.md): __version__; models() with parameters;
    # a Brdf pickles (Dask ships objects) and compares by its spec, a file by its absolute path.
    assert halfback.__version__.count(".") == 2
    ggx = halfback.models()["ggx"]
    alpha = next(p for p in ggx["params"] if p["name"] == "alpha")
    assert alpha["min"] == 0.001 and alpha["max"] == 10 and alpha["default"] == 0.2
    assert next(p for p in ggx["params"] if p["name"] == "alpha_x")["default_from"] == "alpha"
    assert "ggx" in list(halfback.models())
    for spec in ("ggx:alpha=0.2", "lambert:albedo=0.3+ggx:alpha=0.1", "embedded:pink-felt"):
        b = halfback.load(spec)
        assert b == halfback.load(spec) and hash(b) == hash(halfback.load(spec))
        c = pickle.loads(pickle.dumps(b))
        assert c == b and c.name == b.name
        pairs = np.hstack([unit_rows(20, 1), unit_rows(20, 2)])
        np.testing.assert_array_equal(c.eval(pairs), b.eval(pairs))
    assert halfback.load("ggx:alpha=0.2") != halfback.load("ggx:alpha=0.3")
