"""The report as numbers (``summary.json``) and as terminal text — one dictionary both are read from."""

from __future__ import annotations

import math

import numpy as np

from .._core import __version__
from ..estimators import get as get_estimator
from ..model.effects import EFFECTS, channel_units, param_units
from ..model.fitting import row_medians
from ..model.refinement.result import term_move_text
from ..model.refinement.words import describe_region
from ._fitsummary import fit_dict
from ._regression import channels_not_kept, regression_dict, regression_lines
from .fmt import CLOCK_TERMS, count, duration, g, json_list, json_number, json_value, pct, step_params
from .forecasting import forecast_dict, forecast_text
from .paper002 import text_lines as paper002_text
from .settings import NOTHING_ADDED
from .sidefiles import side_files_entry, uses_side_files

__all__ = ["summarize", "text_summary", "refinement_dict"]


def _fit_errors(f, r) -> dict:
    """χ²/dof, RMS z and RMS ADEV error (%, on the refinement's scored τ) of the start or final model on the
    record's curve: the chain's numbers (:meth:`Refinement.curve_errors`, the steps' first before / last after)."""
    return {k: json_number(v) for k, v in r.curve_errors(f).items()}


#: What each step's before → after is measured on (summary.json's refinement.statistics).
_STATISTICS = {
    "allan_curve": "every step's before/after, on the record's own Allan curve (a component removed in "
    "time is part of the model through what it changed in the curve, AVAR(y) − AVAR(y − component)), so "
    "that each step's before is the previous step's after: χ²/dof and RMS z of the Allan-curve fit by the "
    "calibrated tests' standard (the generalised least-squares χ² of the residual on ~4 τ per octave under "
    "the exact covariance of the estimates across τ; not the fit section's χ²/dof), RMS ADEV error (%) "
    "on 4 τ per octave whose estimate is "
    "within ±10 %; heldout_rms_adev_pct: the model fitted on alternate blocks (8, joined; removals refitted "
    "on them) predicting the other blocks' curve, both ways (null for curve-only input). A change of noise "
    "level leaves the curve's model as it is (before = after); a spectral line's amplitude and f0, measured "
    "in the samples, are held in every fit of the curve",
    "window_levels": "what found a change point (its step's window_levels): the log Allan variances of "
    "16 windows along the record about piecewise-constant levels without → with this change point (every "
    "other one in both); heldout_rms_adev_pct in it: held out per segment (each segment's alternate blocks "
    "predicted by its own held-in part's model), without → with it, the earlier ones in both (the first "
    "one's before is one level, each next one's before the previous one's after)",
}

#: What an axis's ``unexplained`` entries hold (summary.json's refinement.unexplained).
_UNEXPLAINED_WORDS = (
    "per axis, what the final model still misses, largest misfit first (empty when the final "
    "model passes every calibrated check of what it may still miss, each at its share of the axis's level): "
    "domain (allan, psd, time, level, channels, outliers), tau_s [lo, hi] in s, t_s [lo, hi] in s (the time "
    "region along the record, null where the entry has none), band_hz [lo, hi] in Hz (null where "
    "it has no band, or for curve-only input), chi2_dof of the dense Allan curve over that τ range (null "
    "where the evidence is not on the curve), what (in words), the check's statistic, threshold and alpha, "
    "and text (the entry in words); still_missing: the sentences the page and the console print"
)


