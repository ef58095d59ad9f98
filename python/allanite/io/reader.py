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

import os
import warnings
from pathlib import Path

import numpy as np

from .._mapped import column, read_rows
from .._validate import check_choice, check_fs, check_input
from ..errors import InputError, ParameterError
from ..units import parse_unit
from ._columns import AUTO_CHANNELS, check_column_spec
from ._columns import AUTO_TIME as AUTO_TIME
from ._external import read_bag, read_parquet
from ._numpy import read_npy, read_npz
from ._text import read_text
from ._timeunit import time_unit as time_unit_of_record
from ._timing import finish
from ._units import units_of
from .log import GAP_FACTOR, GAP_MODES, Gap, Log
from .log import JITTER_WARN as JITTER_WARN
from .log import TIME_UNITS as TIME_UNITS
from .sniff import sniff_format

__all__ = ["read_log", "Log", "Gap", "sniff_format", "GAP_MODES", "GAP_FACTOR"]


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
    time_unit=None,
    array=None,
    topic=None,
    channels=AUTO_CHANNELS,
) -> Log:
    """Read a gyro log.

    Parameters
    ----------
    path : str or Path
        The file. Its format comes from the name and the first bytes: text (``.csv``, ``.tsv``,
        ``.txt``, …; ``.gz`` is decompressed), ``.npy`` (memory-mapped), ``.npz``, ``.parquet``
        (needs pyarrow), a ROS 1 ``.bag`` or a ROS 2 bag folder / ``.db3`` / ``.mcap`` (needs rosbags).
    fs : float, optional
        Sampling rate, Hz. Without it, derived from the time column: 1 / its median step (or, where float64
        rounds large time stamps — epoch seconds at hundreds of Hz — 1 / the mean of its regular steps).
    columns : str, int or list, optional
        Which columns are the samples, by name or 0-based index. A single name or index gives 1-D
        data; a list gives (samples, axes). Default: every column except the time column, the channels and a
        column that counts the rows (each value the previous + 1: pandas' unnamed index, a sequence counter)
        or, in a text log, holds text on its first and last rows of the head (``rostopic echo -p``'s
        ``field.header.frame_id``) — each left out with a warning (ROS bags: the three ``angular_velocity_*``
        components).
    time_column : str or int, optional
        Column of sample times (seconds unless ``time_unit`` says otherwise; in a text log also ISO 8601
        date-times, ``2026-11-27T10:00:00.005`` with an optional ``Z`` or offset: 1.8 s of CPU per 10⁶ rows
        against ≈ 0.4 s for numbers). Used to derive ``fs`` and to find gaps and irregular sampling. For
        ``.npz`` it may also name a separate array. ROS bags always use ``header.stamp``
        (``time_column="receive"``: the bag's receive time). When neither ``fs`` nor ``time_column`` is given,
        a column named like a time column (``time``, ``t``, ``timestamp``, ``stamp``, ``sec``, ``seconds``,
        ``datetime``, ``header.stamp``, …, or one of them ending in a unit: ``time_ns``, ``timestamp_us``,
        ``t [ms]``) is taken as the time column; ``Log.time_column`` says which
        (``Log.time_column_recognised`` is then True).
    unit : str, optional
        Unit of the samples (:func:`allanite.units.parse_unit`): a rate unit for ``input="rate"``, an
        angle unit for ``"increment"`` and ``"angle"``. ROS bags default to ``"rad/s"``. Without it, the unit the
        sample columns' names give (:mod:`allanite.io._units`: ``w_RS_S_x [rad s^-1]``, ``gx (deg/s)``, ``gz_dps``)
        when they all give the same one of the kind needed; columns of several units (an IMU's gyro and
        accelerometer) leave ``Log.unit`` None and are told apart by ``Log.groups`` (``Log.take`` one group).
        Given, it wins over the header, with a warning where a column's name says another unit.
        ``Log.unit_source`` says where the unit came from.
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
        whitespace). Numbers take a decimal point: a decimal comma (``0,0125``) is an InputError that says so.
    time_unit : {"s", "ms", "us", "ns"}, optional
        Unit of a text/array time column (a ParameterError where no time column is read — ``fs`` given without
        ``time_column``, or a ROS bag, whose stamps are seconds — rather than a unit silently unused). Default: the
        unit its name ends in (``time_ns``, ``timestamp_us``, ``t [ms]``, ``Time (nsec)``; ``rostopic echo -p``'s
        ``%time``: ns), else the unit in which its first stamp is an epoch date (≈ 1.7·10⁹ s, 10¹² ms, 10¹⁵ µs,
        10¹⁸ ns), else seconds — where seconds are implausible, an InputError (a span over 10 years) or a warning
        (under 1 Hz over 10⁴ rows) says so, with what the steps read as in ms, µs and ns
        (:mod:`allanite.io._timeunit`). ``Log.time_unit`` says which unit was used, ``Log.time_unit_source`` why.
    array : str, optional
        For ``.npz``: which array holds the samples (default: the only one).
    topic : str, optional
        For ROS bags: the ``sensor_msgs/Imu`` topic (default: the only one).
    channels : "auto", str, int, list or None
        Other columns to read beside the samples, into ``Log.channels`` (not ``data``): what
        :func:`allanite.refine` regresses the rate on. ``"auto"`` (default): the columns whose names say they
        are a temperature (a word ``temp`` or ``temperature`` — ``temp``, ``imu_temp``, ``TEMP_OUT``,
        ``boardTemperature`` —, or a temperature unit in brackets — ``T [degC]``, ``die (°C)``, ``T[K]``;
        case-insensitive; :func:`allanite.io._columns.is_temperature`), except the time column and ``columns``;
        a name, index or list of them: those columns (never also a sample or the time column); None: none. A
        temperature-named column is never a sample column by default, with or without ``channels`` — name it in
        ``columns`` to analyse it. A channel's missing values (NaN, null, an empty text field) are filled by
        linear interpolation, with a warning; an infinite value, fewer than two finite ones or a run of NaN over
        1 % of the samples is an InputError naming the column (a recognised channel is then left out with a
        warning instead). Read from text, Parquet, a structured ``.npy``/``.npz`` (by field name) or a plain 2-D
        array (by index); cut with the samples (the same span with ``gaps="longest"``/``"split"``, NaN at the
        gaps with ``gaps="nan"``). ROS bags: the ``sensor_msgs/Temperature`` topics (``"auto"``: all; else topic
        names), each interpolated linearly at the Imu messages' times (by ``header.stamp``, or the receive time
        with ``time_column="receive"``), named by its topic; Imu messages before its first or after its last
        message are missing values, as above.

    Returns
    -------
    Log

    Raises
    ------
    InputError
        The file cannot be read as asked: missing, empty, ragged rows, text in a numeric column,
        NaN/inf, missing column, time that does not increase, gaps with ``gaps="error"``.
    ParameterError
        Bad arguments: neither ``fs`` nor ``time_column``, an unknown or mismatched unit, a ``time_unit`` no time
        column is read in, …
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

    A column named as a temperature is a channel (what :func:`allanite.refine` regresses on), not an axis:

    >>> temp = 20.0 + 0.01 * np.arange(500)
    >>> np.savetxt(path, np.c_[t, np.full((500, 2), 0.05), temp], delimiter=",", header="t,gx,gy,T [degC]", comments="")
    >>> log = allanite.read_log(path, time_column="t", unit="deg/s")
    >>> log.columns, list(log.channels), log.channels_recognised
    (['gx', 'gy'], ['T [degC]'], True)
    """
    path = Path(os.fspath(path))
    fs = None if fs is None else check_fs(fs)
    input = check_input(input)
    u = _check_arguments(path, columns, time_column, unit, input, gaps, time_unit, channels)
    fmt = sniff_format(path)
    check_time_unit_used(time_unit, fs, time_column, fmt)
    if fmt in ("ros1", "ros2"):
        rec = read_bag(path, fmt, columns, time_column, topic, channels)
    else:
        if fs is None and time_column is None:
            # neither given: a column named like a time column (time, t, timestamp, …) is the time column
            time_column = AUTO_TIME
        rec = _read_file(path, fmt, columns, time_column, delimiter, array, channels)
    t_unit = t_source = None
    if rec.time is not None and rec.time_is_seconds is False:
        t_unit, t_source = time_unit_of_record(path, rec, time_unit)
    fmt = "text" if fmt == "text.gz" else fmt
    log = finish(path, fmt, rec, fs, u, input, gaps)
    if rec.time is not None:
        log.time_unit = t_unit or "s"
        log.time_unit_source = t_source or "the reader (seconds)"
        log.time_unit_from_name = t_source == "its name" and t_unit != "s"
    log.time_column_recognised = time_column is AUTO_TIME and rec.time_name is not None
    log.unit, log.unit_source, log.column_units = units_of(path, log.columns, u, input, ros=fmt in ("ros1", "ros2"))
    return log


