"""The study one BRDF at a time (halfback.study_brdf), on Dask distributed, and the merge."""

import os
import pickle
import subprocess
from pathlib import Path

import numpy as np
import pytest

import halfback
from helpers import main_thread_turns_during

# Small settings: a few seconds per BRDF. Without the learned design, each BRDF's study is
# independent of the others (LEARNED below: with it, from the profiles of all of them).
SETTINGS = {
    "params": ["halfdiff", "ortho", "hybrid", "spherical"],  # the paper's, to keep the tests short
    "designs": ["own", "angle", "merl"],
    "quick": True,
    "test_pairs": 3000,
    "budgets": [300, 1000],
    "env": ["sky"],
    "image_size": 16,
    "image_spp": 2,
}
SPECS = ["lambert", "ggx:alpha=0.3", "test:S", "embedded:acrylic_felt_green"]
CSVS = ["azimuthal.csv", "separability.csv", "gonio.csv", "budget.csv", "image.csv"]
TABLES = ["azimuthal", "separability", "gonio", "image"]


def csvs(directory):
    return {name: (Path(directory) / name).read_text() for name in CSVS}


# Whole studies run about 30 times slower under AddressSanitizer: the orchestration tests (Dask,
# merges, the GIL) run in the release build's suite only; the study code itself runs under the
# sanitizers in test_tables_of_one_brdf and in the C++ tests.
slow_under_sanitizers = pytest.mark.skipif(
    os.environ.get("HALFBACK_SANITIZED") == "1",
    reason="whole studies under AddressSanitizer: run by the release build's suite",
)


@pytest.fixture(scope="module")
def local():
    return [halfback.study_brdf(spec, SETTINGS) for spec in SPECS]


def test_tables_of_one_brdf(local):
    felt = local[3]
    assert felt["brdf"].splitlines()[1].startswith("embedded:acrylic_felt_green,1,")
    rows = felt["gonio"].splitlines()
    assert rows[0] == "brdf,parameterization,design,samples,error,dims,budget,spacing"
    # 4 parameterizations x (own in 2 layouts and the sequential design, angle and merl in the
    # regular one) x 2 budgets, numbers that parse as floats.
    assert len(rows) == 1 + 4 * 5 * 2
    assert sorted({r.split(",")[7] for r in rows[1:]}) == ["angle", "merl", "own"]
    errors = [float(r.split(",")[4]) for r in rows[1:]]
    assert all(0 < e < 1 for e in errors)
    assert len(felt["renderings"]) == 5
    assert felt["renderings"][0].shape == (16, 16, 3)
    assert np.all(np.isfinite(felt["renderings"][0]))


def test_bad_settings_are_clear_errors():
    with pytest.raises(ValueError, match="unknown key 'budget'"):
        halfback.study_brdf("lambert", {"budget": [100]})
    with pytest.raises(ValueError, match="--error-space 'sqrt'"):
        halfback.study_brdf("lambert", {"space": "sqrt"})
    with pytest.raises(ValueError, match="--spacings: 'sqrt' is not a spacing"):
        halfback.study_brdf("lambert", {"designs": ["own", "sqrt"]})
    # The learned design, asked for, without the profiles it learns from (left out of the
    # defaults when there are none: test_study_brdf_defaults_work_alone).
    with pytest.raises(ValueError, match=r"learned design needs settings\['profiles'\]"):
        halfback.study_brdf("lambert", {"quick": True, "designs": ["learned"]})
    with pytest.raises(ValueError, match="no profile of 'lambert'"):
        profile = halfback.study_profile("test:S", {"quick": True})
        halfback.study_brdf("lambert", {"quick": True, "profiles": [profile]})
    with pytest.raises(ValueError, match=r"settings\['test_pairs'\]"):
        halfback.study_brdf("lambert", {"test_pairs": "many"})


def test_params_choose_the_parameterizations():
    d = halfback.study_brdf("lambert", {"params": ["hybrid", "halfdiff"], "no_gonio": True})
    rows = d["azimuthal"].splitlines()
    assert [r.split(",")[1] for r in rows[1:]] == ["hybrid", "halfdiff"]
    assert d["settings"].startswith("parameterizations = hybrid,halfdiff\n")
    with pytest.raises(ValueError, match="--params: 'nope' is not a parameterization"):
        halfback.study_brdf("lambert", {"params": ["nope"]})


