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

import base64
import datetime as _dt
import html as _html
import io as _io
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import AllaniteError, ParameterError

__all__ = ["Report", "build_report", "from_log", "default_window", "default_hop", "FIT_MODEL"]

#: The model the report fits (FORMULAS.md §6; the K column is exact for a sampled random walk).
FIT_MODEL = "σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)·B² + K²·τ0·(2m²+1)/(6m) + R²·τ²/2"
#: Fraction of the record that is the default DAVAR window, and of the window that is the default hop.
WINDOW_FRACTION = 12
HOP_FRACTION = 25
#: DHVAR's cost grows with the window squared (Theo1 at every m of the bias ratio): its default
#: window is capped here (paper 001 uses 401 samples).
DHVAR_MAX_DEFAULT_WINDOW = 2001
#: ... and its default hop keeps the number of windows (each fitted) to about this.
DHVAR_MAX_WINDOWS = 400
#: estimator → (static estimator, dynamic estimator, dynamic τ grid, section titles)
REPORT_ESTIMATORS = {
    "oavar": ("oavar", "oavar", "exp", "Overlapping Allan deviation", "Dynamic Allan variance"),
    "theoh": ("theoh", "theoh", "octave", "TheoH deviation (overlapping Allan ≤ 10 % of the record, TheoBR beyond)",
              "Dynamic TheoH (DHVAR)"),
}
_TERM_NAMES = {"Q": "quantization", "N": "angle random walk", "B": "bias instability",
               "K": "rate random walk", "R": "rate ramp"}


