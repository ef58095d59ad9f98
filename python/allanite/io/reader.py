"""Reading gyro logs: text (CSV/TSV/whitespace, optionally gzipped), .npy, .npz, Parquet, ROS bags.

One entry point, :func:`read_log`, returns a :class:`Log`: the samples as (samples,) or
(samples, axes), the sampling rate, column names, unit, and what was found about the timing — gaps
are detected from a time column and never analysed silently as if the record were continuous.

Every problem with a file is an :class:`~allanite.errors.InputError` naming the file and, where there
is one, the line (or row, or message) and column; a problem with the arguments is a
:class:`~allanite.errors.ParameterError`. Parser errors from NumPy, pyarrow or rosbags are caught and
re-raised with that context.
"""

from __future__ import annotations

import gzip
import numbers
import os
import tokenize
import warnings
import zipfile
import zlib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._mapped import read_rows
from .._validate import INPUTS, check_choice, check_fs
from ..errors import AllaniteError, DataGapError, InputError, MissingDependencyError, ParameterError
from ..units import Unit, parse_unit

__all__ = ["read_log", "Log", "Gap", "sniff_format", "GAP_MODES", "GAP_FACTOR"]

#: What ``gaps=`` accepts.
GAP_MODES = ("error", "longest", "split", "nan")
#: A time step longer than this many nominal steps is a gap.
GAP_FACTOR = 1.5
#: Time-column units accepted by ``time_unit=`` (seconds per unit).
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
#: A step that differs from the nominal one by more than this fraction (but is no gap) is reported as
#: irregular sampling, with a warning.
JITTER_WARN = 0.25

_IMU_TYPES = ("sensor_msgs/msg/Imu", "sensor_msgs/Imu")
_BAG_FIELDS = (
    "angular_velocity_x",
    "angular_velocity_y",
    "angular_velocity_z",
    "linear_acceleration_x",
    "linear_acceleration_y",
    "linear_acceleration_z",
)
#: Names shown in the message when no time column is recognised.
_KNOWN_TIME_SHOWN = ("time", "t", "timestamp", "stamp", "sec", "seconds", "header.stamp")
_TIME_NAMES = {
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
    "header.stamp",
    "header_stamp",
    "header.stamp.sec",
    "%time",
    "field.header.stamp",
}


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


# --------------------------------------------------------------------------------------------------
# public entry point


