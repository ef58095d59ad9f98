"""The allanite report: static Allan deviation with confidence intervals, the IEEE-952 noise model,
the dynamic Allan variance and the noise coefficients over time — as numbers, text, figures and one
self-contained HTML page.

:func:`build_report` (or :func:`from_log` for a :class:`~allanite.Log`) computes everything and
returns a :class:`Report`; :meth:`Report.write` writes ``report.html``, ``summary.json`` and the
PNG figures into a folder; :meth:`Report.text` is the terminal summary. ``allanite report`` (the
command line, :mod:`allanite.cli`) only wires :func:`allanite.read_log` and these together.

Every number the page shows is read from :meth:`Report.summary`, the dictionary written as
``summary.json``, so the two cannot disagree. Its conventions: times and τ in seconds (keys ending
in ``_s``), rates in Hz, Allan deviations in the samples' rate unit (``adev_unit``), coefficients
in their base form (``unit``) and in IEEE-952 units (``ieee_unit``); ``null`` stands for a number
that does not exist (no unit given, an unbounded interval, a read-off outside the τ range).

Examples
--------
>>> import numpy as np, allanite, tempfile
>>> from allanite.report import build_report
>>> y = allanite.simulate(20_000, 100.0, N=0.01, K=1e-3, seed=1)[:, None]
>>> rep = build_report(y, 100.0, unit="deg/s", window=4_000, hop=1_000)
>>> rep.summary()["fit"]["axes"][0]["coefficients"]["N"]["ieee_unit"]
'°/√h'
>>> paths = rep.write(tempfile.mkdtemp())
>>> sorted(p.name for p in paths if p.suffix != ".png")
['report.html', 'summary.json']
"""

from __future__ import annotations

import dataclasses
import datetime as _dt

import numpy as np

from .._validate import check_choice, check_input, check_positive
from ..analysis import avar, davar
from ..errors import AllaniteError, ParameterError
from ..estimators import get as get_estimator
from ..estimators.theo import resolve_decimation
from ..model import fit as fit_model
from ..units import ACCEL_UNITS, accel_factor, parse_unit
from . import _worker
from ._channels import check_channels, log_channels, rate_aligned
from ._plan import memory_plan, octaves, window_and_hop
from ._sections import forecast_section, paper002_section, refine_candidates, refinement_section
from .axes import analyse_by_axis, axes_per_read
from .fmt import json_number
from .forecasting import check_forecast_options, plan_forecast
from .result import Report, steps
from .settings import REPORT_ESTIMATORS

__all__ = ["Report", "build_report", "from_log", "log_source"]


def _check_taus(taus):
    if isinstance(taus, str):
        return taus
    return np.asarray(taus, dtype=np.float64)


