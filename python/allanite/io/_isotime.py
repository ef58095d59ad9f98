"""A text log's time column written as ISO 8601 date-times (``2026-11-27T10:00:00.005``, ``2026-11-27
10:00:00.005``, a trailing ``Z`` or ``+01:00``): recognised from its first data row and read as seconds from the
first stamp, the first stamp kept as POSIX seconds (as a Parquet timestamp column is)."""

from __future__ import annotations

import re
import warnings

import numpy as np

from ..errors import InputError

#: A date, a time to the second at least, an optional fraction and an optional zone (Z, ±hh:mm).
ISO = re.compile(r"^\d{4}-\d{2}-\d{2}[T ]\d{2}:\d{2}:\d{2}(\.\d+)?(Z|[+-]\d{2}:?\d{2})?$")


def is_iso_time(field: str) -> bool:
    """Whether a text field is an ISO 8601 date-time.

    >>> is_iso_time("2026-11-27T10:00:00.005"), is_iso_time("2026-11-27 10:00:00Z"), is_iso_time("10:00:00")
    (True, True, False)
    """
    return bool(ISO.match(field.strip().strip('"').strip("'")))


def iso_seconds(path, fields: list, where) -> tuple[np.ndarray, float]:
    """(seconds from the first stamp, the first stamp as POSIX seconds) of ISO 8601 ``fields``; a field that is
    none is an InputError naming its row (``where``)."""
    clean = [f.strip().strip('"').strip("'") for f in fields]
    for r, f in enumerate(clean):
        if not ISO.match(f):
            raise InputError(f"{path}: {where(r)}, time column: {f!r} is not an ISO 8601 date-time like the first")
    clean = [f[:-1] if f.endswith("Z") else f for f in clean]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "no explicit representation of timezones": an offset is applied (UTC)
        ns = np.array(clean).astype("datetime64[ns]").astype(np.int64)
    return (ns - ns[0]).astype(np.float64) * 1e-9, float(ns[0]) * 1e-9