def refinement_dict(rep) -> dict | None:
    """The refinement of every axis: the curve fit's errors at the start and at the end, and each step with its
    errors before → after on the record's Allan curve (each step's before is the previous step's after);
    ``statistic`` says what accepted it — the Allan curve, or for a change of level the Allan variances of
    windows along the record (a different χ² scale, its numbers under ``window_levels``)."""
    if rep.refinements is None:
        return None
    rate = rep.adev_unit or "rate unit"
    axes = [
        {"axis": k, "name": rep.axis_names[k], "error": True} if r is None else _axis_dict(k, r, rep, rate)
        for k, r in enumerate(rep.refinements)
    ]
    tried = rep.settings.get("refine_candidates", list(EFFECTS))
    curve = [e for e in EFFECTS.values() if e.kind == "curve" and e.name in tried]
    timed = [e for e in EFFECTS.values() if e.kind != "curve" and e.name in tried]
    return {
        "method": "allanite.refine: the residual traced on the Allan curve, in the PSD, along time and in other "
        "channels; an effect is added only if a calibrated test asks for it (GLS score with a bootstrap threshold, "
        "a χ² line test on the Welch PSD, a t test of a regression, a bootstrap of the drift statistic) and it "
        "lowers the held-out error (fit on the odd blocks of the record, predict the even ones, and back)",
        "candidates": _candidates_words(curve, timed),
        "tried": list(tried),
        "units": "; ".join(
            f"{e.name}: " + ", ".join(_param_words(p, u, m, rate) for p, u, m in e.params) for e in EFFECTS.values()
        ),
        "statistics": dict(_STATISTICS),
        "unexplained": _UNEXPLAINED_WORDS,
        "axes": axes,
    }


def _axis_dict(k: int, r, rep, rate: str) -> dict:
    """One refined axis of :func:`refinement_dict`: its terms, the start's and the final model's errors, each
    term's move, each step and what the final model still misses."""
    return {
        "axis": k,
        "name": rep.axis_names[k],
        "terms": list(r.terms),
        "tau_from_s": json_number(r.start.tau[0]),
        "tau_to_s": json_number(r.start.tau[-1]),
        "start": _fit_errors(r.start, r),
        "start_heldout_rms_adev_pct": json_number(r.start_heldout_rms_adev_pct),
        "heldout_note": r.heldout_note,
        "final": _fit_errors(r.fit, r),
        "final_heldout_rms_adev_pct": json_number(r.final_heldout_rms_adev_pct),
        "term_moves": [_term_move_dict(m, r.fit.unit) for m in r.term_moves],
        "steps": [_step_dict(st, rate) for st in r.steps],
        "level": json_number(r.level),
        "unexplained": [_region_dict(reg) for reg in r.unexplained],
        "still_missing": r.missing_sentences(),
        "channels_not_kept": [{k: json_value(v) for k, v in d.items()} for d in channels_not_kept(r)],
        # refine(filter=...): what was declared (type, rate_hz, decimation, taps or order, cutoff_hz, words), or null
        "declared_filter": None
        if getattr(r, "declared_filter", None) is None
        else {k: json_value(v) for k, v in r.declared_filter.items()},
    }


def _term_move_dict(m: dict, unit) -> dict:
    """One noise term's start → final value with its intervals, and the steps that moved it."""
    return {
        "term": m["term"],
        "start": json_number(m["start"]),
        "start_interval": json_value(m["start_interval"]),
        "final": json_number(m["final"]),
        "final_interval": json_value(m["final_interval"]),
        "moved_by": [{k: json_value(v) for k, v in mv.items()} for mv in m["moves"]],
        "text": term_move_text(m, unit),
    }


def _candidates_words(curve: list, timed: list) -> str:
    """The candidate effects tried, in words (the page's "traced the residual to …")."""
    words = ", or ".join(
        ([f"{' / '.join(e.label for e in curve)} signatures in the Allan curve"] if curve else [])
        + ([" or ".join(f"{e.label} along the record" for e in timed)] if timed else [])
    )
    return words or "no candidate effect (only what the five-term model still misses is checked)"


def _region_dict(reg: dict) -> dict:
    """One entry of ``Refinement.unexplained`` as JSON, units in the keys (τ in s, the band in Hz), in words."""
    return {
        "domain": reg.get("domain"),
        "tau_s": json_value(reg["tau"]),
        "t_s": json_value(reg.get("t")),
        "band_hz": json_value(reg.get("band_hz")),
        "chi2_dof": json_number(reg.get("chi2_dof")),
        "what": reg.get("what"),
        "statistic": json_number(reg.get("statistic")),
        "threshold": json_number(reg.get("threshold")),
        "alpha": json_number(reg.get("alpha")),
        "text": describe_region(reg),
    }