def build_report(
    x,
    fs,
    *,
    unit=None,
    input: str = "rate",
    axis_names=None,
    source=None,
    window=None,
    hop=None,
    taus="octave",
    fit: bool = True,
    confidence: float = 0.683,
    notes=(),
    progress=None,
    estimator: str = "oavar",
    refine: bool | tuple = False,
    channels=None,
    frames=None,
    forecast=None,
    taper: str | None = None,
    split: str | None = None,
    max_memory=None,
    gaps: str = "error",
    refine_filter=None,
) -> Report:
    """Compute everything the report shows.

    Parameters
    ----------
    x : array_like, (samples,) or (samples, axes)
        The samples (rate, increments or cumulative angle, per ``input``).
    fs : float
        Sampling rate, Hz.
    unit : str, optional
        Unit of the samples (a rate unit, or an angle unit for increments/angle). Without it the
        numbers are in "the samples' unit" and the coefficients stay in base form. An accelerometer's unit
        (:data:`allanite.units.ACCEL_UNITS`: ``"m/s^2"``, ``"g"``, ``"mg"``, …; rate input) makes the report
        an accelerometer's: Allan deviations in it, the coefficients in base form (that unit and seconds) and in
        the accelerometer's report units (:func:`allanite.units.accel_report_unit`: velocity random walk in
        m/s/√h, bias instability in µg, acceleration random walk in m/s/h^1.5) — ``Report.accel_unit``.
    axis_names : list of str, optional
        One per axis (default "axis 0", "axis 1", …).
    source : dict, optional
        JSON-able description of where the record came from (shown in the Record section).
    window, hop : int, optional
        DAVAR window and hop in samples; defaults :func:`default_window` (record/12) and
        :func:`default_hop` (window/25).
    taus : str or array_like
        τ of the static analysis: a grid name (default ``"octave"``) or τ in seconds. The DAVAR
        uses paper 000's exponential grid on the window (DHVAR: the octave grid).
    refine : bool or sequence of str
        Also run :func:`allanite.refine` on every axis (a few seconds per 10⁶ samples): the page gains a
        "Model refinement" section — the effects the five-term model lacks, their parameters and the
        error before and after, and what the final model still misses (or that it passes every calibrated
        check). True tries every candidate effect; a sequence of effect names (keys of
        :data:`allanite.model.effects.EFFECTS`) tries only those — e.g. without ``"outliers"`` on quantised
        accelerometers (docs/refinement.md); an empty one only says what the five-term model misses.
    channels : dict of str → array_like, optional
        Other channels of the same record (a temperature, a supply voltage, an accelerometer), one sample per
        sample of ``x`` (with ``input="angle"`` each is averaged over the two samples of each rate), passed to
        :func:`allanite.refine` on every axis as ``channels=`` for its ``"regression"`` effect. They imply
        ``refine=True`` (their only use is that regression); ``refine`` naming effects without ``"regression"``
        is a :class:`~allanite.errors.ParameterError` (the channels would never be used). Their unit is not
        known to the report: a coefficient is in the rate unit per unit of the channel (e.g. "deg/s per unit of
        temp").
    refine_filter : array_like, (b, a) or dict, optional
        The sensor's own digital filter, passed to :func:`allanite.refine` on every axis as ``filter=`` (FIR taps,
        an IIR's (b, a), or a dict with ``"rate"``/``"decimation"``): the bandwidth effect's one kind, exact; the
        page says what was declared. Used only where the report refines.
    estimator : {"oavar", "theoh"}
        ``"oavar"`` (default): overlapping Allan deviation and DAVAR. ``"theoh"``: TheoH for the
        whole record and paper 001's DHVAR over time (overlapping Allan up to 10 % of the record or
        window, bias-removed Theo1 beyond, reaching 75 %); the default window is then capped at
        ``DHVAR_MAX_DEFAULT_WINDOW`` samples and the default hop keeps ≤ ``DHVAR_MAX_WINDOWS``
        windows; records over 100 000 samples get their whole-record TheoBR part from block
        averages (``avar(decimate="auto")``, Taylor & Howe's fast TheoBR).
    fit : bool
        Fit the IEEE-952 noise model (whole record and every window).
    confidence : float
        Level of all intervals (default 68.3 %).
    notes : sequence of str
        Extra notes to show (warnings from reading, …).
    progress : bool or object with ``step(name)``, optional
        None (default): a ``tqdm.auto`` bar when a notebook or a terminal is attached, none otherwise;
        True/False: always/never; an object with ``step(name)`` and ``add(n)`` (the CLI's bar) is told
        before each step instead.
    frames : float, optional
        Time-frame DAVAR (paper 004): frames of this many seconds, the noise model fitted in each, and a
        "Coefficient forecast" section. Without ``forecast`` the first 2/3 of the frames build, the rest check.
    forecast : (int, int) or "BUILD:CHECK", optional
        The build/check split in frames (paper 004: 60:30). Without ``frames`` the record is cut into
        BUILD + CHECK frames.
    max_memory : int, optional
        Byte budget of the report (default ``ALLANITE_MAX_MEMORY`` or 2 GiB, as :func:`allanite.davar`): the
        DAVAR surface, the per-window fits and what the report keeps of them
        (:func:`allanite.report.budget.report_memory`). A request over it raises
        :class:`~allanite.errors.MemoryBudgetError` before any heavy work, with a hop that fits.
    gaps : {"error", "skip"}
        ``"skip"``: NaN marks missing samples (``read_log(..., gaps="nan")``; :func:`from_log` sets it for such a
        log) — the Allan deviation and DAVAR skip the terms that touch one (``avar(gaps="skip")``), the fit scales
        each τ's EDF by the terms kept (``fit(gaps="skip")``), the refinement fills the gaps for its searches along
        time (``refine(gaps="skip")``, at most 5 % missing), and the noise type behind each interval is identified
        on the samples with the gaps filled the same way (the line between their neighbourhoods' medians:
        :func:`allanite.model.refinement._gapfill.filled_columns`). Overlapping Allan only (``estimator="oavar"``).
    """
    notes = list(notes)
    check_choice(gaps, "gaps", ("error", "skip"))
    input = check_input(input)
    x, plan = _record_and_plan(x, fs, frames, forecast)
    candidates, channels = _refine_asked(refine, channels, np.shape(x)[0], input, notes)
    progress, own_bar = steps(progress, 5 + (candidates is not None) + (plan is not None), "report")
    accel_unit = accelerometer_unit(unit, input, notes)
    # an accelerometer's unit is no gyro's: none for the gyro's conversions, and its own note (not "unknown")
    x, unit_name, axis_names = _axes_and_unit(x, None if accel_unit else unit, input, axis_names, notes, accel_unit)
    taus = _check_taus(taus)
    check_choice(estimator, "estimator", tuple(REPORT_ESTIMATORS))
    static, dynamic, settings = _analyse(
        x, fs, input=input, taus=taus, estimator=estimator, window=window, hop=hop, fit=fit, confidence=confidence,
        max_memory=max_memory, progress=progress, gaps=gaps,
        # a figure process draws the DAVAR figures while the intervals and the model are computed
        on_dynamic=lambda st, dy: _offer(st, dy, None, None, unit_name, input, axis_names, complete=False),
    )  # fmt: skip
    fits = series = fit_error = series_error = None
    if fit:
        fits, series, fit_error, series_error = _fit_record_and_windows(
            static, dynamic, (unit_name, accel_unit), confidence, axis_names, notes, progress
        )
    else:
        progress.add(2)
    if candidates is not None or plan is not None or taper or split:  # and the rest while more is computed
        _offer(static, dynamic, fits, series, unit_name, input, axis_names, complete=True)
    asked = (candidates, channels, plan, confidence, taper, split, refine_filter)
    sections = _later_sections((x, fs, input), static, dynamic, unit_name, axis_names, asked, notes, settings, progress)
    created = _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat()
    if own_bar:
        progress.close()
    return Report(
        **sections,
        static=static,
        dynamic=dynamic,
        fits=fits,
        series=series,
        fs=float(static.fs),
        unit=unit_name,
        accel_unit=accel_unit,
        input=input,
        axis_names=axis_names,
        source=dict(source or {}),
        settings=settings,
        notes=notes,
        fit_requested=bool(fit),
        fit_error=fit_error,
        series_error=series_error,
        created=created,
    )