def read_log(
    path,
    *,
    fs=None,
    columns=None,
    time_column=None,
    unit=None,
    input="rate",
    gaps="error",
    delimiter=None,
    time_unit="s",
    array=None,
    topic=None,
) -> Log:
    """Read a gyro log.

    Parameters
    ----------
    path : str or Path
        The file. Its format comes from the name and the first bytes: text (``.csv``, ``.tsv``,
        ``.txt``, …; ``.gz`` is decompressed), ``.npy`` (memory-mapped), ``.npz``, ``.parquet``
        (needs pyarrow), a ROS 1 ``.bag`` or a ROS 2 bag folder / ``.db3`` / ``.mcap`` (needs rosbags).
    fs : float, optional
        Sampling rate, Hz. Without it, derived from the time column (1 / median step).
    columns : str, int or list, optional
        Which columns are the samples, by name or 0-based index. A single name or index gives 1-D
        data; a list gives (samples, axes). Default: every column except the time column (ROS bags:
        the three ``angular_velocity_*`` components).
    time_column : str or int, optional
        Column of sample times (seconds unless ``time_unit`` says otherwise). Used to derive ``fs``
        and to find gaps and irregular sampling. For ``.npz`` it may also name a separate array. ROS
        bags always use ``header.stamp`` (``time_column="receive"``: the bag's receive time). When
        neither ``fs`` nor ``time_column`` is given, a column named like a time column (``time``,
        ``t``, ``timestamp``, ``stamp``, ``sec``, ``seconds``, ``header.stamp``, …) is taken as the
        time column; ``Log.time_column`` says which (``Log.time_column_recognised`` is then True).
    unit : str, optional
        Unit of the samples (:func:`allanite.units.parse_unit`): a rate unit for ``input="rate"``, an
        angle unit for ``"increment"`` and ``"angle"``. ROS bags default to ``"rad/s"``.
    input : {"rate", "increment", "angle"}
        What the samples are, as for :func:`allanite.avar`.
    gaps : {"error", "longest", "split", "nan"}
        What to do when the time column shows gaps (a step > 1.5 nominal steps): raise an error
        listing them (default), keep the longest gap-free stretch, keep every stretch in
        ``Log.segments`` (``data`` is then the longest), or fill each gap with ``Gap.missing`` rows of
        NaN (``data`` is then float64 on the nominal time grid, ``span`` the whole record) for
        :func:`allanite.avar` with ``gaps="skip"``.
    delimiter : str, optional
        Text field separator; default: guessed from the first data line (``,``, tab, ``;`` or
        whitespace).
    time_unit : {"s", "ms", "us", "ns"}
        Unit of a text/array time column.
    array : str, optional
        For ``.npz``: which array holds the samples (default: the only one).
    topic : str, optional
        For ROS bags: the ``sensor_msgs/Imu`` topic (default: the only one).

    Returns
    -------
    Log

    Raises
    ------
    InputError
        The file cannot be read as asked: missing, empty, ragged rows, text in a numeric column,
        NaN/inf, missing column, time that does not increase, gaps with ``gaps="error"``.
    ParameterError
        Bad arguments: neither ``fs`` nor ``time_column``, an unknown or mismatched unit, …
    MissingDependencyError
        pyarrow (Parquet) or rosbags (ROS bags) is not installed.

    Examples
    --------
    >>> import numpy as np, allanite, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "gyro.csv")
    >>> t = np.arange(500) / 100.0
    >>> np.savetxt(path, np.c_[t, np.full((500, 3), 0.05)], delimiter=",", header="t,gx,gy,gz", comments="")
    >>> log = allanite.read_log(path, time_column="t", unit="deg/s")
    >>> log.data.shape, log.fs, log.columns
    ((500, 3), 100.0, ['gx', 'gy', 'gz'])
    """
    path = Path(os.fspath(path))
    check_choice(input, "input", INPUTS)
    check_choice(gaps, "gaps", GAP_MODES)
    check_choice(time_unit, "time_unit", tuple(TIME_UNITS))
    if fs is not None:
        fs = check_fs(fs)
    u = None
    if unit is not None:
        need = "rate" if input == "rate" else "angle"
        try:
            u = parse_unit(unit, kind=need)
        except ParameterError as exc:
            raise ParameterError(
                f"{exc} (input={input!r} needs {'a rate' if need == 'rate' else 'an angle'} unit)"
            ) from None
    if columns is not None:
        _check_column_spec(columns, "columns")
    if time_column is not None:
        _check_column_spec(time_column, "time_column", single=True)
    if not path.exists():
        raise InputError(f"{path}: no such file")

    fmt = sniff_format(path)
    if fmt in ("ros1", "ros2"):
        rec = _read_bag(path, fmt, columns, time_column, topic)
        if u is None and input == "rate":
            u = parse_unit("rad/s")  # REP 103: ROS angular velocity is in rad/s
    else:
        if fs is None and time_column is None:
            # neither given: a column named like a time column (time, t, timestamp, …) is the time column
            time_column = AUTO_TIME
        if fmt == "npy":
            rec = _read_npy(path, columns, time_column)
        elif fmt == "npz":
            rec = _read_npz(path, columns, time_column, array)
        elif fmt == "parquet":
            rec = _read_parquet(path, columns, time_column)
        else:
            rec = _read_text(path, columns, time_column, delimiter, gz=(fmt == "text.gz"))
        if rec.time is not None and rec.time_is_seconds is False:
            rec.time = rec.time * TIME_UNITS[time_unit]
    fmt = "text" if fmt == "text.gz" else fmt
    log = _finish(path, fmt, rec, fs, u, input, gaps)
    log.time_column_recognised = time_column is AUTO_TIME and rec.time_name is not None
    return log


# --------------------------------------------------------------------------------------------------
# shared machinery


@dataclass
class _Record:
    """What a format reader hands to :func:`_finish`."""

    data: np.ndarray  # (n, k) or (n,)
    names: list
    time: np.ndarray | None  # float seconds (or time_unit units when time_is_seconds is False)
    time_name: str | None
    where: Callable[[int], str]  # sample index → "line 12" / "row 11" / "message 11"
    time_is_seconds: bool = False
    t_first: float = 0.0  # absolute time of sample 0 when `time` is relative (bags)
    checked_finite: bool = False


def _check_column_spec(spec, name, single=False):
    def ok(c):
        return isinstance(c, str) or (isinstance(c, (numbers.Integral, np.integer)) and not isinstance(c, bool))

    if ok(spec):
        return
    if not single and isinstance(spec, (list, tuple)) and len(spec) > 0 and all(ok(c) for c in spec):
        return
    what = "a column name or 0-based index" if single else "a column name or index, or a non-empty list of them"
    raise ParameterError(f"{name} must be {what}, got {spec!r}")