def _param_words(name: str, unit: str, meaning: str, rate: str) -> str:
    """ "sigma in °/s", or what a parameter without a unit is ("q (quality factor …)", "channel (name of …)")."""
    if unit:
        return f"{name} in {unit.replace('rate unit', rate)}"
    return f"{name} ({meaning.split(' (')[0]})"


def _step_dict(st, rate) -> dict:
    """One refinement step as JSON: its parameters at acceptance and after the final joint refit, with units
    and intervals; before/after on the record's Allan curve (each step's before the previous step's after);
    the test that accepted it; a change point's window-level statistic."""
    fp, fi = (st.final_params, st.final_intervals) if st.final_params else (st.params, st.intervals)
    out = {
        "effect": st.effect,
        "statistic": "window_levels" if st.effect == "change_point" else "allan_curve",
        "domain": EFFECTS[st.effect].domain if st.effect in EFFECTS else None,
        "params": {p: json_value(v) for p, v in st.params.items()},
        "final_params": {p: json_value(v) for p, v in fp.items()},
        "units": channel_units(param_units(st.effect, rate), st.params),
        "intervals": {p: json_value(iv) for p, iv in st.intervals.items()},
        "final_intervals": {p: json_value(iv) for p, iv in fi.items()},
        "before": {q: json_number(v) for q, v in st.before.items()},
        "after": {q: json_number(v) for q, v in st.after.items()},
        "test": _jsonable_test(st.evidence.get("test")),
    }
    reg = regression_dict(st.evidence) if st.effect == "regression" else None
    if reg is not None:
        out["regression"] = reg
    if "folded_into" in st.evidence:  # a periodic family's own line found again: its power is in the family's rms
        out["folded_into"] = st.evidence["folded_into"]["effect"]
    if "window_levels" in st.evidence:
        out["window_levels"] = {
            k: {q: json_number(v) for q, v in d.items()} for k, d in st.evidence["window_levels"].items()
        }
    return out


def _jsonable_test(t):
    if not isinstance(t, dict):
        return None
    return {k: json_number(v) for k, v in t.items()}


def _positions(st) -> np.ndarray:
    """Terms per estimate that the reader can compare with the record: Allan τ as counted by the estimator,
    Theo τ as the N − m positions of the Theo1 sum (the double sum's (N − m)·m/2 terms exceed the record)."""
    n = np.asarray(st.n, dtype=np.int64).copy()
    if st.source is not None:
        theo = np.array([get_estimator(str(s)).theo_tau for s in st.source])
        n[theo] = st.n_samples + 1 - np.asarray(st.m)[theo]
    return n


def summarize(rep) -> dict:
    """Every number of the report, JSON-able (``summary.json``)."""
    inline = not uses_side_files(rep)  # per-window lists in the JSON, or in the side files
    return {
        "schema": "allanite-report/1",
        "allanite_version": __version__,
        "created": rep.created,
        "unit": rep.unit,
        "fs_hz": rep.fs,
        "samples": rep.static.n_samples,
        "axes": rep.n_axes,
        "record": _record_dict(rep),
        "notes": list(rep.notes),
        "static": _static_dict(rep),
        "dynamic": _dynamic_dict(rep, inline),
        "fit": fit_dict(rep, inline),
        "refinement": refinement_dict(rep),
        "forecast": forecast_dict(rep),
        "paper002": getattr(rep, "paper002", None),
        "side_files": None if inline else side_files_entry(rep),
        "conventions": "times and τ in s (keys ending _s), fs in Hz; Allan deviations in adev_unit (the samples' "
        "rate unit); coefficients: value/ci in base form ('unit'), ieee/ieee_ci in IEEE-952 units "
        "('ieee_unit'; an accelerometer's report, fit.sensor 'accelerometer': its units, m/s/√h, µg, m/s/h^1.5); "
        "intervals at 'confidence'; null = does not exist (unknown unit, unbounded "
        "interval, read-off outside the τ range)",
    }