def test_metrics_and_their_options_are_settings_keys():
    # The keys of the metrics come from the study's list of metrics: "metrics", no_NAME and each
    # metric's options, typed by its kind.
    d = halfback.study_brdf("lambert", {"params": ["halfdiff"], "quick": True, "metrics": ["fit"],
                                        "fit_samples": 1000, "fit_budgets": [300]})
    assert len(d["fit"].splitlines()) == 1 + 2 * 2  # two designs, two weightings
    assert len(d["sampling"].splitlines()) == 1  # the header only: not run
    assert "\nfit_budgets = 300\nfit_samples = 1000\n" in d["settings"]
    with pytest.raises(ValueError, match="unknown key 'no_metric'.*no_sampling.*fit_budgets"):
        halfback.study_brdf("lambert", {"no_metric": True})
    with pytest.raises(ValueError, match=r"settings\['fit_budgets'\]"):
        halfback.study_brdf("lambert", {"fit_budgets": "many"})


def test_the_neural_metric_runs_when_named():
    # Off by default; named, a network per width on each parameterization's coordinates, and
    # halfdiff's with Sztrajman et al.'s vectors.
    settings = {"params": ["halfdiff", "hybrid"], "quick": True, "no_gonio": True, "no_sampling": True,
                "no_fit": True}
    assert len(halfback.study_brdf("lambert", settings)["neural"].splitlines()) == 1
    d = halfback.study_brdf("lambert", {**settings, "metrics": ["neural"], "neural_widths": [2, 4],
                                        "neural_samples": 2000, "neural_epochs": 2})
    rows = d["neural"].splitlines()
    assert len(rows) == 1 + 2 * 3
    assert sum(",vectors," in r for r in rows) == 2
    assert "\nneural_widths = 2,4\n" in d["settings"]


def test_functions_travel_to_other_processes():
    # Engines pickle the task's function to send it to worker processes (a real cluster): by
    # name, so these are the same functions on arrival (a pybind11 built-in does not pickle).
    for f in (halfback.study_brdf, halfback.merge_study, halfback.study_profile):
        assert pickle.loads(pickle.dumps(f)) is f


@slow_under_sanitizers
def test_dask_run_equals_local_run(local, tmp_path):
    distributed = pytest.importorskip("distributed")
    # Threads, not processes: the workers share this process's module (a real cluster's workers
    # import halfback themselves; docs/study.md, "Scaling out").
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        futures = client.map(halfback.study_brdf, SPECS, settings=SETTINGS, pure=False)
        remote = client.gather(futures)
    for a, b in zip(local, remote):
        for t in TABLES + ["settings"]:
            assert a[t] == b[t], t
        for x, y in zip(a["renderings"], b["renderings"]):
            np.testing.assert_array_equal(x, y)
    merged_local = halfback.merge_study(str(tmp_path / "local"), local)
    merged_remote = halfback.merge_study(str(tmp_path / "dask"), remote)
    assert "report.md" in merged_remote["files"]
    assert csvs(tmp_path / "local") == csvs(tmp_path / "dask")
    assert merged_local["markdown"].count("| embedded:acrylic_felt_green |") >= 1


def cli_study(out, specs, designs="own,angle,merl"):
    cli = os.environ.get("HALFBACK_CLI")
    if not cli:
        pytest.skip("HALFBACK_CLI is not set (ctest sets it)")
    args = [cli, "study", "--quick", "--test-pairs", "3000", "--budgets", "300,1000"]
    args += ["--params", ",".join(SETTINGS["params"]), "--designs", designs]
    args += ["--env", "sky", "--image-size", "16", "--image-spp", "2", "-o", str(out)] + specs
    subprocess.run(args, check=True, capture_output=True)


