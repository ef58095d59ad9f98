"""From a format reader's record to a :class:`~allanite.io.Log`: finite values, the sampling rate, gaps,
jitter, and what ``gaps=`` asks for."""

from __future__ import annotations

import warnings

import numpy as np

from .._mapped import read_rows
from ..errors import DataGapError, InputError, ParameterError
from ._channels import finish_channels
from ._columns import Record, first_nonfinite
from .log import GAP_FACTOR, JITTER_WARN, Gap, Log


def _log_fields(path, fmt, rec: Record, fs, unit, input, t0, gap_list, jitter) -> dict:
    """The :class:`Log` fields that every way of keeping a record shares (columns, rate, unit, origin, source,
    gaps, jitter, the record's length); the data kept, their span and times are each way's own."""
    return dict(
        fs=float(fs),
        columns=list(rec.names),
        unit=unit,
        input=input,
        t0=t0,
        path=path,
        format=fmt,
        gaps=gap_list,
        jitter=jitter,
        n_record=int(rec.data.shape[0]),
        channels_recognised=rec.channels_recognised,
    )


def _filled_with_nan(path, fmt, rec, data, t, fs, unit, input, t0, gap_list, jitter) -> Log:
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
    shared = _log_fields(path, fmt, rec, fs, unit, input, t0, gap_list, jitter)
    # the channels' own missing values filled, then NaN where the samples are (a gap misses both)
    channels = {k: _nan_rows(c, gap_list) for k, c in finish_channels(path, rec, 0, int(data.shape[0])).items()}
    span = (0, int(data.shape[0]))
    return Log(data=filled, span=span, time=tt - tt[0], time_column=rec.time_name, channels=channels, **shared)


def _nan_rows(c: np.ndarray, gap_list: list) -> np.ndarray:
    """A channel with ``Gap.missing`` NaN at each gap, as ``gaps="nan"`` fills the samples."""
    bounds = [0] + [g.index for g in gap_list]
    pieces = []
    for g, a in zip(gap_list, bounds):
        pieces += [c[a : g.index], np.full(g.missing, np.nan)]
    return np.concatenate(pieces + [c[bounds[-1] :]])


def finish(path, fmt, rec: Record, fs, unit, input, gaps) -> Log:
    """The :class:`Log` of a format reader's record: its values checked finite, its timing read from the time
    column (sampling rate, gaps, jitter), and the gaps handled as ``gaps=`` asks."""
    data = rec.data
    n = int(data.shape[0])
    if n == 0:
        raise InputError(f"{path}: no samples (the file holds no data rows)")
    if not rec.checked_finite:
        _check_finite(path, rec, n)
    t = rec.time
    gap_list: list = []
    jitter = None
    t0 = 0.0
    if t is not None:
        t = np.asarray(t, dtype=np.float64)
        fs, gap_list, jitter = _time_steps(path, rec, t, n, fs)
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
            f"stretch, gaps='split' for every stretch, or gaps='nan' to keep the whole log with the missing rows NaN"
        )
    if gaps == "nan" and gap_list:
        return _filled_with_nan(path, fmt, rec, data, t, fs, unit, input, t0, gap_list, jitter)
    longest = max(range(len(spans)), key=lambda j: spans[j][1] - spans[j][0])
    span = spans[longest]
    segments = segment_spans = None
    if gaps == "split":
        segments = [data[a:b] for a, b in spans]
        segment_spans = spans
    kept = data[span[0] : span[1]] if span != (0, n) else data
    time_rel = None
    if t is not None:
        t0 = float(t[span[0]]) + rec.t_first
        time_rel = _relative(rec, t, span)
    return Log(
        data=kept,
        span=span,
        channels=finish_channels(path, rec, *span),
        segments=segments,
        segment_spans=segment_spans,
        time=time_rel,
        time_column=rec.time_name if t is not None else None,
        **_log_fields(path, fmt, rec, fs, unit, input, t0, gap_list, jitter),
    )


def _relative(rec: Record, t: np.ndarray, span) -> np.ndarray:
    """The times of ``span`` from its first: in place where the record's time column is the reader's own array (a
    text log's — no second array of the record's length), else a new array."""
    kept = t[span[0] : span[1]]
    if rec.time_owned and t is rec.time:
        kept -= t[span[0]]
        return kept
    return kept - t[span[0]]