def _record_dict(rep) -> dict:
    """The record: its name, samples, axes, rate, unit and source, and how the analysis held it."""
    n = rep.static.n_samples
    return {
        "name": rep.source.get("name", "record"),
        "samples": n,
        "axes": rep.n_axes,
        "axis_names": rep.axis_names,
        "fs_hz": rep.fs,
        "duration_s": n / rep.fs,
        "unit": rep.unit,
        "unit_known": rep.unit is not None,
        "accel_unit": rep.accel_unit,
        "adev_unit": rep.adev_unit,
        "input": rep.input,
        "source": rep.source,
        # how the analysis held the record (report/axes.py) and the report's memory estimate (report/budget.py)
        "analysed_axis_by_axis": bool(rep.settings.get("by_axis", False)),
        "memory_estimate_bytes": rep.settings.get("memory_estimate_bytes"),
    }


def _static_dict(rep) -> dict:
    """The static analysis: the Allan deviation per τ and axis with its interval, EDF and noise type."""
    st = rep.static
    lo, hi = (np.atleast_2d(a) for a in st.adev_ci)
    return {
        "estimator": st.estimator,
        "grid": rep.settings["taus"],
        "confidence": st.confidence,
        "edf_method": "greenhall" if st.source is None else "greenhall (Allan τ), Howe's Theo1 EDF (TheoBR τ)",
        "tau_s": json_list(st.tau),
        "m": json_list(st.m),
        # n: squared differences averaged (Allan τ), or positions i of the Theo1 sum, N − m (Theo τ) — at most
        # the record. Stable32's "Thêo1 #" counts every term of the double sum, (N − m)·m/2: n_stable32.
        "n": json_list(_positions(st)),
        "n_stable32": json_list(st.n),
        "source": None if st.source is None else [str(v) for v in st.source],
        "kf": None if st.kf is None else json_list(np.atleast_1d(st.kf)),
        "theo_decimation": rep.settings.get("theo_decimation"),
        "adev_unit": rep.adev_unit,
        "adev": json_list(np.atleast_2d(st.adev)),
        "adev_ci_low": json_list(lo),
        "adev_ci_high": json_list(hi),
        "edf": json_list(np.atleast_2d(st.edf)),
        "alpha": json_list(np.atleast_2d(st.alpha)),
    }


def _dynamic_axis(rep, k: int) -> dict:
    """One axis of the dynamic analysis: its ADEV at the shortest τ over time, and per τ over the windows."""
    dy = rep.dynamic
    av = dy.avar[k]
    row = np.sqrt(av[0])
    med = float(np.median(row))
    j_max, j_min = int(np.argmax(row)), int(np.argmin(row))
    return {
        "axis": k,
        "name": rep.axis_names[k],
        "tau_s": json_number(dy.tau[0]),
        "adev_shortest_tau_median": med,
        "adev_shortest_tau_max": float(row[j_max]),
        "t_of_max_s": float(dy.t[j_max]),
        "adev_shortest_tau_min": float(row[j_min]),
        "t_of_min_s": float(dy.t[j_min]),
        "max_over_min": json_number(row[j_max] / row[j_min]) if row[j_min] > 0 else None,
        "adev_median_over_time": json_list(np.sqrt(row_medians(av))),
        "adev_min_over_time": json_list(np.sqrt(av.min(axis=1))),
        "adev_max_over_time": json_list(np.sqrt(av.max(axis=1))),
    }


def _dynamic_dict(rep, inline: bool) -> dict:
    """The dynamic analysis: the windows, their τ and times (``inline``, else in the side files), and per axis."""
    dy, fs, n = rep.dynamic, rep.fs, rep.static.n_samples
    return {
        "method": dy.method,
        "estimator": dy.estimator,
        "grid": rep.settings.get("dynamic_grid", "exp"),
        "source": None if dy.source is None else [str(v) for v in dy.source],
        "kf_median": None if dy.kf is None else json_list(np.median(np.atleast_2d(dy.kf), axis=1)),
        "window_samples": int(dy.window),
        "hop_samples": int(dy.hop),
        "window_s": dy.window / fs,
        "hop_s": dy.hop / fs,
        "window_rule": rep.settings["window_rule"],
        "hop_rule": rep.settings["hop_rule"],
        "unused_samples": int(n - ((dy.t.size - 1) * dy.hop + dy.window)),
        "windows": int(dy.t.size),
        "tau_s": json_list(dy.tau),
        "t_s": json_list(dy.t) if inline else None,
        "adev_unit": rep.adev_unit,
        "axes": [_dynamic_axis(rep, k) for k in range(rep.n_axes)],
    }


