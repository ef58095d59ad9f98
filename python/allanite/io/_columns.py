"""Shared by every format reader: the record a reader hands on, and choosing the sample and time columns."""

from __future__ import annotations

import numbers
import re
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, ParameterError

#: Names shown in the message when no time column is recognised.
KNOWN_TIME_SHOWN = ("time", "t", "timestamp", "stamp", "sec", "seconds", "header.stamp")
TIME_NAMES = {
    "t",
    "time",
    "times",
    "timestamp",
    "timestamps",
    "stamp",
    "time_s",
    "t_s",
    "sec",
    "seconds",
    "time[s]",
    "time(s)",
    "time_ns",
    "timestamp_ns",
    "time_us",
    "time_ms",
    "epoch",
    "datetime",
    "date_time",
    "utc",
    "header.stamp",
    "header_stamp",
    "header.stamp.sec",
    "%time",
    "field.header.stamp",
}


#: A time column's name that ends in its unit (``time_ns``, ``timestamp_us``, ``t [ms]``, ``Time (nsec)``,
#: ``stamp_millis``; ``rostopic echo -p``'s ``%time``, ``field.header.stamp``: ns): the unit ``read_log`` reads it in
#: when ``time_unit=`` is not given.
_TIME_UNIT_SUFFIX = re.compile(
    r"(?:^|[\s_.\-\[(])(?P<u>ns|nsec|nanos|nanoseconds|us|µs|usec|micros|microseconds|ms|msec|millis|milliseconds|"
    r"s|sec|secs|seconds)[\])]?\s*$",
    re.IGNORECASE,
)
_UNIT_WORDS = {"n": "ns", "u": "us", "µ": "us", "m": "ms", "s": "s"}
#: Time columns whose unit is known by convention: ``rostopic echo -p`` writes both in ns.
_KNOWN_TIME_UNITS = {"%time": "ns", "field.header.stamp": "ns"}


def time_unit_of(name) -> str | None:
    """The unit a time column's name ends in (``"ns"``, ``"us"``, ``"ms"``, ``"s"``), or None when it names none:
    ``time_ns`` → ``"ns"``, ``t [ms]`` → ``"ms"``, ``stamp_usec`` → ``"us"``, ``time`` → None.

    >>> [time_unit_of(c) for c in ("time_ns", "timestamp_us", "t [ms]", "Time (nsec)", "time_s", "time", "%time")]
    ['ns', 'us', 'ms', 'ns', 's', None, 'ns']
    """
    if not isinstance(name, str):
        return None
    if name.strip().lower() in _KNOWN_TIME_UNITS:
        return _KNOWN_TIME_UNITS[name.strip().lower()]
    m = _TIME_UNIT_SUFFIX.search(name.strip())
    if m is None or m.start("u") == 0:  # the whole name a unit word: "sec", "seconds" are seconds, "ms" a column
        return "s" if m is not None and m.group("u").lower().startswith("s") else None
    u = m.group("u").lower()
    return "s" if u.startswith("s") else _UNIT_WORDS[u[0]]


def is_time_name(name) -> bool:
    """Whether a column's name says it is time: one of ``TIME_NAMES``, or one of them followed by a unit
    (``timestamp_us``, ``t [ms]``, ``Time (nsec)``)."""
    low = str(name).strip().lower()
    if low in TIME_NAMES:
        return True
    m = _TIME_UNIT_SUFFIX.search(low)
    return m is not None and m.start("u") > 0 and low[: m.start()].strip() in TIME_NAMES


