"""The report's HTML page: ``template.html.j2`` and ``report.css``, rendered by Jinja2.

Every number comes from the report's summary (what ``summary.json`` holds), so page and JSON cannot
disagree; this module only shapes the summary into the tables and sentences the template lays out.
"""

from __future__ import annotations

import base64
import math
from functools import lru_cache
from importlib import resources
from typing import TYPE_CHECKING, Any

from .._core import __version__
from ._regression import REGRESSION_COLUMNS, regression_row
from .fmt import CLOCK_TERMS, LONG_RECORD_S, clock, duration, g, num, step_params
from .forecasting import forecast_page
from .paper002 import page_context as paper002_page
from .settings import NOTHING_ADDED, REPORT_ESTIMATORS

if TYPE_CHECKING:
    import jinja2

__all__ = ["html_page", "page_context"]


@lru_cache(maxsize=1)
def _template() -> jinja2.Template:
    import jinja2  # where a page is written: not on ``import allanite`` (~0.1 s)

    here = resources.files(__package__)
    env = jinja2.Environment(autoescape=True, trim_blocks=False, lstrip_blocks=False, undefined=jinja2.StrictUndefined)
    return env.from_string(here.joinpath("template.html.j2").read_text(encoding="utf-8"))


@lru_cache(maxsize=1)
def _css() -> str:
    return resources.files(__package__).joinpath("report.css").read_text(encoding="utf-8")


def _table(header, rows, left: int = 1) -> dict[str, Any]:
    """A table for the template; ``header`` None for a table of label/value rows without a header row."""
    return {"header": None if header is None else list(header), "rows": [list(r) for r in rows], "left": left}


def _ci(v, ci) -> str:
    hi = ci[1] if ci[1] is not None else math.inf
    return f"{g(v)} [{g(ci[0])}, {g(hi)}]"


def _record(rec: dict) -> dict:
    src = rec["source"]
    rows: list[tuple[str, Any]] = [
        ("samples per axis", rec["samples"]),
        ("axes", f"{rec['axes']} ({', '.join(rec['axis_names'])})"),
        ("sampling rate", f"{rec['fs_hz']:g} Hz"),
        ("duration", f"{g(rec['duration_s'], 6)} s ({duration(rec['duration_s'])})"),
        ("unit", rec["unit"] or (f"{rec['accel_unit']} (an accelerometer's)" if rec.get("accel_unit") else "unknown")),
        ("input", rec["input"]),
    ]
    for key, label in (
        ("path", "file"),
        ("format", "format"),
        ("what", "description"),
        ("fs_from", "fs from"),
        ("samples_in_file", "samples in file"),
        ("seed", "seed"),
    ):
        if src.get(key) is not None:
            rows.append((label, src[key]))
    if src.get("time_column"):
        how = " (recognised by its name: none was named, nor fs given)" if src.get("time_column_recognised") else ""
        unit = f", in {src['time_unit']}" if src.get("time_unit") not in (None, "s") else ""
        rows.append(("time column", f"{src['time_column']}{unit}{how}"))
    if src.get("channels"):  # the log's other channels (a temperature): none is an axis
        used = set(src.get("channels_used") or ())
        how = " by name" if src.get("channels_recognised") else ""
        rows.append(
            (
                "channels (not axes)",
                "; ".join(
                    f"{c} ({'the refinement tried a regression on it' if c in used else 'not used'})"
                    for c in src["channels"]
                )
                + (f", recognised{how}" if how else ""),
            )
        )
    if src.get("gaps"):
        shown = "; ".join(f"{gap['duration_s']:.6g} s after sample {gap['after_sample']}" for gap in src["gaps"][:10])
        rows.append(("gaps", shown + (" …" if len(src["gaps"]) > 10 else "")))
    return _table(None, rows, left=1)


