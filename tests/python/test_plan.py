"""Two-stage measurement plans from Python (docs/acquisition.md): the sequential design's main
stage planned from its pilot's values, measured and reconstructed, is the study's sequential
design."""
import io
import math

import numpy as np
import pytest

import halfback

TRUTH = "lambert:albedo=0.2+ggx:alpha=0.1,f0=0.9"


def study_error(design, budget, settings):
    """The error the study reports for `design` at `budget` in halfdiff."""
    import csv
    rows = csv.DictReader(io.StringIO(halfback.study_brdf(TRUTH, settings)["gonio"]))
    for row in rows:
        if row["design"] == design and row["budget"] == str(budget) and row["spacing"] == "own":
            return float(row["error"])
    raise AssertionError(f"no {design} row at {budget}")


def test_sequential_main_stage_is_the_studys_design(tmp_path):
    truth = halfback.load(TRUTH)
    pilot = halfback.plan("halfdiff", design="sequential", budget=3000, max_theta=np.radians(85))
    # Every angle of the Python API in radians; the CSV's degrees beside them.
    assert np.allclose(pilot["positions"], np.radians(pilot["positions_deg"]))
    values = truth.eval(pilot["wi"], pilot["wo"])
    main = halfback.plan_main(pilot["sidecar"], values)
    assert '"stage":"main"' in main["sidecar"] and '"learned_warps"' in main["sidecar"]
    measured = truth.eval(main["wi"], main["wo"])
    error = halfback.plan_error(main["sidecar"], measured, truth, test_pairs=20000, max_theta=np.radians(85))
    settings = {"params": ["halfdiff"], "budgets": [3000], "designs": ["own"],
                "test_pairs": 20000, "no_images": True, "no_sampling": True, "no_fit": True}
    assert error == pytest.approx(study_error("sequential", 3000, settings), rel=1e-9)
    # The main stage's sidecar is read back from a file, and reconstructs.
    (tmp_path / "main.json").write_text(main["sidecar"])
    b = halfback.reconstruct(tmp_path / "main.json", measured, tmp_path / "m.binary")
    wi, wo = np.array([[0.6, 0.0, 0.8]]), np.array([[0.5, 0.5, 0.7071068]])  # off the lobe
    assert b.eval(wi, wo)[0, 1] == pytest.approx(truth.eval(wi, wo)[0, 1], rel=0.05)

    # The wrong stage, the wrong count, a negative value: ValueError, nothing planned.
    with pytest.raises(ValueError, match="not the pilot"):
        halfback.plan_main(main["sidecar"], measured)
    with pytest.raises(ValueError, match="expected"):
        halfback.plan_main(pilot["sidecar"], values[:5])
    negative = values.copy()
    negative[4] = [0.1, -0.2, 0.1]
    with pytest.raises(ValueError, match="row 4"):
        halfback.plan_main(pilot["sidecar"], negative)
    with pytest.raises(RuntimeError, match="sequential"):  # an edited sidecar (FormatError)
        halfback.plan_main(pilot["sidecar"].replace('"budget":3000', '"budget":9000', 1), values)
    with pytest.raises(ValueError, match="space 'db'"):
        halfback.plan_error(main["sidecar"], measured, truth, space="db")


def test_dupuy_jakob_stages_from_python(tmp_path):
    truth = halfback.load(TRUTH)
    retro = halfback.plan(design="dupuy-jakob", budget=1000)
    assert len(retro["row_of_point"]) == 62  # the NDF's nodes of a layout of 1000
    assert np.allclose(retro["wi"], retro["wo"])  # the retro-reflection
    slices = halfback.plan_main(retro["sidecar"], truth.eval(retro["wi"], retro["wo"]))
    measured = truth.eval(slices["wi"], slices["wo"])
    b = halfback.reconstruct(slices["sidecar"], measured, tmp_path / "dj.bsdf")
    wi, wo = np.array([[0.3, 0.0, 0.9539392]]), np.array([[-0.2, 0.3, 0.9327379]])
    assert b.eval(wi, wo)[0, 1] == pytest.approx(truth.eval(wi, wo)[0, 1], rel=0.1)
    missing = truth.eval(retro["wi"], retro["wo"])
    missing[3] = math.nan
    with pytest.raises(ValueError, match="row 3 was not measured"):
        halfback.plan_main(retro["sidecar"], missing)
    with pytest.raises(ValueError, match="below its smallest"):
        halfback.plan(design="dupuy-jakob", budget=40)


def test_learned_plan_from_a_studys_profiles_is_the_studys_design(tmp_path):
    # The study's learned design for TRUTH: warps learned from the other BRDFs' profiles. The same
    # profiles as files, planned by the CLI with TRUTH left out, measured and reconstructed, give
    # the study's error to 1e-9.
    import os
    import subprocess
    cli = os.environ.get("HALFBACK_CLI")
    if not cli:
        pytest.skip("HALFBACK_CLI not set (run through ctest)")
    specs = ["lambert:albedo=0.5+ggx:alpha=0.05,f0=0.9", "lambert:albedo=0.1+ggx:alpha=0.4", TRUTH]
    settings = {"params": ["halfdiff"], "budgets": [2000], "designs": ["own", "learned"],
                "test_pairs": 20000, "no_images": True, "no_sampling": True, "no_fit": True}
    profiles = [halfback.study_profile(s, settings) for s in specs]
    folder = tmp_path / "profiles"
    folder.mkdir()
    for k, text in enumerate(profiles):  # in the study's order
        (folder / f"{k}.profile").write_text(text)
    import csv
    rows = csv.DictReader(io.StringIO(halfback.study_brdf(TRUTH, dict(settings, profiles=profiles))["gonio"]))
    study = [float(r["error"]) for r in rows if r["spacing"] == "learned" and r["budget"] == "2000"]
    assert len(study) == 1
    done = subprocess.run([cli, "plan", "--design", "learned", "--param", "halfdiff", "--budget",
                           "2000", "--max-theta", "85", "--profiles", str(folder), "--leave-out",
                           TRUTH, "-o", str(tmp_path / "l.csv")], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    table = np.genfromtxt(tmp_path / "l.csv", delimiter=",", names=True)
    wi = np.stack([table["wi_x"], table["wi_y"], table["wi_z"]], axis=1)
    wo = np.stack([table["wo_x"], table["wo_y"], table["wo_z"]], axis=1)
    truth = halfback.load(TRUTH)
    error = halfback.plan_error(tmp_path / "l.json", truth.eval(wi, wo), truth, test_pairs=20000,
                               max_theta=np.radians(85))
    assert error == pytest.approx(study[0], rel=1e-9)
    # Without TRUTH left out, its own profile is learned from: other warps, another error.
    done = subprocess.run([cli, "plan", "--design", "learned", "--param", "halfdiff", "--budget",
                           "2000", "--max-theta", "85", "--profiles", str(folder), "-o",
                           str(tmp_path / "all.csv")], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "all.json").read_text() != (tmp_path / "l.json").read_text()
    done = subprocess.run([cli, "plan", "--design", "learned", "--param", "halfdiff", "--profiles",
                           str(folder), "--leave-out", "nothing", "-o", str(tmp_path / "x.csv")],
                          capture_output=True, text=True)
    assert done.returncode == 2 and "--leave-out 'nothing'" in done.stderr
    assert not (tmp_path / "x.csv").exists()
