"""Checks shared by the forecast models: a series of finite numbers, the SD convention, the horizon."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError, ParameterError

SD_CHOICES = ("population", "sample")


def as_series(series: Any, *, name: str = "series", min_len: int = 4) -> np.ndarray:
    """``series`` as a 1-D float64 array of at least ``min_len`` finite values; errors name ``name``."""
    try:
        x = np.asarray(series, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be a 1-D sequence of numbers ({exc})") from None
    if x.ndim != 1:
        raise InputError(f"{name} must be 1-D, got shape {x.shape}")
    if x.size < min_len:
        raise InputError(f"{name} has {x.size} values; at least {min_len} are needed")
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        i = int(bad[0])
        raise InputError(
            f"{name}[{i}] = {x[i]} is not finite ({bad.size} non-finite value(s)); remove or fill them first"
        )
    return x


def check_sd(sd: str) -> int:
    """The ddof of an SD convention: 0 for "population", 1 for "sample"."""
    if sd not in SD_CHOICES:
        raise ParameterError(f"sd = {sd!r} is not allowed; use 'population' (divide by n) or 'sample' (n - 1)")
    return 0 if sd == "population" else 1


def check_horizon(h: Any) -> int:
    """A forecast horizon: a non-negative integer number of steps."""
    if isinstance(h, bool) or not isinstance(h, (int, np.integer)) or h < 0:
        raise ParameterError(f"h = {h!r} must be a non-negative integer (the number of steps ahead)")
    return int(h)
