from typing import Literal

import numpy as np
import numpy.typing as npt

Param = Literal["dirs", "spherical", "halfdiff", "ortho", "hybrid"]
FloatArray = npt.NDArray[np.float32] | npt.NDArray[np.float64]

def convert(x: npt.ArrayLike, src: Param, dst: Param, isotropic: bool = False) -> FloatArray:
    """Converts rows of x (N, 6 | 4 | 3) from `src` to `dst`; invalid rows become NaN."""

def valid(x: npt.ArrayLike, param: Param, isotropic: bool = False) -> npt.NDArray[np.bool_]:
    """Mask of the rows of x inside `param`'s valid domain (or valid direction pairs)."""

def jacobian(x: npt.ArrayLike, param: Param, isotropic: bool = False) -> FloatArray:
    """J with d(wi) d(wo) = J d(params) at each row of x (NaN where invalid)."""

def columns(name: Param, isotropic: bool = False) -> list[str]:
    """Column names of a form, in order."""