def _refine_asked(refine, channels, n_samples: int, input: str, notes: list) -> tuple:
    """(candidate effects or None, channels) of the refinement: the channels checked against the candidates and
    the record's length and aligned with its rates (:func:`._channels.rate_aligned`); channels without a
    refinement asked imply ``refine=True``, said in ``notes``."""
    candidates = refine_candidates(refine)
    channels = check_channels(channels, candidates, n_samples)
    if channels and candidates is None:  # channels imply refine=True: the regression is their only use
        candidates = refine_candidates(True)
        notes.append("No refinement was asked for: the channels imply it (its regression is their only use).")
    return candidates, rate_aligned(channels, input)


def _later_sections(record, static, dynamic, unit_name, axis_names, asked, notes, settings, progress) -> dict:
    """The report's optional sections, as :class:`.result.Report`'s fields, in the order they are computed
    (each None where not asked for): every axis's refinement, the time-frame forecast, paper 002's.
    ``record``: (samples, fs, input); ``asked``: (candidates, channels, forecast plan, confidence, taper,
    split, the declared filter)."""
    x, fs, input = record
    candidates, channels, plan, confidence, taper, split, declared = asked
    refinements = refinement_section(
        x, fs, input, unit_name, static, axis_names, (candidates, channels, declared), notes, settings, progress
    )
    frames, forecasts, forecast_settings, forecast_error = forecast_section(
        x, fs, plan, unit_name, input, confidence, notes, progress
    )
    paper002 = paper002_section(x, fs, input, dynamic, unit_name, axis_names, taper, split, notes, progress)
    return {
        "refinements": refinements,
        "frames": frames,
        "forecasts": forecasts,
        "forecast_settings": forecast_settings,
        "forecast_error": forecast_error,
        "paper002": paper002,
    }