# --------------------------------------------------------------------------------------------------
# text


def text_summary(s: dict) -> str:
    """The terminal summary of a report's :func:`summarize` output."""
    rec = s["record"]
    lines = [
        f"allanite report: {rec['name']}",
        f"  {rec['samples']} samples × {count(rec['axes'], 'axis', 'axes')} ({', '.join(rec['axis_names'])}) at "
        f"{rec['fs_hz']:g} Hz = "
        f"{duration(rec['duration_s'])}; unit {_unit_words(rec)}, {rec['input']} input",
    ]
    for note in s["notes"]:
        lines.append(f"  note: {note}")
    lines += _adev_text(s)
    lines += _fit_text(s)
    lines += _dynamic_text(s)
    lines += _refinement_text(s)
    lines += forecast_text(s.get("forecast"))
    lines += paper002_text(s.get("paper002"))
    return "\n".join(lines)


def _unit_words(rec: dict) -> str:
    """The record's unit as the summary's first lines say it: a gyro's, an accelerometer's, or unknown."""
    if rec.get("accel_unit"):
        return f"{rec['accel_unit']} (an accelerometer's)"
    return rec["unit"] or "unknown (give --unit)"


def column_heads(names, width: int) -> list[str]:
    """Axis names cut to ``width`` characters for a table's heads — from the end, after an ellipsis, where cutting
    their ends leaves two alike (``field.linear_acceleration.x`` … were three heads ``field.linear_acceleration.``).

    >>> column_heads(["gx [dps]", "field.angular_velocity.x", "field.angular_velocity.y"], 12)
    ['gx [dps]', '…_velocity.x', '…_velocity.y']
    """
    heads = [nm[:width] for nm in names]
    if len(set(heads)) == len(heads):
        return heads
    return [nm if len(nm) <= width else "…" + nm[len(nm) - width + 1 :] for nm in names]


def _instant(t: float) -> str:
    """A time along the record in whole seconds, and in h from an hour on (a 25-hour log's 52050 s: 14.5 h).

    >>> _instant(1106.4), _instant(52050.0)
    ('1106 s', '52050 s (14.5 h)')
    """
    return f"{t:.0f} s" + (f" ({duration(t)})" if t >= 3600 else "")


def _adev_text(s: dict) -> list[str]:
    """The static Allan deviation: a table of τ, n and each axis's value with its interval."""
    rec, st = s["record"], s["static"]
    names = rec["axis_names"]
    au = rec["adev_unit"] or "samples' unit"
    conf = st["confidence"]
    lines = ["", f"Overlapping Allan deviation ({au}), {conf:.1%} interval as −/+ % of the value"]
    rows = []
    for i in range(len(st["tau_s"])):
        cells = []
        for k in range(len(names)):
            v, lo, hi = st["adev"][k][i], st["adev_ci_low"][k][i], st["adev_ci_high"][k][i]
            cells.append(f"{g(v):>10} (−{pct(v, lo)}/+{pct(v, hi)} %)")
        rows.append(cells)
    w = max([27] + [len(c) + 2 for cells in rows for c in cells])  # never one column run into the next
    lines.append(f"  {'tau (s)':>9} {'n':>10}  " + "".join(f"{nm:<{w}}" for nm in column_heads(names, w - 1)).rstrip())
    for tau, n, cells in zip(st["tau_s"], st["n"], rows):
        lines.append(f"  {tau:>9.4g} {n:>10}  " + "".join(c.ljust(w) for c in cells).rstrip())
    return lines


def coefficient_rows(fit: dict) -> list:
    """(term label, unit, one "value [lo, hi]" cell per axis) for each term of :func:`fit_dict`'s ``fit``: IEEE-952
    (or the accelerometer's) units where the unit is known, the fit's own otherwise; an open upper bound as ∞."""
    ieee = fit["unit_known"]
    rows = []
    for t in fit["terms"]:
        c0 = fit["axes"][0]["coefficients"][t]
        cells = []
        for ax in fit["axes"]:
            c = ax["coefficients"][t]
            v, ci = (c["ieee"], c["ieee_ci"]) if ieee else (c["value"], c["ci"])
            cells.append(f"{g(v, 3)} [{g(ci[0], 3)}, {g(ci[1] if ci[1] is not None else math.inf, 3)}]")
        rows.append((f"{t} {c0['name']}", (c0["ieee_unit"] if ieee else c0["unit"]) or "", cells))
    return rows