@dataclass
class Record:
    """What a format reader hands to :func:`finish`."""

    data: np.ndarray  # (n, k) or (n,)
    names: list
    time: np.ndarray | None  # float seconds (or time_unit units when time_is_seconds is False)
    time_name: str | None
    where: Callable[[int], str]  # sample index → "line 12" / "row 11" / "message 11"
    time_is_seconds: bool = False
    t_first: float = 0.0  # absolute time of sample 0 when `time` is relative (bags)
    checked_finite: bool = False
    #: Other channels (``read_log(channels=…)``): column name → float64 samples, NaN where a value is missing.
    channels: dict | None = None
    channels_recognised: bool = False  # found by their names (channels="auto")
    #: Whether ``time`` is the reader's own float64 array (no view of a file or of the caller's data): scaled to
    #: seconds and made relative in place, without a second array of the record's length.
    time_owned: bool = False


def check_column_spec(spec, name, single=False):
    def ok(c):
        return isinstance(c, str) or (isinstance(c, (numbers.Integral, np.integer)) and not isinstance(c, bool))

    if ok(spec):
        return
    if not single and isinstance(spec, (list, tuple)) and len(spec) > 0 and all(ok(c) for c in spec):
        return
    what = "a column name or 0-based index" if single else "a column name or index, or a non-empty list of them"
    raise ParameterError(f"{name} must be {what}, got {spec!r}")


def resolve_column(spec, names, path, what="column"):
    """Index of one column spec among `names`."""
    n = len(names)
    if isinstance(spec, str):
        if spec in names:
            return names.index(spec)
        folded = [i for i, c in enumerate(names) if c.strip().lower() == spec.strip().lower()]
        if len(folded) == 1:
            return folded[0]
        raise InputError(f"{path}: no {what} named {spec!r}; available: {', '.join(map(repr, names))}")
    k = int(spec)
    if not -n <= k < n:
        raise InputError(
            f"{path}: {what} index {k} is out of range: the file has {n} columns "
            f"(indices 0–{n - 1}: {', '.join(names)})"
        )
    return k % n


#: ``read_log(channels=…)``'s default: the columns whose names say they are a temperature (:func:`is_temperature`).
AUTO_CHANNELS = "auto"

#: Words that make a column a temperature (a word of its name: ``temp``, ``imu_temp``, ``TEMP_OUT``,
#: ``boardTemperature``, ``temperature.x``), and the units in brackets that do so on any name (``T [degC]``,
#: ``die (°C)``, ``t[K]``) — the unit alone, since ``t`` or ``T`` without one is a time column.
TEMPERATURE_WORDS = ("temp", "temperature")
TEMPERATURE_UNITS = ("c", "°c", "degc", "deg c", "deg_c", "celsius", "k", "kelvin", "f", "°f", "degf", "deg f")
_BRACKETED = re.compile(r"[\[(]\s*([^\])]*?)\s*[\])]\s*$")


def is_temperature(name) -> bool:
    """Whether a column's name says it is a temperature: a word of it (case-insensitive; camelCase, ``_``, ``.``,
    spaces and digits split words) is one of :data:`TEMPERATURE_WORDS`, or it ends in one of
    :data:`TEMPERATURE_UNITS` in brackets or parentheses."""
    name = str(name)
    unit = _BRACKETED.search(name)
    if unit is not None and unit.group(1).lower() in TEMPERATURE_UNITS:
        return True
    words = re.findall(r"[a-z]+", re.sub(r"([a-z])([A-Z])", r"\1_\2", name).lower())
    return any(w in TEMPERATURE_WORDS for w in words)


def channel_indices(channels, names, path, t_idx=None) -> list:
    """Indices of ``read_log``'s ``channels=`` among ``names``: none for None, the temperature-named columns but the
    time column for ``"auto"``, else the columns named (names or 0-based indices; never the time column, nor one
    twice)."""
    if channels is None:
        return []
    if isinstance(channels, str) and channels == AUTO_CHANNELS:
        return [i for i, c in enumerate(names) if i != t_idx and is_temperature(c)]
    check_column_spec(channels, "channels")
    specs = [channels] if not isinstance(channels, (list, tuple)) else list(channels)
    idx = [resolve_column(c, names, path, "column") for c in specs]
    if t_idx is not None and t_idx in idx:
        raise ParameterError(f"{path}: column {names[t_idx]!r} is both the time column and a channel")
    if len(set(idx)) != len(idx):
        raise ParameterError(f"{path}: channels {specs!r} name the same column twice")
    return idx