def _record_and_plan(x, fs, frames, forecast):
    """The samples as an array and the time-frame forecast's plan (None without frames or a split): the
    options checked first, the plan made before anything is computed — a frame or split that does not fit
    the record is the caller's option."""
    frame_s, fc_split = check_forecast_options(frames, forecast)
    x = np.asarray(x) if not isinstance(x, np.ndarray) else x
    if frame_s is None and fc_split is None:
        return x, None
    return x, plan_forecast(int(x.shape[0]), float(fs), frame_s, fc_split)


def _offer(static, dynamic, fits, series, unit_name, input, axis_names, complete: bool) -> None:
    """Offer the figure process (if one waits: :mod:`allanite.report._worker`) the report as far as it is
    computed; ``complete``: every figure it has is final (the fits are in; refinement, frames and forecast
    figures come with the whole report)."""
    if _worker.waiting():
        partial = Report(
            static=static, dynamic=dynamic, fits=fits, series=series, fs=float(static.fs), unit=unit_name,
            input=input, axis_names=axis_names, source={}, settings={},
        )  # fmt: skip
        _worker.offer(partial, complete=complete)


def accelerometer_unit(unit, input, notes) -> str | None:
    """The canonical name of ``unit`` where it is an accelerometer's (rate input; a note says what the report
    then holds), else None (no unit, or a gyro's: :func:`_axes_and_unit` checks it)."""
    if not isinstance(unit, str):
        return None
    try:
        parse_unit(unit)
        return None
    except ParameterError:
        pass
    try:
        factor = accel_factor(unit)
    except ParameterError:
        return None  # neither: _axes_and_unit's message lists the gyro's units, and says to give none
    if input != "rate":
        raise ParameterError(
            f"unit {unit!r} is an accelerometer's, analysed as rate input only (input={input!r}); allowed "
            "input: 'rate' (or give a gyro's angle unit)"
        )
    name = next(n for n in ACCEL_UNITS if accel_factor(n) == factor)
    notes.append(
        f"The samples are an accelerometer's, in {name}: Allan deviations in {name}, the noise coefficients in "
        f"base form ({name} and seconds) and in the accelerometer's units — velocity random walk in m/s/√h, bias "
        "instability in µg, acceleration random walk in m/s/h^1.5 (the gyro's terms N, B, K)."
    )
    return name


def _axes_and_unit(x, unit, input, axis_names, notes, accel_unit=None) -> tuple:
    """(samples as (samples, axes), the unit's name or None, one name per axis), checked; a note when the unit
    is unknown (neither a gyro's nor ``accel_unit``)."""
    if x.ndim == 1:
        x = x[:, None]
    unit_name = None if unit is None else parse_unit(unit, kind="rate" if input == "rate" else "angle").name
    if unit_name is None and accel_unit is None:
        notes.append(
            "The unit of the samples is unknown (not given): Allan deviations are in the "
            "samples' own unit and the noise coefficients in base form, without IEEE-952 conversion."
        )
    n_axes = x.shape[1]
    if axis_names is None:
        axis_names = [f"axis {k}" for k in range(n_axes)]
    axis_names = [str(a) for a in axis_names]
    if len(axis_names) != n_axes:
        raise ParameterError(f"axis_names has {len(axis_names)} names for {n_axes} axes")
    return x, unit_name, axis_names