@slow_under_sanitizers
def test_merge_equals_one_cli_run(local, tmp_path):
    # The Python results, merged with a CLI run's directory, are the CLI's run over all of them.
    cli_study(tmp_path / "whole", SPECS)
    cli_study(tmp_path / "half", SPECS[2:])
    halfback.merge_study(str(tmp_path / "merged"), local[:2] + [str(tmp_path / "half")])
    assert csvs(tmp_path / "merged") == csvs(tmp_path / "whole")
    with pytest.raises(RuntimeError, match="'lambert' is in both"):
        halfback.merge_study(str(tmp_path / "twice"), local[:1] + [str(tmp_path / "whole")])
    other = halfback.study_brdf("test:G", dict(SETTINGS, seed=2))
    with pytest.raises(RuntimeError, match="different settings"):
        halfback.merge_study(str(tmp_path / "other"), local[:1] + [other])


@slow_under_sanitizers
def test_study_brdf_releases_the_gil():
    # While one thread is inside study_brdf (about a second of work), this thread keeps running
    # Python code: with the GIL held for the whole call, it could not run until the call returned.
    result, turns = main_thread_turns_during(
        lambda: halfback.study_brdf("embedded:acrylic_felt_green", SETTINGS))
    assert result["gonio"].count("\n") == 41  # header + 4 params x 5 designs x 2 budgets
    assert turns >= 20, "the main thread did not run during study_brdf: the GIL was held"


@slow_under_sanitizers
def test_learned_design_on_dask_equals_the_cli_run(tmp_path):
    # The learned design: the profiles of every BRDF first (a map), then each BRDF's study with
    # all of them (a second map); the same tables as one CLI run, which learns from the same
    # profiles in the same order.
    distributed = pytest.importorskip("distributed")
    settings = {k: v for k, v in SETTINGS.items() if k != "designs"}  # the default: all four
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        profiles = client.gather(
            client.map(halfback.study_profile, SPECS, settings=settings, pure=False)
        )
        with_profiles = dict(settings, profiles=profiles)
        remote = client.gather(
            client.map(halfback.study_brdf, SPECS, settings=with_profiles, pure=False)
        )
    for r in remote:
        assert ",learned" in r["gonio"]
        assert "learned_from = 4 profiles," in r["settings"]
    cli_study(tmp_path / "cli", SPECS, designs="own,angle,merl,learned")
    profile_files = sorted((tmp_path / "cli" / "profiles").rglob("*.profile"))
    assert sorted(p.read_text() for p in profile_files) == sorted(profiles)
    halfback.merge_study(str(tmp_path / "dask"), remote)
    assert csvs(tmp_path / "dask") == csvs(tmp_path / "cli")


def test_study_brdf_defaults_work_alone():
    # A new user's first call (docs/reliability/python.md): without profiles the default designs
    # leave out the learned one (it needs the other BRDFs' profiles); asked for by name, it still
    # needs them. Not silently: a UserWarning names the design left out and how to have it.
    with pytest.warns(UserWarning, match=r"learned design .* is left out.*settings\['profiles'\]"):
        r = halfback.study_brdf("ggx:alpha=0.2", {"quick": True, "no_images": True})
    assert "designs = own,angle,merl" in r["settings"]
    with pytest.raises(ValueError, match="learned design needs"):
        halfback.study_brdf("ggx:alpha=0.2", {"quick": True, "designs": ["own", "learned"]})


def test_merged_quick_results_keep_the_quick_run_warning(tmp_path):
    # The report merge_study writes from quick results warns as `halfback study --quick` does:
    # its headline is not the study's.
    settings = {"quick": True, "no_images": True, "no_sampling": True, "no_fit": True,
                "designs": ["own"], "params": ["halfdiff", "spherical"]}
    r = halfback.study_brdf("ggx:alpha=0.2", settings)
    assert "quick = 1" in r["settings"]
    md = halfback.merge_study(str(tmp_path / "merged"), [r])["markdown"]
    assert "**A quick run**" in md
    full = dict(settings, quick=False, budgets=[100, 300], test_pairs=500)
    md_full = halfback.merge_study(str(tmp_path / "full"),
                                   [halfback.study_brdf("ggx:alpha=0.2", full)])["markdown"]
    assert "**A quick run**" not in md_full
