"""The type stubs' lists of names (__init__.pyi) are the module's. Those generated at build time
from the library's lists (src/python/stubgen.cpp: losses, renderers, sampler charts, the study's
metric settings) and those written in the template (python/halfback/__init__.pyi.in) are
compared with what the functions accept, as their ValueError lists it, so that a name added,
renamed or removed in the library and not in the stubs fails here."""

import pathlib
import re

import numpy as np
import pytest

import halfback

STUBS = (pathlib.Path(halfback.__file__).parent / "__init__.pyi").read_text()


def literal(pattern):
    """The names of the Literal[...] that follows `pattern` in the stubs (the first match)."""
    m = re.search(pattern + r"Literal\[([^\]]*)\]", STUBS)
    assert m, f"no Literal after {pattern!r} in the stubs"
    return [n.strip().strip('"') for n in m.group(1).split(",")]


def listed(call):
    """The names the ValueError of call() lists: "expected a, b or c", "'x' is not one of a, b",
    "kind 'x' is not a, b or c", with or without quotes, up to ", got ..." or the end, without
    the remarks in parentheses."""
    with pytest.raises(ValueError) as e:
        call()
    text = re.sub(r"\s*\([^)]*\)", "", str(e.value))
    m = re.search(r"(?:expected|is not one of|is not) (.*)", text)
    assert m, text
    names = re.split(r", | or ", m.group(1).split(", got")[0].rstrip(". )"))
    return [n.strip().strip("'\"") for n in names]


def test_listed_reads_the_forms_of_the_messages():
    def raises(text):
        def call():
            raise ValueError(text)
        return call

    assert listed(raises("kind: expected 'full', 'isotropic' or 'slice', got 'x'")) == [
        "full", "isotropic", "slice"]
    assert listed(raises("target 'x': expected mitsuba3, pbrt-v4")) == ["mitsuba3", "pbrt-v4"]
    assert listed(raises("axes: kind 'x' is not angle, azimuth or length")) == [
        "angle", "azimuth", "length"]
    assert listed(raises("design 'x': expected a or b (isotropic)")) == ["a", "b"]


def test_losses_are_the_fits():
    assert literal(r"\nLoss = ") == listed(
        lambda: halfback.fit_loss("lambert", "lambert", loss="no-such-loss", samples=10))


def test_emit_targets_are_the_renderers():
    assert literal(r"def emit\(spec: str, target: ") == listed(
        lambda: halfback.emit("lambert", "no-such-renderer"))


def test_render_strategies_and_brdf_samplers():
    brdf = halfback.load("lambert")
    for arg in ("strategy", "brdf_sampling"):
        assert literal(rf"\n        {arg}: ") == listed(
            lambda: brdf.render(width=8, height=8, spp=1, **{arg: "no-such"})), arg


def test_resample_kinds():
    brdf = halfback.load("lambert")
    assert literal(r"\nKind = ") == listed(lambda: brdf.resample(kind="no-such", size=4))


def test_hemisphere_projections_and_centres():
    for arg in ("projection", "centre"):
        assert literal(rf"\n    {arg}: ") == listed(
            lambda: halfback.hemisphere("hybrid", 0.3, pixels=8, **{arg: "no-such"})), arg


def test_plan_designs_spacings_and_instruments():
    for arg in ("design", "spacing", "instrument"):
        accepted = listed(lambda: halfback.plan(budget=100, **{arg: "no-such"}))
        if arg == "design":
            # Dupuy & Jakob's layout is plan()'s own (no design of the plan's setup), tried first.
            accepted.append("dupuy-jakob")
            assert "dupuy-jakob" in halfback.plan(design="dupuy-jakob", budget=1000)["sidecar"]
        assert literal(rf"\n    {arg}: ") == accepted, arg


def test_axis_kinds_and_sampler_charts():
    def user(**kw):
        args = dict(name="stub-check", forward=lambda wi, wo: np.zeros((len(wi), 4)),
                    inverse=lambda q: (np.zeros((len(q), 3)), np.zeros((len(q), 3))),
                    axes=[("a", "length", 0.0, 1.0), ("b", "azimuth", 0.0, 2 * np.pi),
                          ("c", "length", 0.0, 1.0), ("d", "azimuth", 0.0, 2 * np.pi)])
        args.update(kw)
        return halfback.Parameterization(**args)

    assert literal(r"Axis = tuple\[str, ") == listed(
        lambda: user(axes=[("a", "no-such", 0.0, 1.0)] * 4))
    assert literal(r"sampler_chart: ") == listed(lambda: user(sampler_chart="no-such"))


def test_simd_isa_is_one_the_stubs_name():
    assert halfback.simd_isa() in literal(r"def simd_isa\(\) -> ")


def test_study_settings_are_the_keys_study_brdf_accepts():
    body = re.search(r"class StudySettings\(TypedDict, total=False\):\n(.*?)\n\n\S", STUBS, re.S)
    keys = re.findall(r"^    (\w+): ", body.group(1), re.M)
    with pytest.raises(ValueError) as e:
        halfback.study_brdf("lambert", {"no_such_key": 1})
    accepted = re.search(r"\(accepted: (.*)\)", str(e.value)).group(1).split(", ")
    # The stubs also name the older spellings study_brdf takes (error_space, designs).
    assert sorted(set(keys) - {"error_space", "designs"}) == sorted(accepted)
    assert len(keys) == len(set(keys))
