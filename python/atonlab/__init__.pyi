# Type stub of the atonlab package (docs/python.md), for editors and type checkers.
from os import PathLike
from typing import Any, Callable, Iterable, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt
import pandas as pd

_Path = Union[str, PathLike[str]]
_Paths = Union[_Path, Iterable[_Path]]
_Value = Union[bool, int, float, str, Sequence[Any], Mapping[str, Any]]

__version__: str

class InputError(ValueError):
    """Bad input: str(e) is the command line's sentence; file, line (1-based), key and option say where."""
    file: Optional[str]
    line: Optional[int]
    key: Optional[str]
    option: Optional[str]
    message: Optional[str]

class InputFileNotFoundError(InputError, FileNotFoundError):
    """An input file that does not exist: an InputError and a FileNotFoundError (filename names it)."""

class NoContextError(RuntimeError):
    """No OpenGL 4.5 context can be made on this machine."""

class StudyFileError(OSError):
    """A study file the store refuses or cannot write; file names it."""
    file: Optional[str]

class Frame:
    """One rendered frame."""
    hdr: npt.NDArray[np.float32]  # H×W×3, linear Rec.709, cd/m², a view of the frame's memory
    rgba: npt.NDArray[np.float32]  # H×W×4, the same memory
    codes: Union[npt.NDArray[np.uint8], npt.NDArray[np.uint16], None]  # display codes
    bits: int  # the display's code depth
    deg_per_px: float  # degrees of visual angle per pixel at the centre
    time_s: float  # scene time, s
    render_s: float  # wall-clock s inside the library
    metadata: dict[str, Any]  # the EXR header's attributes
    display: dict[str, Any]  # the display as numbers: peak_cd_m2, black_cd_m2, encoding, bits, primaries_xy, ...
    @property
    def displayed_cd_m2(self) -> npt.NDArray[np.float32]: ...  # H×W×3: what each channel emits, cd/m²
    def added_lux(self, light: str, radius_deg: float = 0.5) -> float: ...  # `atonlab check`'s "adds", lx

class Scene:
    """A scene file with its overrides applied."""
    @staticmethod
    def load(path: _Path, overrides: Optional[Mapping[str, _Value]] = None) -> Scene: ...
    @property
    def path(self) -> str: ...
    @property
    def width_px(self) -> int: ...
    @property
    def height_px(self) -> int: ...
    @property
    def adaptation_cd_m2(self) -> float: ...
    def render(self, time_s: float = 0.0) -> Frame: ...

def tonemap(hdr: npt.ArrayLike, *, operator: Optional[str] = None, adaptation_cd_m2: Optional[float] = None,
            encoding: Optional[str] = None, peak_cd_m2: Optional[float] = None, black_cd_m2: Optional[float] = None,
            dither: Optional[bool] = None, blueshift: Optional[bool] = None, hue_preservation: Optional[str] = None,
            key: Optional[float] = None, reinhard_white: Union[float, str, None] = None,
            white_cd_m2: Optional[float] = None, epsilon_cd_m2: Optional[float] = None,
            scale: Optional[float] = None, scene: Optional[str] = None,
            display: Optional[str] = None) -> npt.NDArray[np.uint8]:
    """H×W×3 cd/m² → H×W×3 uint8 display codes, as `atonlab tonemap`. display= is encoding='s deprecated old name."""

def glare(hdr: npt.ArrayLike, deg_per_px: float, *, model: Optional[str] = None,
          adaptation_cd_m2: Optional[float] = None, pupil_mm: Optional[float] = None,
          radius_deg: Optional[float] = None, window: Optional[str] = None,
          psf_size: Optional[int] = None, scene: Optional[str] = None,
          **settings: Union[bool, int, float, str]) -> npt.NDArray[np.float32]:
    """H×W×3 cd/m² with a glare model's glare added, as `atonlab glare`; settings: the models' own (bloom_sigma_deg=…)."""

def psf(*, pupil_mm: Optional[float] = None, adaptation_cd_m2: Optional[float] = None,
        eye_preset: Optional[str] = None, clear: bool = False, spd: str = "d65", size: int = 512, samples: int = 30,
        seed: Optional[int] = None, time_s: float = 0.0,
        scene: Optional[str] = None) -> tuple[npt.NDArray[np.float32], dict[str, Any]]:
    """The eye's RGB glare PSF (luminance sums to 1) and its metadata, as `atonlab psf`."""

def read_exr(path: _Path) -> tuple[npt.NDArray[np.float32], dict[str, Any]]: ...
def write_exr(path: _Path, hdr: npt.ArrayLike, *, deg_per_px: Optional[float] = None,
              adaptation_cd_m2: Optional[float] = None, units: str = "cd/m2",
              strings: Optional[Mapping[str, str]] = None) -> None: ...

class light:
    """Allard's law (K2012 eq 2.1), as `atonlab light`."""
    @staticmethod
    def range_nmi(intensity_cd: float, *, colour: str = "white", visibility_nmi: Optional[float] = None,
                  transmissivity_per_nmi: Optional[float] = None, period: str = "night",
                  background: str = "none") -> float: ...
    @staticmethod
    def intensity_cd(range_nmi: float, *, colour: str = "white", visibility_nmi: Optional[float] = None,
                     transmissivity_per_nmi: Optional[float] = None, period: str = "night",
                     background: str = "none") -> float: ...

class Check:
    displayable: bool
    display: dict[str, Any]
    conditions: dict[str, dict[str, Any]]
    text: str
    refusal: str
    data: dict[str, Any]
    @property
    def table(self) -> pd.DataFrame: ...
    def __bool__(self) -> bool: ...

def check(protocol: _Path, display: Optional[Mapping[str, float]] = None, db: Optional[_Path] = None) -> Check: ...

def run(protocol: _Path, db: _Path,
        observer: Union[str, Callable[[dict[str, Any]], Union[str, tuple[str, float]]]] = "model",
        headless: bool = True, progress: Optional[Callable[[int, Optional[int]], None]] = None, *,
        script: Optional[_Path] = None, resume: Optional[int] = None, resume_last: bool = False,
        seed: Optional[int] = None, observer_seed: Optional[int] = None, allow_undisplayable: bool = False,
        true_pse: bool = True, verbose: bool = False, observer_code: Optional[str] = None,
        observer_name: Optional[str] = None) -> dict[str, Any]: ...

CATEGORY_MAX_VALUES: int
CATEGORY_MAX_FRACTION: float

def read_study(paths: _Paths, salvage: bool = False) -> pd.DataFrame: ...

class Analysis:
    fits: pd.DataFrame
    summary: dict[str, Any]
    out: Optional[str]
    exit_status: int

def analyze(paths: _Paths, out: Optional[_Path] = None, *, bootstrap: Optional[int] = None,
            seed: Optional[int] = None, family: str = "normal", threads: Optional[int] = None,
            salvage: bool = False) -> Analysis: ...

class Fit(dict[str, Any]):
    threshold: float
    slope: float
    width: float
    alpha: float
    beta: float
    gamma: float
    reliable: bool
    reason: str
    n_trials: int
    n_levels: int
    deviance: float
    log_likelihood: float
    ci_lower: float
    ci_upper: float
    def psi(self, x: Sequence[float]) -> list[float]: ...

def fit(levels: Sequence[float], n_trials: Sequence[int], n_yes: Sequence[int], task: str = "2afc",
        family: str = "normal", *, guess_rate: Optional[float] = None, target_p: Optional[float] = None,
        lapse_max: float = 0.06, bootstrap: int = 0, seed: Optional[int] = None) -> Fit: ...