def _analyse(
    x, fs, *, input, taus, estimator, window, hop, fit, confidence, max_memory, progress, on_dynamic, gaps="error"
) -> tuple:
    """(static result with intervals, dynamic result, settings): the request's size first — over the memory
    budget it is refused before any heavy work — then every axis at once, or one at a time (report/axes.py).
    ``on_dynamic(static, dynamic)`` is called once both exist (with every axis at once: before the intervals)."""
    static_est, dynamic_est, dynamic_grid = REPORT_ESTIMATORS[estimator][:3]
    n_axes = x.shape[1]
    n = int(x.shape[0]) - (input == "angle")  # rate samples (angle input: differenced)
    window, hop, settings = window_and_hop(n, window, hop, estimator)
    resolve_m = get_estimator(dynamic_est).resolve_m
    assert resolve_m is not None  # every dynamic estimator of the report resolves its grid
    dyn_ms = resolve_m(dynamic_grid, window, check_positive(fs, "fs"))
    n_fit = octaves(dyn_ms) if estimator == "oavar" else dyn_ms.size  # DHVAR's short windows: every τ
    by_axis, cost = memory_plan(x, n, n_axes, window, hop, dyn_ms.size, n_fit, fit, max_memory)
    extra: dict = {"decimate": "auto"} if static_est == "theoh" else {}
    if gaps == "skip":  # NaN-marked missing samples (the by-axis path's DAVAR then refuses them: a NaN)
        extra["gaps"] = "skip"
    if by_axis:  # one axis in memory at a time (report/axes.py): a long or memory-mapped record
        static, dynamic = analyse_by_axis(
            x, fs, input=input, taus=taus, static_est=static_est, static_extra=extra, confidence=confidence,
            window=window, hop=hop, grid=dynamic_grid, dynamic_est=dynamic_est, max_memory=max_memory,
            progress=progress, group=axes_per_read(n, n_axes, cost["total"], max_memory),
        )  # fmt: skip
        on_dynamic(static, dynamic)
    else:
        progress.step("static Allan deviation")
        static = avar(x, fs, input=input, taus=taus, estimator=static_est, **extra)
        progress.step("dynamic Allan variance")
        dynamic = davar(
            x, fs, window=window, hop=hop, taus=dynamic_grid, input=input, estimator=dynamic_est,
            max_memory=max_memory, gaps=gaps,
        )  # fmt: skip
        on_dynamic(static, dynamic)  # before the intervals: the DAVAR figures need nothing more
        progress.step("confidence intervals")
        # the noise type behind each interval is identified on the samples (gaps: filled for that alone by the
        # line between their neighbourhoods' medians, as refine fills them — a spike beside a gap is no ramp across
        # it; the EDF counts the complete terms, ``static.n``)
        if gaps == "skip":
            from ..model.refinement._gapfill import filled_columns  # here: refine's package loads with refine

            x = filled_columns(x)
        static = static.with_confidence(x, confidence=confidence)
    settings.update(
        taus=taus if isinstance(taus, str) else "explicit",
        estimator=estimator,
        dynamic_grid=dynamic_grid,
        theo_decimation=(resolve_decimation("auto", n, taus) if static_est == "theoh" else None),
        memory_estimate_bytes=int(cost["total"]),
        by_axis=by_axis,
    )
    return static, dynamic, settings


def _fit_record_and_windows(static, dynamic, units, confidence, axis_names, notes, progress) -> tuple:
    """(whole-record fits, per-window series, their errors or None): the noise model of the whole record, then
    of every window on the same τ range as its axis's whole-record fit; a failure becomes a note. ``units``: (the
    gyro's unit or None, the accelerometer's or None) — the windows' coefficients carry either (an
    accelerometer's: in its report units, as the whole record's table), the whole record's the gyro's alone."""
    unit_name, window_unit = units[0], units[0] or units[1]
    fits = series = fit_error = series_error = None
    progress.step("noise-model fit")
    try:
        # tau_range="auto": a real sensor's shortest τ (anti-alias filter, vibration lines) are often not
        # the model's; they would dominate the fit and give wrong coefficients. The cut is stated.
        fits = fit_model(static, unit=unit_name, confidence=confidence, tau_range="auto", gaps="skip")
        if not isinstance(fits, list):
            fits = [fits]
        for k, f in enumerate(fits):
            notes.extend(f"{axis_names[k]}: {note}." for note in f.notes)
    except AllaniteError as exc:
        fit_error = str(exc)
        notes.append(f"The noise model could not be fitted to the whole record: {exc}")
    progress.step("noise-model fit over time")
    try:
        # the windows use the same τ range as the whole-record fit of their axis
        if fits is not None:
            per_axis = [dynamic.avar] if dynamic.avar.ndim == 2 else list(dynamic.avar)
            series = [
                _fit_windows(dataclasses.replace(dynamic, avar=row), window_unit, confidence, float(f.tau[0]))
                for row, f in zip(per_axis, fits)
            ]
            if dynamic.avar.ndim == 2:
                series = series[0]
        else:
            series = fit_model(dynamic, unit=window_unit, confidence=confidence, tau_range="auto")
    except AllaniteError as exc:
        series_error = str(exc)
        notes.append(
            f"The coefficients over time could not be fitted (DAVAR window of {dynamic.window} samples): {exc}"
        )
    return fits, series, fit_error, series_error


