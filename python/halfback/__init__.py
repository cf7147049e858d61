"""halfback: exact, fast BRDF parameterizations (Barla, Belcour, Pacanowski 2015).

Forms: "dirs" (wi_x, wi_y, wi_z, wo_x, wo_y, wo_z) and the parameterizations in the table below
(their columns; parameterizations() gives each one's summary and axes). With isotropic=True,
phi_h is dropped and the second azimuth is relative. Conventions and derivations: docs/math.md.

BRDFs: load(spec) gives a Brdf (analytic models, MERL, RGL, ALTA files, embedded materials) with
vectorized eval(wi, wo), info, albedo(), resample() and render(); hemisphere() gives the data of
the paper's Figure 1. study_brdf() studies one BRDF (any engine can map it over a
database) and merge_study() writes the report of the results (docs/study.md).
"""

import atexit
import math
import os
import weakref

import numpy as _np

from ._core import (
    Brdf,
    check_brdf,
    columns,
    convert,
    hemisphere,
    image_error,
    jacobian,
    load,
    models,
    Parameterization,
    parameterizations,
    register_brdf,
    register_parameterization,
    simd_isa,
    Viewer,
    ssim,
    valid,
)
from . import _core

__version__ = _core.__version__


class RenderedImage(_np.ndarray):
    """Brdf.render()'s image: an (H, W, 3) float32 numpy array of linear radiance, row 0 at the
    top, with `sampler`: the BRDF sampler used and, when brdf_sampling="auto" chose it, why (the
    line `halfback render` prints on stderr)."""

    def __new__(cls, image, sampler=""):
        obj = _np.asarray(image).view(cls)
        obj.sampler = sampler
        return obj

    def __array_finalize__(self, obj):
        self.sampler = getattr(obj, "sampler", "")

    def __reduce__(self):  # pickled with its sampler (Dask workers send results back)
        rebuild, args, state = super().__reduce__()
        return rebuild, args, (state, self.sampler)

    def __setstate__(self, state):
        array_state, self.sampler = state
        super().__setstate__(array_state)


def _parameterization_table():
    """The built-in parameterizations and their columns, aligned, for the module's docstring."""
    rows = [(f'"{p["name"]}"', ", ".join(a["column"] for a in p["axes"]))
            for p in parameterizations()]
    width = max(len(name) for name, _ in rows)
    return "".join(f"  {name:<{width}}  {cols}\n" for name, cols in rows)


if __doc__ is not None:  # None under python -OO
    __doc__ += "\nParameterizations:\n" + _parameterization_table()


# Python functions, not the module's built-ins: pickle sends a Python function by its name, so
# that engines which ship tasks to other processes (Dask workers) can send these; a pybind11
# built-in cannot be pickled.
def study_brdf(spec, settings=None):
    return _core.study_brdf(spec, settings)


def merge_study(out, parts):
    return _core.merge_study(out, parts)


def study_profile(spec, settings=None):
    return _core.study_profile(spec, settings)


def fit(brdf, model, loss="ngan", samples=20000, threads=0, starts=(), max_iterations=200,
        max_theta=math.pi / 2, energy=True):
    return _core.fit(brdf, model, loss, samples, threads, list(starts), max_iterations, max_theta,
                     energy)


def fit_loss(brdf, model, loss="ngan", samples=20000, threads=0):
    return _core.fit_loss(brdf, model, loss, samples, threads)


def factor(brdf, param="hybrid", rank=2, counts=(32, 32, 32), threads=0):
    return _core.factor(brdf, param, rank, tuple(counts), threads)


def fit_samples(n):
    return _core.fit_samples(n)


def emit(spec, target, name="halfback_fit"):
    return _core.emit(spec, target, name)


def nbrdf_train(brdf, output, hidden=(21, 21), samples=640000, epochs=100, batch=512,
                learning_rate=5e-4, seed=0, threads=0, param="", final_learning_rate=0.0, restarts=1,
                restart_epochs=5, loss="sztrajman"):
    import os
    return _core.nbrdf_train(brdf, os.fspath(output), list(hidden), samples, epochs, batch,
                             learning_rate, seed, threads, param, final_learning_rate, restarts,
                             restart_epochs, loss)


