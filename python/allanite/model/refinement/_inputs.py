"""What :func:`allanite.refine` is given, checked and put in the form its loop takes: the samples' magnitude,
the samples or a static result (the Allan curve on a dense exponential τ grid), the other channels, the τ range,
and the note saying how the held-out error is computed."""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping

import numpy as np

from ..._validate import as_rate_columns, check_choice
from ...analysis import GAPS, avar, gap_columns
from ...errors import InputError, ParameterError
from ...estimators.grid import tau_grid
from ...results import AllanResult
from ...units import ACCEL_UNITS, accel_unit_name, check_sensor_unit, parse_unit
from .. import fitting
from .._chunked import CHUNK, chunks
from .._gapfit import gapless_terms
from ..channels import check_channel
from ._gapfill import MAX_GAP, MAX_MISSING, fill_channel, filled_record
from .scoring import HELDOUT_BLOCKS

__all__ = [
    "REFINE_SCALE",
    "check_channels",
    "check_scale",
    "check_truth",
    "check_unit",
    "heldout_note",
    "inputs",
    "resolve_tau_range",
]


def resolve_tau_range(tau_range, result, start):
    """(low, high) τ in seconds: every τ for None, ``fit``'s cut for ``"auto"``, else the pair checked."""
    if isinstance(tau_range, str):
        if tau_range != "auto":
            raise ParameterError(f"tau_range must be a (low, high) pair of seconds or 'auto', got {tau_range!r}")
        nf = fitting.fit(result, terms=start, tau_range="auto")
        return float(nf.tau[0]) * (1 - 1e-9), math.inf
    return (0.0, math.inf) if tau_range is None else fitting.check_tau_range(tau_range)


#: refine's searches square and multiply variances: samples beyond this magnitude range are refused (fit and
#: avar handle any scale exactly; refine's NNLS searches on 1e-300 variances do not).
REFINE_SCALE = (1e-100, 1e100)


def check_scale(x_or_result) -> None:
    """Refuse samples (or a result's ADEV) whose largest finite magnitude is outside :data:`REFINE_SCALE`."""
    values = x_or_result.avar if isinstance(x_or_result, AllanResult) else x_or_result
    if np.iscomplexobj(values):
        return  # the samples' own checks refuse complex samples (a float cast would drop the imaginary part)
    try:
        arr = np.asarray(values)  # an array stays as it is (float32 samples are converted a chunk at a time)
        if arr.dtype.kind not in "fiu":
            arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        return  # the samples' own checks report it
    peak = _finite_peak(arr)
    if isinstance(x_or_result, AllanResult):
        peak = peak**0.5
    if peak > 0 and not REFINE_SCALE[0] < peak < REFINE_SCALE[1]:
        raise InputError(
            f"refine needs samples of magnitude within {REFINE_SCALE[0]:g}…{REFINE_SCALE[1]:g}, got {peak:.3g}: "
            f"express them in another unit (avar and fit take any scale)"
        )