def _check_arguments(path, columns, time_column, unit, input, gaps, time_unit, channels):
    """``read_log``'s arguments checked (a ParameterError naming a bad one; an InputError for a missing file);
    the samples' parsed unit, or None."""
    check_input(input)
    check_choice(gaps, "gaps", GAP_MODES)
    if time_unit is not None:
        check_choice(time_unit, "time_unit", tuple(TIME_UNITS))
    u = None if unit is None else _sample_unit(unit, input)
    if columns is not None:
        check_column_spec(columns, "columns")
    if time_column is not None:
        check_column_spec(time_column, "time_column", single=True)
    if channels is not None and not (isinstance(channels, str) and channels == AUTO_CHANNELS):
        check_column_spec(channels, "channels")
    if not path.exists():
        raise InputError(f"{path}: no such file")
    return u


def check_time_unit_used(time_unit, fs, time_column, fmt) -> None:
    """A ParameterError where ``time_unit`` would be silently unused: with ``fs`` and no ``time_column`` no time
    column is read, and a ROS bag's stamps are seconds (``header.stamp`` or the receive time). ``fmt`` None: no file
    yet (``allanite batch`` checks its options once, before its files)."""
    if time_unit is None:
        return
    if fmt in ("ros1", "ros2"):
        raise ParameterError(
            f"time_unit={time_unit!r} is given for a ROS bag, whose stamps are seconds (header.stamp, or the "
            "receive time): time_unit applies to a text or array log's time column; drop time_unit="
        )
    if fs is not None and time_column is None:
        raise ParameterError(
            f"time_unit={time_unit!r} is the unit of a time column, but fs={fs:g} without time_column= reads no time "
            "column: give time_column= as well (its stamps then find gaps, in that unit) or drop time_unit="
        )


