from os import PathLike
from typing import Any, Callable, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

MaterialSpec = Union[str, Mapping[str, Any], "Material"]
# A path (str or PathLike), TOML text, Mitsuba XML text, or a dict in the TOML grammar.
Scene = Union[str, PathLike[str], Mapping[str, Any]]
Path = Union[str, PathLike[str]]
ArrayLike = npt.ArrayLike
# False/None: silent; True: a line on stderr; a callable: called with (done, total).
Progress = Union[bool, None, Callable[[int, int], Any]]
Defines = Optional[Mapping[str, Any]]

class ValidationCheck:
    subject: str
    name: str
    figure: str
    passed: Optional[bool]

class ValidationReport:
    checks: list[ValidationCheck]
    passed: bool
    summary: str

class Material:
    def __init__(self, spec: MaterialSpec) -> None: ...
    @property
    def description(self) -> str: ...
    @property
    def is_stochastic(self) -> bool: ...
    @property
    def spec(self) -> dict[str, Any]: ...
    @property
    def toml(self) -> str: ...
    def __eq__(self, other: object) -> bool: ...
    def __hash__(self) -> int: ...
    def eval(
        self,
        wi: ArrayLike,
        wo: ArrayLike,
        samples: int = ...,
        mode: str = ...,
        seed: int = ...,
        *,
        cosine: bool = ...,
        threads: Optional[int] = ...,
        progress: Progress = ...,
        with_error: bool = ...,
    ) -> Union[npt.NDArray[np.float64], tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]]: ...
    def pdf(
        self, wi: ArrayLike, wo: ArrayLike, mode: str = ..., *, threads: Optional[int] = ...
    ) -> npt.NDArray[np.float64]: ...
    def sample(
        self,
        wo: ArrayLike,
        u: Optional[ArrayLike] = ...,
        mode: str = ...,
        seed: int = ...,
        *,
        threads: Optional[int] = ...,
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64], list[str]]: ...
    def albedo(
        self,
        theta_i: Union[float, Sequence[float]],
        samples: int = ...,
        seed: int = ...,
        *,
        threads: Optional[int] = ...,
        progress: Progress = ...,
    ) -> dict[str, npt.NDArray[np.float64]]: ...
    def to_merl(self, path: Path, noise: float = ..., seed: int = ...) -> int: ...
    def validate(self, samples: int = ..., seed: int = ..., *, progress: Progress = ...) -> ValidationReport: ...

def render(
    scene: Scene,
    spp: Optional[int] = ...,
    seed: int = ...,
    threads: Optional[int] = ...,
    exposure: Optional[float] = ...,
    *,
    defines: Defines = ...,
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    time_limit: Optional[float] = ...,
    progress: Progress = ...,
) -> npt.NDArray[np.float32]: ...
def render_part(
    scene: Scene,
    part: int,
    parts: int,
    spp: Optional[int] = ...,
    seed: int = ...,
    threads: Optional[int] = ...,
    *,
    defines: Defines = ...,
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    progress: Progress = ...,
) -> bytes: ...
def render_in_parts(
    scene: Scene,
    parts: int,
    spp: Optional[int] = ...,
    seed: int = ...,
    threads: Optional[int] = ...,
    *,
    defines: Defines = ...,
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    progress: Progress = ...,
) -> npt.NDArray[np.float32]: ...
def merge_render_parts(parts: Sequence[bytes], exposure: Optional[float] = ...) -> npt.NDArray[np.float32]: ...
def write_image(path: Path, image: ArrayLike, exposure: float = ...) -> None: ...
def read_image(path: Path, linear: bool = ...) -> npt.NDArray[np.float32]: ...
def tabulate(
    material: MaterialSpec,
    step: float = ...,
    samples: Optional[int] = ...,
    output: Optional[Path] = ...,
    *,
    tolerance: Optional[float] = ...,
    progress: Progress = ...,
) -> bytes: ...
def tabulate_part(
    material: MaterialSpec,
    part: int,
    parts: int,
    step: float = ...,
    samples: Optional[int] = ...,
    *,
    tolerance: Optional[float] = ...,
    progress: Progress = ...,
) -> bytes: ...
def merge_table_parts(parts: Sequence[bytes], output: Optional[Path] = ...) -> bytes: ...
def fit(
    path: Path,
    model: str = ...,
    distribution: str = ...,
    il_evaluation: str = ...,
    il_samples: int = ...,
    error: str = ...,
    samples: int = ...,
    max_theta: float = ...,
    seed: int = ...,
    output: Optional[Path] = ...,
    *,
    progress: Progress = ...,
) -> dict[str, Any]: ...
def measure(material: MaterialSpec, path: Path, noise: float = ..., seed: int = ...) -> int: ...
def set_limit(key: str, value: int) -> None: ...
def limits() -> dict[str, tuple[int, int, int, str]]: ...
