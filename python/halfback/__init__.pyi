from collections.abc import Mapping, Sequence
from typing import Any, Literal, TypedDict

import numpy as np
import numpy.typing as npt

Param = Literal["dirs", "spherical", "halfdiff", "ortho", "hybrid"]
FloatArray = npt.NDArray[np.float32] | npt.NDArray[np.float64]

def convert(
    x: npt.ArrayLike,
    src: Param,
    dst: Param,
    isotropic: bool = False,
    out: FloatArray | None = None,
) -> FloatArray:
    """Converts rows of x (N, 6 | 4 | 3) from `src` to `dst`; invalid rows become NaN."""

def valid(x: npt.ArrayLike, param: Param, isotropic: bool = False) -> npt.NDArray[np.bool_]:
    """Mask of the rows of x inside `param`'s valid domain (or valid direction pairs)."""

def jacobian(x: npt.ArrayLike, param: Param, isotropic: bool = False) -> FloatArray:
    """J with d(wi) d(wo) = J d(params) at each row of x (NaN where invalid)."""

def columns(name: Param, isotropic: bool = False) -> list[str]:
    """Column names of a form, in order."""

def simd_isa() -> Literal["scalar", "sse2", "avx2", "avx512"]:
    """The instruction set of the SIMD kernels in use (HALFBACK_ISA, else the CPU's best)."""

Kind = Literal["full", "isotropic", "slice"]

class Brdf:
    @property
    def name(self) -> str: ...
    @property
    def description(self) -> str: ...
    @property
    def isotropic(self) -> bool: ...
    @property
    def reciprocal(self) -> bool: ...
    @property
    def info(self) -> dict[str, object]:
        """Name, description, symmetries and data facts."""
    def eval(self, wi: npt.ArrayLike, wo: npt.ArrayLike | None = None) -> npt.NDArray[np.float64]:
        """rho(wi, wo) in 1/sr, (N, 3); wi, wo (N, 3) unit vectors, or wi alone (N, 6)."""
    def albedo(
        self, theta_i: float, n: int = 256
    ) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """Directional albedo at theta_i (radians) and its standard errors."""
    def resample(
        self,
        param: Param = "hybrid",
        kind: Kind = "isotropic",
        size: int | Sequence[int] = 64,
        azimuth: float = 0.0,
        nodes: bool = False,
        ranges: Mapping[str, tuple[float, float]] = ...,
    ) -> dict[str, Any]:
        """rho, valid, axes, axis_names, metadata of the BRDF on a grid of `param`."""
    def render(
        self,
        env: str = "default",
        width: int = 256,
        height: int = 256,
        spp: int = 64,
        seed: int = 1,
        strategy: Literal["mis", "brdf", "env"] = "mis",
        threads: int = 0,
    ) -> npt.NDArray[np.float32]:
        """A sphere of the BRDF under `env`: (height, width, 3) linear radiance."""

def hemisphere(
    param: Param,
    theta_o: float,
    pixels: int = 256,
    projection: Literal["equal-area", "orthographic", "equidistant"] = "equal-area",
    centre: Literal["normal", "mirror", "back"] = "normal",
) -> dict[str, Any]:
    """first, second, region (pixels x pixels), u, v, wo: Figure 1's data for one disk."""

def load(spec: str) -> Brdf:
    """A BRDF from a file, a model spec ("ggx:alpha=0.2"), a sum or "embedded:NAME"."""

def models() -> list[str]:
    """The analytic models' names."""

class StudySettings(TypedDict, total=False):
    """The options of `halfback study`, '-' spelled '_' (missing: the defaults)."""

    params: Sequence[str]  # parameterization names (default: all of them, spherical last)
    space: str  # the error space (also "error_space")
    error_space: str
    designs: Sequence[str]
    profiles: Sequence[str]  # study_profile() of every BRDF, for the learned design
    quick: bool
    no_gonio: bool
    no_images: bool
    budgets: Sequence[int]
    budgets_4d: Sequence[int]
    test_pairs: int
    env: Sequence[str]
    image_budget: int
    image_size: int
    image_spp: int
    max_theta: float
    seed: int

def study_brdf(spec: str, settings: StudySettings | None = None) -> dict[str, Any]:
    """The study of one BRDF: tables as CSV text, "settings" and "renderings" (GIL released)."""

def study_profile(spec: str, settings: StudySettings | None = None) -> str:
    """The profile of one BRDF for the learned design, as text (settings["profiles"])."""

def merge_study(out: str, parts: Sequence[Mapping[str, Any] | str]) -> dict[str, Any]:
    """Writes the report of study_brdf results and study directories into `out`."""

def ssim(
    x: npt.ArrayLike, y: npt.ArrayLike, mask: npt.ArrayLike | None = None
) -> float:
    """SSIM (Wang et al. 2004) of two 2D images in [0, 1], over the masked full windows."""
