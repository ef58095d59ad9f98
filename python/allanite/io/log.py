"""What :func:`~allanite.io.read_log` returns: a :class:`Log` and its :class:`Gap` list, and the
timing constants the reader applies."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

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
            f"{self.duration:.6g} s (≈{self.missing} samples) missing after sample {self.index - 1} "
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
            f"  unit: {self.unit.name + ' (' + self.unit.kind + ')' if self.unit else 'not given'}, "
            f"input: {self.input}",
        ]
        if self.time is None and not self.gaps:
            lines.append("  timing: no time column (fs given; gaps cannot be detected)")
        else:
            jit = f", max jitter {100 * self.jitter:.3g} % of the step" if self.jitter is not None else ""
            which = (
                (
                    f"time column {self.time_column!r}"
                    + (" (recognised by its name)" if self.time_column_recognised else "")
                    + (f" in {self.time_unit} (its name says so)" if self.time_unit_from_name else "")
                    + ", "
                )
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