def sniff_format(path: Path) -> str:
    """The format of ``path`` from its content and name: "csv", "csv.gz", "npy", "npz", "parquet",
    "ros1" or "ros2" — or an InputError saying what the file is not."""
    if path.is_dir():
        if (path / "metadata.yaml").is_file() or any(path.glob("*.db3")) or any(path.glob("*.mcap")):
            return "ros2"
        raise InputError(f"{path}: is a folder, not a log file (a ROS 2 bag folder holds metadata.yaml)")
    try:
        with open(path, "rb") as f:
            head = f.read(16)
    except OSError as exc:
        raise InputError(f"{path}: cannot be opened ({exc.strerror or exc})") from None
    suffix = path.suffix.lower()
    if head.startswith(b"\x93NUMPY"):
        return "npy"
    if head.startswith(b"PK\x03\x04") or head.startswith(b"PK\x05\x06"):
        return "npz"
    if head.startswith(b"PAR1"):
        return "parquet"
    if head.startswith(b"#ROSBAG"):
        return "ros1"
    if suffix in (".db3", ".mcap"):
        return "ros2"
    if head.startswith(b"\x1f\x8b"):
        _check_text(path, gz=True)
        return "text.gz"
    if suffix == ".npy":
        raise InputError(f"{path}: not a valid .npy file (no NumPy header)")
    if suffix == ".npz":
        raise InputError(f"{path}: not a valid .npz file (not a zip archive)")
    if suffix in (".parquet", ".pq"):
        raise InputError(f"{path}: not a valid Parquet file (no PAR1 magic)")
    if suffix == ".bag":
        raise InputError(f"{path}: not a valid ROS 1 bag (no #ROSBAG header)")
    if suffix == ".gz":
        raise InputError(f"{path}: not a valid gzip file")
    _check_text(path, gz=False)
    return "text"


#: Bytes that never occur in a text log (NUL and the C0 controls other than tab, newline, CR, FF, VT).
_BINARY_BYTES = bytes(range(0, 9)) + bytes(range(14, 32))