def _fit_text(s: dict) -> list[str]:
    """The noise model: a table of terms × axes with intervals, χ²/dof and the read-offs (or why not fitted)."""
    rec, fit = s["record"], s["fit"]
    names = rec["axis_names"]
    if fit["axes"] is None:
        return ["", f"Noise model: not fitted ({fit['error']})"] if fit["requested"] and fit["error"] else []
    ieee = fit["unit_known"]
    lines = [
        "",
        f"Noise model (IEEE 952) {_units_words(fit)}, {fit['confidence']:.1%} intervals",
        f"  {fit['model']}",
        *([] if ieee else [f"  ({CLOCK_TERMS})"]),
    ]
    rows = coefficient_rows(fit)
    # each column as wide as its widest cell and two spaces: "2.37e-05 [2.37e-05, 2.37e-05]" ran into the next
    w2 = max([26] + [len(c) + 2 for _, _, cells in rows for c in cells])
    w1 = max([25] + [len(label) + 1 for label, _, _ in rows])  # "K acceleration random walk" (26)
    lines.append(
        f"  {'term':<{w1}}{'unit':<10}" + "".join(f"{nm:<{w2}}" for nm in column_heads(names, w2 - 1)).rstrip()
    )
    for label, unit, cells in rows:
        lines.append(f"  {label:<{w1}}{unit:<10}" + "".join(c.ljust(w2) for c in cells).rstrip())
    lines.append(
        f"  {'χ²/dof':<{w1}}{'':<10}" + "".join(f"{g(ax['chi2_dof'], 3):<{w2}}" for ax in fit["axes"]).rstrip()
    )
    ro = [ax["readoffs"] for ax in fit["axes"]]
    if ieee:
        lines.append(
            f"  {'read-off N = σ(1 s)':<{w1}}{ro[0]['arw_readoff_ieee_unit']:<10}"
            + "".join(f"{g(r['arw_readoff_ieee'], 3):<{w2}}" for r in ro).rstrip()
        )
        lines.append(
            f"  {'read-off B = σmin/0.664':<{w1}}{ro[0]['bias_instability_readoff_ieee_unit']:<10}"
            + "".join(f"{g(r['bias_instability_readoff_ieee'], 3):<{w2}}" for r in ro).rstrip()
        )
    lines.append(
        f"  {'σmin (at τ)':<{w1}}{rec['adev_unit'] or '':<10}"
        + "".join(f"{g(r['adev_min'], 3) + ' (' + g(r['tau_at_min_s'], 3) + ' s)':<{w2}}" for r in ro).rstrip()
    )
    return lines


def _units_words(fit: dict) -> str:
    """The units the noise model's table is in: IEEE-952 (a gyro's), an accelerometer's, or base form."""
    if fit.get("sensor") == "accelerometer":
        return f"in the accelerometer's units (samples in {fit['accel_unit']})"
    return "in IEEE-952 units" if fit["unit_known"] else "in base form (unit unknown)"