#: Passed as ``time_column`` when neither fs nor a time column was given: recognise the time column by name.
AUTO_TIME = "<recognise by name>"


def recognise_time(names, path) -> int:
    """Index of the column whose name says it is time (``TIME_NAMES``), or the error that fs is needed."""
    hits = [i for i, c in enumerate(names) if is_time_name(c)]
    if not hits:
        raise ParameterError(
            f"{path}: give the sampling rate (fs=… in Hz) or the time column (time_column=…) — neither was passed, "
            f"and no column is named like a time column ({', '.join(sorted(KNOWN_TIME_SHOWN))}, …); "
            f"columns: {', '.join(map(repr, names[:12]))}"
        )
    return hits[0]


def select_columns(columns, time_column, names, path, default=None, channels=None):
    """(data column indices, time column index or None, squeeze to 1-D). Without ``columns`` (and ``default``):
    every column but the time column, the ``channels`` and the temperature-named ones (:func:`is_temperature`)."""
    if time_column is AUTO_TIME:
        t_idx: int | None = recognise_time(names, path)
    else:
        t_idx = None if time_column is None else resolve_column(time_column, names, path, "time column")
    if columns is None:
        apart: set = set()
        if default is not None:
            idx = [names.index(d) for d in default]
        else:
            apart |= set(channel_indices(channels, names, path, t_idx)) | {
                i for i, c in enumerate(names) if is_temperature(c)
            }
            idx = [i for i in range(len(names)) if i != t_idx and i not in apart]
            if t_idx is None:
                timeish = [names[i] for i in idx if is_time_name(names[i])]
                if timeish and len(idx) > 1:
                    raise ParameterError(
                        f"{path}: column {timeish[0]!r} looks like a time column; pass time_column="
                        f"{timeish[0]!r} (to use it) or columns=[…] (to choose the sample columns)"
                    )
        if not idx:
            besides = [repr(names[i]) for i in sorted(apart | ({t_idx} if t_idx is not None else set()))]
            raise InputError(
                f"{path}: no sample columns besides {', '.join(besides)} (the time column, the channels and the "
                "columns named as a temperature); name the sample columns with columns=[…]"
            )
        return idx, t_idx, len(idx) == 1
    single = not isinstance(columns, (list, tuple))
    specs = [columns] if single else list(columns)
    idx = [resolve_column(c, names, path) for c in specs]
    if t_idx is not None and t_idx in idx:
        raise ParameterError(f"{path}: column {names[t_idx]!r} is both the time column and a sample column")
    if len(set(idx)) != len(idx):
        raise ParameterError(f"{path}: columns {specs!r} name the same column twice")
    return idx, t_idx, single


def pick_channels(channels, idx, t_idx, names, path) -> list:
    """The channel columns' indices (:func:`channel_indices`), none of them a sample column: ``"auto"`` leaves the
    sample columns out, a column named in both ``columns`` and ``channels`` is refused."""
    ch = channel_indices(channels, names, path, t_idx)
    if isinstance(channels, str) and channels == AUTO_CHANNELS:
        return [i for i in ch if i not in idx]
    both = [names[i] for i in ch if i in idx]
    if both:
        raise ParameterError(
            f"{path}: column {both[0]!r} is both a sample column and a channel: a column is either analysed "
            "(columns=) or a channel the samples are regressed on (channels=), once"
        )
    return ch


def first_nonfinite(block):
    """(row, column) of the first non-finite value of a 2-D block, or None."""
    bad = ~np.isfinite(block)
    if not bad.any():
        return None
    r = int(np.argmax(bad.any(axis=1)))
    c = int(np.argmax(bad[r]))
    return r, c
