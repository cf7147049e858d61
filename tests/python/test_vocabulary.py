"""One vocabulary in Python: every angle argument is in radians (degrees only where the name says
so, *_deg), refused with a message that says radians when given in degrees; render() tells which
BRDF sampler it used (docs/reliability/python.md)."""
import inspect
import math
import pickle
import re

import numpy as np
import pytest

import halfback

ANGLE = re.compile(r"theta|azimuth|phi|angle|elevation|zenith|tilt|rotation")


def _parameters(f):
    """The parameter names of a Python function or of a pybind11 function (its signature line)."""
    try:
        return list(inspect.signature(f).parameters)
    except (TypeError, ValueError):
        first = (f.__doc__ or "").splitlines()[0] if f.__doc__ else ""
        return re.findall(r"(\w+):", first[first.find("(") + 1:])


def angle_arguments():
    """(callable name, argument) for every angle argument of the public API, from the module."""
    found = set()
    owners = [(name, getattr(halfback, name)) for name in halfback.__all__]
    owners += [(f"Brdf.{n}", getattr(halfback.Brdf, n)) for n in dir(halfback.Brdf)
               if not n.startswith("_")]
    for name, f in owners:
        if not callable(f) or inspect.isclass(f):
            continue
        for arg in _parameters(f):
            if ANGLE.search(arg) and not arg.endswith("_deg"):
                found.add((name, arg))
    return found


def _plan_error(max_theta):
    p = halfback.plan("halfdiff", budget=300)
    truth = halfback.load("lambert")
    return halfback.plan_error(p["sidecar"], truth.eval(p["wi"], p["wo"]), truth,
                               test_pairs=1000, max_theta=max_theta)


# How to call each angle argument alone (the others at their defaults or small).
PROBES = {
    ("plan", "max_theta"): lambda v: halfback.plan("hybrid", budget=300, max_theta=v),
    ("plan_error", "max_theta"): _plan_error,
    ("fit", "max_theta"): lambda v: halfback.fit("lambert", "lambert", samples=300,
                                                 max_theta=v),
    ("hemisphere", "theta_o"): lambda v: halfback.hemisphere("hybrid", v, pixels=8),
    ("Brdf.albedo", "theta_i"): lambda v: halfback.load("lambert").albedo(v, n=8),
    ("Brdf.resample", "azimuth"): lambda v: halfback.load("lambert").resample(
        "hybrid", "slice", 8, azimuth=v),
}


def test_every_angle_argument_is_known():
    # A new angle argument fails here until it is probed below (radians, or named *_deg).
    assert angle_arguments() == set(PROBES)


@pytest.mark.parametrize("where", sorted(PROBES))
def test_angle_arguments_are_radians_and_degrees_are_refused(where):
    probe = PROBES[where]
    probe(math.radians(80))  # radians: accepted
    with pytest.raises(ValueError, match="radians"):
        probe(80.0)  # 80 degrees, given by mistake: refused, saying radians


def test_plan_reach_in_radians_is_the_cli_reach_in_degrees(tmp_path):
    import os
    import subprocess

    cli = os.environ.get("HALFBACK_CLI")
    if not cli:
        pytest.skip("HALFBACK_CLI not set (run through ctest)")
    done = subprocess.run([cli, "plan", "--param", "halfdiff", "--budget", "500",
                           "--max-theta", "60", "-o", str(tmp_path / "p.csv")],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    cli = np.genfromtxt(tmp_path / "p.csv", delimiter=",", names=True)
    py = halfback.plan("halfdiff", budget=500, max_theta=math.radians(60))
    assert len(py["wi"]) == len(cli)
    np.testing.assert_allclose(py["wi"][:, 2], cli["wi_z"], rtol=1e-9, atol=1e-12)
    # Both directions within the reach (cos 60° = 0.5), and some near it.
    assert py["wi"][:, 2].min() >= 0.5 - 1e-12 and py["wo"][:, 2].min() >= 0.5 - 1e-12
    assert py["wi"][:, 2].min() < 0.6


def test_study_reach_is_radians():
    with pytest.raises(ValueError, match=r"max_theta.*radians"):
        halfback.study_brdf("lambert", {"max_theta": 85})
    with pytest.raises(ValueError, match=r"max_theta.*radians"):
        halfback.study_profile("lambert", {"max_theta": 0.0})
    # Accepted in radians; math.radians(85) is the default reach of 85 degrees exactly (the same
    # settings, which merge_study compares with a CLI run's), and 60 is 60.
    small = {"params": ["hybrid"], "no_gonio": True, "quick": True, "no_sampling": True}
    default = halfback.study_brdf("lambert", small)["settings"]
    assert "\nmax_theta_deg = 85\n" in default
    assert halfback.study_brdf("lambert", {**small, "max_theta": math.radians(85)})[
        "settings"] == default
    sixty = halfback.study_brdf("lambert", {**small, "max_theta": math.radians(60)})["settings"]
    assert sixty == default.replace("\nmax_theta_deg = 85\n", "\nmax_theta_deg = 60\n")


def test_study_spacings_key_and_its_older_name():
    with pytest.raises(ValueError, match="--spacings: 'sqrt' is not a spacing"):
        halfback.study_brdf("lambert", {"spacings": ["own", "sqrt"]})
    with pytest.raises(ValueError, match="--spacings: 'sqrt' is not a spacing"):
        halfback.study_brdf("lambert", {"designs": ["own", "sqrt"]})


def test_render_says_which_sampler_it_used():
    measured = halfback.load("embedded:gold-metallic-paint3")  # no sampler of its own
    img = measured.render(width=16, height=16, spp=1)
    assert isinstance(img, np.ndarray) and isinstance(img, halfback.RenderedImage)
    assert img.shape == (16, 16, 3) and img.dtype == np.float32
    # auto chose, and says so with the measured ratio against its threshold.
    assert "chosen:" in img.sampler and "threshold" in img.sampler, img.sampler
    table = measured.render(width=16, height=16, spp=1, brdf_sampling="table")
    assert table.sampler.startswith("tabulated") and "chosen" not in table.sampler
    assert halfback.load("ggx:alpha=0.2").render(width=8, height=8, spp=1).sampler == (
        "own sampler of ggx")
    # Kept through pickling (a Dask worker's result) and slicing.
    back = pickle.loads(pickle.dumps(img))
    assert back.sampler == img.sampler
    np.testing.assert_array_equal(back, img)
    assert img[2:4].sampler == img.sampler