def _dynamic_text(s: dict) -> list[str]:
    """The dynamic Allan deviation: the windows, each axis's ADEV over time, the coefficients over the windows."""
    dy, fit = s["dynamic"], s["fit"]
    lines = [
        "",
        f"Dynamic Allan deviation: window {dy['window_samples']} samples ({g(dy['window_s'])} s, "
        f"{dy['window_rule']}), hop {dy['hop_samples']} ({g(dy['hop_s'])} s, {dy['hop_rule']}); "
        f"{dy['windows']} windows × {len(dy['tau_s'])} τ ({g(dy['tau_s'][0])}–{g(dy['tau_s'][-1])} s)",
    ]
    for ax in dy["axes"]:
        ratio = g(ax["max_over_min"], 3)
        lines.append(
            f"  {ax['name']}: ADEV at τ = {g(ax['tau_s'])} s over time: median "
            f"{g(ax['adev_shortest_tau_median'])}, max {g(ax['adev_shortest_tau_max'])} at t = "
            f"{_instant(ax['t_of_max_s'])}, min {g(ax['adev_shortest_tau_min'])} at t = "
            f"{_instant(ax['t_of_min_s'])}, max/min = {ratio}"
        )
    ser = fit.get("series")
    if ser and ser["axes"] is not None:
        lines.append(
            f"  noise coefficients {_series_units(fit)} over the windows: median of all windows (one that does not "
            "resolve the term counts as 0) [min, max of those resolving it (> 0)] (windows resolving / all: theirs)"
        )
        for ax in ser["axes"]:
            parts = []
            for t, c in ax["coefficients"].items():
                if c["stats"]["windows_nonzero"] == 0:
                    continue
                st_ = c["stats"]
                parts.append(
                    f"{t} {g(st_['median'], 3)} [{g(st_['min'], 3)}, {g(st_['max'], 3)}]"
                    f"{' ' + st_['unit'] if st_['unit'] else ''} ({st_['windows_nonzero']}/{st_['windows']}"
                    + (f": {g(st_['median_resolved'], 3)})" if st_["windows_nonzero"] < st_["windows"] else ")")
                )
            lines.append(f"    {ax['name']}: " + ("; ".join(parts) or "all zero"))
    elif ser and ser["error"]:
        lines.append(f"  noise coefficients over time: not fitted ({ser['error']})")
    return lines


def _series_units(fit: dict) -> str:
    """The units of the coefficients over the windows: IEEE-952's (a gyro's), an accelerometer's, or base form."""
    if fit.get("sensor") == "accelerometer":
        return "in the accelerometer's units"
    return "in IEEE-952 units" if fit["unit"] else "(base form)"


def _refinement_text(s: dict) -> list[str]:
    """The model refinement per axis: the effects found, the curve's errors start → final, each step's
    parameters, the coefficients that moved, and what the final model still misses."""
    rec, ref = s["record"], s.get("refinement")
    if ref is None:
        return []
    lines = [
        "",
        "Model refinement (what the five-term model lacks; allanite.refine; its curve χ²/dof is the calibrated "
        "tests' GLS χ² on ~4 τ per octave, not the noise-model table's)",
    ]
    for ax in ref["axes"]:
        if ax.get("error"):
            lines.append(f"  {ax['name']}: failed (see the notes)")
            continue
        found = ", ".join(st["effect"] for st in ax["steps"]) or NOTHING_ADDED
        a, b = ax["start"], ax["final"]
        lines.append(
            f"  {ax['name']}: {found}; curve χ²/dof {g(a['chi2_dof'], 3)} → {g(b['chi2_dof'], 3)}, "
            f"RMS ADEV error {g(a['rms_adev_pct'], 3)} → {g(b['rms_adev_pct'], 3)} %" + _heldout_words(ax)
        )
        for st in ax["steps"]:
            fold = f" (one of the {st['folded_into']} family's lines)" if st.get("folded_into") else ""
            lines.append(
                f"    {st['effect']}: {step_params(st, rec['fs_hz'], rec['duration_s'], units=True, final=True)}{fold}"
            )
            lines += [f"      {t}" for t in regression_lines(st.get("regression"))]
        lines += [f"    {m['text']}" for m in ax.get("term_moves", [])]
        lines += [f"    {t}" for t in ax.get("still_missing", [])]
        lines += [f"    {d['text']}" for d in ax.get("channels_not_kept", [])]
    return lines


def _heldout_words(ax: dict) -> str:
    """ ", held-out a → b %" — the error refine decides by (the in-sample one can rise as it falls: a regression
    on a temperature 2.17 → 2.43 % in sample, 7.59 → 2.96 % held out); nothing for curve-only input."""
    a, b = ax.get("start_heldout_rms_adev_pct"), ax.get("final_heldout_rms_adev_pct")
    return "" if a is None or b is None else f", held-out {g(a, 3)} → {g(b, 3)} %"
