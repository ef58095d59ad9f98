"""A log's other channels (``read_log(channels=…)``: a temperature, a supply voltage): cut as the samples are, and
their missing values filled.

A channel is slow next to the samples it is read with (a temperature logged every second in a 100 Hz log, where a
text export leaves ``nan`` or an empty field in the rows between), so a missing value is filled by linear
interpolation between its finite neighbours (before the first / after the last finite value: that value), with a
warning that says how many. A single missing value is always filled.
Refused (an :class:`~allanite.errors.InputError` naming the column): an infinite value (no reading, but no gap
either), fewer than two finite values, or a run of missing values longer than :data:`MAX_MISSING_RUN` of the record
(interpolation would invent the channel there). A channel recognised by its name (``channels="auto"``) is left out
with a warning instead of refused: the log is still read, without it.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..errors import InputError

#: Longest run of missing values a channel may have, as a share of the samples kept: 1 % (a 1 Hz temperature in a
#: 100 Hz log has runs of 99 samples; at 1 % a record of 10⁴ samples already takes them) — and one value always.
MAX_MISSING_RUN = 0.01


def finish_channels(path, rec, a: int, b: int) -> dict:
    """The record's channels on the samples ``a:b`` it keeps, missing values filled (module docstring); a
    recognised channel that cannot be used is left out with a warning."""
    out: dict = {}
    for name, c in (rec.channels or {}).items():
        x = np.array(c[a:b], dtype=np.float64)
        try:
            out[name] = fill_missing(path, name, x, lambda i: rec.where(a + i))
        except InputError as exc:
            if not rec.channels_recognised:
                raise
            warnings.warn(
                f"{exc} — so {name!r}, recognised as a temperature, is not used as a channel",
                stacklevel=4,  # the caller of read_log (read_log → finish → finish_channels)
            )
    return out


def fill_missing(path, name: str, x: np.ndarray, where) -> np.ndarray:
    """``x`` with its NaN filled by linear interpolation (ends: the nearest finite value), or the InputError that
    says why not (an infinite value, fewer than two finite values, a run of NaN over :data:`MAX_MISSING_RUN`)."""
    inf = np.flatnonzero(np.isinf(x))
    if inf.size:
        raise InputError(
            f"{path}: {where(int(inf[0]))}, channel column {name!r}: infinite value {x[inf[0]]}; a channel's "
            "values must be finite numbers, or NaN where one is missing"
        )
    miss = np.isnan(x)
    if not miss.any():
        return x
    n, k = x.size, int(miss.sum())
    if n - k < 2:
        raise InputError(
            f"{path}: channel column {name!r} has {n - k} finite value(s) of {n}: too few to read the channel from "
            "(channels=None leaves it out)"
        )
    start, run = _longest_run(miss)
    if run > max(1.0, MAX_MISSING_RUN * n):  # one value between two readings is always filled
        raise InputError(
            f"{path}: channel column {name!r} misses {run} values in a row from {where(start)} — more than "
            f"{100 * MAX_MISSING_RUN:g} % of the {n} samples, where interpolation would invent it; fill or cut the "
            "log, or leave the channel out (channels=None)"
        )
    idx = np.arange(n)
    x[miss] = np.interp(idx[miss], idx[~miss], x[~miss])
    warnings.warn(
        f"{path}: channel column {name!r}: {k} of {n} values missing (NaN; the longest run {run}, from "
        f"{where(start)}), filled by linear interpolation between their neighbours",
        stacklevel=5,
    )
    return x


def _longest_run(miss: np.ndarray) -> tuple[int, int]:
    """(start, length) of the longest run of True in ``miss`` (which holds one)."""
    edges = np.diff(np.concatenate(([0], miss.view(np.int8), [0])))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    j = int(np.argmax(ends - starts))
    return int(starts[j]), int(ends[j] - starts[j])