def published_fits(path):
    return _core.published_fits(str(path))


def plan(param="hybrid", design="regular", budget=10000, spacing="own", full=False,
         max_theta=math.pi / 2, seed=1, instrument="light-detector"):
    return _core.plan(param, design, budget, spacing, full, max_theta, seed, instrument)


def plan_main(pilot, values):
    import os
    return _core.plan_main(os.fspath(pilot) if not isinstance(pilot, str) else pilot, values)


def plan_error(plan, values, truth, test_pairs=200000, seed=1, max_theta=math.radians(85),
               space="log"):
    import os
    return _core.plan_error(os.fspath(plan) if not isinstance(plan, str) else plan, values, truth,
                            test_pairs, seed, max_theta, space)


def reconstruct(plan, values, out, name="measured"):
    """A BRDF from the values measured at a plan's rows (docs/acquisition.md), as `halfback
    reconstruct`: plan is a PLAN.json path or plan()'s "sidecar" text; values (rows, 3) or
    (rows,), NaN where a row was not measured (filled from the neighbouring cells); out a MERL
    .binary or RGL .bsdf file, written; returns load(out). The GIL is released while it runs."""
    import os
    _core._reconstruct(os.fspath(plan) if not isinstance(plan, str) else plan, values,
                       os.fspath(out), name)
    return load(os.fspath(out))


study_brdf.__doc__ = _core.study_brdf.__doc__
fit.__doc__ = _core.fit.__doc__
plan.__doc__ = _core.plan.__doc__
plan_main.__doc__ = _core.plan_main.__doc__
plan_error.__doc__ = _core.plan_error.__doc__
fit_loss.__doc__ = _core.fit_loss.__doc__
fit_samples.__doc__ = _core.fit_samples.__doc__
factor.__doc__ = _core.factor.__doc__
emit.__doc__ = _core.emit.__doc__
published_fits.__doc__ = _core.published_fits.__doc__
nbrdf_train.__doc__ = _core.nbrdf_train.__doc__
merge_study.__doc__ = _core.merge_study.__doc__
study_profile.__doc__ = _core.study_profile.__doc__

_viewers = weakref.WeakSet()


def view(*brdfs, roots=(), host="127.0.0.1", port=0, threads=0, workers=16, open=False):
    """Starts the explorer of `halfback view` in this process (a notebook or a script) and returns
    a Viewer (url, stop(), wait(); in a notebook its link shows as the cell's output).

    brdfs: specs ("ggx:alpha=0.2", a file, "embedded:NAME"), Brdf objects, or Python callables
    eval(wi, wo) -> rho on (N, 3) arrays, registered by register_brdf under their __name__ (and
    checked first: a callable that raises, returns NaN or the wrong shape is refused with the
    check's message). roots: directories whose files the page may open (--root). The server
    stops with stop(), at the end of a `with` block, or when the interpreter exits; a script
    keeps it running with wait()."""
    items = []
    for b in brdfs:
        if callable(b) and not isinstance(b, (str, Brdf)):
            name = getattr(b, "__name__", "")
            b = register_brdf(name if name.isidentifier() else "function", b)
        items.append(b)
    viewer = _core._view(items, [os.fspath(r) for r in roots], host, port, threads, workers)
    _viewers.add(viewer)
    if open:
        import webbrowser

        webbrowser.open(viewer.url)
    return viewer


@atexit.register
def _stop_viewers():
    for v in list(_viewers):
        v.stop()


__all__ = [
    "Brdf",
    "check_brdf",
    "columns",
    "convert",
    "emit",
    "factor",
    "fit",
    "fit_loss",
    "fit_samples",
    "hemisphere",
    "image_error",
    "jacobian",
    "load",
    "merge_study",
    "nbrdf_train",
    "plan",
    "plan_error",
    "plan_main",
    "models",
    "published_fits",
    "reconstruct",
    "register_brdf",
    "RenderedImage",
    "simd_isa",
    "ssim",
    "study_brdf",
    "study_profile",
    "valid",
    "view",
    "Viewer",
]