def _static(st: dict, names: list) -> dict:
    theoh = st["source"] is not None
    if theoh:
        decimated = (st.get("theo_decimation") or 1) > 1
        edf_words = (
            "Greenhall's equivalent degrees of freedom (ν) at Allan τ and Howe's Theo1 ν at TheoBR τ (bias ratio "
            f"kf = {', '.join(g(k) for k in st['kf'])}; TheoBR values belong to τ = 0.75·m/fs"
            + (
                f"; TheoBR and kf from block averages of {st['theo_decimation']} samples — Taylor & Howe's fast "
                "TheoBR — as Theo1 of the full record would cost O(N²)"
                if decimated
                else ""
            )
            + ")"
        )
    else:
        edf_words = "Greenhall's equivalent degrees of freedom (ν)"
    header = ["τ (s)", "n"] + [h for nm in names for h in (f"{nm} ADEV", "interval", "ν")]
    rows = []
    for i, tau in enumerate(st["tau_s"]):
        r = [g(tau), st["n"][i]]
        for k in range(len(names)):
            lo, hi = st["adev_ci_low"][k][i], st["adev_ci_high"][k][i]
            r += [g(st["adev"][k][i]), f"[{g(lo)}, {g(hi)}]", g(st["edf"][k][i], 3)]
        rows.append(r)
    return {
        "title": REPORT_ESTIMATORS["theoh" if theoh else "oavar"][3],
        "estimator": st["estimator"],
        "grid": st["grid"],
        "intervals": f"{st['confidence']:.1%} χ² intervals with {edf_words}",
        "table": _table(header, rows, left=0),
    }


def _model(fit: dict, names: list, au: str) -> dict:
    if fit["axes"] is None:
        return {"status": "error" if fit["requested"] else "not requested", "error": fit["error"]}
    ieee = fit["unit_known"]
    axes = fit["axes"]
    tables = []
    if ieee:
        rows = []
        for t in fit["terms"]:
            c0 = axes[0]["coefficients"][t]
            rows.append(
                [f"{t} — {c0['name']}", c0["ieee_unit"]]
                + [_ci(c["ieee"], c["ieee_ci"]) for c in (ax["coefficients"][t] for ax in axes)]
            )
            if "also" in c0:
                rows.append(
                    [f"{t} — {c0['name']}", c0["also"]["unit"]]
                    + [_ci(c["also"]["value"], c["also"]["ci"]) for c in (ax["coefficients"][t] for ax in axes)]
                )
        tables.append(_table(["term", "unit"] + names, rows, left=2))
    rows = []
    for t in fit["terms"]:
        c0 = axes[0]["coefficients"][t]
        rows.append(
            [f"{t} — {c0['name']}", c0["unit"] or "(samples' unit)·s^p"]
            + [_ci(c["value"], c["ci"]) for c in (ax["coefficients"][t] for ax in axes)]
        )
    tables.append(_table(["term", "base unit"] + names, rows, left=2))
    ro = [ax["readoffs"] for ax in axes]
    good = [
        ["χ²/dof"] + [g(ax["chi2_dof"], 4) for ax in axes],
        ["χ², dof"] + [f"{g(ax['chi2'], 4)}, {ax['dof']}" for ax in axes],
        ["p-value"] + [g(ax["p_value"], 3) for ax in axes],
        ["τ points fitted"] + [f"{len(ax['tau_s'])} ({g(ax['tau_s'][0])}–{g(ax['tau_s'][-1])} s)" for ax in axes],
        [f"σ(1 s) ({au})"]
        + [g(r["adev_at_1s"]) + (" (interpolated)" if r["adev_at_1s_interpolated"] else "") for r in ro],
        [f"σ minimum ({au}) at τ (s)"] + [f"{g(r['adev_min'])} at {g(r['tau_at_min_s'])}" for r in ro],
        [f"σmin/0.664 ({au})"] + [g(r["bias_instability_readoff"]) for r in ro],
    ]
    if ieee:
        good.append(
            [f"read-off N = σ(1 s)·√1 s ({ro[0]['arw_readoff_ieee_unit']})"] + [g(r["arw_readoff_ieee"]) for r in ro]
        )
        good.append(
            [f"read-off B = σmin/0.664 ({ro[0]['bias_instability_readoff_ieee_unit']})"]
            + [g(r["bias_instability_readoff_ieee"]) for r in ro]
        )
    methods = {ax["method"] for ax in axes}
    how = (
        "Generalized least squares with the estimates' exact covariance across τ"
        if methods == {"gls"}
        else "Weighted non-negative least squares in variance space, iteratively reweighted"
    )
    return {
        "status": "fitted",
        "method": f"{how}, on octave-spaced τ",
        "formula": fit["model"],
        "confidence": f"{fit['confidence']:.1%}",
        "tables": tables,
        "goodness": _table([""] + names, good, left=1),
        "units_note": (
            f"Coefficients in the accelerometer's units (samples in {fit['accel_unit']}: velocity random walk, bias "
            "instability, acceleration random walk); base form in the second table."
            if fit.get("sensor") == "accelerometer"
            else "Coefficients in IEEE-952 units; base form in the second table."
            if ieee
            else "The unit is unknown, so coefficients are in base form (the samples' unit and seconds); "
            + CLOCK_TERMS
            + "."
        ),
    }