def default_window(n_samples: int) -> int:
    """The report's default DAVAR window: 1/12 of the record (at least 2 samples)."""
    return max(2, int(n_samples) // WINDOW_FRACTION)


def default_hop(window: int) -> int:
    """The report's default hop: 1/25 of the window (at least 1 sample) — 25 windows overlap at any time."""
    return max(1, int(window) // HOP_FRACTION)


# --------------------------------------------------------------------------------------------------
# numbers → JSON


def _num(v):
    """A JSON number: Python float/int, ``None`` for NaN/inf/None (JSON has no infinity)."""
    if v is None:
        return None
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    v = float(v)
    return v if math.isfinite(v) else None


def _list(a):
    """Nested lists of JSON numbers (exact doubles; non-finite → None)."""
    a = np.asarray(a)
    if a.dtype.kind in "iub":
        return a.tolist()
    a = a.astype(np.float64)
    if np.all(np.isfinite(a)):
        return a.tolist()
    return [_list(r) for r in a] if a.ndim > 1 else [_num(v) for v in a]


# --------------------------------------------------------------------------------------------------
# the report


class _NoProgress:
    def step(self, name: str) -> None:
        pass

    def add(self, n: int) -> None:
        pass


@dataclass
class Report:
    """Everything the report shows. Build it with :func:`build_report` or :func:`from_log`.

    Attributes
    ----------
    static : AllanResult
        Overlapping Allan variance of the whole record, with confidence intervals, (axes, τ).
    dynamic : DynamicAllanResult
        DAVAR, (axes, τ, t).
    fits : list of NoiseFit or None
        Whole-record noise-model fit per axis (None with ``fit=False`` or when it failed: ``fit_error``).
    series : list of CoefficientSeries or None
        The coefficients fitted in every DAVAR window, per axis (``series_error`` when it failed).
    unit : str or None
        Unit of the samples (canonical name, e.g. ``"deg/s"``); None when unknown.
    axis_names : list of str
    source : dict
        Where the record came from (JSON-able): path, format, columns, gaps, …
    notes : list of str
        Things the reader must know (unit unknown, gaps, warnings while reading).
    """

    static: object
    dynamic: object
    fits: list | None
    series: list | None
    fs: float
    unit: str | None
    input: str
    axis_names: list
    source: dict
    settings: dict
    notes: list = field(default_factory=list)
    fit_requested: bool = True
    fit_error: str | None = None
    series_error: str | None = None
    created: str = ""
    #: per axis :class:`~allanite.Refinement` (``refine=True``), else None
    refinements: list | None = None
    _summary: dict | None = field(default=None, repr=False)

    # ---------------------------------------------------------------------------- properties
    @property
    def n_axes(self) -> int:
        return len(self.axis_names)

    @property
    def adev_unit(self) -> str | None:
        """Label of the Allan deviation's unit (e.g. ``"°/s"``), None when the unit is unknown."""
        if self.unit is None:
            return None
        from .units import adev_unit_label

        return adev_unit_label(self.unit)

    def __repr__(self) -> str:
        fit = "not fitted" if self.fits is None else f"{len(self.fits)} noise fits"
        return (f"Report({self.source.get('name', 'record')!r}: {self.static.n_samples} samples × {self.n_axes} "
                f"axes at {self.fs:g} Hz, unit {self.unit or 'unknown'}; {self.static.tau.size} τ, "
                f"{self.dynamic.t.size} DAVAR windows; {fit})")

    # ---------------------------------------------------------------------------- summary
    def summary(self) -> dict:
        """Every number of the report, JSON-able (what ``summary.json`` holds)."""
        if self._summary is None:
            self._summary = _summary(self)
        return self._summary

    def text(self) -> str:
        """The terminal summary: ADEV table with intervals, fitted coefficients, DAVAR summary."""
        return _text(self.summary())

    # ---------------------------------------------------------------------------- figures
    def figure_specs(self) -> list:
        """(file name, title, caption, draw) for every figure; ``draw(fig)`` fills a matplotlib Figure."""
        return _figure_specs(self)

    def render_figures(self, progress=None, dpi: int = 100) -> dict:
        """File name → PNG bytes of every figure."""
        from matplotlib.figure import Figure

        progress = progress or _NoProgress()
        images = {}
        for name, _title, _caption, size, draw in self.figure_specs():
            progress.step(f"figure {name}")
            fig = Figure(figsize=size, dpi=dpi)
            draw(fig)
            buf = _io.BytesIO()
            fig.savefig(buf, format="png", dpi=dpi)
            images[name] = buf.getvalue()
        return images

    def html(self, images: dict) -> str:
        """The self-contained HTML page, with ``images`` (file name → PNG bytes) embedded as data URIs."""
        return _html_page(self, images)

    def write(self, out, progress=None, dpi: int = 100) -> list:
        """Write ``report.html``, ``summary.json`` and the PNG figures into folder ``out`` (created if
        needed). Returns the paths written, report.html and summary.json first."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        progress = progress or _NoProgress()
        images = self.render_figures(progress, dpi=dpi)
        progress.step("writing report.html, summary.json")
        pngs = []
        for name, data in images.items():
            p = out / name
            p.write_bytes(data)
            pngs.append(p)
        summary = self.summary()
        summary["files"] = {"html": "report.html", "summary": "summary.json", "figures": list(images)}
        (out / "summary.json").write_text(json.dumps(summary, indent=1, ensure_ascii=False, allow_nan=False),
                                          encoding="utf-8")
        (out / "report.html").write_text(self.html(images), encoding="utf-8")
        return [out / "report.html", out / "summary.json"] + pngs


def _check_taus(taus):
    if isinstance(taus, str):
        return taus
    return np.asarray(taus, dtype=np.float64)


def build_report(x, fs, *, unit=None, input: str = "rate", axis_names=None, source=None, window=None, hop=None,
                 taus="octave", fit: bool = True, confidence: float = 0.683, notes=(), progress=None,
                 estimator: str = "oavar", refine: bool = False) -> Report:
    """Compute everything the report shows.

    Parameters
    ----------
    x : array_like, (samples,) or (samples, axes)
        The samples (rate, increments or cumulative angle, per ``input``).
    fs : float
        Sampling rate, Hz.
    unit : str, optional
        Unit of the samples (a rate unit, or an angle unit for increments/angle). Without it the
        numbers are in "the samples' unit" and the coefficients stay in base form.
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
    refine : bool
        Also run :func:`allanite.refine` on every axis (a few seconds per 10⁶ samples): the page gains a
        "Model refinement" section — the effects the five-term model lacks, their parameters and the
        error before and after.
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
    progress : object with ``step(name)``, optional
        Told before each step (the CLI's progress bar).
    """
    from ._input import check_choice
    from .allan import avar, davar
    from .theo import resolve_decimation
    from .grid import _check_count
    from .units import parse_unit

    progress = progress or _NoProgress()
    notes = list(notes)
    x = np.asarray(x) if not isinstance(x, np.ndarray) else x
    if x.ndim == 1:
        x = x[:, None]
    unit_name = None if unit is None else parse_unit(unit, kind="rate" if input == "rate" else "angle").name
    if unit_name is None:
        notes.append("The unit of the samples is unknown (not given): Allan deviations are in the "
                     "samples' own unit and the noise coefficients in base form, without IEEE-952 conversion.")
    n_axes = x.shape[1]
    if axis_names is None:
        axis_names = [f"axis {k}" for k in range(n_axes)]
    axis_names = [str(a) for a in axis_names]
    if len(axis_names) != n_axes:
        raise ParameterError(f"axis_names has {len(axis_names)} names for {n_axes} axes")
    taus = _check_taus(taus)
    check_choice(estimator, "estimator", tuple(REPORT_ESTIMATORS))
    static_est, dynamic_est, dynamic_grid = REPORT_ESTIMATORS[estimator][:3]

    progress.step("static Allan deviation")
    extra = {"decimate": "auto"} if static_est == "theoh" else {}
    static = avar(x, fs, input=input, taus=taus, estimator=static_est, **extra)
    progress.step("confidence intervals")
    static = static.with_confidence(x, confidence=confidence)

    n = static.n_samples
    window_given, hop_given = window is not None, hop is not None
    if window is None:
        window = default_window(n)
        if estimator == "theoh":
            window = min(window, DHVAR_MAX_DEFAULT_WINDOW)
    else:
        window = _check_count(window, "window", 2)
    if hop is None:
        hop = default_hop(window)
        if estimator == "theoh":
            # every DHVAR window gets its own fit: keep it to about DHVAR_MAX_WINDOWS of them
            hop = max(hop, -(-(n - window) // DHVAR_MAX_WINDOWS))
    progress.step("dynamic Allan variance")
    dynamic = davar(x, fs, window=window, hop=hop, taus=dynamic_grid, input=input, estimator=dynamic_est)
    settings = {"window": int(dynamic.window), "hop": int(dynamic.hop), "window_default": not window_given,
                "hop_default": not hop_given, "taus": taus if isinstance(taus, str) else "explicit",
                "estimator": estimator, "dynamic_grid": dynamic_grid,
                "theo_decimation": (resolve_decimation("auto", n, taus) if static_est == "theoh" else None)}

    fits = series = None
    fit_error = series_error = None
    if fit:
        from .fit import fit as fit_model

        progress.step("noise-model fit")
        try:
            # tau_range="auto": a real sensor's shortest τ (anti-alias filter, vibration lines) are often not
            # the model's; they would dominate the fit and give wrong coefficients. The cut is stated.
            fits = fit_model(static, unit=unit_name, confidence=confidence, tau_range="auto")
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
                import dataclasses

                per_axis = [dynamic.avar] if dynamic.avar.ndim == 2 else list(dynamic.avar)
                series = [fit_model(dataclasses.replace(dynamic, avar=row), unit=unit_name, confidence=confidence,
                                    tau_range=(float(f.tau[0]) * (1 - 1e-9), None))
                          for row, f in zip(per_axis, fits)]
                if dynamic.avar.ndim == 2:
                    series = series[0]
            else:
                series = fit_model(dynamic, unit=unit_name, confidence=confidence, tau_range="auto")
        except AllaniteError as exc:
            series_error = str(exc)
            notes.append(f"The coefficients over time could not be fitted (DAVAR window of {dynamic.window} "
                         f"samples): {exc}")
    else:
        progress.add(2)

    refinements = None
    if refine:
        from .refine import refine as refine_axis

        progress.step("model refinement")
        refinements = []
        # the same τ range the whole-record fit used (none unless given): start at 0.1 s when the
        # shortest τ are below it, as real gyros' anti-alias filters colour them
        t0 = 0.1 if static.tau[0] < 0.1 else None
        for k in range(n_axes):
            try:
                refinements.append(refine_axis(np.asarray(x[:, k], dtype=np.float64), fs, input=input,
                                               unit=unit_name, tau_range=None if t0 is None else (t0, None)))
            except AllaniteError as exc:
                refinements.append(None)
                notes.append(f"Model refinement of {axis_names[k]} failed: {exc}")
    created = _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat()
    return Report(refinements=refinements, static=static, dynamic=dynamic, fits=fits, series=series, fs=float(static.fs), unit=unit_name,
                  input=input, axis_names=axis_names, source=dict(source or {}), settings=settings, notes=notes,
                  fit_requested=bool(fit), fit_error=fit_error, series_error=series_error, created=created)


def _refinement_dict(rep) -> dict | None:
    if rep.refinements is None:
        return None
    axes = []
    for k, r in enumerate(rep.refinements):
        if r is None:
            axes.append({"axis": k, "name": rep.axis_names[k], "error": True})
            continue
        s0 = r.start
        axes.append({
            "axis": k, "name": rep.axis_names[k], "terms": list(r.terms),
            "tau_from_s": _num(s0.tau[0]),
            "start": {"chi2_dof": _num(s0.chi2_dof), "rms_z": _num(np.sqrt(np.mean(s0.z ** 2)))},
            "final": {"chi2_dof": _num(r.fit.chi2_dof)},
            "steps": [{"effect": st.effect, "params": {p: _num(v) for p, v in st.params.items()},
                       "intervals": {p: [_num(a), _num(b)] for p, (a, b) in st.intervals.items()},
                       "before": {q: _num(v) for q, v in st.before.items()},
                       "after": {q: _num(v) for q, v in st.after.items()}} for st in r.steps],
        })
    return {"method": "allanite.refine: Gauss–Markov / sinusoid signatures and change points, added by BIC on an "
                      "effective χ²; params in the rate unit (σ, amplitude), s (tc, t), Hz (f0)", "axes": axes}


def log_source(log) -> dict:
    """JSON-able description of a :class:`~allanite.Log` for the report's Record section."""
    src = {
        "name": log.path.name, "path": str(log.path), "format": log.format, "columns": list(log.columns),
        "fs_hz": float(log.fs), "fs_from": "time column" if log.time is not None else "given",
        "unit": log.unit.name if log.unit is not None else None, "input": log.input,
        "t0_s": _num(log.t0), "samples_in_file": int(log.n_record),
        "kept": [int(log.span[0]), int(log.span[1])],
        "gaps": [{"after_sample": g.index - 1, "time_s": g.time, "duration_s": g.duration, "missing_samples": g.missing}
                 for g in log.gaps],
        "jitter": _num(log.jitter),
    }
    if log.segment_spans is not None:
        src["segments"] = [[int(a), int(b)] for a, b in log.segment_spans]
    return src


def from_log(log, **kwargs) -> Report:
    """:func:`build_report` on a :class:`~allanite.Log` from :func:`allanite.read_log` (its unit,
    input kind, column names and reading notes)."""
    notes = list(kwargs.pop("notes", ()))
    if log.gaps:
        notes.append(f"The log has {len(log.gaps)} gap(s); only the longest gap-free stretch, samples "
                     f"{log.span[0]}–{log.span[1] - 1} of {log.n_record}, is analysed"
                     + (f" (all {len(log.segment_spans)} stretches are listed in summary.json)."
                        if log.segment_spans is not None else "."))
    unit = kwargs.pop("unit", None) or (log.unit.name if log.unit is not None else None)
    return build_report(log.data, log.fs, unit=unit, input=log.input, axis_names=list(log.columns),
                        source=log_source(log), notes=notes, **kwargs)


# --------------------------------------------------------------------------------------------------
# summary


def _coef_dict(c, unit, name) -> dict:
    from .units import ieee952

    d = {"name": _TERM_NAMES[name], "value": _num(c.value), "ci": [_num(c.ci[0]), _num(c.ci[1])],
         "unit": c.unit, "ieee": _num(c.ieee),
         "ieee_ci": None if c.ieee_ci is None else [_num(c.ieee_ci[0]), _num(c.ieee_ci[1])],
         "ieee_unit": c.ieee_unit}
    if name == "Q" and unit is not None:
        q = ieee952("Q", c.value, unit, to="urad")
        d["also"] = {"value": _num(q.value), "ci": [_num(ieee952("Q", c.ci[0], unit, to="urad").value),
                                                     _num(ieee952("Q", c.ci[1], unit, to="urad").value)],
                     "unit": q.unit}
    return d


def _readoffs(f, unit, adev_unit) -> dict:
    from .units import ieee952

    r = f.readoffs
    out = {
        "adev_at_1s": _num(r["adev_at_1s"]), "adev_at_1s_interpolated": r["adev_at_1s_interpolated"],
        "adev_min": _num(r["adev_min"]), "tau_at_min_s": _num(r["tau_at_min"]),
        "bias_instability_readoff": _num(r["bias_instability_readoff"]), "adev_unit": adev_unit,
    }
    if unit is not None:
        n_ro = ieee952("N", r["adev_at_1s"], unit) if r["adev_at_1s"] is not None else None
        b_ro = ieee952("B", r["bias_instability_readoff"], unit)
        out["arw_readoff_ieee"] = None if n_ro is None else _num(n_ro.value)
        out["arw_readoff_ieee_unit"] = ieee952("N", 1.0, unit).unit
        out["bias_instability_readoff_ieee"] = _num(b_ro.value)
        out["bias_instability_readoff_ieee_unit"] = b_ro.unit
    return out


def _series_dict(s, unit) -> dict:
    from .fit import _base_unit
    from .units import ieee952

    coeffs = {}
    for t in s.terms:
        v, lo, hi = s.values[t], s.ci_low[t], s.ci_high[t]
        d = {"name": _TERM_NAMES[t], "unit": _base_unit(t, unit) if unit is not None else None,
             "value": _list(v), "ci_low": _list(lo), "ci_high": _list(hi)}
        show, show_unit = v, d["unit"]
        if unit is not None:
            ie = ieee952(t, v, unit)
            show, show_unit = np.asarray(ie.value), ie.unit
            d.update(ieee_unit=ie.unit, ieee=_list(show), ieee_ci_low=_list(ieee952(t, lo, unit).value),
                     ieee_ci_high=_list(ieee952(t, hi, unit).value))
        j_max, j_min = int(np.argmax(show)), int(np.argmin(show))
        d["stats"] = {"median": _num(np.median(show)), "min": _num(show[j_min]), "t_of_min_s": _num(s.t[j_min]),
                      "max": _num(show[j_max]), "t_of_max_s": _num(s.t[j_max]), "unit": show_unit,
                      "windows_nonzero": int(np.count_nonzero(v > 0))}
        coeffs[t] = d
    return {"t_s": _list(s.t), "chi2_dof": _list(s.chi2_dof), "coefficients": coeffs}


def _summary(rep: Report) -> dict:
    from . import __version__

    st, dy = rep.static, rep.dynamic
    adev = np.atleast_2d(st.adev)
    lo, hi = (np.atleast_2d(a) for a in st.adev_ci)
    fs = rep.fs
    n = st.n_samples
    au = rep.adev_unit
    record = {
        "name": rep.source.get("name", "record"), "samples": n, "axes": rep.n_axes, "axis_names": rep.axis_names,
        "fs_hz": fs, "duration_s": n / fs, "unit": rep.unit, "unit_known": rep.unit is not None,
        "adev_unit": au, "input": rep.input, "source": rep.source,
    }
    static = {
        "estimator": st.estimator, "grid": rep.settings["taus"], "confidence": st.confidence,
        "edf_method": "greenhall" if st.source is None else "greenhall (Allan τ), Howe's Theo1 EDF (TheoBR τ)",
        "tau_s": _list(st.tau), "m": _list(st.m), "n": _list(st.n),
        "source": None if st.source is None else [str(v) for v in st.source],
        "kf": None if st.kf is None else _list(np.atleast_1d(st.kf)),
        "theo_decimation": rep.settings.get("theo_decimation"),
        "adev_unit": au, "adev": _list(adev), "adev_ci_low": _list(lo), "adev_ci_high": _list(hi),
        "edf": _list(np.atleast_2d(st.edf)), "alpha": _list(np.atleast_2d(st.alpha)),
    }
    d_axes = []
    for k in range(rep.n_axes):
        av = dy.avar[k]
        row = np.sqrt(av[0])
        med = float(np.median(row))
        j_max, j_min = int(np.argmax(row)), int(np.argmin(row))
        d_axes.append({
            "axis": k, "name": rep.axis_names[k], "tau_s": _num(dy.tau[0]),
            "adev_shortest_tau_median": med,
            "adev_shortest_tau_max": float(row[j_max]), "t_of_max_s": float(dy.t[j_max]),
            "adev_shortest_tau_min": float(row[j_min]), "t_of_min_s": float(dy.t[j_min]),
            "max_over_min": _num(row[j_max] / row[j_min]) if row[j_min] > 0 else None,
            "adev_median_over_time": _list(np.sqrt(np.median(av, axis=1))),
            "adev_min_over_time": _list(np.sqrt(av.min(axis=1))),
            "adev_max_over_time": _list(np.sqrt(av.max(axis=1))),
        })
    dynamic = {
        "method": dy.method, "estimator": dy.estimator, "grid": rep.settings.get("dynamic_grid", "exp"),
        "source": None if dy.source is None else [str(v) for v in dy.source],
        "kf_median": None if dy.kf is None else _list(np.median(np.atleast_2d(dy.kf), axis=1)),
        "window_samples": int(dy.window), "hop_samples": int(dy.hop), "window_s": dy.window / fs,
        "hop_s": dy.hop / fs,
        "window_rule": f"record/{WINDOW_FRACTION}" if rep.settings["window_default"] else "given",
        "hop_rule": f"window/{HOP_FRACTION}" if rep.settings["hop_default"] else "given",
        "windows": int(dy.t.size), "tau_s": _list(dy.tau), "t_s": _list(dy.t), "adev_unit": au,
        "axes": d_axes,
    }
    fit = {"requested": rep.fit_requested, "model": FIT_MODEL, "unit": rep.unit, "unit_known": rep.unit is not None,
           "confidence": st.confidence if rep.fit_requested else None, "error": rep.fit_error, "axes": None,
           "series": None}
    if rep.fits is not None:
        f0 = rep.fits[0]
        fit["terms"] = list(f0.terms)
        fit["confidence"] = f0.confidence
        fit["axes"] = [{
            "axis": k, "name": rep.axis_names[k],
            "coefficients": {t: _coef_dict(f.coefficients[t], rep.unit, t) for t in f.terms},
            "chi2": _num(f.chi2), "dof": int(f.dof), "chi2_dof": _num(f.chi2_dof), "p_value": _num(f.p_value),
            "tau_s": _list(f.tau), "iterations": int(f.iterations), "method": f.method, "notes": list(f.notes),
            "readoffs": _readoffs(f, rep.unit, au),
        } for k, f in enumerate(rep.fits)]
    if rep.fit_requested:
        ser = {"error": rep.series_error, "axes": None}
        if rep.series is not None:
            ser["terms"] = list(rep.series[0].terms)
            ser["confidence"] = rep.series[0].confidence
            ser["window_samples"] = int(dy.window)
            ser["hop_samples"] = int(dy.hop)
            ser["axes"] = [dict(axis=k, name=rep.axis_names[k], **_series_dict(s, rep.unit))
                           for k, s in enumerate(rep.series)]
        fit["series"] = ser
    return {
        "schema": "allanite-report/1", "allanite_version": __version__, "created": rep.created,
        "unit": rep.unit, "fs_hz": fs, "samples": n, "axes": rep.n_axes,
        "record": record, "notes": list(rep.notes), "static": static, "dynamic": dynamic, "fit": fit,
        "refinement": _refinement_dict(rep),
        "conventions": "times and τ in s (keys ending _s), fs in Hz; Allan deviations in adev_unit (the samples' "
                       "rate unit); coefficients: value/ci in base form ('unit'), ieee/ieee_ci in IEEE-952 units "
                       "('ieee_unit'); intervals at 'confidence'; null = does not exist (unknown unit, unbounded "
                       "interval, read-off outside the τ range)",
    }


# --------------------------------------------------------------------------------------------------
# text


def _g(v, d: int = 4) -> str:
    if v is None:
        return "—"
    if isinstance(v, float) and math.isinf(v):
        return "∞"
    return f"{v:.{d}g}"


def _pct(v, b) -> str:
    if v is None or b is None or v == 0:
        return "?"
    p = abs(b / v - 1.0) * 100.0
    return f"{p:.1f}" if p < 9.95 else f"{p:.0f}"


def _duration(s: float) -> str:
    if s >= 3600:
        return f"{s / 3600:.3g} h"
    if s >= 60:
        return f"{s / 60:.3g} min"
    return f"{s:.4g} s"


def _text(s: dict) -> str:
    rec, st, dy, fit = s["record"], s["static"], s["dynamic"], s["fit"]
    names = rec["axis_names"]
    au = rec["adev_unit"] or "samples' unit"
    lines = [f"allanite report: {rec['name']}",
             f"  {rec['samples']} samples × {rec['axes']} axes ({', '.join(names)}) at {rec['fs_hz']:g} Hz = "
             f"{_duration(rec['duration_s'])}; unit {rec['unit'] or 'unknown (give --unit)'}, {rec['input']} input"]
    for note in s["notes"]:
        lines.append(f"  note: {note}")
    conf = st["confidence"]
    lines += ["", f"Overlapping Allan deviation ({au}), {conf:.1%} interval as −/+ % of the value"]
    w = 27
    lines.append(f"  {'tau (s)':>9} {'n':>10}  " + "".join(f"{nm[:w - 1]:<{w}}" for nm in names).rstrip())
    for i, tau in enumerate(st["tau_s"]):
        cells = []
        for k in range(len(names)):
            v, lo, hi = st["adev"][k][i], st["adev_ci_low"][k][i], st["adev_ci_high"][k][i]
            cells.append(f"{_g(v):>10} (−{_pct(v, lo)}/+{_pct(v, hi)} %)".ljust(w))
        lines.append(f"  {tau:>9.4g} {st['n'][i]:>10}  " + "".join(cells).rstrip())

    if fit["axes"] is not None:
        ieee = fit["unit_known"]
        lines += ["", f"Noise model (IEEE 952) {'in IEEE-952 units' if ieee else 'in base form (unit unknown)'}, "
                      f"{fit['confidence']:.1%} intervals", f"  {fit['model']}"]
        w2 = 26
        lines.append(f"  {'term':<25}{'unit':<10}" + "".join(f"{nm[:w2 - 1]:<{w2}}" for nm in names).rstrip())
        for t in fit["terms"]:
            c0 = fit["axes"][0]["coefficients"][t]
            unit = (c0["ieee_unit"] if ieee else c0["unit"]) or ""
            cells = []
            for ax in fit["axes"]:
                c = ax["coefficients"][t]
                v, ci = (c["ieee"], c["ieee_ci"]) if ieee else (c["value"], c["ci"])
                cells.append(f"{_g(v, 3)} [{_g(ci[0], 3)}, {_g(ci[1] if ci[1] is not None else math.inf, 3)}]"
                             .ljust(w2))
            lines.append(f"  {t + ' ' + c0['name']:<25}{unit:<10}" + "".join(cells).rstrip())
        lines.append(f"  {'χ²/dof':<25}{'':<10}" + "".join(f"{_g(ax['chi2_dof'], 3):<{w2}}" for ax in fit["axes"])
                     .rstrip())
        ro = [ax["readoffs"] for ax in fit["axes"]]
        if ieee:
            lines.append(f"  {'read-off N = σ(1 s)':<25}{ro[0]['arw_readoff_ieee_unit']:<10}"
                         + "".join(f"{_g(r['arw_readoff_ieee'], 3):<{w2}}" for r in ro).rstrip())
            lines.append(f"  {'read-off B = σmin/0.664':<25}{ro[0]['bias_instability_readoff_ieee_unit']:<10}"
                         + "".join(f"{_g(r['bias_instability_readoff_ieee'], 3):<{w2}}" for r in ro).rstrip())
        lines.append(f"  {'σmin (at τ)':<25}{rec['adev_unit'] or '':<10}"
                     + "".join(f"{_g(r['adev_min'], 3) + ' (' + _g(r['tau_at_min_s'], 3) + ' s)':<{w2}}"
                               for r in ro).rstrip())
    elif fit["requested"] and fit["error"]:
        lines += ["", f"Noise model: not fitted ({fit['error']})"]

    lines += ["", f"Dynamic Allan deviation: window {dy['window_samples']} samples ({_g(dy['window_s'])} s, "
                  f"{dy['window_rule']}), hop {dy['hop_samples']} ({_g(dy['hop_s'])} s, {dy['hop_rule']}); "
                  f"{dy['windows']} windows × {len(dy['tau_s'])} τ ({_g(dy['tau_s'][0])}–{_g(dy['tau_s'][-1])} s)"]
    for ax in dy["axes"]:
        ratio = _g(ax["max_over_min"], 3)
        lines.append(f"  {ax['name']}: ADEV at τ = {_g(ax['tau_s'])} s over time: median "
                     f"{_g(ax['adev_shortest_tau_median'])}, max {_g(ax['adev_shortest_tau_max'])} at t = "
                     f"{ax['t_of_max_s']:.0f} s, min {_g(ax['adev_shortest_tau_min'])} at t = "
                     f"{ax['t_of_min_s']:.0f} s, max/min = {ratio}")
    ser = fit.get("series")
    if ser and ser["axes"] is not None:
        lines.append(f"  noise coefficients over the windows, median [min, max]"
                     f"{' in IEEE-952 units' if fit['unit_known'] else ' (base form)'}:")
        for ax in ser["axes"]:
            parts = []
            for t, c in ax["coefficients"].items():
                if c["stats"]["windows_nonzero"] == 0:
                    continue
                st_ = c["stats"]
                parts.append(f"{t} {_g(st_['median'], 3)} [{_g(st_['min'], 3)}, {_g(st_['max'], 3)}]"
                             f"{' ' + st_['unit'] if st_['unit'] else ''}")
            lines.append(f"    {ax['name']}: " + ("; ".join(parts) or "all zero"))
    elif ser and ser["error"]:
        lines.append(f"  noise coefficients over time: not fitted ({ser['error']})")
    return "\n".join(lines)


# --------------------------------------------------------------------------------------------------
# figures


def _figure_specs(rep: Report) -> list:
    from .plot import plot_adev, plot_coefficient_series, plot_davar, plot_davar3d, plot_fit

    st, dy, unit, names = rep.static, rep.dynamic, rep.unit, rep.axis_names
    specs = []
    conf = f"{st.confidence:.1%}"
    theoh = st.source is not None
    static_word = "TheoH deviation" if theoh else "Overlapping Allan deviation"
    dynamic_word = "Dynamic TheoH deviation (DHVAR)" if theoh else "Dynamic Allan deviation"
    static_lower = "TheoH deviation" if theoh else "Allan deviation"
    dynamic_lower = "dynamic TheoH deviation (DHVAR)" if theoh else "dynamic Allan deviation"

    def overview(fig):
        ax = fig.add_subplot()
        plot_adev(st, ax=ax, unit=unit, labels=names)
        if rep.fits is not None:
            for k, f in enumerate(rep.fits):
                plot_fit(f, ax=ax, unit=unit, tau=st.tau, points=False, terms=False,
                         color=f"C{k % 10}", label=f"{names[k]} fit", lw=1.0)
        ax.set_title(f"{static_word}, {conf} intervals" + (" and fits" if rep.fits else ""))
        fig.subplots_adjust(left=0.11, right=0.975, bottom=0.11, top=0.93)

    specs.append(("adev.png", "Allan deviation, all axes", f"Overlapping ADEV of every axis with its {conf} "
                  "interval band" + (" and fitted model." if rep.fits else "."), (7.2, 4.8), overview))

    def davar_all(fig):
        axs = fig.subplots(rep.n_axes, 1, squeeze=False)
        for k in range(rep.n_axes):
            plot_davar(dy, ax=axs[k, 0], axis=k, unit=unit)
            axs[k, 0].set_title(f"{dynamic_word}, {names[k]}")
        fig.subplots_adjust(left=0.1, right=1.0, bottom=0.45 / fig.get_figheight(), top=1 - 0.35 / fig.get_figheight(),
                            hspace=0.55)

    specs.append(("davar.png", "Dynamic Allan deviation, all axes", "DAVAR heat maps, one panel per axis.",
                  (7.5, 2.7 * rep.n_axes + 0.3), davar_all))

    for k in range(rep.n_axes):
        def adev_k(fig, k=k):
            ax = fig.add_subplot()
            plot_adev(st, ax=ax, unit=unit, labels=names, axis=k)
            if rep.fits is not None:
                plot_fit(rep.fits[k], ax=ax, unit=unit, tau=st.tau, points=False, color="k")
            ax.set_title(f"{names[k]}: {static_lower}" + (" and noise model" if rep.fits else ""))
            fig.subplots_adjust(left=0.11, right=0.975, bottom=0.11, top=0.93)

        def davar_k(fig, k=k):
            ax = fig.add_subplot()
            plot_davar(dy, ax=ax, axis=k, unit=unit)
            ax.set_title(f"{names[k]}: {dynamic_lower} (window {dy.window / rep.fs:g} s)")
            fig.subplots_adjust(left=0.1, right=1.0, bottom=0.12, top=0.92)

        def davar3d_k(fig, k=k):
            ax = fig.add_subplot(projection="3d")
            plot_davar3d(dy, ax=ax, axis=k, unit=unit)
            ax.set_title(f"{names[k]}: {dynamic_lower}")
            fig.subplots_adjust(left=0.0, right=0.95, bottom=0.05, top=0.95)

        specs.append((f"adev_axis{k}.png", f"{names[k]}: Allan deviation",
                      f"ADEV of {names[k]} with its {conf} interval band"
                      + ("; fitted model (black) and each term (dashed)." if rep.fits else "."), (7.2, 4.8), adev_k))
        specs.append((f"davar_axis{k}.png", f"{names[k]}: DAVAR heat map",
                      "ADEV of every window: window centre on x, τ on y, log colour.", (7.5, 4.2), davar_k))
        specs.append((f"davar3d_axis{k}.png", f"{names[k]}: DAVAR surface",
                      "The same as a surface (t, log₁₀ τ, log₁₀ ADEV), drawn on a thinned grid.", (7.5, 5.6),
                      davar3d_k))
        if rep.series is not None:
            s = rep.series[k]
            n_panels = len([t for t in s.terms if np.any(s.values[t] > 0)] or s.terms)

            def coef_k(fig, k=k, s=s, n_panels=n_panels):
                axs = fig.subplots(n_panels, 1, sharex=True, squeeze=False)[:, 0]
                plot_coefficient_series(s, axes=axs, reference=rep.fits[k] if rep.fits else None)
                axs[0].set_title(f"{names[k]}: noise coefficients per DAVAR window, {s.confidence:.1%} intervals")
                fig.subplots_adjust(left=0.13, right=0.975, bottom=0.5 / fig.get_figheight(),
                                    top=1 - 0.35 / fig.get_figheight(), hspace=0.12)

            specs.append((f"coefficients_axis{k}.png", f"{names[k]}: coefficients over time",
                          "Coefficients fitted in every DAVAR window (non-zero terms), with interval bands; "
                          "dotted: the whole-record value.", (7.5, 1.2 + 1.7 * n_panels), coef_k))
    return specs


# --------------------------------------------------------------------------------------------------
# HTML

_CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,Helvetica,Arial,sans-serif;margin:0 auto;
max-width:1100px;padding:1em 1.5em;color:#1b1b1b;line-height:1.45}
h1{font-size:1.6em;margin-bottom:.1em}h2{border-bottom:2px solid #ddd;padding-bottom:.2em;margin-top:1.6em}
h3{margin-bottom:.3em}.sub{color:#555;margin-top:0}nav a{margin-right:1em}
table{border-collapse:collapse;margin:.6em 0;font-size:.9em}
th,td{border:1px solid #ddd;padding:.25em .6em;text-align:right;font-variant-numeric:tabular-nums}
th{background:#f3f3f3}td.l,th.l{text-align:left}
figure{margin:.8em 0;display:inline-block;vertical-align:top;max-width:100%}
figure img{max-width:100%;height:auto;border:1px solid #eee}
figcaption{font-size:.85em;color:#555;max-width:720px}
.note{background:#fff7e0;border-left:4px solid #e0a800;padding:.4em .8em;margin:.4em 0}
.pair figure{max-width:49%}code{background:#f3f3f3;padding:0 .2em}
footer{margin-top:2em;color:#777;font-size:.85em}
"""


def _e(s) -> str:
    return _html.escape(str(s), quote=True)


def _table(header, rows, left=1) -> str:
    h = "".join(f"<th class=\"l\">{_e(c)}</th>" if i < left else f"<th>{_e(c)}</th>" for i, c in enumerate(header))
    body = []
    for r in rows:
        body.append("<tr>" + "".join(f"<td class=\"l\">{_e(c)}</td>" if i < left else f"<td>{_e(c)}</td>"
                                     for i, c in enumerate(r)) + "</tr>")
    return f"<table><thead><tr>{h}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def _img(images, specs_by_name, name) -> str:
    if name not in images:
        return ""
    _, title, caption, _, _ = specs_by_name[name]
    data = base64.b64encode(images[name]).decode("ascii")
    return (f"<figure><img src=\"data:image/png;base64,{data}\" alt=\"{_e(title)}\">"
            f"<figcaption>{_e(caption)} <code>{_e(name)}</code></figcaption></figure>")


def _html_page(rep: Report, images: dict) -> str:
    from . import __version__

    s = rep.summary()
    specs = {sp[0]: sp for sp in rep.figure_specs()}
    rec, st, dy, fit = s["record"], s["static"], s["dynamic"], s["fit"]
    names = rec["axis_names"]
    au = rec["adev_unit"] or "samples' unit"
    out = []
    out.append(f"<header><h1>Allan variance report — {_e(rec['name'])}</h1>"
               f"<p class=\"sub\">allanite {_e(__version__)} · {_e(s['created'])}</p></header>")
    out.append("<nav><a href=\"#record\">Record</a><a href=\"#static\">Allan deviation</a>"
               "<a href=\"#model\">Noise model</a><a href=\"#davar\">Dynamic Allan variance</a>"
               "<a href=\"#series\">Coefficients over time</a></nav>")

    # record
    src = rec["source"]
    rows = [("samples per axis", rec["samples"]), ("axes", f"{rec['axes']} ({', '.join(names)})"),
            ("sampling rate", f"{rec['fs_hz']:g} Hz"), ("duration", f"{_g(rec['duration_s'], 6)} s "
                                                        f"({_duration(rec['duration_s'])})"),
            ("unit", rec["unit"] or "unknown"), ("input", rec["input"])]
    for key, label in (("path", "file"), ("format", "format"), ("what", "description"), ("fs_from", "fs from"),
                       ("samples_in_file", "samples in file"), ("seed", "seed")):
        if src.get(key) is not None:
            rows.append((label, src[key]))
    if src.get("gaps"):
        rows.append(("gaps", "; ".join(f"{g['duration_s']:.6g} s after sample {g['after_sample']}"
                                       for g in src["gaps"][:10]) + (" …" if len(src["gaps"]) > 10 else "")))
    out.append("<section id=\"record\"><h2>Record</h2>" + _table(("", ""), rows, left=1))
    for note in s["notes"]:
        out.append(f"<p class=\"note\">{_e(note)}</p>")
    out.append("</section>")

    # static
    conf = st["confidence"]
    theoh = st["source"] is not None
    titles = REPORT_ESTIMATORS["theoh" if theoh else "oavar"][3:]
    edf_words = ("Greenhall's equivalent degrees of freedom (ν) at Allan τ and Howe's Theo1 ν at TheoBR τ "
                 f"(bias ratio kf = {', '.join(_g(k) for k in st['kf'])}; TheoBR values belong to τ = 0.75·m/fs"
                 + (f"; TheoBR and kf from block averages of {st['theo_decimation']} samples — Taylor & Howe's "
                    "fast TheoBR — as Theo1 of the full record would cost O(N²)"
                    if (st.get("theo_decimation") or 1) > 1 else "") + ")"
                 if theoh else "Greenhall's equivalent degrees of freedom (ν)")
    out.append(f"<section id=\"static\"><h2>{_e(titles[0])}</h2>"
               f"<p>Estimator <code>{_e(st['estimator'])}</code> on the <code>{_e(st['grid'])}</code> τ grid; "
               f"{conf:.1%} χ² intervals with {edf_words} for the noise type "
               f"identified at each τ. ADEV in {_e(au)}.</p>")
    out.append(_img(images, specs, "adev.png"))
    header = ["τ (s)", "n"] + [h for nm in names for h in (f"{nm} ADEV", "interval", "ν")]
    rows = []
    for i, tau in enumerate(st["tau_s"]):
        r = [_g(tau), st["n"][i]]
        for k in range(len(names)):
            lo, hi = st["adev_ci_low"][k][i], st["adev_ci_high"][k][i]
            r += [_g(st["adev"][k][i]), f"[{_g(lo)}, {_g(hi)}]", _g(st["edf"][k][i], 3)]
        rows.append(r)
    out.append(_table(header, rows, left=0) + "</section>")

    # model
    out.append("<section id=\"model\"><h2>Noise model (IEEE Std 952)</h2>")
    if fit["axes"] is not None:
        ieee = fit["unit_known"]
        out.append(f"<p>Weighted non-negative least squares in variance space, iteratively reweighted, on "
                   f"octave-spaced τ: <code>{_e(fit['model'])}</code>. {fit['confidence']:.1%} intervals. "
                   + ("Coefficients in IEEE-952 units; base form in the second table." if ieee else
                      "The unit is unknown, so coefficients are in base form (the samples' unit and seconds).")
                   + "</p>")
        if ieee:
            header = ["term", "unit"] + names
            rows = []
            for t in fit["terms"]:
                c0 = fit["axes"][0]["coefficients"][t]
                rows.append([f"{t} — {c0['name']}", c0["ieee_unit"]]
                            + [f"{_g(c['ieee'])} [{_g(c['ieee_ci'][0])}, {_g(c['ieee_ci'][1] if c['ieee_ci'][1] is not None else math.inf)}]"
                               for c in (ax["coefficients"][t] for ax in fit["axes"])])
                if "also" in c0:
                    rows.append([f"{t} — {c0['name']}", c0["also"]["unit"]]
                                + [f"{_g(c['also']['value'])} [{_g(c['also']['ci'][0])}, "
                                   f"{_g(c['also']['ci'][1] if c['also']['ci'][1] is not None else math.inf)}]"
                                   for c in (ax["coefficients"][t] for ax in fit["axes"])])
            out.append(_table(header, rows, left=2))
        header = ["term", "base unit"] + names
        rows = []
        for t in fit["terms"]:
            c0 = fit["axes"][0]["coefficients"][t]
            rows.append([f"{t} — {c0['name']}", c0["unit"] or "(samples' unit)·s^p"]
                        + [f"{_g(c['value'])} [{_g(c['ci'][0])}, {_g(c['ci'][1] if c['ci'][1] is not None else math.inf)}]"
                           for c in (ax["coefficients"][t] for ax in fit["axes"])])
        out.append(_table(header, rows, left=2))
        rows = [["χ²/dof"] + [_g(ax["chi2_dof"], 4) for ax in fit["axes"]],
                ["χ², dof"] + [f"{_g(ax['chi2'], 4)}, {ax['dof']}" for ax in fit["axes"]],
                ["p-value"] + [_g(ax["p_value"], 3) for ax in fit["axes"]],
                ["τ points fitted"] + [f"{len(ax['tau_s'])} ({_g(ax['tau_s'][0])}–{_g(ax['tau_s'][-1])} s)"
                                       for ax in fit["axes"]]]
        ro = [ax["readoffs"] for ax in fit["axes"]]
        rows.append([f"σ(1 s) ({au})"] + [_g(r["adev_at_1s"]) + (" (interpolated)" if r["adev_at_1s_interpolated"]
                                                                 else "") for r in ro])
        rows.append([f"σ minimum ({au}) at τ (s)"] + [f"{_g(r['adev_min'])} at {_g(r['tau_at_min_s'])}" for r in ro])
        rows.append([f"σmin/0.664 ({au})"] + [_g(r["bias_instability_readoff"]) for r in ro])
        if ieee:
            rows.append([f"read-off N = σ(1 s)·√1 s ({ro[0]['arw_readoff_ieee_unit']})"]
                        + [_g(r["arw_readoff_ieee"]) for r in ro])
            rows.append([f"read-off B = σmin/0.664 ({ro[0]['bias_instability_readoff_ieee_unit']})"]
                        + [_g(r["bias_instability_readoff_ieee"]) for r in ro])
        out.append("<h3>Goodness of fit and datasheet read-offs</h3>" + _table([""] + names, rows, left=1))
    elif not fit["requested"]:
        out.append("<p>Not fitted (<code>--no-fit</code>).</p>")
    else:
        out.append(f"<p class=\"note\">Not fitted: {_e(fit['error'])}</p>")
    out.append("<div>" + "".join(_img(images, specs, f"adev_axis{k}.png") for k in range(len(names))) + "</div>")
    out.append("</section>")

    # davar
    what = ("the static TheoH of its window (its own bias ratio kf and switch point)" if theoh
            else "the static overlapping Allan variance of its window")
    grid_words = "octave grid" if dy["grid"] == "octave" else "exponential grid"
    out.append(f"<section id=\"davar\"><h2>{_e(titles[1])}</h2><p>Window {dy['window_samples']} samples "
               f"({_g(dy['window_s'])} s, {_e(dy['window_rule'])}), hop {dy['hop_samples']} samples "
               f"({_g(dy['hop_s'])} s, {_e(dy['hop_rule'])}): {dy['windows']} windows × {len(dy['tau_s'])} τ "
               f"({_g(dy['tau_s'][0])}–{_g(dy['tau_s'][-1])} s, {grid_words}), method "
               f"<code>{_e(dy['method'])}</code>. Each column is exactly {what}.</p>")
    rows = [[ax["name"], _g(ax["tau_s"]), _g(ax["adev_shortest_tau_median"]),
             f"{_g(ax['adev_shortest_tau_max'])} at {ax['t_of_max_s']:.0f} s",
             f"{_g(ax['adev_shortest_tau_min'])} at {ax['t_of_min_s']:.0f} s", _g(ax["max_over_min"], 3)]
            for ax in dy["axes"]]
    out.append(_table(["axis", "τ (s)", f"median ADEV ({au})", "max at t", "min at t", "max/min"], rows, left=1))
    for k, nm in enumerate(names):
        out.append(f"<h3>{_e(nm)}</h3><div class=\"pair\">" + _img(images, specs, f"davar_axis{k}.png")
                   + _img(images, specs, f"davar3d_axis{k}.png") + "</div>")
    out.append("</section>")

    # series
    out.append("<section id=\"series\"><h2>Noise coefficients over time</h2>")
    ser = fit.get("series")
    if ser and ser["axes"] is not None:
        out.append(f"<p>The noise model fitted in every DAVAR window ({ser['confidence']:.1%} intervals) — paper "
                   f"002's 2-D representation. Median, minimum and maximum over the windows"
                   f"{', in IEEE-952 units' if fit['unit_known'] else ' (base form)'}:</p>")
        rows = []
        for ax in ser["axes"]:
            for t, c in ax["coefficients"].items():
                sc = c["stats"]
                rows.append([ax["name"], f"{t} — {c['name']}", sc["unit"] or "", _g(sc["median"]),
                             f"{_g(sc['min'])} at {_g(sc['t_of_min_s'])} s", f"{_g(sc['max'])} at {_g(sc['t_of_max_s'])} s",
                             f"{sc['windows_nonzero']}/{len(ax['t_s'])}"])
        out.append(_table(["axis", "term", "unit", "median", "min", "max", "windows > 0"], rows, left=3))
        out.append("<div>" + "".join(_img(images, specs, f"coefficients_axis{k}.png") for k in range(len(names)))
                   + "</div>")
    elif not fit["requested"]:
        out.append("<p>Not fitted (<code>--no-fit</code>).</p>")
    else:
        out.append(f"<p class=\"note\">Not fitted: {_e((ser or {}).get('error'))}</p>")
    out.append("</section>")
    ref = s.get("refinement")
    if ref is not None:
        out.append("<section id=\"refinement\"><h2>Model refinement</h2><p>What the five-term model lacks: "
                   "<code>allanite.refine</code> traced the residual to Gauss–Markov or sinusoid signatures in the "
                   "Allan curve, or to changes of level along the record (16 windows), and kept an effect only where it "
                   "earned its parameters (BIC on an effective χ²). Parameters: σ and amplitude in the rate unit, "
                   "T<sub>c</sub> and t in s, f0 in Hz; intervals ~68 %. Its χ²/dof weights each τ of a dense curve "
                   "independently, so it is not the fit table's χ²/dof (which accounts for the correlation between "
                   "τ).</p>")
        rows = []
        for ax in ref["axes"]:
            if ax.get("error"):
                rows.append([ax["name"], "failed", "", "", ""])
                continue
            if not ax["steps"]:
                rows.append([ax["name"], "nothing found", "", f"{_g(ax['start']['chi2_dof'], 3)}", ""])
            for st in ax["steps"]:
                params = "; ".join(f"{p} = {_g(v, 3)} [{_g(st['intervals'][p][0], 3)}, {_g(st['intervals'][p][1], 3)}]"
                                   for p, v in st["params"].items())
                rows.append([ax["name"], st["effect"], params,
                             f"{_g(st['before']['chi2_dof'], 3)} → {_g(st['after']['chi2_dof'], 3)}",
                             f"{_g(st['before']['rms_adev_pct'], 3)} → {_g(st['after']['rms_adev_pct'], 3)} %"])
        out.append(_table(["axis", "effect", "parameters", "χ²/dof before → after", "RMS ADEV error before → after"],
                          rows, left=3))
        out.append("</section>")
    out.append(f"<footer>Every number on this page is in <code>summary.json</code> beside it, with its unit. "
               f"Figures: {', '.join(_e(n) for n in images)}.</footer>")
    body = "\n".join(out)
    return (f"<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
            f"<title>allanite report — {_e(rec['name'])}</title><style>{_CSS}</style></head>\n<body>\n{body}\n"
            f"</body></html>\n")