def _fit_windows(dynamic, unit, confidence, tau_from):
    """The coefficients of every window, on the τ range of the whole-record fit of that axis. A short
    window (DHVAR's ≤ 2001 samples) holds few octaves: when thinning to octaves leaves too few τ for the
    terms, every τ is fitted (their correlation is in the covariance for overlapping estimates)."""
    tau_range = (tau_from * (1 - 1e-9), None)
    try:
        return fit_model(dynamic, unit=unit, confidence=confidence, tau_range=tau_range)
    except ParameterError as exc:
        if "usable τ (octave-spaced)" not in str(exc):
            raise
        return fit_model(dynamic, unit=unit, confidence=confidence, tau_range=tau_range, thin=False)


def _share(log) -> str:
    """The analysed stretch's share of a gapped log, said where it is under half of it: many short gaps
    (dropped samples) leave a stretch far shorter than the log, which the report's numbers are of."""
    share = (log.span[1] - log.span[0]) / log.n_record
    if share >= 0.5:
        return ""
    listed = "" if log.segment_spans is not None else " (--gaps split lists every stretch)"
    return f" — {100 * share:.2g} % of the log: its gaps are many or long, each result is of this stretch alone{listed}"


def log_source(log) -> dict:
    """JSON-able description of a :class:`~allanite.Log` for the report's Record section."""
    src = {
        "name": log.path.name,
        "path": str(log.path),
        "format": log.format,
        "columns": list(log.columns),
        "fs_hz": float(log.fs),
        "fs_from": "time column" if log.time is not None else "given",
        "time_column": log.time_column,
        "time_column_recognised": bool(log.time_column_recognised),
        "time_unit": log.time_unit,
        "time_unit_source": log.time_unit_source,
        "unit": log.unit.name if log.unit is not None else None,
        "unit_source": log.unit_source,
        "column_units": [None if cu is None else cu.name for cu in log.column_units],
        "input": log.input,
        "t0_s": json_number(log.t0),
        "samples_in_file": int(log.n_record),
        "kept": [int(log.span[0]), int(log.span[1])],
        "gaps": [
            {"after_sample": g.index - 1, "time_s": g.time, "duration_s": g.duration, "missing_samples": g.missing}
            for g in log.gaps
        ],
        "jitter": json_number(log.jitter),
        # the log's other channels (from_log adds which ones the refinement used: "channels_used")
        "channels": list(log.channels),
        "channels_recognised": bool(log.channels_recognised),
    }
    if log.segment_spans is not None:
        src["segments"] = [[int(a), int(b)] for a, b in log.segment_spans]
    return src


def log_accel_unit(log) -> str | None:
    """The accelerometer's unit every column's name gives (``a_RS_S_x [m s^-2]``, …: ``Log.take`` of that group),
    else None — a log of rate input without a gyro unit whose columns all name the same acceleration unit."""
    units = log.column_units or [None]
    if log.unit is not None or log.input != "rate" or any(cu is None or cu.kind != "acceleration" for cu in units):
        return None
    names = {cu.name for cu in units}
    return names.pop() if len(names) == 1 else None


def _unit_notes(log) -> list:
    """The note on a unit the column names gave (``Log.unit_source``), or on the unit they give that is no gyro's
    (an accelerometer's m/s²: Allan deviations in it, the coefficients in base form)."""
    if log.unit is not None and (log.unit_source or "").startswith("from the column names"):
        return [f"The unit {log.unit.name} is the one the column names give ({log.unit_source[23:]})."]
    named = {cu.name for cu in log.column_units if cu is not None}
    if log_accel_unit(log) is not None:
        return []  # build_report's note says the report is an accelerometer's
    if log.unit is None and len(named) == 1:
        u = named.pop()
        return [f"The column names give the unit {u}, no gyro unit: the samples' own unit below is {u} (and seconds)."]
    return []