def _dynamic(dy: dict, theoh: bool, au: str) -> dict:
    rows = [
        [
            ax["name"],
            g(ax["tau_s"]),
            g(ax["adev_shortest_tau_median"]),
            f"{g(ax['adev_shortest_tau_max'])} at {ax['t_of_max_s']:.0f} s",
            f"{g(ax['adev_shortest_tau_min'])} at {ax['t_of_min_s']:.0f} s",
            g(ax["max_over_min"], 3),
        ]
        for ax in dy["axes"]
    ]
    grid_words = "octave grid" if dy["grid"] == "octave" else "exponential grid"
    return {
        "title": REPORT_ESTIMATORS["theoh" if theoh else "oavar"][4],
        "window": f"{dy['window_samples']} samples ({g(dy['window_s'])} s, {dy['window_rule']})",
        "hop": f"{dy['hop_samples']} samples ({g(dy['hop_s'])} s, {dy['hop_rule']})",
        "grid": f"{dy['windows']} windows × {len(dy['tau_s'])} τ ({g(dy['tau_s'][0])}–{g(dy['tau_s'][-1])} s, "
        f"{grid_words})"
        + (f"; the last {dy['unused_samples']} samples fall after the last window" if dy.get("unused_samples") else ""),
        "method": dy["method"],
        "what": (
            "the static TheoH of its window (its own bias ratio kf and switch point)"
            if theoh
            else "the static overlapping Allan variance of its window"
        ),
        "table": _table(["axis", "τ (s)", f"median ADEV ({au})", "max at t", "min at t", "max/min"], rows, left=1),
    }


def _series(fit: dict, rec: dict) -> dict:
    ser = fit.get("series")
    if not ser or ser["axes"] is None:
        return {"status": "error" if fit["requested"] else "not requested", "error": (ser or {}).get("error")}
    long = rec["duration_s"] > LONG_RECORD_S

    def at(v, t):
        # a window centre: whole seconds (h:mm:ss on a long record) say where; the window is far wider
        return "—" if v is None else f"{g(v)} at " + (clock(t, 1.0, long=True) if long else f"{num(t, 7)} s")

    rows = []
    for ax in ser["axes"]:
        for t, c in ax["coefficients"].items():
            sc = c["stats"]
            rows.append(
                [
                    ax["name"],
                    f"{t} — {c['name']}",
                    sc["unit"] or "",
                    g(sc["median"]),
                    at(sc["min"], sc["t_of_min_s"]),
                    at(sc["max"], sc["t_of_max_s"]),
                    _resolved_count(sc),
                ]
            )
    return {
        "status": "fitted",
        "confidence": f"{ser['confidence']:.1%}",
        "units_note": ", in the accelerometer's units"
        if fit.get("sensor") == "accelerometer"
        else (", in IEEE-952 units" if fit["unit"] else " (base form)"),
        "table": _table(
            ["axis", "term", "unit", "median (unresolved = 0)", "min", "max", "windows resolved (> 0)"], rows, left=3
        ),
    }


