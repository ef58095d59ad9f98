from collections.abc import Sequence

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

def theo1_static(
    columns: Sequence[npt.NDArray[np.float64]],
    ms: Sequence[int],
    workers: int,
) -> npt.NDArray[np.float64]:
    """Theo1 of each whole rate record at every even m (phase: M + 1 points): shape (axes, len(ms))."""

def theo1_dynamic(
    columns: Sequence[npt.NDArray[np.float64]],
    window: int,
    hop: int,
    ms: Sequence[int],
    workers: int,
) -> npt.NDArray[np.float64]:
    """Theo1 of every sliding window at every even m: shape (axes, len(ms), windows)."""