def _finite_peak(arr: np.ndarray) -> float:
    """The largest finite |value| of ``arr`` as float64 (0 if none), a chunk of rows at a time: the float64
    copy, the finite values and their magnitudes as whole arrays were three copies of the record (2.4 GB at 10⁸
    samples) before refine began."""
    arr = np.atleast_1d(arr)
    rows = max(1, CHUNK // max(1, arr[:1].size))
    peak = 0.0
    for s in chunks(arr.shape[0], rows):
        part = np.asarray(arr[s], dtype=np.float64)
        finite = part[np.isfinite(part)]
        if finite.size:
            peak = max(peak, float(np.max(np.abs(finite))))
    return peak


def inputs(x_or_result, fs, input, points, axis, channels, gaps="error"):
    """(samples or None, the static one-row AllanResult to refine, the channels by name, what was filled or None),
    checked. ``gaps="skip"``: NaN marks missing samples, filled for the searches along time (:mod:`._gapfill`)."""
    y, filled = None, None
    if isinstance(x_or_result, AllanResult):
        if fs is not None:
            raise ParameterError("fs is taken from the result; pass fs only with samples")
        if np.any(np.asarray(x_or_result.missing) > 0):
            raise ParameterError(
                "refine takes the samples of a record with gaps, not its AllanResult (its curve's EDF would be the "
                "gapless record's): pass the NaN-marked samples with gaps='skip'"
            )
        result = x_or_result
    elif hasattr(x_or_result, "tau") and hasattr(x_or_result, "t"):
        raise ParameterError(
            "refine needs samples or a static AllanResult; for a dynamic result pass the samples "
            "so that change points can be located"
        )
    else:
        if fs is None:
            raise ParameterError("fs (Hz) is needed with samples")
        cols, fs = _rate_columns(x_or_result, fs, input, gaps)
        axis = _one_axis(axis, len(cols))
        if not 0 <= axis < len(cols):
            raise ParameterError(f"axis = {axis} is outside 0..{len(cols) - 1}")
        y, filled = filled_record(cols[axis], fs)
        top = max(1, y.size // 9)
        grid = tau_grid(y.size, fs, "exp", points=points, m_max=top) if top > 1 else "octave"
        result = avar(y, fs, taus=grid)
        if filled is not None:
            filled["curve_change_pct"] = _fill_change(cols[axis], result)
    if input == "angle" and y is not None and isinstance(channels, Mapping):
        channels = {k: interval_means(c, y.size) for k, c in channels.items()}
    if filled is not None and channels is not None and isinstance(channels, Mapping):
        channels = {k: fill_channel(str(k), c, fs) for k, c in channels.items()}
    chans = check_channels(channels, y)
    if result.avar.ndim == 2:
        result = result.static_row(result.avar[_one_axis(axis, result.avar.shape[0])])
    return y, result, chans, filled


def interval_means(c, n: int):
    """A channel read at an angle record's M + 1 instants (``n`` = M rate samples): the mean of each interval's two
    ends, the channel over the interval the rate sample stands for — a clock's temperature logged with each phase
    reading, or an IMU's with each integrated angle. Any other channel as given (its own check names its size)."""
    arr = np.asarray(c)
    if arr.ndim == 1 and arr.size == n + 1 and arr.dtype.kind in "iuf":
        arr = arr.astype(np.float64)
        return 0.5 * (arr[1:] + arr[:-1])
    return c


def _rate_columns(x, fs, input, gaps):
    """The rate columns and fs; NaN an InputError naming gaps='skip', or with it kept as missing samples."""
    check_choice(gaps, "gaps", GAPS)
    arr = np.asarray(x)
    if arr.dtype.kind == "f" and np.isnan(arr).any():
        if gaps != "skip":
            i = int(np.flatnonzero(np.isnan(arr).reshape(arr.shape[0], -1).any(axis=1))[0])
            raise InputError(
                f"the samples hold NaN (first at sample {i}): refine(..., gaps='skip') takes NaN as missing samples "
                f"(at most {100 * MAX_MISSING:g} %, no gap over {100 * MAX_GAP:g} % of the record) and fills them "
                f"for the searches along time"
            )
        cols, fs, _ = gap_columns(arr, fs, input)
        return cols, fs
    cols, fs, _ = as_rate_columns(x, fs, input)
    return cols, fs


def _fill_change(y_nan, result) -> float:
    """The largest change (%) the fill made to the Allan curve against the curve that skips the gaps, over the τ
    where the skipping curve keeps at least 90 % of a gapless record's terms (further out the two average different
    subsets of the terms, and their difference is mostly the sampling noise of the terms the gaps touch)."""
    skip = avar(y_nan, result.fs, taus=result.tau, gaps="skip")
    share = skip.n / np.maximum(gapless_terms("oavar", skip.m, skip.n_samples), 1)
    ok = (share >= 0.9) & np.isfinite(skip.avar) & (skip.avar > 0)
    return float(100 * np.max(np.abs(result.avar[ok] / skip.avar[ok] - 1))) if ok.any() else float("nan")


def _one_axis(axis, n_axes: int) -> int:
    """The axis to refine: ``axis``, or without it the first — with a warning when there are others (a log's
    ``data`` of six columns was refined on its first alone, and the result said nothing of it)."""
    if axis is not None:
        return axis
    if n_axes > 1:
        warnings.warn(
            f"refine refines one axis: axis 0 of {n_axes}; pass axis= for another (or call refine once per axis)",
            stacklevel=4,  # refine's caller (refine → inputs → _one_axis)
        )
    return 0


def check_channels(channels, y) -> dict:
    """The other channels by name, each checked against the samples ``y`` (None: an AllanResult, refused)."""
    chans: dict = {}
    if channels is None:
        return chans
    if not isinstance(channels, Mapping):
        raise ParameterError(
            f"channels must be a dict of name → samples (e.g. {{'temp': T}}), got {type(channels).__name__}"
        )
    if channels:
        if y is None:
            raise ParameterError("channels need samples (a regression is fitted along time), not an AllanResult")
        for name, c in channels.items():
            if not str(name).strip():  # the report names the regression by it: "regression on " read as a blank
                raise ParameterError(f"a channel's name must not be empty, got {str(name)!r}; e.g. {{'temp': T}}")
            if str(name) in chans:  # 1 and "1": one would replace the other silently
                raise ParameterError(f"two channels are named {str(name)!r}; each channel needs its own name")
            chans[str(name)] = check_channel(str(name), c, y.size)
    return chans


def check_unit(unit, input: str, x_or_result) -> None:
    """Refuse, before any work, a unit refine does not know, or one of the other kind than the samples: a rate
    unit for rates, an angle unit for increments or a cumulative angle (an AllanResult: either, as ``fit``
    takes it). It was read only by the final fit, after the whole refinement; and an angle unit given with rate
    samples (increments whose ``input`` was left at "rate") was taken as that angle per second, silently."""
    if unit is None:
        return
    if isinstance(x_or_result, AllanResult) or input not in ("rate", "increment", "angle"):
        check_sensor_unit(unit)  # a bad ``input`` is reported by the samples' own check
        return
    if accel_unit_name(unit) is not None:  # an accelerometer's acceleration samples: rates, as a gyro's °/s
        if input != "rate":
            raise ParameterError(
                f"unit {unit!r} is an accelerometer's, taken for acceleration samples only (input='rate'), got "
                f"input={input!r}; for velocity increments give no unit (allowed accelerometer units: "
                f"{', '.join(ACCEL_UNITS)})"
            )
        return
    if input == "rate":
        check_sensor_unit(unit)  # unknown: the message lists the gyro's and the accelerometer's units
    kind = "rate" if input == "rate" else "angle"
    try:
        parse_unit(unit, kind=kind)
    except ParameterError as e:
        if "unknown unit" in str(e) or "must be a string" in str(e):
            raise
        other = "angle increments: input='increment'" if kind == "rate" else "rates: input='rate'"
        what = "rates" if kind == "rate" else "angles"
        raise ParameterError(f"{e} (input={input!r}: the samples are {what}; {other})") from None


def check_truth(truth, effects) -> None:
    """``truth`` is None or a dict of effect name (one of ``effects``) → dict of parameter name → value; an unknown
    effect or another shape was ignored silently (no step reported an error against it)."""
    if truth is None:
        return
    if not isinstance(truth, Mapping):
        raise ParameterError(
            f"truth must be a dict of effect → {{parameter: value}} (e.g. {{'gauss_markov': {{'tc': 10.0}}}}), "
            f"got {type(truth).__name__}"
        )
    for effect, params in truth.items():
        if effect not in effects:
            raise ParameterError(f"truth names an unknown effect {effect!r}; allowed: {', '.join(effects)}")
        if not isinstance(params, Mapping):
            raise ParameterError(f"truth[{effect!r}] must be a dict of parameter → value, got {type(params).__name__}")


def heldout_note(y, heldout) -> str:
    """How the held-out error was computed, or why there is none."""
    if y is None:
        return "curve-only input (an AllanResult without samples): no held-out error; steps rest on the calibrated test"
    if heldout is None:
        return "record too short to hold out alternate blocks: no held-out error"
    return (
        f"alternate blocks in time ({HELDOUT_BLOCKS}; odd ↔ even, each part's blocks joined): the model fitted "
        "on one part predicts the other part's Allan curve, both ways, mean RMS ADEV error on the τ whose "
        "estimate is within ±10 % (4 per octave); a drift is refitted on the held-in part"
    )