def _resolved_count(sc: dict) -> str:
    """ "31/276 (their median 271)": how many windows resolve a term and, where some do not, those windows' median —
    beside the median of all windows, not as the typical value."""
    n, total = sc["windows_nonzero"], sc["windows"]
    return f"{n}/{total}" + (f" (their median {g(sc['median_resolved'])})" if 0 < n < total else "")


def _heldout(st: dict) -> str:
    a, b = st["before"].get("heldout_rms_adev_pct"), st["after"].get("heldout_rms_adev_pct")
    if a is None or b is None:
        return "n/a (no samples)"
    return f"{g(a, 3)} → {g(b, 3)} %"


def _axis_summary(ax: dict) -> list:
    """The summary row of one refined axis: effects added, χ²/dof and RMS error start → final, the τ fitted."""
    return [
        ax["name"],
        ", ".join(st["effect"] for st in ax["steps"]) or NOTHING_ADDED,
        f"{g(ax['start']['chi2_dof'], 3)} → {g(ax['final']['chi2_dof'], 3)}",
        f"{g(ax['start']['rms_adev_pct'], 3)} → {g(ax['final']['rms_adev_pct'], 3)} %",
        _tau_fitted(ax),
    ]


def _tau_fitted(ax: dict) -> str:
    """The τ the refinement fitted and checked the curve on: a misfit beyond its end is not what it judged."""
    lo, hi = ax["tau_from_s"], ax.get("tau_to_s")
    if lo is None:
        return "—"
    return f"{g(lo)}–{g(hi)} s" if hi is not None else f"{g(lo)} s on"


def _step_rows(name: str, st: dict, fs: float, duration_s: float) -> tuple[list, list | None]:
    """One step's row of the steps table and, for a change of noise level, its row of the changes table."""
    curve = [
        name,
        st["effect"],
        step_params(st, fs, duration_s, units=True, intervals=True),
        step_params(st, fs, duration_s, units=True, intervals=True, final=True),
        f"{g(st['before']['chi2_dof'], 3)} → {g(st['after']['chi2_dof'], 3)}",
        f"{g(st['before']['rms_adev_pct'], 3)} → {g(st['after']['rms_adev_pct'], 3)} %",
        _heldout(st),
    ]
    if "window_levels" not in st:
        return curve, None
    w = st["window_levels"]
    change = [
        name,
        step_params(st, fs, duration_s, units=True, intervals=True),
        f"{g(w['before']['chi2_dof'], 3)} → {g(w['after']['chi2_dof'], 3)}",
        _heldout({"before": w["before"], "after": w["after"]}),
    ]
    return curve, change


def _refinement_rows(axes: list, fs: float, duration_s: float) -> dict[str, list]:
    """The rows of the refinement's tables (summary, curve, change, move) and each axis's still-missing sentences."""
    rows: dict[str, list] = {"summary": [], "curve": [], "change": [], "regression": [], "move": [], "missing": []}
    for ax in axes:
        if ax.get("error"):
            rows["summary"].append([ax["name"], "failed (see the notes)", "—", "—", "—"])
            continue
        said = ax["still_missing"] + [d["text"] for d in ax.get("channels_not_kept", [])]
        rows["missing"].append({"name": ax["name"], "sentences": said, "found": bool(ax["unexplained"])})
        rows["summary"].append(_axis_summary(ax))
        rows["move"] += [[ax["name"], m["text"]] for m in ax.get("term_moves", [])]
        for st in ax["steps"]:
            curve, change = _step_rows(ax["name"], st, fs, duration_s)
            rows["curve"].append(curve)
            if change is not None:
                rows["change"].append(change)
            reg = regression_row(ax["name"], st)
            if reg is not None:
                rows["regression"].append(reg)
    return rows


