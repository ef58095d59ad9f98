"""The report's "Coefficient forecast" section (paper 004): time-frame DAVAR, the five coefficients per
frame, and every forecasting method judged on a build/check split — as summary numbers, terminal text,
page tables and figures. :func:`run_forecast` computes it; the rest only reads its summary.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ParameterError
from ..model.timeframes import MIN_FRAME_SAMPLES, frame_for_count, frames
from .fmt import g, json_list, json_number

__all__ = [
    "check_forecast_options",
    "plan_forecast",
    "run_forecast",
    "forecast_dict",
    "forecast_text",
    "forecast_page",
    "forecast_specs",
]

#: Share of the frames that builds the model when only ``frames`` is given (paper 004: 60 of 90).
DEFAULT_BUILD_SHARE = 2 / 3


def check_forecast_options(frame, split) -> tuple[float | None, tuple[int, int] | None]:
    """Validate ``frames=`` (s) and ``forecast=`` ((build, check) or "build:check"); errors name the value."""
    fr = None
    if frame is not None:
        try:
            fr = float(frame)
        except (TypeError, ValueError):
            raise ParameterError(f"frames = {frame!r} must be a frame length in seconds") from None
        if not (np.isfinite(fr) and fr > 0):
            raise ParameterError(f"frames = {frame!r} must be a positive frame length in seconds")
    sp = None
    if split is not None:
        parts = split.split(":") if isinstance(split, str) else list(split)
        try:
            if len(parts) != 2:
                raise ValueError
            b, c = (int(str(p).strip()) for p in parts)
        except (TypeError, ValueError):
            raise ParameterError(
                f"forecast = {split!r} must be BUILD:CHECK, two whole numbers of frames (e.g. 60:30)"
            ) from None
        if b < 4:
            raise ParameterError(f"forecast = {split!r}: build = {b} frames; GM(1,1) needs at least 4")
        if c < 2:
            raise ParameterError(f"forecast = {split!r}: check = {c} frames; C and P need at least 2")
        sp = (b, c)
    return fr, sp


def plan_forecast(n: int, fs: float, frame: float | None, split: tuple[int, int] | None) -> dict:
    """Frame length, split and how they were chosen, checked against the record before anything is computed.

    ``frame`` None: the record is cut into build + check frames. ``split`` None: the first
    ``DEFAULT_BUILD_SHARE`` of the frames build, the rest check. Errors name the values."""
    rule = "given"
    if frame is None:
        if split is None:
            raise ParameterError("give frames (a frame length in s) or forecast (BUILD:CHECK), or both")
        frame = frame_for_count(n, fs, split[0] + split[1])
        rule = f"record cut into build + check = {split[0] + split[1]} frames"
    samples = int(round(frame * fs))
    if samples < MIN_FRAME_SAMPLES:
        raise ParameterError(
            f"frames = {frame:g} s is {samples} samples at {fs:g} Hz; at least {MIN_FRAME_SAMPLES} are needed "
            "for a noise-model fit per frame"
        )
    count = n // samples
    if split is None:
        b = int(round(count * DEFAULT_BUILD_SHARE))
        split = (b, count - b)
        if b < 4 or count - b < 2:
            raise ParameterError(
                f"frames = {frame:g} s gives {count} frames of the record ({n} samples); at least 6 are needed "
                "to build (4) and check (2) a forecast"
            )
    if split[0] + split[1] > count:
        raise ParameterError(
            f"forecast = {split[0]}:{split[1]} needs {split[0] + split[1]} frames, but the record "
            f"({n} samples) gives {count} frames of {frame:g} s: use shorter frames or a smaller split"
        )
    return {"frame_s": samples / fs, "frame_rule": rule, "build": split[0], "check": split[1]}


def run_forecast(x, fs, plan: dict, *, unit, input, confidence) -> tuple[list, list]:
    """Frames and forecasts of every axis: (list of TimeFrames, list of compare() tables).

    ``tau_range="auto"`` as in the rest of the report (a real sensor's shortest τ are often not white); a
    short frame holds few octaves: when thinning to octaves leaves too few τ for the five terms, every τ is
    fitted (their correlation is in the covariance)."""
    kw = dict(frame=plan["frame_s"], unit=unit, input=input, confidence=confidence, tau_range="auto")
    try:
        fr = frames(x, fs, **kw)
    except ParameterError as exc:
        if "usable τ (octave-spaced)" not in str(exc):
            raise
        fr = frames(x, fs, thin=False, **kw)
    fr = fr if isinstance(fr, list) else [fr]
    tables = [f.forecast(plan["build"], plan["check"]) for f in fr]
    return fr, tables


def forecast_dict(rep) -> dict | None:
    """The section's numbers for summary.json (None when not requested)."""
    if getattr(rep, "frames", None) is None and getattr(rep, "forecast_error", None) is None:
        return None
    if rep.frames is None:
        return {"error": rep.forecast_error, "axes": None}
    st = rep.forecast_settings
    axes = [_forecast_axis(k, f, tab, rep) for k, (f, tab) in enumerate(zip(rep.frames, rep.forecasts))]
    first = rep.frames[0]
    return {
        "error": None,
        "frame_s": first.frame_s,
        "frame_samples": first.frame_samples,
        "frame_rule": st["frame_rule"],
        "frames": first.n_frames,
        "dropped_samples": first.dropped_samples,
        "build": st["build"],
        "check": st["check"],
        "sd": rep.forecasts[0]["sd"],
        "confidence": first.series.confidence,
        "units": {t: u for t, u in first.units().items()},
        "methods": list(rep.forecasts[0]["methods"]),
        "scoring": (
            "honest: C = S2/S1 and P of the forecast against the raw check frames (C ignores a constant offset; "
            "rmse and bias show it); paper rule (paper 004 §3.2): in-sample fit over the build frames — the "
            "smoothed series for the improved model — and the forecast over the check frames together, x⁰(1) "
            "left out; grades: c_grade by paper 004 Table 2 (1: C < 0.35, 2: < 0.5, 3: < 0.65, 4), grade the "
            "joint C/P label; rmse_over_se: forecast RMSE over the RMS standard error of the frame fits in the "
            "check part (≈ 1: the forecast is as good as the frames' own estimation noise allows)"
        ),
        "axes": axes,
    }


def _forecast_axis(k: int, f, tab: dict, rep) -> dict:
    """One axis of :func:`forecast_dict`: its frames' values and intervals, what is forecastable, and every
    method's cell on every term."""
    vals, (lo, hi) = f.values(), f.intervals()
    cells: dict[str, Any] = {m: {t: _cell_dict(tab["cells"][m][t]) for t in tab["terms"]} for m in tab["methods"]}
    return {
        "axis": k,
        "name": rep.axis_names[k],
        "t_s": json_list(f.t),
        "values": {t: json_list(vals[t]) for t in f.terms},
        "ci_low": {t: json_list(lo[t]) for t in f.terms},
        "ci_high": {t: json_list(hi[t]) for t in f.terms},
        "forecastable": dict(f.forecastable),
        "frames_at_zero": {t: int(np.count_nonzero(f.series.values[t] <= 0)) for t in f.terms},
        "not_forecastable": {t: tab["skipped"].get(t, f.not_forecastable.get(t)) for t in tab["skipped"]},
        "terms": list(tab["terms"]),
        "scatter": {t: json_number(v) for t, v in tab["scatter"].items()},
        "se_check": {t: json_number(v) for t, v in tab["se_check"].items()},
        "cells": cells,
    }


def _cell_dict(c: dict) -> dict:
    """One method's score on one term (or its error) for summary.json."""
    if "error" in c:
        return {"error": c["error"]}
    return {
        "C": json_number(c["C"]),
        "P": json_number(c["P"]),
        "c_grade": c["c_grade"],
        "grade": c["grade"],
        "C_paper": json_number(c["C_paper"]),
        "P_paper": json_number(c["P_paper"]),
        "c_grade_paper": c["c_grade_paper"],
        "grade_paper": c["grade_paper"],
        "rmse": json_number(c["rmse"]),
        "bias": json_number(c["bias"]),
        "rmse_over_se": json_number(c.get("rmse_over_se")),
        "forecast": json_list(c["forecast"]),
    }


def _f2(v) -> str:
    """Two decimals; None (a non-finite C in the JSON) as ∞."""
    return "∞" if v is None else f"{v:.2f}"


def _cell_text(c: dict) -> str:
    if "error" in c:
        return "error"
    return f"{_f2(c['C'])} ({c['c_grade']}) P {_f2(c['P'])}"


def forecast_text(d: dict | None) -> list[str]:
    """Terminal lines of the section."""
    if d is None:
        return []
    if d["axes"] is None:
        return ["", f"Coefficient forecast: not computed ({d['error']})"]
    lines = [
        "",
        f"Coefficient forecast (paper 004): {d['frames']} frames of {g(d['frame_s'])} s, build {d['build']} / "
        f"check {d['check']}; honest C (Table 2 grade) and P vs the raw check frames [paper-rule C]",
    ]
    for ax in d["axes"]:
        if not ax["terms"]:
            lines.append(f"  {ax['name']}: no term resolved in every frame; nothing forecastable")
        for t in ax["terms"]:
            parts = []
            for m in d["methods"]:
                c = ax["cells"][m][t]
                paper = "" if "error" in c else f" [{_f2(c['C_paper'])}]"
                parts.append(f"{m} {_cell_text(c)}{paper}")
            lines.append(f"  {ax['name']} {t}: " + "; ".join(parts))
        if ax["not_forecastable"]:
            zeros = ", ".join(f"{t} {ax['frames_at_zero'][t]}" for t in ax["not_forecastable"])
            lines.append(
                f"  {ax['name']}: not forecastable (not resolved in every frame; frames at 0 of {d['frames']}: {zeros})"
            )
    return lines


def forecast_page(d: dict | None) -> dict | None:
    """Tables and sentences for the template."""
    if d is None:
        return None
    if d["axes"] is None:
        return {"status": "error", "error": d["error"]}
    tables = []
    skipped = []
    for ax in d["axes"]:
        terms = ax["terms"]
        if terms:
            rows = []
            for m in d["methods"]:
                row = [m]
                for t in terms:
                    c = ax["cells"][m][t]
                    row.append(
                        "error"
                        if "error" in c
                        else f"{_f2(c['C'])} ({c['c_grade']}) / {_f2(c['P'])} · paper {_f2(c['C_paper'])} "
                        f"({c['c_grade_paper']}) · rmse/SE {_f2(c['rmse_over_se'])}"
                    )
                rows.append(row)
            tables.append(
                {
                    "title": ax["name"],
                    "table": {"header": ["method"] + terms, "rows": rows, "left": 1},
                }
            )
        if ax["not_forecastable"]:
            skipped.append(
                f"{ax['name']}: "
                + ", ".join(
                    f"{t} (at 0 in {ax['frames_at_zero'][t]} of {d['frames']} frames)" for t in ax["not_forecastable"]
                )
            )
    return {
        "status": "computed",
        "intro": (
            f"{d['frames']} consecutive frames of {g(d['frame_s'])} s ({d['frame_samples']} samples; "
            f"{d['frame_rule']}), "
            f"the noise model fitted in each; the first {d['build']} frames build each method, the next "
            f"{d['check']} check it. Cells: honest C (paper 004 Table 2 grade) / P against the raw check frames · "
            f"C (grade) by paper 004's own rule · forecast RMSE over the frame fits' standard error."
        ),
        "tables": tables,
        "skipped": skipped,
        "scoring": d["scoring"],
    }


def forecast_specs(rep) -> list:
    """(file name, title, caption, size, draw) of the section's figures: per axis, the frames with their
    intervals (paper 004 Fig. 3) and the forecasts (Fig. 3–4)."""
    if getattr(rep, "frames", None) is None:
        return []
    specs = []
    for k, (f, tab) in enumerate(zip(rep.frames, rep.forecasts)):
        name = rep.axis_names[k]
        shown = [t for t in f.terms if np.any(f.series.values[t] > 0)] or list(f.terms)

        def draw_frames(fig, f=f, shown=shown, name=name):
            axs = fig.subplots(len(shown), 1, sharex=True, squeeze=False)[:, 0]
            f.plot(axes=list(axs), terms=shown)
            axs[0].set_title(f"{name}: noise coefficients per {f.frame_s:g} s frame")
            fig.subplots_adjust(left=0.14, right=0.975, bottom=0.5 / fig.get_figheight(), top=0.92, hspace=0.15)

        specs.append(
            (
                f"frames_axis{k}.png",
                f"{name}: coefficients per frame",
                "Time-frame DAVAR (paper 004 Fig. 3): each resolved term per frame with its interval band.",
                (7.5, 1.2 + 1.5 * len(shown)),
                draw_frames,
            )
        )
        if tab["terms"]:

            def draw_fc(fig, f=f, tab=tab, name=name):
                axs = fig.subplots(len(tab["terms"]), 1, sharex=True, squeeze=False)[:, 0]
                f.plot_forecast(tab, axes=list(axs))
                axs[0].set_title(f"{name}: GM(1,1) forecasts of the coefficients")
                fig.subplots_adjust(left=0.14, right=0.975, bottom=0.5 / fig.get_figheight(), top=0.92, hspace=0.15)

            specs.append(
                (
                    f"forecast_axis{k}.png",
                    f"{name}: coefficient forecast",
                    "Per-frame values (grey), the improved model's wavelet-smoothed build series (green, paper "
                    "004 Fig. 4), each GM(1,1)'s in-sample fit (dashed) and forecast (solid); dotted: the split.",
                    (7.5, 1.2 + 1.9 * len(tab["terms"])),
                    draw_fc,
                )
            )
    return specs
