from typing import Optional, Sequence

import numpy as np
import numpy.typing as npt

from . import Defines, MaterialSpec, Path, Scene

def render(
    scene: Scene,
    parts: int,
    output: Optional[Path] = ...,
    spp: Optional[int] = ...,
    seed: int = ...,
    address: Optional[str] = ...,
    num_cpus: Optional[int] = ...,
    threads_per_task: int = ...,
    max_retries: int = ...,
    progress: bool = ...,
    defines: Defines = ...,
) -> npt.NDArray[np.float32]: ...
def tabulate(
    material: MaterialSpec,
    parts: int,
    output: Optional[Path] = ...,
    step: float = ...,
    samples: Optional[int] = ...,
    address: Optional[str] = ...,
    num_cpus: Optional[int] = ...,
    max_retries: int = ...,
    progress: bool = ...,
    tolerance: Optional[float] = ...,
) -> bytes: ...
def main(argv: Optional[Sequence[str]] = ...) -> int: ...
