"""Every built-in parameterization and loss is named where the Python API lists them: the module's
docstring, convert()'s and fit()'s, and every study setting in study_brdf()'s (the lists are
generated from the registries)."""

import re

import pytest

import halfback


def named(text, name):
    """name in text as a word of its own, not inside a longer name ("halfdiff" in "stereo-halfdiff")."""
    return re.search(r"(?<![\w-])" + re.escape(name) + r"(?![\w-])", text) is not None


def builtin_parameterizations():
    # The registry's, in its order: the built-in ones first (none is registered at import).
    return [p["name"] for p in halfback.parameterizations()]


def losses():
    # The registry's list, as fit_loss() states it when the loss is unknown.
    with pytest.raises(ValueError) as e:
        halfback.fit_loss("lambert", "lambert", loss="no-such-loss", samples=10)
    listed = str(e.value).split("expected ", 1)[1]
    return [name.strip() for name in listed.split(",")]


def test_the_lists_the_test_compares_with_are_the_registries():
    params, loss_names = builtin_parameterizations(), losses()
    assert {"spherical", "halfdiff", "ortho", "hybrid", "stereo-halfdiff", "halfway-disk"} <= set(params)
    assert {"ngan", "cube-root", "nielsen", "bbm-ngan", "bbm-standard-log"} <= set(loss_names)
    assert not named("stereo-halfdiff", "halfdiff") and not named("bbm-ngan", "ngan")
    assert named('"halfdiff", and', "halfdiff")


@pytest.mark.parametrize("where", ["module", "convert"])
def test_every_parameterization_is_in_the_docstrings_that_list_them(where):
    doc = halfback.__doc__ if where == "module" else halfback.convert.__doc__
    absent = [p for p in builtin_parameterizations() if not named(doc, p)]
    assert not absent, f"{where}'s docstring lacks {absent}"
    # convert()'s table gives each one's columns.
    if where == "convert":
        for p in builtin_parameterizations():
            assert ", ".join(halfback.columns(p)) in doc, p


def test_every_loss_is_in_fits_docstring():
    absent = [name for name in losses() if not named(halfback.fit.__doc__, name)]
    assert not absent, f"fit's docstring lacks {absent}"


def test_render_docstring_says_what_auto_measures():
    doc = halfback.Brdf.render.__doc__
    assert "variances" in doc and "pilot" not in doc
    assert 'render(env="studio"' in doc


def test_every_study_setting_is_in_study_brdfs_docstring():
    # The metrics' keys and their values are generated from the study's list of metrics.
    with pytest.raises(ValueError) as e:
        halfback.study_brdf("lambert", {"no_such_key": 1})
    accepted = re.search(r"\(accepted: (.*)\)", str(e.value)).group(1).split(", ")
    doc = halfback.study_brdf.__doc__
    absent = [key for key in accepted if not re.search(rf"(?<!\w){key}(?!\w)", doc)]
    assert not absent, f"study_brdf's docstring lacks {absent}"
    assert "fit_budgets (default [1000, 10000]; quick: [1000])" in " ".join(doc.split())
