from typing import Sequence

import numpy as np
import numpy.typing as npt

__version__: str

def davar(
    columns: Sequence[npt.NDArray[np.float64]],
    window: int,
    hop: int,
    ms: Sequence[int],
    estimator: str,
    method: str,
    workers: int,
) -> npt.NDArray[np.float64]:
    """Allan variance of every window at every m for every axis: shape (axes, len(ms), windows)."""