def _nan_rows(log) -> int:
    """How many of a log's rows hold a NaN (``read_log(..., gaps="nan")`` marked its gaps so)."""
    data = np.asarray(log.data)
    if data.dtype.kind != "f":
        return 0
    return int(np.isnan(data).reshape(len(data), -1).any(axis=1).sum())


def _time_notes(log) -> list:
    """The notes on the time column where the reader chose it or its unit: recognised by its name (no time column
    named, no fs given — with the unit that was given, if one was), its unit from its name or from an epoch
    magnitude. None where the time column and its unit were both given, or fs was (no time column read)."""
    notes = []
    if log.time_column_recognised:
        given = (
            f", read in {log.time_unit} as given (--time-unit / time_unit=)"
            if log.time_unit_source == "time_unit="
            else ""
        )
        notes.append(
            f"No time column was named (--time-column / time_column=) nor fs given: column {log.time_column!r} was "
            f"taken as the time column by its name{given}; fs = {log.fs:g} Hz from its steps."
        )
    if log.time_unit_from_name:
        notes.append(
            f"Time column {log.time_column!r} was read in {log.time_unit}, the unit its name gives (time_ns, "
            "t [ms]; rostopic echo -p's %time: ns) (--time-unit / read_log(time_unit=…) overrides it)."
        )
    if log.time_unit_source == "epoch magnitude":
        notes.append(
            f"Time column {log.time_column!r} names no unit: read in {log.time_unit}, the unit in which its first "
            "stamp is an epoch date (--time-unit / read_log(time_unit=…) overrides it)."
        )
    return notes


def from_log(log, **kwargs) -> Report:
    """:func:`build_report` on a :class:`~allanite.Log` from :func:`allanite.read_log` (its unit — a gyro's, or
    the accelerometer's its columns' names all give, as ``Log.take`` keeps one of ``Log.groups`` —, its
    input kind, column names and reading notes) and, without ``channels=``, its channels (``Log.channels``):
    those named in ``read_log(channels=[…])`` imply the refinement, as ``channels=`` does; those recognised as a
    temperature by their names are handed to the refinement only when ``refine=`` asks for one that tries the
    regression — a report without ``refine`` stays the same, and says in a note that the column is no axis."""
    notes = list(kwargs.pop("notes", ())) + _time_notes(log)
    lost = _nan_rows(log) if log.gaps else 0
    if lost:
        notes.append(
            f"The log has {len(log.gaps)} gap(s): {lost} missing rows marked NaN (--gaps nan) — the Allan curves skip "
            "the terms that touch one, the fit scales each τ's EDF by the terms kept, the refinement fills them for "
            "its searches along time."
        )
        kwargs.setdefault("gaps", "skip")
    elif log.gaps:
        notes.append(
            f"The log has {len(log.gaps)} gap(s); only the longest gap-free stretch, samples "
            f"{log.span[0]}–{log.span[1] - 1} of {log.n_record}, is analysed{_share(log)}"
            + (
                f" (all {len(log.segment_spans)} stretches are listed in summary.json)."
                if log.segment_spans is not None
                else "."
            )
        )
    notes += _unit_notes(log) if "unit" not in kwargs else []
    unit = kwargs.pop("unit", None) or (log.unit.name if log.unit is not None else log_accel_unit(log))
    if "channels" not in kwargs:  # the log's own: a temperature column recognised by its name, or those named
        kwargs["channels"] = log_channels(log, kwargs.get("refine", False), notes)
    used = kwargs["channels"]  # build_report checks it (a mapping of name → samples)
    source = dict(log_source(log), channels_used=[str(k) for k in used] if isinstance(used, dict) else [])
    return build_report(
        log.data,
        log.fs,
        unit=unit,
        input=log.input,
        axis_names=list(log.columns),
        source=source,
        notes=notes,
        **kwargs,
    )