def _refinement_tables(rows: dict[str, list]) -> list[dict[str, Any]]:
    """The refinement's tables for the template: the summary always, the others where they have rows."""
    tables = [
        _table(
            ["axis", "effects added", "curve χ²/dof start → final", "RMS ADEV error start → final", "τ fitted"],
            rows["summary"],
            left=2,
        )
    ]
    if rows["curve"]:
        tables.append(
            _table(
                [
                    "axis",
                    "effect",
                    "parameters at acceptance",
                    "after the final joint refit",
                    "χ²/dof before → after",
                    "RMS ADEV error before → after",
                    "held-out RMS ADEV error before → after",
                ],
                rows["curve"],
                left=4,
            )
        )
    if rows["change"]:
        tables.append(
            _table(
                [
                    "axis",
                    "change of noise level at",
                    "window-level χ²/dof: one level → levels split at every change found",
                    "held out per segment: one-level model → each segment's own",
                ],
                rows["change"],
                left=2,
            )
        )
    if rows["regression"]:
        tables.append(_table(list(REGRESSION_COLUMNS), rows["regression"], left=7))
    if rows["move"]:
        tables.append(
            _table(["axis", "a term the refinement moved outside the plain fit's interval"], rows["move"], left=2)
        )
    return tables


def _refinement(ref: dict | None, rec: dict) -> dict | None:
    if ref is None:
        return None
    rows = _refinement_rows(ref["axes"], rec["fs_hz"], rec["duration_s"])
    return {
        "candidates": ref["candidates"],
        "units": ref["units"],
        "tables": _refinement_tables(rows),
        "missing": rows["missing"],
        "chi2_note": (
            "Every step is scored on the record's own Allan curve, a component removed in time part of the model "
            "through what it changed in the curve, so each step's before is the previous step's after (χ²/dof "
            "is the calibrated tests' own: the generalised least-squares χ² of the residual on ~4 τ per octave "
            "under the exact covariance of the estimates across τ, per degree of freedom — not the noise-model "
            "table's, a fit on its own τ grid). A change of noise level leaves the record's curve as it is: it was "
            "found and is judged on the Allan variances of 16 windows along the record (their own χ² scale)."
        ),
    }


def html_page(rep: Any, images: dict, context: dict | None = None) -> str:
    """The self-contained HTML page of a report, figures embedded as data URIs; ``context``: the page's
    context made beforehand (:func:`page_context`, while the figures were drawn elsewhere)."""
    specs = {sp[0]: sp for sp in rep.figure_specs()}
    figures = {
        name: {"data": base64.b64encode(data).decode("ascii"), "title": specs[name][1], "caption": specs[name][2]}
        for name, data in images.items()
    }
    context = page_context(rep) if context is None else context
    return _template().render(**context, figures=figures).rstrip() + "\n"


def page_context(rep: Any) -> dict:
    """Everything the page shows but its figures, from the report's summary; the template compiled (Jinja2
    imported) on the first call."""
    _template()
    s = rep.summary()
    rec, st, dy, fit = s["record"], s["static"], s["dynamic"], s["fit"]
    names = rec["axis_names"]
    au = rec["adev_unit"] or "samples' unit"
    return {
        "name": rec["name"],
        "version": __version__,
        "created": s["created"],
        "css": _css(),
        "record": _record(rec),
        "notes": s["notes"],
        # allanite report's accelerometer report beside this one (cli: its folder, relative to this page)
        "accel_report": rec["source"].get("accelerometer_report"),
        "gyro_report": rec["source"].get("gyro_report"),  # and on the accelerometer's page, the gyro's
        "adev_unit": au,
        "axes": list(range(len(names))),
        "axis_names": names,
        "static": _static(st, names),
        "model": _model(fit, names, au),
        "dynamic": _dynamic(dy, st["source"] is not None, au),
        "series": _series(fit, rec),
        "refinement": _refinement(s.get("refinement"), rec),
        "forecast": forecast_page(s.get("forecast")),
        "paper002": paper002_page(s.get("paper002")),
    }
