"""What :func:`~allanite.io.read_log` returns: a :class:`Log` and its :class:`Gap` list, and the
timing constants the reader applies."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..units import Unit

__all__ = ["GAP_FACTOR", "GAP_MODES", "JITTER_WARN", "TIME_UNITS", "Gap", "Log"]

#: What ``gaps=`` accepts.
GAP_MODES = ("error", "longest", "split", "nan")
#: A time step longer than this many nominal steps is a gap.
GAP_FACTOR = 1.5
#: Time-column units accepted by ``time_unit=`` (seconds per unit).
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
#: A step that differs from the nominal one by more than this fraction (but is no gap) is reported as
#: irregular sampling, with a warning.
JITTER_WARN = 0.25


@dataclass(frozen=True)
class Gap:
    """A stretch of missing samples, found from the time column.

    Attributes
    ----------
    index : int
        Where it is: between sample ``index − 1`` and sample ``index`` of the full record, so
        ``data[:index]`` comes before it.
    time : float
        Time of the last sample before the gap, seconds from the first sample of the record.
    duration : float
        Time without samples, seconds: the step across the gap minus one nominal step.
    missing : int
        About how many samples are missing (``round(duration · fs)``).
    """

    index: int
    time: float
    duration: float
    missing: int

    def __str__(self) -> str:
        return (
            # 4 digits: a ns epoch stamp's float rounding read a 10 ms gap as 0.00999998 s
            f"{self.duration:.4g} s (≈{self.missing} sample{'' if self.missing == 1 else 's'}) missing after "
            f"sample {self.index - 1} "
            f"at t = {self.time:.6g} s"
        )


@dataclass(repr=False)
class Log:
    """A gyro log read by :func:`read_log`.

    Attributes
    ----------
    data : ndarray
        Samples, (samples,) for one column, else (samples, axes); float64, or for ``.npy`` a read-only
        memory map of the file (no copy) in the file's dtype.
    fs : float
        Sampling rate, Hz (given, or 1 / the median time step, to 9 significant digits).
    columns : list of str
        Names of the columns in ``data`` (``"col0"``, ``"col1"``, … when the file has none).
    unit : Unit or None
        Unit of the samples (see :mod:`allanite.units`); ``None`` when not given.
    input : {"rate", "increment", "angle"}
        What the samples are, as for :func:`allanite.avar`.
    t0 : float
        Time of ``data[0]`` on the file's clock, seconds (0 when there is no time column).
    path : Path
    format : str
        ``"text"``, ``"npy"``, ``"npz"``, ``"parquet"``, ``"ros1"`` or ``"ros2"``.
    gaps : list of Gap
        Gaps in the full record (empty when there is no time column to find them from).
    span : (int, int)
        Which samples of the full record ``data`` holds: ``data = record[span[0]:span[1]]``.
    segments : list of ndarray or None
        With ``gaps="split"``: the gap-free stretches, in order (``data`` is the longest); their
        sample ranges are in ``segment_spans``.
    segment_spans : list of (int, int) or None
    time : ndarray or None
        Times of the samples in ``data``, seconds from ``t0`` (so ``time[0] == 0``), when the file
        has a time column.
    jitter : float or None
        Largest deviation of a (non-gap) time step from the nominal step, as a fraction of it.
    n_record : int
        Samples in the full record, before any gap handling.
    channels : dict of str → ndarray
        Other channels of the log (``read_log(channels=…)``: by default the columns whose names say they are a
        temperature), column name → float64 samples of ``data``'s rows (the same span; missing values filled,
        see :mod:`allanite.io._channels`); empty without any. Not among ``columns``.
    channels_recognised : bool
        Whether the channels were found by their names (``channels="auto"``) rather than named.
    unit_source : str or None
        Where ``unit`` came from (``unit=``, the column names, a ROS bag's convention).
    column_units : list
        Per column, the unit its name gives (a ``ColumnUnit(name, kind, text)``) or None; :attr:`groups` gathers
        the columns by it and :meth:`take` keeps one group.
    time_unit, time_unit_source : str or None
        The time column's unit and why: ``time_unit=``, its name, an epoch magnitude, or the default (seconds).
    """

    data: np.ndarray
    fs: float
    columns: list
    unit: Unit | None
    input: str
    t0: float
    path: Path
    format: str
    gaps: list = field(default_factory=list)
    span: tuple = (0, 0)
    segments: list | None = None
    segment_spans: list | None = None
    time: np.ndarray | None = None
    jitter: float | None = None
    n_record: int = 0
    #: Name of the time column the times came from (None without one), and whether it was recognised
    #: by its name because neither ``fs`` nor ``time_column`` was given.
    time_column: str | None = None
    time_column_recognised: bool = False
    #: Unit the time column was read in (``time_unit=``, else the unit its name ends in, else "s"; None without
    #: one), and whether its name gave a unit other than seconds (``time_ns`` → "ns").
    time_unit: str | None = None
    time_unit_from_name: bool = False
    channels: dict = field(default_factory=dict)
    channels_recognised: bool = False
    #: Where ``unit`` came from: ``"given as unit="``, ``"from the column names: [rad s^-1]"``,
    #: ``"ROS convention (REP 103)"``, …; None without a unit.
    unit_source: str | None = None
    #: Per column of ``columns``, the unit its name gives (:func:`allanite.io._units.column_unit`: a
    #: ``ColumnUnit(name, kind, text)``), or None.
    column_units: list = field(default_factory=list)
    #: Where ``time_unit`` came from: ``"time_unit="``, ``"its name"``, ``"epoch magnitude"`` (a first stamp that
    #: reads as a date in 2001–2286 in that unit) or ``"default"`` (seconds); None without a time column.
    time_unit_source: str | None = None

    @property
    def groups(self) -> dict:
        """The columns by the unit their names give: unit name (``"rad/s"``, ``"m/s^2"``; ``None`` for none) →
        column names, in order — an IMU log's gyro and accelerometer columns apart. One group for a log whose
        columns give one unit (or none)."""
        out: dict = {}
        units = self.column_units or [None] * len(self.columns)
        for c, cu in zip(self.columns, units):
            out.setdefault(None if cu is None else cu.name, []).append(c)
        return out

    def take(self, columns) -> Log:
        """This log on some of its ``columns`` (names, in the order given; e.g. one of :attr:`groups`): ``data``
        (and ``segments``) of those columns, 1-D for a single name; the log's unit where it was given (``unit=``, a
        ROS bag's), else the unit those columns' names give when they give one gyro unit (``unit_source`` says so).

        Raises
        ------
        ParameterError
            A name that is not one of ``columns``, or none at all.
        """
        from ._units import units_of

        names = [columns] if isinstance(columns, str) else list(columns)
        missing = [c for c in names if c not in self.columns]
        if not names or missing:
            raise ParameterError(
                f"Log.take: {missing[0] if missing else columns!r} is not one of the log's columns: "
                f"{', '.join(map(repr, self.columns))}"
            )
        idx = [self.columns.index(c) for c in names]
        pick = idx[0] if isinstance(columns, str) else idx
        two = self.data if self.data.ndim == 2 else self.data[:, None]
        cols = [self.column_units[i] if self.column_units else None for i in idx]
        unit, source = self.unit, self.unit_source
        if unit is None or (source or "").startswith("from the column names"):  # the names' unit: theirs now
            unit, source, cols = units_of(self.path, names, None, self.input)
        segments = None
        if self.segments is not None:
            segments = [np.asarray(s).reshape(len(s), -1)[:, pick] for s in self.segments]
        return replace(
            self, data=two[:, pick], columns=names, segments=segments, unit=unit, unit_source=source, column_units=cols
        )

    @property
    def n_samples(self) -> int:
        """Number of samples (rows) in the log."""
        return int(self.data.shape[0])

    @property
    def n_axes(self) -> int:
        """Number of axes (columns) read; 1 for a one-dimensional log."""
        return 1 if self.data.ndim == 1 else int(self.data.shape[1])

    @property
    def duration(self) -> float:
        """Length of ``data`` in seconds (samples / fs)."""
        return self.n_samples / self.fs

    def _unit_said(self) -> str:
        """The repr's unit: the unit, its kind and where it came from; the header's groups where its columns give
        several units; "not given"."""
        if self.unit is not None:
            return f"{self.unit.name} ({self.unit.kind}{'; ' + self.unit_source if self.unit_source else ''})"
        groups = self.groups
        if len(groups) > 1 or None not in groups:
            shown = "; ".join(f"{u or 'no unit'}: {', '.join(map(str, cs))}" for u, cs in groups.items())
            return f"none — the column names give {shown} (Log.take(columns) for one group)"
        return "not given"

    def _time_unit_said(self) -> str:
        """The repr's time unit and where it came from; nothing for seconds named so (``time_s``)."""
        why = {
            "epoch magnitude": "read from its epoch magnitude",
            "time_unit=": "given as time_unit=",
            "default": "by default: neither its name nor an epoch magnitude gives one",
        }.get(self.time_unit_source or "")
        if self.time_unit_from_name:
            why = "its name says so"
        return f" in {self.time_unit} ({why})" if why else ""

    def __repr__(self) -> str:
        kind = "memory-mapped " if isinstance(self.data, np.memmap) else ""
        dur = self.duration
        dur_s = f"{dur / 3600:.3g} h" if dur >= 3600 else f"{dur:.4g} s"
        lines = [
            f"Log({self.path.name!r}, {self.format})",
            f"  data: {self.n_samples} samples × {self.n_axes} {'axis' if self.n_axes == 1 else 'axes'}, "
            f"{kind}{self.data.dtype}, "
            f"fs = {self.fs:g} Hz ({dur_s})",
            f"  columns: {', '.join(self.columns)}",
            *(
                [f"  channels: {', '.join(self.channels)}{' (recognised by name)' if self.channels_recognised else ''}"]
                if self.channels
                else []
            ),
            f"  unit: {self._unit_said()}, input: {self.input}",
        ]
        if self.time is None and not self.gaps:
            lines.append("  timing: no time column (fs given; gaps cannot be detected)")
        else:
            jit = f", max jitter {100 * self.jitter:.3g} % of the step" if self.jitter is not None else ""
            which = (
                f"time column {self.time_column!r}"
                + (" (recognised by its name)" if self.time_column_recognised else "")
                + self._time_unit_said()
                + ", "
                if self.time_column
                else ""
            )
            lines.append(f"  timing: {which}t0 = {self.t0:.16g} s, {len(self.gaps)} gap(s){jit}")
        for g in self.gaps[:5]:
            lines.append(f"    gap: {g}")
        if len(self.gaps) > 5:
            lines.append(f"    … and {len(self.gaps) - 5} more")
        if self.span != (0, self.n_record):
            lines.append(
                f"  kept samples {self.span[0]}–{self.span[1] - 1} of {self.n_record} (longest gap-free stretch)"
            )
        if self.segments is not None:
            lines.append(
                f"  segments: {len(self.segments)} "
                f"({', '.join(f'{a}–{b - 1}' for a, b in (self.segment_spans or [])[:6])}"
                f"{', …' if len(self.segments) > 6 else ''})"
            )
        return "\n".join(lines)
