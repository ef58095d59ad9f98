"""What the Dask front doors share: dask itself (imported here once, with a clear error when the extra is
not installed), the default chunk, and the checks and conversion of the samples."""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError, MissingDependencyError, ParameterError

try:
    import dask
    import dask.array as da
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise MissingDependencyError("allanite.dask needs dask and distributed: pip install 'allanite[dask]'") from exc

__all__ = ["DEFAULT_CHUNK", "as_dask", "check_inputs", "da", "dask", "rate", "target_chunk"]

#: Samples per chunk when the caller's chunks are rechunked (2^22 float64 = 32 MiB per axis).
DEFAULT_CHUNK = 1 << 22

ESTIMATORS = ("oavar", "avar")
INPUTS = ("rate", "increment")


def as_dask(x) -> da.Array:
    """``x`` as a 1-D or 2-D dask array of real numbers with known chunk sizes."""
    arr = x if isinstance(x, da.Array) else da.asarray(x)
    if arr.ndim not in (1, 2):
        raise InputError(f"samples must be 1-D (samples,) or 2-D (samples, axes), got {arr.ndim}-D shape {arr.shape}")
    if arr.dtype.kind not in "iuf":
        raise InputError(f"samples must be real numbers (integer or float dtype), got dtype {arr.dtype}")
    if any(math.isnan(s) for s in arr.shape):
        raise InputError("samples have an unknown length (NaN chunks): call .compute_chunk_sizes() first")
    if arr.ndim == 2 and arr.shape[1] == 0:
        raise InputError(f"samples have shape {arr.shape}: at least one axis is needed")
    return arr


def check_inputs(estimator: str, input: str, fs) -> float:
    """The estimator and input allanite.dask computes, and fs as a positive finite float."""
    if estimator not in ESTIMATORS:
        raise ParameterError(f"estimator {estimator!r}: allanite.dask computes {', '.join(map(repr, ESTIMATORS))}")
    if input not in INPUTS:
        raise ParameterError(f"input {input!r}: allanite.dask takes {', '.join(map(repr, INPUTS))}")
    try:
        fs = float(fs)
    except (TypeError, ValueError):
        raise ParameterError(f"fs must be a positive finite number of Hz, got {fs!r}") from None
    if not (math.isfinite(fs) and fs > 0):
        raise ParameterError(f"fs must be a positive finite number of Hz, got {fs!r}")
    return fs


def target_chunk(arr: da.Array, chunk: int | None) -> int:
    """Samples per chunk asked for: ``chunk``, else the caller's first chunk, at least DEFAULT_CHUNK/4."""
    return int(chunk if chunk is not None else max(int(arr.chunks[0][0]), DEFAULT_CHUNK // 4))


def rate(block, fs: float, input: str) -> np.ndarray:
    """A block as (samples, axes) float64 rate samples."""
    b = np.asarray(block, dtype=np.float64)
    if b.ndim == 1:
        b = b[:, None]
    # the single-machine conversion, element by element (allanite._validate.as_rate_columns)
    return b * fs if input == "increment" else b