def _check_finite(path, rec: Record, n: int) -> None:
    """An InputError naming the first non-finite value of the record, read in blocks of ≈ 4·10⁶ values."""
    data, names = rec.data, rec.names
    arr2 = data if data.ndim == 2 else data[:, None]
    chunk = max(1, 4_000_000 // max(1, arr2.shape[1]))
    for s in range(0, n, chunk):
        # a memory-mapped .npy is read from its file: its pages are not mapped in (allanite._mapped)
        block = read_rows(data, s, s + chunk)
        hit = first_nonfinite(np.asarray(block if block.ndim == 2 else block[:, None], dtype=np.float64))
        if hit is not None:
            r, c = hit
            v = arr2[s + r, c]
            raise InputError(
                f"{path}: {rec.where(s + r)}, column {names[c]!r}: non-finite value {v} "
                f"(NaN or inf); only finite numbers are allowed"
            )


def _step(t: np.ndarray, d: np.ndarray) -> tuple[float, float]:
    """(nominal time step, its relative rounding): the median step, or — when the times are so large that float64
    rounds each step by more than 10⁻⁷ of it (epoch seconds at 400 Hz, epoch nanoseconds read as float) — the mean
    of the regular steps (within ``GAP_FACTOR`` of the median), whose rounding errors cancel but at the ends:
    1.7·10⁹ s + k/400 has steps 0.0025 ± 2.4·10⁻⁷, median 399.991 Hz, mean 400.000."""
    step = float(np.median(d, overwrite_input=True))  # reorders d (no copy of the record's length)
    ulp = float(np.spacing(max(abs(float(t[0])), abs(float(t[-1])))))
    if ulp <= 1e-7 * step:
        return step, 5e-10
    d = np.diff(t)  # in order again: the mean below sums in the record's order
    regular = d[np.abs(d - step) <= (GAP_FACTOR - 1.0) * step]
    if not regular.size:
        return step, 5e-10
    return float(np.mean(regular)), 2.0 * ulp / float(np.sum(regular))


def _shortest(x: float, rel: float) -> float:
    """The decimal with the fewest significant digits within ``rel`` of ``x`` (time stamps carry rounding:
    1/0.010000000000000009 is 100 Hz)."""
    for digits in range(1, 18):
        v = float(f"{x:.{digits}g}")
        if abs(v - x) <= rel * abs(x):
            return v
    return x


def _time_steps(path, rec: Record, t: np.ndarray, n: int, fs):
    """(fs, gaps, jitter) from the time column ``t`` (seconds): the times checked finite and increasing, fs
    derived from the median step (or checked against it when given), the gaps found, irregular steps warned
    about."""
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
    step, rel = _step(t, d)
    del d  # _step's median reordered it: taken again, never two at once
    d = np.diff(t)
    if fs is None:
        fs = _shortest(1.0 / step, rel)
    elif abs(step * fs - 1.0) > 0.01:
        raise ParameterError(
            f"{path}: fs = {fs:g} Hz, but the median step of time column {tn!r} is {step:g} "
            f"({1.0 / step:g} Hz); drop fs=, or check the time column and time_unit="
        )
    dt = 1.0 / fs
    is_gap = d > GAP_FACTOR * dt
    # the largest |step − dt| / dt off the gaps, from the extreme steps (no temporaries of the record's length)
    kept = d[~is_gap] if is_gap.any() else d
    jitter = max(float(kept.max()) - dt, dt - float(kept.min())) / dt if kept.size else 0.0
    gap_list = []
    for gi in np.flatnonzero(is_gap):
        i = int(gi)
        dur = float(d[i] - dt)
        gap_list.append(Gap(index=i + 1, time=float(t[i] - t[0]), duration=dur, missing=int(round(dur * fs))))
    if jitter > JITTER_WARN:
        warnings.warn(
            f"{path}: irregular sampling — a time step differs from the nominal {dt:g} s by {100 * jitter:.3g} %",
            stacklevel=4,  # the caller of read_log (read_log → finish → _time_steps)
        )
    return fs, gap_list, jitter