def _check_text(path: Path, gz: bool) -> None:
    """An InputError naming what the file is not, when its first 4 KiB hold bytes no text log has."""
    try:
        with gzip.open(path, "rb") if gz else open(path, "rb") as f:
            head = f.read(4096)
    except (OSError, EOFError, zlib.error):
        return  # the reader reports a damaged gzip stream with its own message
    bad = sum(head.count(b) for b in _BINARY_BYTES)
    # one stray control byte is a damaged line (the text reader names it); many are not text at all
    if head and bad > max(2, len(head) // 100):
        kind = "gzip-compressed data that is not text" if gz else "binary data"
        raise InputError(
            f"{path}: not a log allanite can read — it holds {kind} ({bad} control bytes in the first "
            f"{len(head)}); allanite reads text (CSV/TSV, optionally .gz), .npy, .npz, Parquet and ROS bag files"
        )


def _resolve(spec, names, path, what="column"):
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


#: Passed as ``time_column`` when neither fs nor a time column was given: recognise the time column by name.
AUTO_TIME = "<recognise by name>"


def _recognise_time(names, path) -> int:
    """Index of the column whose name says it is time (``_TIME_NAMES``), or the error that fs is needed."""
    hits = [i for i, c in enumerate(names) if c.strip().lower() in _TIME_NAMES]
    if not hits:
        raise ParameterError(
            f"{path}: give the sampling rate (fs=… in Hz) or the time column (time_column=…) — neither was passed, "
            f"and no column is named like a time column ({', '.join(sorted(_KNOWN_TIME_SHOWN))}, …); "
            f"columns: {', '.join(map(repr, names[:12]))}"
        )
    return hits[0]


def _select(columns, time_column, names, path, default=None):
    """(data column indices, time column index or None, squeeze to 1-D)."""
    if time_column is AUTO_TIME:
        t_idx: int | None = _recognise_time(names, path)
    else:
        t_idx = None if time_column is None else _resolve(time_column, names, path, "time column")
    if columns is None:
        if default is not None:
            idx = [names.index(d) for d in default]
        else:
            idx = [i for i in range(len(names)) if i != t_idx]
            if t_idx is None:
                timeish = [names[i] for i in idx if names[i].strip().lower() in _TIME_NAMES]
                if timeish and len(idx) > 1:
                    raise ParameterError(
                        f"{path}: column {timeish[0]!r} looks like a time column; pass time_column="
                        f"{timeish[0]!r} (to use it) or columns=[…] (to choose the sample columns)"
                    )
        if not idx:
            raise InputError(f"{path}: no sample columns besides the time column {names[t_idx]!r}")
        return idx, t_idx, len(idx) == 1
    single = not isinstance(columns, (list, tuple))
    specs = [columns] if single else list(columns)
    idx = [_resolve(c, names, path) for c in specs]
    if t_idx is not None and t_idx in idx:
        raise ParameterError(f"{path}: column {names[t_idx]!r} is both the time column and a sample column")
    if len(set(idx)) != len(idx):
        raise ParameterError(f"{path}: columns {specs!r} name the same column twice")
    return idx, t_idx, single


def _first_nonfinite(block):
    """(row, column) of the first non-finite value of a 2-D block, or None."""
    bad = ~np.isfinite(block)
    if not bad.any():
        return None
    r = int(np.argmax(bad.any(axis=1)))
    c = int(np.argmax(bad[r]))
    return r, c


def _filled_with_nan(path, fmt, rec, data, t, fs, unit, input, t0, gap_list, jitter, names) -> Log:
    """The record with every gap filled by ``Gap.missing`` NaN rows (times on the nominal grid)."""
    dt = 1.0 / fs
    pieces, times, start = [], [], 0
    for g in gap_list:
        pieces.append(np.asarray(data[start : g.index], dtype=np.float64))
        times.append(t[start : g.index])
        pieces.append(np.full((g.missing,) + data.shape[1:], np.nan))
        times.append(t[g.index - 1] + dt * np.arange(1, g.missing + 1))
        start = g.index
    pieces.append(np.asarray(data[start:], dtype=np.float64))
    times.append(t[start:])
    filled = np.concatenate(pieces)
    tt = np.concatenate(times)
    return Log(
        data=filled,
        fs=float(fs),
        columns=list(names),
        unit=unit,
        input=input,
        t0=t0,
        path=path,
        format=fmt,
        gaps=gap_list,
        span=(0, int(data.shape[0])),
        time=tt - tt[0],
        jitter=jitter,
        n_record=int(data.shape[0]),
        time_column=rec.time_name,
    )


def _finish(path, fmt, rec: _Record, fs, unit, input, gaps) -> Log:
    data = rec.data
    n = int(data.shape[0])
    if n == 0:
        raise InputError(f"{path}: no samples (the file holds no data rows)")
    names = rec.names
    if not rec.checked_finite:
        arr2 = data if data.ndim == 2 else data[:, None]
        chunk = max(1, 4_000_000 // max(1, arr2.shape[1]))
        for s in range(0, n, chunk):
            # a memory-mapped .npy is read from its file: its pages are not mapped in (allanite._mapped)
            block = read_rows(data, s, s + chunk)
            hit = _first_nonfinite(np.asarray(block if block.ndim == 2 else block[:, None], dtype=np.float64))
            if hit is not None:
                r, c = hit
                v = arr2[s + r, c]
                raise InputError(
                    f"{path}: {rec.where(s + r)}, column {names[c]!r}: non-finite value {v} "
                    f"(NaN or inf); only finite numbers are allowed"
                )

    t = rec.time
    gap_list: list = []
    jitter = None
    t0 = 0.0
    if t is not None:
        t = np.asarray(t, dtype=np.float64)
        tn = rec.time_name
        if not np.isfinite(t).all():
            i = int(np.argmin(np.isfinite(t)))
            raise InputError(f"{path}: {rec.where(i)}, time column {tn!r}: non-finite time {t[i]}")
        if n < 2:
            raise InputError(f"{path}: only one sample; the time step cannot be derived")
        d = np.diff(t)
        back = np.flatnonzero(d <= 0)
        if back.size:
            i = int(back[0]) + 1
            how = "repeats" if d[i - 1] == 0 else "goes backwards"
            raise InputError(
                f"{path}: {rec.where(i)}, time column {tn!r}: time {how} ({float(t[i])!r} after {float(t[i - 1])!r}); "
                f"times must increase — is {tn!r} really the time column? ({back.size} such step(s))"
            )
        step = float(np.median(d))
        if fs is None:
            # time stamps written in decimal carry rounding: 1/0.010000000000000009 is 100 Hz
            fs = float(f"{1.0 / step:.9g}")
        elif abs(step * fs - 1.0) > 0.01:
            raise ParameterError(
                f"{path}: fs = {fs:g} Hz, but the median step of time column {tn!r} is {step:g} "
                f"({1.0 / step:g} Hz); drop fs=, or check the time column and time_unit="
            )
        dt = 1.0 / fs
        is_gap = d > GAP_FACTOR * dt
        rel = np.abs(d[~is_gap] - dt) / dt
        jitter = float(rel.max()) if rel.size else 0.0
        for gi in np.flatnonzero(is_gap):
            i = int(gi)
            dur = float(d[i] - dt)
            gap_list.append(Gap(index=i + 1, time=float(t[i] - t[0]), duration=dur, missing=int(round(dur * fs))))
        if jitter > JITTER_WARN:
            warnings.warn(
                f"{path}: irregular sampling — a time step differs from the nominal {dt:g} s by {100 * jitter:.3g} %",
                stacklevel=3,
            )
        t0 = float(t[0]) + rec.t_first
    elif fs is None:  # pragma: no cover - read_log checks this first
        raise ParameterError(f"{path}: give fs= or time_column=")

    bounds = [0] + [g.index for g in gap_list] + [n]
    spans = list(zip(bounds[:-1], bounds[1:]))
    if gap_list and gaps == "error":
        shown = "; ".join(str(g) for g in gap_list[:10])
        more = f"; … and {len(gap_list) - 10} more" if len(gap_list) > 10 else ""
        raise DataGapError(
            f"{path}: {len(gap_list)} gap(s) in time column {rec.time_name!r} (a step over {GAP_FACTOR}× the "
            f"nominal {1.0 / fs:g} s): {shown}{more}. Pass gaps='longest' to keep the longest gap-free "
            f"stretch, or gaps='split' for every stretch"
        )
    if gaps == "nan" and gap_list:
        return _filled_with_nan(path, fmt, rec, data, t, fs, unit, input, t0, gap_list, jitter, names)
    longest = max(range(len(spans)), key=lambda j: spans[j][1] - spans[j][0])
    span = spans[longest]
    segments = segment_spans = None
    if gaps == "split":
        segments = [data[a:b] for a, b in spans]
        segment_spans = spans
    kept = data[span[0] : span[1]] if span != (0, n) else data
    time_rel = None
    if t is not None:
        time_rel = t[span[0] : span[1]] - t[span[0]]
        t0 = float(t[span[0]]) + rec.t_first
    return Log(
        data=kept,
        fs=float(fs),
        columns=list(names),
        unit=unit,
        input=input,
        t0=t0,
        path=path,
        format=fmt,
        gaps=gap_list,
        span=span,
        segments=segments,
        segment_spans=segment_spans,
        time=time_rel,
        jitter=jitter,
        n_record=n,
        time_column=rec.time_name if t is not None else None,
    )


# --------------------------------------------------------------------------------------------------
# text


def _is_number(s: str) -> bool:
    """What NumPy's text parser accepts: Python's float() also takes "1_0" and non-ASCII digits."""
    if not s.isascii() or "_" in s:
        return False
    try:
        float(s)
    except ValueError:
        return False
    return True


def _split(line: str, delim):
    fields = line.split(delim) if delim is not None else line.split()
    return [f.strip() for f in fields]


def _strip_comment(line: str) -> str:
    k = line.find("#")
    return line if k < 0 else line[:k]


def _guess_delimiter(line: str):
    for d in (",", "\t", ";"):
        if d in line:
            return d
    return None


def _read_text(path, columns, time_column, delimiter, gz):
    try:
        with open(path, "rb") as f:
            raw = f.read()
        if gz:
            raw = zlib.decompress(raw, 16 + zlib.MAX_WBITS) if raw else raw
    except (OSError, zlib.error, EOFError, gzip.BadGzipFile) as exc:
        raise InputError(f"{path}: cannot be read{' as gzip' if gz else ''} ({exc})") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    del raw
    if text.startswith("\ufeff"):
        text = text[1:]
    lines = text.splitlines()

    # first content line: the header or the first data row
    i0 = next((i for i, ln in enumerate(lines) if _strip_comment(ln).strip()), None)
    if i0 is None:
        what = "only comment lines" if any(ln.strip() for ln in lines) else "nothing"
        raise InputError(f"{path}: empty file — it holds {what}, no data rows")
    if delimiter is None:
        delim = _guess_delimiter(_strip_comment(lines[i0]))
    else:
        if not isinstance(delimiter, str) or len(delimiter) != 1 and delimiter.strip() != "":
            raise ParameterError(
                f"delimiter must be one character (',', '\\t', ';', …) or ' ' for whitespace, got {delimiter!r}"
            )
        delim = None if delimiter.strip() == "" else delimiter
    first = _split(_strip_comment(lines[i0]), delim)
    header = None
    # a header has no numeric field; a line mixing numbers and text is a (bad) data row
    if not any(_is_number(f) for f in first):
        header = [f.strip().strip('"').strip("'").strip() for f in first]
        start = i0 + 1
        i1 = next((i for i in range(start, len(lines)) if _strip_comment(lines[i]).strip()), None)
        if i1 is None:
            raise InputError(f"{path}: line {i0 + 1} is a header ({', '.join(header)}) but no data rows follow")
        ncols = len(_split(_strip_comment(lines[i1]), delim))
        if len(header) != ncols:
            raise InputError(
                f"{path}: the header on line {i0 + 1} names {len(header)} columns but line {i1 + 1} has {ncols} fields"
            )
    else:
        start = i0
        ncols = len(first)
        # a header written as a comment (np.savetxt's "# a,b,c") right before the data
        if i0 > 0 and lines[i0 - 1].lstrip().startswith("#"):
            cand = [f.strip().strip('"').strip("'") for f in _split(lines[i0 - 1].lstrip()[1:], delim)]
            if len(cand) == ncols and all(c and not _is_number(c) for c in cand):
                header = cand
    names = [h if h else f"col{k}" for k, h in enumerate(header)] if header else [f"col{k}" for k in range(ncols)]
    idx, t_idx, squeeze = _select(columns, time_column, names, path)
    need = sorted(set(idx + ([t_idx] if t_idx is not None else [])))
    # parse only the needed columns when a one-character delimiter makes skipping safe
    usecols = need if (delim is not None and len(need) < ncols) else None
    body = lines[start:]

    def where(r):
        return f"line {_line_of_row(lines, start, r)}"

    try:
        arr = np.loadtxt(body, delimiter=delim, comments="#", usecols=usecols, ndmin=2, dtype=np.float64)
    except (ValueError, IndexError) as exc:
        _diagnose(path, lines, start, delim, ncols, need, names, first_line=start + 1)
        raise InputError(f"{path}: cannot parse the numeric data ({exc})") from None
    if arr.shape[0] == 0:
        raise InputError(f"{path}: no data rows after the header on line {i0 + 1}")
    if usecols is not None:
        # loadtxt skips unused fields, so it cannot see ragged rows: compare the number of delimiters
        # with what `rows × (columns − 1)` needs, and look closer only when they differ.
        found = text.count(delim) - sum(ln.count(delim) for ln in lines[:start])
        if found != arr.shape[0] * (ncols - 1):
            _diagnose(path, lines, start, delim, ncols, [], names, first_line=start + 1)
    elif arr.shape[1] != ncols:  # pragma: no cover - loadtxt raises on ragged rows
        _diagnose(path, lines, start, delim, ncols, need, names, first_line=start + 1)
    pos = {c: j for j, c in enumerate(need if usecols is not None else range(ncols))}
    cols = [pos[c] for c in idx]
    if len(cols) == arr.shape[1] and cols == list(range(arr.shape[1])):
        data = arr
    else:
        data = np.ascontiguousarray(arr[:, cols])
    hit = _first_nonfinite(data)
    if hit is not None:
        r, c = hit
        raise InputError(
            f"{path}: {where(r)}, column {idx[c] + 1} ({names[idx[c]]!r}): non-finite value "
            f"{data[r, c]} (NaN or inf); only finite numbers are allowed"
        )
    time = arr[:, pos[t_idx]].copy() if t_idx is not None else None
    del arr
    if squeeze:
        data = data[:, 0].copy()
    return _Record(
        data=data,
        names=[names[i] for i in idx],
        time=time,
        time_name=names[t_idx] if t_idx is not None else None,
        where=where,
        checked_finite=True,
    )


def _line_of_row(lines, start, r):
    """1-based line number of data row r (comments and blank lines skipped) — only on error paths."""
    k = -1
    for i in range(start, len(lines)):
        if _strip_comment(lines[i]).strip():
            k += 1
            if k == r:
                return i + 1
    return len(lines)


def _diagnose(path, lines, start, delim, ncols, need, names, first_line):
    """Find the first bad line the slow, precise way and raise an InputError naming it."""
    sep = "whitespace" if delim is None else repr(delim)
    for i in range(start, len(lines)):
        content = _strip_comment(lines[i])
        if not content.strip():
            continue
        fields = _split(content, delim)
        if len(fields) != ncols:
            raise InputError(
                f"{path}: line {i + 1}: ragged row — {len(fields)} fields (separated by {sep}) where line "
                f"{first_line} and the header have {ncols}"
            )
        for c in need:
            if not _is_number(fields[c]):
                shown = fields[c] if fields[c] else "(empty)"
                raise InputError(f"{path}: line {i + 1}, column {c + 1} ({names[c]!r}): {shown!r} is not a number")


# --------------------------------------------------------------------------------------------------
# NumPy files


def _numeric_check(path, arr, what):
    if arr.dtype.kind not in "iuf":
        raise InputError(f"{path}: {what} has dtype {arr.dtype}; samples must be real numbers (integer or float)")


def _columns_of(mm, idx):
    """Columns `idx` of a 2-D (possibly memory-mapped) array, as a view whenever possible."""
    if len(idx) == mm.shape[1] and idx == list(range(mm.shape[1])):
        return mm
    if idx == list(range(idx[0], idx[0] + len(idx))):
        return mm[:, idx[0] : idx[0] + len(idx)]
    return np.asarray(mm[:, idx])


def _array_record(path, arr, columns, time_column, label, extra_time=None):
    """A record from a 1-D, 2-D or structured array (the .npy/.npz common path)."""
    if arr.dtype.names:
        names = list(arr.dtype.names)
        if arr.ndim != 1:
            raise InputError(f"{path}: {label} is a structured array of shape {arr.shape}; 1-D is expected")
        idx, t_idx, squeeze = _select(columns, time_column, names, path)
        for i in idx + ([t_idx] if t_idx is not None else []):
            _numeric_check(path, arr[names[i]], f"field {names[i]!r}")
        data = np.column_stack([np.asarray(arr[names[i]], dtype=np.float64) for i in idx])
        time = np.asarray(arr[names[t_idx]], dtype=np.float64) if t_idx is not None else None
        if squeeze:
            data = data[:, 0]
        return _Record(
            data=data,
            names=[names[i] for i in idx],
            time=time,
            time_name=names[t_idx] if t_idx is not None else None,
            where=lambda r: f"row {r}",
        )
    _numeric_check(path, arr, label)
    tname = None
    if arr.ndim == 1:
        names = ["col0"]
        if time_column is AUTO_TIME:
            _recognise_time(names, path)  # a lone column is never a time column: fs is needed
        if time_column is not None and extra_time is None:
            raise InputError(
                f"{path}: {label} is 1-D (one column), so it cannot hold a time column "
                f"{time_column!r} besides the samples"
            )
        data, time = arr, extra_time
        if columns is not None:
            _, _, squeeze = _select(columns, None, names, path)
            if not squeeze:
                data = arr.reshape(-1, 1)
        out_names = names
    elif arr.ndim == 2:
        names = [f"col{k}" for k in range(arr.shape[1])]
        if extra_time is not None:
            idx, _, squeeze = _select(columns, None, names, path)
            t_idx = None
        else:
            idx, t_idx, squeeze = _select(columns, time_column, names, path)
        data = _columns_of(arr, idx)
        if squeeze:
            data = data[:, 0]
        time = np.asarray(arr[:, t_idx], dtype=np.float64) if t_idx is not None else extra_time
        out_names = [names[i] for i in idx]
    else:
        raise InputError(
            f"{path}: {label} has shape {arr.shape}; samples must be 1-D (samples,) or 2-D (samples, axes)"
        )
    if extra_time is not None:
        tname = time_column
        if extra_time.shape != (arr.shape[0],):
            raise InputError(
                f"{path}: time array {time_column!r} has shape {extra_time.shape} but the samples "
                f"have {arr.shape[0]} rows"
            )
    elif arr.ndim == 2 and time_column is not None:
        tname = names[t_idx]
    return _Record(data=data, names=out_names, time=time, time_name=tname, where=lambda r: f"row {r}")


#: What NumPy's readers raise on damaged .npy/.npz bytes (header parser, zip layer, decompression).
_DAMAGED = (
    ValueError,
    OSError,
    EOFError,
    zlib.error,
    zipfile.BadZipFile,
    tokenize.TokenError,
    SyntaxError,
    KeyError,
    IndexError,
    TypeError,
    OverflowError,
    MemoryError,
    NotImplementedError,
    UnicodeDecodeError,
)


def _read_npy(path, columns, time_column):
    try:
        arr = np.load(path, mmap_mode="r", allow_pickle=False)
    except _DAMAGED as exc:  # a damaged header fails in NumPy's header parser with many exception types
        raise InputError(f"{path}: not a readable .npy file ({type(exc).__name__}: {exc})") from None
    return _array_record(path, arr, columns, time_column, "the array")


def _read_npz(path, columns, time_column, array):
    try:
        z = np.load(path, allow_pickle=False)
    except _DAMAGED as exc:
        raise InputError(f"{path}: not a readable .npz file ({type(exc).__name__}: {exc})") from None
    try:
        with z:
            files = list(z.files)
            if not files:
                raise InputError(f"{path}: the .npz archive holds no arrays")
            time_arr = None
            if isinstance(time_column, str) and time_column in files and time_column != array:
                t_raw = z[time_column]
                _numeric_check(path, t_raw, f"time array {time_column!r}")
                time_arr = np.asarray(t_raw, dtype=np.float64)
            if array is None:
                cand = [f for f in files if f != (time_column if time_arr is not None else None)]
                if len(cand) != 1:
                    raise ParameterError(
                        f"{path}: the archive holds arrays {', '.join(map(repr, files))}; pass "
                        f"array=… to choose the samples"
                    )
                array = cand[0]
            elif array not in files:
                raise InputError(f"{path}: no array named {array!r}; available: {', '.join(map(repr, files))}")
            try:
                arr = z[array]
            except _DAMAGED as exc:
                raise InputError(f"{path}: array {array!r} cannot be read ({type(exc).__name__}: {exc})") from None
            return _array_record(path, arr, columns, time_column, f"array {array!r}", extra_time=time_arr)
    except AllaniteError:
        raise
    except _DAMAGED as exc:  # damaged members: bad CRC, truncated streams, broken member headers
        raise InputError(f"{path}: not a readable .npz file ({type(exc).__name__}: {exc})") from None


# --------------------------------------------------------------------------------------------------
# Parquet


def _need(module: str, extra: str, what: str):
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingDependencyError(
            f"reading {what} needs the optional package {module.split('.')[0]!r}: pip install 'allanite[{extra}]'"
        ) from None


def _read_parquet(path, columns, time_column):
    pq = _need("pyarrow.parquet", "parquet", "Parquet files")
    pa = _need("pyarrow", "parquet", "Parquet files")
    try:
        schema = pq.read_schema(path)
    except Exception as exc:  # pyarrow raises ArrowInvalid / OSError subclasses
        raise InputError(f"{path}: not a readable Parquet file ({exc})") from None
    names = list(schema.names)
    if not names:
        raise InputError(f"{path}: the Parquet file has no columns")
    idx, t_idx, squeeze = _select(columns, time_column, names, path)
    want = [names[i] for i in idx] + ([names[t_idx]] if t_idx is not None else [])
    try:
        table = pq.read_table(path, columns=want)
    except Exception as exc:
        raise InputError(f"{path}: cannot read columns {want} ({exc})") from None

    def column(name, is_time):
        col = table.column(name)
        typ = col.type
        if col.null_count:
            mask = np.asarray(col.is_null().to_numpy(zero_copy_only=False))
            raise InputError(
                f"{path}: row {int(np.argmax(mask))}, column {name!r}: missing value (null); "
                f"only finite numbers are allowed"
            )
        if is_time and pa.types.is_timestamp(typ):
            ns = np.asarray(col.cast(pa.timestamp("ns")).cast(pa.int64()).to_numpy(), dtype=np.int64)
            if ns.size == 0:
                return ns.astype(np.float64), 0.0
            return (ns - ns[0]).astype(np.float64) * 1e-9, float(ns[0]) * 1e-9
        if not (pa.types.is_integer(typ) or pa.types.is_floating(typ)):
            raise InputError(f"{path}: column {name!r} has type {typ}, not a number")
        return np.asarray(col.to_numpy(), dtype=np.float64), None

    cols = [column(names[i], False)[0] for i in idx]
    data = np.column_stack(cols) if cols else np.empty((0, 0))
    if squeeze:
        data = data[:, 0]
    time, t_first, secs = None, 0.0, False
    if t_idx is not None:
        time, first = column(names[t_idx], True)
        if first is not None:
            t_first, secs = first, True
    return _Record(
        data=data,
        names=[names[i] for i in idx],
        time=time,
        time_name=names[t_idx] if t_idx is not None else None,
        where=lambda r: f"row {r}",
        time_is_seconds=secs,
        t_first=t_first,
    )


# --------------------------------------------------------------------------------------------------
# ROS bags


def _read_bag(path, fmt, columns, time_column, topic):
    hl = _need("rosbags.highlevel", "ros", "ROS bags")
    bag = path.parent if (fmt == "ros2" and path.is_file()) else path
    if time_column not in (None, "header", "receive"):
        raise ParameterError(
            f"for a ROS bag, time_column must be None or 'header' (header.stamp) or 'receive' "
            f"(the bag's receive time), got {time_column!r}"
        )
    names = list(_BAG_FIELDS)
    idx, _, squeeze = _select(columns, None, names, path, default=None if columns is not None else names[:3])
    try:
        reader = hl.AnyReader([bag])
        reader.open()
    except Exception as exc:  # rosbags raises its own ReaderError / AnyReaderError
        raise InputError(f"{path}: not a readable ROS bag ({type(exc).__name__}: {exc})") from None
    try:
        imu = [c for c in reader.connections if c.msgtype in _IMU_TYPES]
        topics = sorted({c.topic for c in imu})
        if topic is None:
            if len(topics) != 1:
                others = sorted({f"{c.topic} ({c.msgtype})" for c in reader.connections})
                if not topics:
                    raise InputError(
                        f"{path}: no sensor_msgs/Imu topic in the bag; it holds: {', '.join(others) or 'nothing'}"
                    )
                raise ParameterError(f"{path}: several sensor_msgs/Imu topics ({', '.join(topics)}); pass topic=…")
            topic = topics[0]
        elif topic not in topics:
            raise InputError(f"{path}: no sensor_msgs/Imu topic {topic!r}; Imu topics: {', '.join(topics) or 'none'}")
        conns = [c for c in imu if c.topic == topic]
        vals = []
        stamps = []
        for k, (con, t_recv, raw) in enumerate(reader.messages(connections=conns)):
            try:
                m = reader.deserialize(raw, con.msgtype)
            except Exception as exc:
                raise InputError(f"{path}: message {k} on {topic} cannot be decoded ({exc})") from None
            w, a = m.angular_velocity, m.linear_acceleration
            vals.append((w.x, w.y, w.z, a.x, a.y, a.z))
            if time_column == "receive":
                stamps.append(int(t_recv))
            else:
                st = m.header.stamp
                stamps.append(int(st.sec) * 1_000_000_000 + int(getattr(st, "nanosec", getattr(st, "nsec", 0))))
    finally:
        reader.close()
    if not vals:
        raise InputError(f"{path}: topic {topic} holds no messages")
    allv = np.asarray(vals, dtype=np.float64)
    data = allv[:, idx]
    if squeeze:
        data = data[:, 0].copy()
    ns = np.asarray(stamps, dtype=np.int64)
    if time_column != "receive" and not ns.any():
        raise InputError(
            f"{path}: every header.stamp on {topic} is zero; pass time_column='receive' to use the bag's receive times"
        )
    time = (ns - ns[0]).astype(np.float64) * 1e-9
    tname = "receive time" if time_column == "receive" else "header.stamp"
    return _Record(
        data=data,
        names=[names[i] for i in idx],
        time=time,
        time_name=tname,
        where=lambda r: f"message {r} on {topic}",
        time_is_seconds=True,
        t_first=float(ns[0]) * 1e-9,
    )