def _read_file(path, fmt, columns, time_column, delimiter, array, channels):
    """The record of a .npy, .npz, Parquet or text log, without the columns that count rows (unless named)."""
    if fmt == "npy":
        rec = read_npy(path, columns, time_column, channels)
    elif fmt == "npz":
        rec = read_npz(path, columns, time_column, array, channels)
    elif fmt == "parquet":
        rec = read_parquet(path, columns, time_column, channels)
    else:
        rec = read_text(path, columns, time_column, delimiter, gz=(fmt == "text.gz"), channels=channels)
    if columns is None:
        _drop_counters(path, rec)
    return rec


def _drop_counters(path, rec) -> None:
    """Without ``columns=``: a column that counts rows (each value the previous + 1 — pandas' unnamed index,
    a sequence or packet counter) is no axis; left out, with a warning (its Allan deviation was reported as
    a gyro's). Checked on the first 1000 rows, then on the whole column when they count."""
    data = rec.data
    if data.ndim != 2 or data.shape[1] < 2 or data.shape[0] < 3:
        return
    head = np.asarray(read_rows(data, 0, 1000), dtype=np.float64)  # a mapped .npy: from its file, pages unmapped
    counters = [k for k in range(data.shape[1]) if np.all(np.diff(head[:, k]) == 1.0) and _counts(data, k)]
    if not counters or len(counters) == data.shape[1]:
        return
    keep = [k for k in range(data.shape[1]) if k not in counters]
    warnings.warn(
        f"{path}: column(s) {', '.join(repr(rec.names[k]) for k in counters)} count the rows (0, 1, 2, …: an index "
        "or a sequence counter): not analysed as an axis; name the columns to analyse with columns= (--columns)",
        stacklevel=3,
    )
    rec.data = data[:, keep] if len(keep) > 1 else data[:, keep[0]]
    rec.names = [rec.names[k] for k in keep]


def _counts(data, k: int) -> bool:
    """Whether column ``k``, whose first 1000 rows count, rises by exactly 1 from row to row throughout."""
    return data.shape[0] <= 1000 or bool(np.all(np.diff(column(data, k)) == 1.0))


def _sample_unit(unit, input):
    """The parsed unit of the samples: a rate unit for ``input="rate"``, else an angle unit."""
    need = "rate" if input == "rate" else "angle"
    try:
        return parse_unit(unit, kind=need)
    except ParameterError as exc:
        raise ParameterError(
            f"{exc} (input={input!r} needs {'a rate' if need == 'rate' else 'an angle'} unit)"
        ) from None
